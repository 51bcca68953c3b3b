//! [`Image`]: RGB pixels, top row first, and their PNG encoding.

use std::path::Path;

use crate::error::{Error, ErrorKind};

/// An RGB image, 8 bits per channel, rows from the top.
///
/// ```
/// use mjcf_forge::sheet::Image;
///
/// let mut image = Image::new(4, 2, [10, 20, 30]);
/// image.put(3, 1, [255, 0, 0]);
/// assert_eq!(image.pixel(3, 1), [255, 0, 0]);
/// assert_eq!(image.pixel(0, 0), [10, 20, 30]);
/// let png = image.to_png().unwrap();
/// assert_eq!(&png[1..4], b"PNG");
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 3` bytes: R, G, B per pixel, row after row from the top.
    pub rgb: Vec<u8>,
}

impl Image {
    /// An image of one colour.
    pub fn new(width: u32, height: u32, color: [u8; 3]) -> Image {
        let n = width as usize * height as usize;
        Image {
            width,
            height,
            rgb: color.iter().copied().cycle().take(n * 3).collect(),
        }
    }

    /// An image from OpenGL's rows (bottom row first).
    pub fn from_bottom_up(width: u32, height: u32, rgb: Vec<u8>) -> Image {
        let row = width as usize * 3;
        let rgb = rgb.chunks(row.max(1)).rev().flatten().copied().collect();
        Image { width, height, rgb }
    }

    /// The colour at column `x`, row `y` (from the top); panics outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let at = (y as usize * self.width as usize + x as usize) * 3;
        [self.rgb[at], self.rgb[at + 1], self.rgb[at + 2]]
    }

    /// Sets the colour at column `x`, row `y`; nothing outside the image.
    pub fn put(&mut self, x: u32, y: u32, color: [u8; 3]) {
        if x < self.width && y < self.height {
            let at = (y as usize * self.width as usize + x as usize) * 3;
            self.rgb[at..at + 3].copy_from_slice(&color);
        }
    }

    /// Copies `other` in with its top left corner at (`x`, `y`), clipped to this image.
    pub fn blit(&mut self, other: &Image, x: u32, y: u32) {
        if x >= self.width || y >= self.height {
            return;
        }
        let w = other.width.min(self.width - x) as usize * 3;
        for row in 0..other.height.min(self.height - y) {
            let from = row as usize * other.width as usize * 3;
            let to = ((y + row) as usize * self.width as usize + x as usize) * 3;
            self.rgb[to..to + w].copy_from_slice(&other.rgb[from..from + w]);
        }
    }

    /// The part `width` x `height` at (`x`, `y`), clipped to this image.
    pub fn crop(&self, x: u32, y: u32, width: u32, height: u32) -> Image {
        let x = x.min(self.width);
        let y = y.min(self.height);
        let (width, height) = (width.min(self.width - x), height.min(self.height - y));
        let mut rgb = Vec::with_capacity(width as usize * height as usize * 3);
        for row in y..y + height {
            let from = (row as usize * self.width as usize + x as usize) * 3;
            rgb.extend_from_slice(&self.rgb[from..from + width as usize * 3]);
        }
        Image { width, height, rgb }
    }

    /// An image of `width` x `height` from `rgb` (R, G, B per pixel, top row first); an
    /// error when the length is not `width * height * 3`.
    ///
    /// ```
    /// use mjcf_forge::sheet::Image;
    ///
    /// let image = Image::from_rgb(2, 1, vec![1, 2, 3, 4, 5, 6]).unwrap();
    /// assert_eq!(image.pixel(1, 0), [4, 5, 6]);
    /// assert!(Image::from_rgb(2, 2, vec![0; 6]).is_err());
    /// ```
    pub fn from_rgb(width: u32, height: u32, rgb: Vec<u8>) -> Result<Image, Error> {
        let want = width as usize * height as usize * 3;
        if rgb.len() != want {
            return Err(invalid(format!(
                "an image of {width}x{height} pixels takes {want} bytes of RGB, not {}",
                rgb.len()
            )));
        }
        Ok(Image { width, height, rgb })
    }

    /// The image as a PNG file's bytes: 8-bit RGB, every row unfiltered (filter type 0, so
    /// that a reader needs only zlib), compressed at zlib's level 9 (`Compression::High`).
    pub fn to_png(&self) -> Result<Vec<u8>, Error> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        encoder.set_filter(png::Filter::NoFilter);
        let fail = |e: png::EncodingError| invalid(format!("cannot encode the PNG image: {e}"));
        let mut writer = encoder.write_header().map_err(fail)?;
        writer.write_image_data(&self.rgb).map_err(fail)?;
        writer.finish().map_err(fail)?;
        Ok(out)
    }

    /// Writes the image as a PNG file, atomically (see [`crate::write_atomic`]): a failure
    /// leaves no partial file and an existing file as it was.
    pub fn write_png(&self, path: &Path) -> Result<(), Error> {
        let bytes = self.to_png()?;
        crate::output::write_atomic(path, &bytes)
    }
}

fn invalid(message: String) -> Error {
    Error {
        location: None,
        kind: ErrorKind::Invalid(message),
    }
}
