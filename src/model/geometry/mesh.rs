//! Mesh vertices as MuJoCo reads them, for bounds.
//!
//! MuJoCo (XMLreference, asset/mesh) loads binary STL, OBJ and its own MSH format, or the
//! inline `vertex` list, then applies the asset's transform in this order (compiler's
//! `mjCMesh::ApplyTransformations`): subtract `refpos`, rotate by the conjugate of the
//! normalized `refquat`, multiply by `scale` per axis. Coordinates are stored as 32-bit
//! floats, so they are rounded to `f32` on reading, as MuJoCo does. Faces, normals and
//! texture coordinates do not move the extent and are not read. ASCII STL, which MuJoCo
//! does not load, is read too, for tools that make such files.
//!
//! MuJoCo then re-centres every mesh at its centre of mass and principal axes and moves
//! the referencing geom's frame by the same transform; the two cancel, so the vertices
//! here placed with the geom's written pose are where MuJoCo puts them.

use std::path::Path;

use super::frame::quat_to_mat;
use super::{err_at, exact, numbers};
use crate::document::tree::Node;
use crate::document::{Document, Section};
use crate::error::Error;

/// The `<mesh>` asset that a geom's `mesh` attribute names: by its `name`, or, for an
/// unnamed mesh, by its file name without folder and extension (MuJoCo's rule).
///
/// ```
/// let doc = mjcf_forge::Document::from_str(
///     r#"<mujoco><asset><mesh vertex="0 0 0 1 0 0 0 1 0 0 0 1"/>
///        <mesh name="tet" vertex="0 0 0 2 0 0 0 2 0 0 0 2"/></asset></mujoco>"#, ".")?;
/// let tet = mjcf_forge::geometry::find_mesh(&doc, "tet").unwrap();
/// assert_eq!(doc.attr(tet, "name"), Some("tet"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn find_mesh(doc: &Document, name: &str) -> Option<Node> {
    let asset = doc.find_section(Section::Asset)?;
    doc.elements(asset)
        .filter(|&n| doc.tag(n) == "mesh")
        .find(|&n| mesh_name(doc, n).as_deref() == Some(name))
}

/// The name a mesh asset goes by.
pub(super) fn mesh_name(doc: &Document, mesh: Node) -> Option<String> {
    if let Some(n) = doc.attr(mesh, "name") {
        return Some(n.to_string());
    }
    let file = doc.attr(mesh, "file")?;
    let base = file.rsplit(['/', '\\']).next().unwrap_or(file);
    Some(base.rfind('.').map_or(base, |dot| &base[..dot]).to_string())
}

