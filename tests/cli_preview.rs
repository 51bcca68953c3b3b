//! `mjcf-forge preview` (cargo feature `mujoco`, and a headless OpenGL: EGL or OSMesa):
//! the contact sheet is a real picture, its cells differ where the variants differ and are
//! the same where they do not, and every placed object of a variant is drawn in its cell
//! (segmentation of the same cells, checked against the objects the variant placed).
//!
//! Pass: once per MuJoCo the feature `mujoco` links (scripts/test.sh: 3.17.0 and 4.0.0),
//! since what it checks depends on that MuJoCo; the build without the feature runs the
//! tests here that need none (they are cheap: not worth a file of their own).

mod common;

use common::{forge, path_arg, scratch, stderr};

/// A build without MuJoCo says so and writes nothing.
#[cfg(not(mjcf_mujoco))]
#[test]
fn preview_needs_the_mujoco_feature() {
    let dir = scratch("cli_preview_no_mujoco");
    let out_path = dir.join("sheet.png");
    let out = forge(&["preview", "-n", "2", "-o", path_arg(&out_path)]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("built without the `mujoco` feature; rebuild with --features mujoco"),
        "{}",
        stderr(&out)
    );
    assert!(!out_path.exists());
}

#[cfg(mjcf_mujoco)]
mod with_mujoco {
    use std::collections::BTreeSet;
    use std::path::Path;

    use super::{forge, path_arg, scratch, stderr};
    use crate::common::root;
    use mjcf_forge::mujoco::{ObjType, compile_document};
    use mjcf_forge::preview::{GAP, Geoms, Layout, SheetOptions, segment_cells};
    use mjcf_forge::scene::Scene;

