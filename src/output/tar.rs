//! A streaming tar (POSIX ustar) writer: one output folder as one stream that standard
//! tools (`tar`, Python's `tarfile`, WebDataset loaders) read.
//!
//! Headers are deterministic (mtime 0, mode 0644, uid and gid 0, no user or group name),
//! so the same members in the same order give the same bytes on every machine. Members
//! are written as they come and nothing is held back, so memory stays bounded whatever
//! the stream's length. Hand-written rather than the `tar` crate: the format needed here
//! is one header layout and two padding rules, and owning it keeps the bytes pinned.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, ErrorKind};

const BLOCK: usize = 512;

/// The largest member size the header's 11 octal digits can hold (8 GiB - 1).
const MAX_SIZE: u64 = 0o77777777777;

/// Writes a tar stream to any [`Write`]: [`TarWriter::append`] per member, then
/// [`TarWriter::finish`].
///
/// ```
/// use mjcf_forge::TarWriter;
/// let mut tar = TarWriter::new(Vec::new(), "shard-000000.tar");
/// tar.append("000000000.xml", b"<mujoco/>")?;
/// tar.append("000000000.json", b"{}")?;
/// let bytes = tar.finish()?;
/// // A header and a data block per member, then two zero blocks.
/// assert_eq!(bytes.len(), 512 * 6);
/// assert_eq!(&bytes[257..263], b"ustar\0");
/// # Ok::<(), mjcf_forge::Error>(())
/// ```
#[derive(Debug)]
pub struct TarWriter<W: Write> {
    out: W,
    /// What errors call the stream (a file name, or `standard output`).
    name: PathBuf,
}

impl<W: Write> TarWriter<W> {
    /// A tar stream into `out`; `name` is how error messages call it.
    pub fn new(out: W, name: impl Into<PathBuf>) -> TarWriter<W> {
        TarWriter {
            out,
            name: name.into(),
        }
    }

    fn fail(&self, reason: impl Into<String>) -> Error {
        Error::bare(ErrorKind::Write {
            path: self.name.clone(),
            reason: reason.into(),
        })
    }

    /// Appends a regular file `name` (a relative path with `/` separators, such as
    /// `assets/3f2a.stl`) holding `bytes`.
    pub fn append(&mut self, name: &str, bytes: &[u8]) -> Result<(), Error> {
        let header = self.header(name, bytes.len() as u64)?;
        let padding = (BLOCK - bytes.len() % BLOCK) % BLOCK;
        self.out
            .write_all(&header)
            .and_then(|()| self.out.write_all(bytes))
            .and_then(|()| self.out.write_all(&[0; BLOCK][..padding]))
            .map_err(|e| self.fail(format!("{name}: {e}")))
    }

    /// Appends a regular file `name` of `size` bytes that `write` streams into the archive
    /// (an asset copied block by block, never whole in memory); `write` returns how many
    /// bytes it wrote, which must be `size`.
    ///
    /// ```
    /// use std::io::Write as _;
    /// let mut tar = mjcf_forge::TarWriter::new(Vec::new(), "t.tar");
    /// tar.append_with("a.txt", 5, |out| {
    ///     out.write_all(b"hello").unwrap();
    ///     Ok(5)
    /// })?;
    /// assert_eq!(&tar.finish()?[512..517], b"hello");
    /// # Ok::<(), mjcf_forge::Error>(())
    /// ```
    pub fn append_with(
        &mut self,
        name: &str,
        size: u64,
        write: impl FnOnce(&mut dyn Write) -> Result<u64, Error>,
    ) -> Result<(), Error> {
        let header = self.header(name, size)?;
        self.out
            .write_all(&header)
            .map_err(|e| self.fail(format!("{name}: {e}")))?;
        let written = write(&mut self.out)?;
        if written != size {
            return Err(self.fail(format!(
                "{name}: {written} bytes written where its header says {size}"
            )));
        }
        let padding = (BLOCK - (size % BLOCK as u64) as usize) % BLOCK;
        self.out
            .write_all(&[0; BLOCK][..padding])
            .map_err(|e| self.fail(format!("{name}: {e}")))
    }

    /// What error messages call the stream.
    pub fn name(&self) -> &Path {
        &self.name
    }

    /// Ends the stream with its two zero blocks, flushes it and gives the writer back.
    pub fn finish(mut self) -> Result<W, Error> {
        self.out
            .write_all(&[0; 2 * BLOCK])
            .and_then(|()| self.out.flush())
            .map_err(|e| self.fail(e.to_string()))?;
        Ok(self.out)
    }

    /// The ustar header of a regular file.
    fn header(&self, name: &str, size: u64) -> Result<[u8; BLOCK], Error> {
        header(name, size).map_err(|e| self.fail(e))
    }
}