/// The vertices of a `<mesh>` asset in the mesh's own frame, after its `refpos`,
/// `refquat` and `scale`: from its `file` (binary or ASCII STL, OBJ, MSH; the type from
/// `content_type` if given, else the extension) or its inline `vertex` list. Built-in
/// (`builtin`) and plugin meshes are refused.
///
/// ```
/// let doc = mjcf_forge::Document::from_str(
///     r#"<mujoco><asset><mesh name="m" scale="2 1 1" refpos="1 0 0"
///          vertex="1 0 0  2 0 0  1 1 0  1 0 1"/></asset></mujoco>"#, ".")?;
/// let mesh = mjcf_forge::geometry::find_mesh(&doc, "m").unwrap();
/// let v = mjcf_forge::geometry::mesh_vertices(&doc, mesh)?;
/// assert_eq!(v[1], [2.0, 0.0, 0.0]); // (2 - 1) * 2
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn mesh_vertices(doc: &Document, mesh: Node) -> Result<Vec<[f64; 3]>, Error> {
    let raw: Vec<[f32; 3]> = if let Some(file) = doc.attr(mesh, "file") {
        let kind = match doc.attr(mesh, "content_type").map(str::trim) {
            Some("model/stl") => "stl".to_string(),
            Some("model/obj") => "obj".to_string(),
            Some("model/vnd.mujoco.msh") => "msh".to_string(),
            Some(other) => {
                return Err(err_at(
                    doc,
                    mesh,
                    format_args!("unsupported content_type '{other}'"),
                ));
            }
            None => Path::new(file)
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase())
                .unwrap_or_default(),
        };
        // Only a regular file within the size limit: a mesh naming a FIFO or a device must
        // not hang or fill memory.
        let bytes =
            crate::document::limits::read_regular_file(Path::new(file), doc.limits.max_file_size)
                .map_err(|e| err_at(doc, mesh, format_args!("cannot read '{file}': {e}")))?;
        let parsed = match kind.as_str() {
            "stl" => read_stl(&bytes),
            "obj" => read_obj(&bytes),
            "msh" => read_msh(&bytes),
            other => Err(format!(
                "unknown mesh file type '{other}' (MuJoCo reads stl, obj, msh)"
            )),
        };
        parsed.map_err(|e| err_at(doc, mesh, format_args!("'{file}': {e}")))?
    } else if let Some(v) = numbers(doc, mesh, "vertex")? {
        if v.len() % 3 != 0 {
            return Err(err_at(doc, mesh, "vertex data must be a multiple of 3"));
        }
        v.chunks_exact(3)
            .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32])
            .collect()
    } else if doc.attr(mesh, "builtin").is_some() {
        return Err(err_at(doc, mesh, "built-in meshes are not supported"));
    } else {
        return Err(err_at(
            doc,
            mesh,
            "mesh has neither 'file' nor 'vertex' (plugin meshes are not supported)",
        ));
    };
    if raw.is_empty() {
        return Err(err_at(doc, mesh, "mesh has no vertices"));
    }
    let refpos = exact::<3>(doc, mesh, "refpos")?.unwrap_or_default();
    let refquat = exact::<4>(doc, mesh, "refquat")?.unwrap_or([1.0, 0.0, 0.0, 0.0]);
    let scale = exact::<3>(doc, mesh, "scale")?.unwrap_or([1.0; 3]);
    let qn = refquat.iter().map(|x| x * x).sum::<f64>().sqrt();
    if qn < 1e-14 {
        return Err(err_at(doc, mesh, "refquat is zero"));
    }
    let rot = (refquat != [1.0, 0.0, 0.0, 0.0]).then(|| quat_to_mat(refquat.map(|x| x / qn)));
    Ok(raw
        .into_iter()
        .map(|v| {
            let p = [
                f64::from(v[0]) - refpos[0],
                f64::from(v[1]) - refpos[1],
                f64::from(v[2]) - refpos[2],
            ];
            // R^T p: the conjugate of refquat.
            let p = match rot {
                Some(m) => [
                    m[0][0] * p[0] + m[1][0] * p[1] + m[2][0] * p[2],
                    m[0][1] * p[0] + m[1][1] * p[1] + m[2][1] * p[2],
                    m[0][2] * p[0] + m[1][2] * p[1] + m[2][2] * p[2],
                ],
                None => p,
            };
            [p[0] * scale[0], p[1] * scale[1], p[2] * scale[2]]
        })
        .collect())
}

fn f32_at(bytes: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// STL: binary when the size matches the triangle count in the header (a binary header
/// may itself start with "solid"), else ASCII.
fn read_stl(bytes: &[u8]) -> Result<Vec<[f32; 3]>, String> {
    if bytes.len() >= 84 {
        let n = u32_at(bytes, 80) as usize;
        if n.checked_mul(50).and_then(|b| b.checked_add(84)) == Some(bytes.len()) {
            let mut out = Vec::with_capacity(3 * n);
            for tri in bytes[84..].chunks_exact(50) {
                for at in [12, 24, 36] {
                    out.push([f32_at(tri, at), f32_at(tri, at + 4), f32_at(tri, at + 8)]);
                }
            }
            return Ok(out);
        }
    }
    let text = std::str::from_utf8(bytes).map_err(|_| {
        "neither a binary STL (size does not match its triangle count) nor ASCII".to_string()
    })?;
    if !text.trim_start().starts_with("solid") {
        return Err("binary STL size does not match its triangle count".into());
    }
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_ascii_whitespace();
        if words.next() == Some("vertex") {
            out.push(three(words, i)?);
        }
    }
    Ok(out)
}

/// Three numbers from a line's words, as `f32` (what MuJoCo keeps).
fn three<'a>(mut words: impl Iterator<Item = &'a str>, line: usize) -> Result<[f32; 3], String> {
    let mut v = [0f32; 3];
    for slot in &mut v {
        let w = words
            .next()
            .ok_or_else(|| format!("line {}: a vertex needs 3 coordinates", line + 1))?;
        *slot = w
            .parse::<f32>()
            .map_err(|_| format!("line {}: '{w}' is not a number", line + 1))?;
    }
    Ok(v)
}

/// OBJ: every `v x y z [w | r g b]` line is a vertex.
fn read_obj(bytes: &[u8]) -> Result<Vec<[f32; 3]>, String> {
    let text = String::from_utf8_lossy(bytes);
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        // Most lines are faces and normals: look at the first bytes before splitting.
        if line.starts_with("v ") || line.starts_with("v\t") {
            out.push(three(line[2..].split_ascii_whitespace(), i)?);
        }
    }
    Ok(out)
}

