//! Source positions: byte offsets turned into 1-based line:col, by each reader its own way.

use crate::document::Span;

/// Turns byte offsets of one source text into 1-based line:col. The reader asks for
/// offsets in increasing order, so a cursor counts only the bytes in between; error paths
/// use [`Lines::line_col`], which counts from the start.
pub(super) struct Lines<'a> {
    pub(super) text: &'a [u8],
    /// Lines counted before `scanned` (1-based line of `scanned`).
    line: u32,
    /// Offset of the first byte of that line.
    line_start: usize,
    scanned: usize,
}

impl<'a> Lines<'a> {
    pub(super) fn new(text: &'a [u8]) -> Lines<'a> {
        Lines {
            text,
            line: 1,
            line_start: 0,
            scanned: 0,
        }
    }

    /// The line and column of `offset`, moving the cursor there.
    pub(super) fn advance(&mut self, offset: usize) -> (u32, u32) {
        if offset < self.scanned {
            (self.line, self.line_start, self.scanned) = (1, 0, 0);
        }
        let end = offset.min(self.text.len());
        if end > self.scanned {
            let chunk = &self.text[self.scanned..end];
            let n = count_newlines(chunk);
            if n > 0 {
                self.line += n as u32;
                let last = chunk.iter().rposition(|&b| b == b'\n').unwrap_or(0);
                self.line_start = self.scanned + last + 1;
            }
            self.scanned = end;
        }
        (self.line, (offset - self.line_start + 1) as u32)
    }

    /// The line and column of any offset, without the cursor (for error positions).
    pub(super) fn line_col(&self, offset: usize) -> (u32, u32) {
        let before = &self.text[..offset.min(self.text.len())];
        let line = 1 + count_newlines(before);
        let start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |i| i + 1);
        (line as u32, (offset - start + 1) as u32)
    }
}

/// The number of `\n` bytes. Counted in blocks of at most 255 bytes into a byte-wide sum,
/// which compiles to a few vector instructions per 16 bytes (a plain count does not
/// vectorise). Called once per tag, on the bytes since the last one.
fn count_newlines(text: &[u8]) -> usize {
    text.chunks(255)
        .map(|block| usize::from(block.iter().fold(0u8, |n, &b| n + u8::from(b == b'\n'))))
        .sum()
}

/// The line of the reading position in [`Builder::parse_fast`], kept up to date as the
/// reader passes over newlines.
///
/// [`Builder::parse_fast`]: super::builder::Builder::parse_fast
pub(super) struct LineCursor {
    pub(super) line: u32,
    /// Offset of the line's first byte.
    pub(super) start: usize,
}

impl LineCursor {
    /// The span of `offset`, which must be on the cursor's line.
    #[inline]
    pub(super) fn span(&self, file: u32, offset: usize) -> Span {
        Span {
            file,
            line: self.line,
            col: (offset - self.start + 1) as u32,
        }
    }

    /// Moves over `bytes[from..to]`.
    #[inline]
    pub(super) fn pass(&mut self, bytes: &[u8], from: usize, to: usize) {
        let region = &bytes[from..to];
        let n = count_newlines(region);
        if n > 0 {
            self.line += n as u32;
            self.start = from + region.iter().rposition(|&b| b == b'\n').unwrap_or(0) + 1;
        }
    }

    /// Moves over one white-space byte at `offset`.
    #[inline]
    pub(super) fn pass_space(&mut self, b: u8, offset: usize) {
        if b == b'\n' {
            self.line += 1;
            self.start = offset + 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_columns() {
        let text = b"ab\ncd\n\nefg";
        let mut lines = Lines::new(text);
        for offset in [0, 1, 2, 3, 5, 6, 7, 8, 10, 11, 20, 4, 0] {
            let slow = {
                let before = &text[..offset.min(text.len())];
                let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
                let start = before
                    .iter()
                    .rposition(|&b| b == b'\n')
                    .map_or(0, |i| i + 1);
                (line as u32, (offset - start + 1) as u32)
            };
            assert_eq!(lines.advance(offset), slow, "{offset}");
            assert_eq!(lines.line_col(offset), slow, "{offset}");
        }
        let long: Vec<u8> = (0..1000)
            .map(|i| if i % 7 == 0 { b'\n' } else { b'x' })
            .collect();
        assert_eq!(
            count_newlines(&long),
            long.iter().filter(|&&b| b == b'\n').count()
        );
    }
}
