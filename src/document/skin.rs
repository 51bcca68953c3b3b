//! Skin files (MuJoCo's binary SKN format) name their bone bodies inside the file, so a
//! model whose bodies are renamed needs those names rewritten: the file's content is
//! written into the `<skin>` element itself (vertex, texcoord, face and `<bone>` children),
//! with every number kept exactly (the file's float32 values, printed so they read back
//! bit for bit).

use crate::document::Document;
use crate::document::tree::Node;
use crate::error::{Error, ErrorKind};

/// The content of an SKN file.
struct Skn {
    vertex: Vec<f32>,
    texcoord: Vec<f32>,
    face: Vec<i32>,
    bones: Vec<Bone>,
}

struct Bone {
    body: String,
    bindpos: [f32; 3],
    bindquat: [f32; 4],
    vertid: Vec<i32>,
    vertweight: Vec<f32>,
}

struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Cursor<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| "file is shorter than its header says".to_string())?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn i32(&mut self) -> Result<i32, String> {
        let b = self.take(4)?;
        Ok(i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn f32(&mut self) -> Result<f32, String> {
        let b = self.take(4)?;
        Ok(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn count(&mut self) -> Result<usize, String> {
        let n = self.i32()?;
        usize::try_from(n).map_err(|_| format!("negative count {n}"))
    }

    fn f32s(&mut self, n: usize) -> Result<Vec<f32>, String> {
        (0..n).map(|_| self.f32()).collect()
    }

    fn i32s(&mut self, n: usize) -> Result<Vec<i32>, String> {
        (0..n).map(|_| self.i32()).collect()
    }
}

fn parse_skn(bytes: &[u8]) -> Result<Skn, String> {
    let mut c = Cursor { bytes, at: 0 };
    let nvert = c.count()?;
    let ntex = c.count()?;
    let nface = c.count()?;
    let nbone = c.count()?;
    let vertex = c.f32s(3 * nvert)?;
    let texcoord = c.f32s(2 * ntex)?;
    let face = c.i32s(3 * nface)?;
    // The count is the file's word: reserve no more than its remaining bytes can hold (a
    // bone takes at least 72), or a hostile header reserves gigabytes.
    let mut bones = Vec::with_capacity(nbone.min((bytes.len() - c.at) / 72));
    for _ in 0..nbone {
        let raw = c.take(40)?;
        let end = raw.iter().position(|&b| b == 0).unwrap_or(raw.len());
        let body = String::from_utf8_lossy(&raw[..end]).into_owned();
        let bindpos = [c.f32()?, c.f32()?, c.f32()?];
        let bindquat = [c.f32()?, c.f32()?, c.f32()?, c.f32()?];
        let n = c.count()?;
        let vertid = c.i32s(n)?;
        let vertweight = c.f32s(n)?;
        bones.push(Bone {
            body,
            bindpos,
            bindquat,
            vertid,
            vertweight,
        });
    }
    if c.at != bytes.len() {
        return Err(format!("{} bytes after the last bone", bytes.len() - c.at));
    }
    Ok(Skn {
        vertex,
        texcoord,
        face,
        bones,
    })
}

/// float32 attributes: the shortest text that reads back as the same float32.
fn f32_list(v: &[f32]) -> String {
    v.iter()
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// double attributes fed from float32 data: the float32's exact value as a double.
fn f32_as_f64_list(v: &[f32]) -> String {
    v.iter()
        .map(|&x| format!("{}", f64::from(x)))
        .collect::<Vec<_>>()
        .join(" ")
}

fn i32_list(v: &[i32]) -> String {
    v.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

impl Document {
    /// Writes the content of every skin file into its `<skin>` element (see module docs).
    pub(crate) fn inline_skin_files(&mut self) -> Result<(), Error> {
        let skins: Vec<Node> = self
            .descendants(self.root)
            .filter(|&n| self.tag(n) == "skin" && self.attr(n, "file").is_some())
            .filter(|&n| {
                self.parent(n)
                    .is_some_and(|p| matches!(self.tag(p), "asset" | "deformable"))
            })
            .collect();
        for skin in skins {
            let file = self.attr(skin, "file").unwrap_or_default().to_string();
            let bad = |reason: String| ErrorKind::Invalid(format!("skin file '{file}': {reason}"));
            let bytes = crate::document::limits::read_regular_file(
                std::path::Path::new(&file),
                self.limits.max_file_size,
            )
            .map_err(|e| self.error_at(skin, bad(e)))?;
            let skn = parse_skn(&bytes).map_err(|e| self.error_at(skin, bad(e)))?;
            self.remove_attr(skin, "file");
            self.set_attr(skin, "vertex", &f32_list(&skn.vertex));
            if !skn.texcoord.is_empty() {
                self.set_attr(skin, "texcoord", &f32_list(&skn.texcoord));
            }
            self.set_attr(skin, "face", &i32_list(&skn.face));
            for bone in &skn.bones {
                self.append_element(
                    skin,
                    "bone",
                    &[
                        ("body", &bone.body),
                        ("bindpos", &f32_as_f64_list(&bone.bindpos)),
                        ("bindquat", &f32_as_f64_list(&bone.bindquat)),
                        ("vertid", &i32_list(&bone.vertid)),
                        ("vertweight", &f32_list(&bone.vertweight)),
                    ],
                );
            }
        }
        Ok(())
    }
}