/// MSH (MuJoCo's legacy binary): int32 nvertex, nnormal, ntexcoord, nface, then float32
/// positions; the size must be exactly 16 + 12 (nvertex + nnormal + nface) + 8 ntexcoord.
fn read_msh(bytes: &[u8]) -> Result<Vec<[f32; 3]>, String> {
    if bytes.len() < 16 {
        return Err("MSH file shorter than its 16-byte header".into());
    }
    let count = |k: usize| {
        i32::from_le_bytes([
            bytes[4 * k],
            bytes[4 * k + 1],
            bytes[4 * k + 2],
            bytes[4 * k + 3],
        ])
    };
    let [nv, nn, nt, nf] = [count(0), count(1), count(2), count(3)];
    if [nv, nn, nt, nf].iter().any(|&c| c < 0) {
        return Err("MSH header has a negative count".into());
    }
    let [nv, nn, nt, nf] = [nv, nn, nt, nf].map(|c| c as usize);
    let expected = 16 + 12 * (nv + nn + nf) + 8 * nt;
    if bytes.len() != expected {
        return Err(format!(
            "MSH file has {} bytes, its header says {expected}",
            bytes.len()
        ));
    }
    Ok((0..nv)
        .map(|i| 16 + 12 * i)
        .map(|at| {
            [
                f32_at(bytes, at),
                f32_at(bytes, at + 4),
                f32_at(bytes, at + 8),
            ]
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binary_stl(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = b"solid but actually binary".to_vec();
        b.resize(80, 0);
        b.extend((tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend([0u8; 12]);
            for v in t {
                v.iter().for_each(|c| b.extend(c.to_le_bytes()));
            }
            b.extend([0u8; 2]);
        }
        b
    }

    #[test]
    fn binary_stl_starting_with_solid_is_read_as_binary() {
        let tri = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.5]];
        let v = read_stl(&binary_stl(&[tri, tri])).unwrap();
        assert_eq!(v.len(), 6);
        assert_eq!(v[2], [7.0, 8.0, 9.5]);
    }

    #[test]
    fn ascii_stl() {
        let text = "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1e-1 0\n  endloop\n endfacet\nendsolid t\n";
        assert_eq!(
            read_stl(text.as_bytes()).unwrap(),
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.1, 0.0]]
        );
        assert!(read_stl(b"junk that is not an stl").is_err());
    }

    #[test]
    fn obj_reads_v_lines_only() {
        let text =
            "# c\nv 1 2 3\nvn 0 0 1\nvt 0.5 0.5\nv -1 -2 -3 1.0\nv 0 0 0 0.1 0.2 0.3\nf 1 2 3\n";
        assert_eq!(
            read_obj(text.as_bytes()).unwrap(),
            vec![[1.0, 2.0, 3.0], [-1.0, -2.0, -3.0], [0.0; 3]]
        );
        assert!(read_obj(b"v 1 2\n").unwrap_err().contains("line 1"));
    }

    #[test]
    fn msh_checks_its_size() {
        let mut b = Vec::new();
        [2i32, 0, 0, 0]
            .iter()
            .for_each(|c| b.extend(c.to_le_bytes()));
        [1f32, 2.0, 3.0, 4.0, 5.0, 6.0]
            .iter()
            .for_each(|c| b.extend(c.to_le_bytes()));
        assert_eq!(
            read_msh(&b).unwrap(),
            vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
        );
        b.push(0);
        assert!(read_msh(&b).unwrap_err().contains("header says 40"));
    }

    #[test]
    fn refquat_rotates_by_its_conjugate_after_refpos_and_before_scale() {
        let doc = Document::from_str(
            r#"<mujoco><asset><mesh name="m" refpos="1 0 0" refquat="0.7071067811865476 0 0 0.7071067811865476"
                 scale="1 3 1" vertex="2 0 0  1 1 0  1 0 1  1 0 0"/></asset></mujoco>"#,
            ".",
        )
        .unwrap();
        let v = mesh_vertices(&doc, find_mesh(&doc, "m").unwrap()).unwrap();
        // (1,0,0) turned by -90 degrees about z is (0,-1,0); then y scaled by 3.
        assert!(
            (v[0][1] + 3.0).abs() < 1e-12 && v[0][0].abs() < 1e-12,
            "{v:?}"
        );
    }

    #[test]
    fn unnamed_meshes_go_by_file_stem() {
        let doc = Document::from_str(
            r#"<mujoco><asset><mesh file="/x/y/Part.v2.STL"/></asset></mujoco>"#,
            ".",
        )
        .unwrap();
        assert!(find_mesh(&doc, "Part.v2").is_some());
    }
}