impl<W: Write> TarWriter<BufWriter<W>> {
    /// Appends whole members that [`frame_text_member`] laid out (in parallel, say), written
    /// past the buffer in one call after flushing what the buffer holds: no copy of a large
    /// member through it.
    ///
    /// ```
    /// use mjcf_forge::{TarWriter, frame_text_member};
    /// let mut text = String::new();
    /// let ((), header) = frame_text_member(&mut text, "000000000.xml", |m| {
    ///     m.push_str("<mujoco/>");
    ///     Ok::<(), std::fmt::Error>(())
    /// })?
    /// .unwrap();
    /// let mut framed = text.into_bytes();
    /// header.write_into(&mut framed)?;
    /// let mut tar = TarWriter::new(std::io::BufWriter::new(Vec::new()), "t.tar");
    /// tar.append_framed(&framed)?;
    /// let mut same = TarWriter::new(Vec::new(), "t.tar");
    /// same.append("000000000.xml", b"<mujoco/>")?;
    /// assert_eq!(tar.finish()?.into_inner().unwrap(), same.finish()?);
    /// # Ok::<(), mjcf_forge::Error>(())
    /// ```
    pub fn append_framed(&mut self, framed: &[u8]) -> Result<(), Error> {
        if !framed.len().is_multiple_of(BLOCK) {
            return Err(self.fail(format!(
                "{} bytes of framed members, not whole 512-byte blocks",
                framed.len()
            )));
        }
        self.out
            .flush()
            .and_then(|()| self.out.get_mut().write_all(framed))
            .map_err(|e| self.fail(e.to_string()))
    }
}

/// Appends one whole tar member named `name` to `out`, its bytes the text `fill` appends
/// (written straight into place: a variant's XML is never copied into its member), after
/// a placeholder block for the header [`TarWriter::append`] writes and before the padding
/// to a whole block. The header itself is given back as a [`PendingHeader`], written over
/// its placeholder once the text is bytes (`String::into_bytes`, which copies nothing):
/// rewriting a block of a `String` in place goes a byte at a time. For laying out members
/// on worker threads, then writing them in order with [`TarWriter::append_framed`]. Gives
/// what `fill` gives, or the header's error (a name that does not fit); if either fails,
/// `out` is as it was.
///
/// ```
/// let mut out = String::new();
/// let ((), header) = mjcf_forge::frame_text_member(&mut out, "a.json", |m| {
///     m.push_str("{}");
///     Ok::<(), std::fmt::Error>(())
/// })?
/// .unwrap();
/// let mut bytes = out.into_bytes();
/// header.write_into(&mut bytes)?;
/// assert_eq!(bytes.len(), 1024);
/// assert!(bytes.starts_with(b"a.json\0"));
/// assert_eq!(&bytes[512..514], b"{}");
/// # Ok::<(), mjcf_forge::Error>(())
/// ```
pub fn frame_text_member<T, E>(
    out: &mut String,
    name: &str,
    fill: impl FnOnce(&mut String) -> Result<T, E>,
) -> Result<Result<(T, PendingHeader), E>, Error> {
    let at = out.len();
    out.push_str(ZEROS);
    let made = match fill(out) {
        Ok(made) => made,
        Err(e) => {
            out.truncate(at);
            return Ok(Err(e));
        }
    };
    let size = out.len() - at - BLOCK;
    let header = match header(name, size as u64) {
        Ok(h) => h,
        Err(reason) => {
            out.truncate(at);
            return Err(Error::bare(ErrorKind::Write {
                path: PathBuf::from(name),
                reason,
            }));
        }
    };
    let padding = (BLOCK - size % BLOCK) % BLOCK;
    out.push_str(&ZEROS[..padding]);
    Ok(Ok((made, PendingHeader { at, header })))
}

/// The header of a member [`frame_text_member`] laid out, and where its placeholder is.
#[derive(Clone, Copy, Debug)]
pub struct PendingHeader {
    at: usize,
    header: [u8; BLOCK],
}

impl PendingHeader {
    /// Writes the header over its placeholder in `framed`: the text the member was laid
    /// out in, as bytes. An error if `framed` is too short to hold it (another buffer).
    ///
    /// ```
    /// let mut out = String::new();
    /// let ((), header) =
    ///     mjcf_forge::frame_text_member(&mut out, "x", |_| Ok::<(), ()>(()))?.unwrap();
    /// assert!(header.write_into(&mut [0u8; 16]).is_err());
    /// # Ok::<(), mjcf_forge::Error>(())
    /// ```
    pub fn write_into(&self, framed: &mut [u8]) -> Result<(), Error> {
        let len = framed.len();
        let place = framed.get_mut(self.at..self.at + BLOCK).ok_or_else(|| {
            Error::bare(ErrorKind::Invalid(format!(
                "a tar header at byte {} does not fit in {len} bytes of framed members",
                self.at
            )))
        })?;
        place.copy_from_slice(&self.header);
        Ok(())
    }
}

/// A block of NUL bytes, appended whole rather than a `char` at a time.
const ZEROS: &str = {
    const BYTES: [u8; BLOCK] = [0; BLOCK];
    match std::str::from_utf8(&BYTES) {
        Ok(s) => s,
        Err(_) => panic!("NUL bytes are UTF-8"),
    }
};