    /// A PNG file's width, height and RGB bytes.
    fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
        let decoder = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(path).expect("the sheet was written"),
        ));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        buf.truncate(info.buffer_size());
        (info.width, info.height, buf)
    }

    /// Cell `k`'s bytes.
    fn cell(rgb: &[u8], sheet_width: u32, layout: &Layout, k: usize) -> Vec<u8> {
        let (x, y) = layout.cell_origin(k);
        let mut out = Vec::new();
        for row in y..y + layout.cell_height {
            let at = (row as usize * sheet_width as usize + x as usize) * 3;
            out.extend_from_slice(&rgb[at..at + layout.cell_width as usize * 3]);
        }
        out
    }

    fn variance(bytes: &[u8]) -> f64 {
        let n = bytes.len() as f64;
        let mean = bytes.iter().map(|&b| f64::from(b)).sum::<f64>() / n;
        bytes
            .iter()
            .map(|&b| (f64::from(b) - mean).powi(2))
            .sum::<f64>()
            / n
    }

    #[test]
    fn cells_differ_where_variants_differ() {
        let dir = scratch("cli_preview_cells");
        let sheet = dir.join("sheet.png");
        let out = forge(&[
            "preview",
            "corpora/scenes/demo/demo.toml",
            "--indices",
            "0,1,1,5",
            "--cell",
            "160x120",
            "--columns",
            "3",
            "-o",
            path_arg(&sheet),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        let (w, h, rgb) = read_png(&sheet);
        let layout = Layout::new(4, 160, 120, Some(3));
        assert_eq!((w, h), (3 * 160 + 2 * GAP, 2 * 120 + GAP));
        assert_eq!((w, h), (layout.width(), layout.height()));

        // A picture, not a cleared buffer; every cell too.
        assert!(variance(&rgb) > 100.0, "variance {}", variance(&rgb));
        let cells: Vec<Vec<u8>> = (0..4).map(|k| cell(&rgb, w, &layout, k)).collect();
        for (k, c) in cells.iter().enumerate() {
            assert!(variance(c) > 100.0, "cell {k}: variance {}", variance(c));
        }
        // The same variant twice: the same pixels (label included); others differ, in
        // more than their labels.
        assert!(cells[1] == cells[2], "index 1 drawn twice differs");
        for (a, b) in [(0, 1), (0, 3), (1, 3)] {
            let differing = cells[a]
                .chunks(3)
                .zip(cells[b].chunks(3))
                .filter(|(p, q)| p != q)
                .count();
            assert!(
                differing > 160 * 120 / 10,
                "cells {a} and {b}: only {differing} pixels differ"
            );
        }
        // The unused cell of the grid is the gap colour.
        let empty = cell(&rgb, w, &layout, 5);
        assert!(empty.chunks(3).all(|p| p == [32, 32, 32]));
    }

    #[test]
    fn a_named_camera_and_errors() {
        let dir = scratch("cli_preview_camera");
        let sheet = dir.join("sheet.png");
        let front = forge(&[
            "preview",
            "corpora/scenes/demo/demo.toml",
            "-n",
            "2",
            "--cell",
            "120x90",
            "--camera",
            "front",
            "--geoms",
            "collision",
            "-o",
            path_arg(&sheet),
        ]);
        assert!(front.status.success(), "{}", stderr(&front));
        let (w, h, rgb) = read_png(&sheet);
        assert_eq!((w, h), (2 * 120 + GAP, 90));
        assert!(variance(&rgb) > 100.0);

        // An unknown camera: the scene, the variant and the cameras there are; no file.
        let bad = dir.join("bad.png");
        let out = forge(&[
            "preview",
            "corpora/scenes/demo/demo.toml",
            "-n",
            "1",
            "--camera",
            "back",
            "-o",
            path_arg(&bad),
        ]);
        assert_eq!(out.status.code(), Some(1));
        assert_eq!(
            stderr(&out).trim(),
            "corpora/scenes/demo/demo.toml: variant 0: the model has no camera named 'back' \
             (its cameras: front)"
        );
        assert!(!bad.exists());
        for args in [
            vec!["preview", "-n", "0", "-o", path_arg(&bad)],
            vec!["preview", "--cell", "0x10", "-o", path_arg(&bad)],
            vec!["preview", "--geoms", "some", "-o", path_arg(&bad)],
        ] {
            let out = forge(&args);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
            assert!(!bad.exists(), "{args:?}");
        }
    }

    /// Every object a variant placed has pixels in its cell: segmentation of the sheet's
    /// cells (same camera, same geoms), each pixel's geom mapped to its body, and each
    /// placed object's root body and its descendants looked for.
    fn every_placed_object_is_drawn(scene: &Scene, indices: &[u64], options: &SheetOptions) {
        let cells = segment_cells(scene, indices, options).unwrap();
        for (&index, seg) in indices.iter().zip(&cells) {
            let v = scene.variant(index).unwrap();
            let model = compile_document(&v.document).unwrap();
            let bodies = model.names(ObjType::Body);
            let parent = model.body_parentid();
            let geom_body = model.geom_bodyid();
            let drawn: BTreeSet<i32> = seg.iter().copied().filter(|&g| g >= 0).collect();
            assert!(drawn.len() > 3, "variant {index}: only {drawn:?} drawn");
            assert!(!v.params.objects.is_empty());
            for object in &v.params.objects {
                let root = bodies.iter().position(|b| *b == object.body).unwrap() as i32;
                let under = |mut b: i32| loop {
                    if b == root {
                        return true;
                    }
                    if b == 0 {
                        return false;
                    }
                    b = parent[b as usize];
                };
                let pixels = seg
                    .iter()
                    .filter(|&&g| g >= 0 && under(geom_body[g as usize]))
                    .count();
                assert!(
                    pixels > 0,
                    "variant {index}: object {} ({}) has no pixel in its cell",
                    object.body,
                    object.model
                );
            }
        }
    }

    #[test]
    fn every_placed_object_is_drawn_in_its_cell_demo() {
        let scene = Scene::load(root().join("corpora/scenes/demo/demo.toml")).unwrap();
        let options = SheetOptions::default();
        every_placed_object_is_drawn(&scene, &[0, 1, 2, 3, 4, 5], &options);
        let front = SheetOptions {
            camera: Some("front".into()),
            geoms: Geoms::Visual,
            ..SheetOptions::default()
        };
        every_placed_object_is_drawn(&scene, &[6, 7], &front);
    }

    #[test]
    fn every_placed_object_is_drawn_in_its_cell_lift5() {
        assert!(
            root().join(".cache/corpus/robosuite-1.5.2").is_dir(),
            ".cache/corpus/robosuite-1.5.2 is missing: run scripts/setup.sh first"
        );
        let scene = Scene::load(root().join("benches/scenes/lift5.toml")).unwrap();
        every_placed_object_is_drawn(&scene, &[0, 1, 2], &SheetOptions::default());
        let agent = SheetOptions {
            camera: Some("agentview".into()),
            ..SheetOptions::default()
        };
        every_placed_object_is_drawn(&scene, &[3], &agent);
    }
}
