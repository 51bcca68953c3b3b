//! A cell's label: its variant's index in small bitmap digits, white on a darkened box in
//! the top left corner. Drawn on the pixels, not by a renderer's font, so that both faces
//! (the command line over the linked MuJoCo, Python over the user's) label alike.

use super::image::Image;

/// 3x5 digits, a row per string, `#` lit.
const DIGITS: [[&[u8; 3]; 5]; 10] = [
    [b"###", b"#.#", b"#.#", b"#.#", b"###"],
    [b".#.", b"##.", b".#.", b".#.", b"###"],
    [b"###", b"..#", b"###", b"#..", b"###"],
    [b"###", b"..#", b"###", b"..#", b"###"],
    [b"#.#", b"#.#", b"###", b"..#", b"..#"],
    [b"###", b"#..", b"###", b"..#", b"###"],
    [b"###", b"#..", b"###", b"#.#", b"###"],
    [b"###", b"..#", b"..#", b"..#", b"..#"],
    [b"###", b"#.#", b"###", b"#.#", b"###"],
    [b"###", b"#.#", b"###", b"..#", b"###"],
];

/// How much the box behind a label keeps of the pixels under it.
const DARKEN: f64 = 0.3;

/// The size of a digit's pixel in a cell of `width` x `height`: one screen pixel per 60 of
/// the cell's shorter side, at least 1.
///
/// ```
/// use mjcf_forge::sheet::label_scale;
/// assert_eq!((label_scale(320, 240), label_scale(40, 30)), (4, 1));
/// ```
pub fn label_scale(width: u32, height: u32) -> u32 {
    (width.min(height) / 60).max(1)
}

/// Draws `text` at `scale` (see [`label_scale`]) into the top left corner of `cell`: a box
/// of the pixels under it darkened to 30% (truncated), the digits in white on it (any other
/// character is drawn as `0`), clipped to the cell.
///
/// ```
/// use mjcf_forge::sheet::{Image, draw_label};
///
/// let mut cell = Image::new(20, 10, [100, 100, 100]);
/// draw_label(&mut cell, "1", 1);
/// assert_eq!(cell.pixel(0, 0), [30, 30, 30]);      // the box
/// assert_eq!(cell.pixel(2, 1), [255, 255, 255]);   // the digit's top
/// assert_eq!(cell.pixel(10, 0), [100, 100, 100]);  // beyond the box
/// ```
pub fn draw_label(cell: &mut Image, text: &str, scale: u32) {
    let scale = scale.max(1);
    let pad = scale;
    let glyphs = u32::try_from(text.chars().count()).unwrap_or(u32::MAX);
    let w = glyphs
        .saturating_mul(4 * scale)
        .saturating_sub(scale)
        .saturating_add(2 * pad);
    let h = 5 * scale + 2 * pad;
    for y in 0..h.min(cell.height) {
        for x in 0..w.min(cell.width) {
            let dark = cell.pixel(x, y).map(|c| (f64::from(c) * DARKEN) as u8);
            cell.put(x, y, dark);
        }
    }
    for (n, ch) in (0u32..).zip(text.chars()) {
        let glyph = &DIGITS[ch.to_digit(10).unwrap_or(0) as usize];
        for (row, bits) in (0u32..).zip(glyph) {
            for (col, _) in (0u32..).zip(bits.iter()).filter(|(_, b)| **b == b'#') {
                let y = pad + row * scale;
                let x = pad + (n * 4 + col) * scale;
                for dy in 0..scale {
                    for dx in 0..scale {
                        cell.put(x + dx, y + dy, [255; 3]);
                    }
                }
            }
        }
    }
}