/// The ustar header of a regular file `name` of `size` bytes, or why it cannot be stored.
fn header(name: &str, size: u64) -> Result<[u8; BLOCK], String> {
    let (prefix, base) = split_name(name).ok_or_else(|| {
        format!(
            "member name '{name}' does not fit a tar header (a relative path of at most \
             255 bytes, its last 100 after a '/')"
        )
    })?;
    if size > MAX_SIZE {
        return Err(format!("member '{name}' is larger than 8 GiB"));
    }
    let mut h = [0u8; BLOCK];
    h[..base.len()].copy_from_slice(base.as_bytes());
    octal(&mut h[100..108], 0o644);
    octal(&mut h[108..116], 0); // uid
    octal(&mut h[116..124], 0); // gid
    octal(&mut h[124..136], size);
    octal(&mut h[136..148], 0); // mtime: the same bytes on every run
    h[156] = b'0'; // regular file
    h[257..263].copy_from_slice(b"ustar\0");
    h[263..265].copy_from_slice(b"00");
    h[345..345 + prefix.len()].copy_from_slice(prefix.as_bytes());
    // The checksum is summed with its own field read as spaces.
    h[148..156].fill(b' ');
    let sum: u32 = h.iter().map(|&b| u32::from(b)).sum();
    octal(&mut h[148..155], u64::from(sum));
    Ok(h)
}

/// Writes `value` as zero-padded octal digits filling `field` but its last byte (NUL).
fn octal(field: &mut [u8], mut value: u64) {
    let digits = field.len() - 1;
    for d in field[..digits].iter_mut().rev() {
        *d = b'0' + (value & 7) as u8;
        value >>= 3;
    }
    field[digits] = 0;
}

/// Splits a member name into ustar's `prefix` (155 bytes) and `name` (100 bytes) at a
/// `/`, or `None` when it cannot be stored (too long, absolute, `..`, NUL).
fn split_name(name: &str) -> Option<(&str, &str)> {
    let path = Path::new(name);
    let plain = !name.is_empty()
        && !name.contains('\0')
        && path
            .components()
            .all(|c| matches!(c, std::path::Component::Normal(_)));
    if !plain {
        return None;
    }
    if name.len() <= 100 {
        return Some(("", name));
    }
    // The rightmost '/' that leaves a name of at most 100 bytes and a prefix of at most 155.
    name.char_indices()
        .filter(|&(i, c)| c == '/' && i <= 155 && name.len() - i - 1 <= 100)
        .map(|(i, _)| (&name[..i], &name[i + 1..]))
        .find(|(_, base)| !base.is_empty())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_are_deterministic_and_checksummed() {
        let build = || {
            let mut tar = TarWriter::new(Vec::new(), "t.tar");
            tar.append("assets/a.stl", &[7; 600]).unwrap();
            tar.append("000000000.xml", b"<mujoco/>").unwrap();
            tar.finish().unwrap()
        };
        let bytes = build();
        assert_eq!(bytes, build());
        // 1 header + 2 data blocks, 1 header + 1 data block, 2 end blocks.
        assert_eq!(bytes.len(), 7 * BLOCK);
        let h = &bytes[..BLOCK];
        assert_eq!(&h[..12], b"assets/a.stl");
        assert_eq!(&h[124..136], b"00000001130\0");
        let stored = u32::from_str_radix(std::str::from_utf8(&h[148..154]).unwrap(), 8).unwrap();
        let sum: u32 = h
            .iter()
            .enumerate()
            .map(|(i, &b)| {
                if (148..156).contains(&i) {
                    32
                } else {
                    u32::from(b)
                }
            })
            .sum();
        assert_eq!(stored, sum);
        assert!(bytes[bytes.len() - 2 * BLOCK..].iter().all(|&b| b == 0));
    }

    #[test]
    fn a_member_shorter_than_its_header_is_an_error() {
        let mut tar = TarWriter::new(Vec::new(), "t.tar");
        let err = tar
            .append_with("a", 10, |out| {
                out.write_all(b"abc").unwrap();
                Ok(3)
            })
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "cannot write 't.tar': a: 3 bytes written where its header says 10"
        );
    }

    #[test]
    fn long_names_use_the_prefix_field_and_bad_names_are_refused() {
        let long = format!("{}/{}", "d".repeat(120), "f".repeat(90));
        assert_eq!(split_name(&long), Some((&long[..120], &long[121..])));
        let mut tar = TarWriter::new(Vec::new(), "t.tar");
        tar.append(&long, b"x").unwrap();
        for bad in ["", "/abs", "../up", &"x".repeat(101)] {
            let err = tar.append(bad, b"x").unwrap_err().to_string();
            assert!(
                err.starts_with("cannot write 't.tar': member name '"),
                "{err}"
            );
        }
    }
}
