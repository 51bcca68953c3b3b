//! Start tags scanned straight from the source bytes, finding exactly what quick-xml finds
//! there: where the tag ends, and its attributes as byte ranges.

use super::bytes::{find_quote, is_xml_space};
use super::lines::LineCursor;

/// A start tag found by [`scan_start_tag`]; offsets into the source.
pub(super) struct StartTag {
    /// The `>` that ends the tag.
    pub(super) gt: usize,
    /// The end of the tag's content (before `/>` for an empty element).
    pub(super) content_end: usize,
    pub(super) name_len: usize,
    pub(super) is_empty: bool,
}

/// Bytes that end a start tag's name or an attribute key in [`scan_start_tag`].
const NAME_END: [bool; 256] = {
    let mut t = [false; 256];
    let ends = *b"= \t\n\r>/\"'";
    let mut i = 0;
    while i < ends.len() {
        t[ends[i] as usize] = true;
        i += 1;
    }
    t
};

/// The end of the name or key starting at `i`: the first [`NAME_END`] byte. Those are all
/// below `@`, as are few name bytes (digits, `-`, `.`), so eight bytes at a time are
/// passed over when none is below `@`.
#[inline]
fn name_end(bytes: &[u8], mut i: usize) -> usize {
    const LO: u64 = 0x0101_0101_0101_0101;
    while let Some(w) = bytes.get(i..i + 8) {
        let w = u64::from_le_bytes(w.try_into().expect("8 bytes"));
        // The lowest mark is exactly the first byte below `@` (higher ones may be false).
        let below = w.wrapping_sub(LO * 0x40) & !w & (LO << 7);
        if below == 0 {
            i += 8;
            continue;
        }
        i += below.trailing_zeros() as usize / 8;
        if NAME_END[bytes[i] as usize] {
            return i;
        }
        i += 1;
    }
    while i < bytes.len() && !NAME_END[bytes[i] as usize] {
        i += 1;
    }
    i
}

/// Reads the start tag whose content begins at `from` (after `<`) in one pass, with its
/// attributes into `spans` (offsets from `from`), for tags whose names and keys hold no
/// quote, `=`, `>` or `/`. For those, quotes appear only around values, so the `>` found
/// here is the one quick-xml's `ElementParser` finds (the first outside quotes), and the
/// attributes are what [`scan_attrs`] finds in that content; anything else is `None`.
pub(super) fn scan_start_tag(
    bytes: &[u8],
    from: usize,
    spans: &mut Vec<AttrSpan>,
    at: &mut LineCursor,
    max_attributes: usize,
) -> Option<StartTag> {
    spans.clear();
    let n = bytes.len();
    // Names and keys hold no newline (it ends them); white space and values may.
    let mut i = name_end(bytes, from);
    let name_len = i - from;
    loop {
        while i < n && is_xml_space(bytes[i]) {
            at.pass_space(bytes[i], i);
            i += 1;
        }
        match *bytes.get(i)? {
            b'>' => {
                return Some(StartTag {
                    gt: i,
                    content_end: i,
                    name_len,
                    is_empty: false,
                });
            }
            b'/' if bytes.get(i + 1) == Some(&b'>') => {
                return Some(StartTag {
                    gt: i + 1,
                    content_end: i,
                    name_len,
                    is_empty: true,
                });
            }
            b'/' | b'"' | b'\'' | b'=' => return None,
            _ => {}
        }
        if i == from + name_len {
            return None; // a name ended by something other than white space
        }
        let key_start = i;
        i = name_end(bytes, i);
        let key_end = i;
        while i < n && is_xml_space(bytes[i]) {
            at.pass_space(bytes[i], i);
            i += 1;
        }
        if bytes.get(i) != Some(&b'=') {
            return None;
        }
        i += 1;
        while i < n && is_xml_space(bytes[i]) {
            at.pass_space(bytes[i], i);
            i += 1;
        }
        let quote = *bytes.get(i)?;
        if quote != b'"' && quote != b'\'' {
            return None;
        }
        if spans.len() >= max_attributes {
            return None; // `parse` reports it
        }
        let value_start = i + 1;
        let (len, unusual) = find_quote(&bytes[value_start..], quote)?;
        i = value_start + len;
        // Rare: a reference to expand, or a newline to count.
        let has_ref = unusual && bytes[value_start..i].contains(&b'&');
        if unusual {
            at.pass(bytes, value_start, i);
        }
        spans.push(AttrSpan {
            key: ((key_start - from) as u32, (key_end - from) as u32),
            value: ((value_start - from) as u32, (i - from) as u32),
            has_ref,
        });
        i += 1;
    }
}

/// One attribute of a start tag, as byte ranges of the tag's content.
#[derive(Clone, Copy)]
pub(super) struct AttrSpan {
    pub(super) key: (u32, u32),
    pub(super) value: (u32, u32),
    /// The value holds `&` (an entity or character reference to expand).
    pub(super) has_ref: bool,
}

/// Bytes that end an attribute key: `=` and XML white space.
const KEY_END: [bool; 256] = {
    let mut t = [false; 256];
    t[b'=' as usize] = true;
    t[b' ' as usize] = true;
    t[b'\t' as usize] = true;
    t[b'\n' as usize] = true;
    t[b'\r' as usize] = true;
    t
};

/// The attributes of a start tag's content from `from` on, found the way quick-xml's
/// attribute iterator finds them in XML mode (same white space, same key and quote rules).
/// `false` for anything quick-xml would report as an error: the caller then takes
/// quick-xml's path, which words the error.
pub(super) fn scan_attrs(content: &[u8], from: usize, out: &mut Vec<AttrSpan>) -> bool {
    out.clear();
    let mut i = from;
    let n = content.len();
    loop {
        while i < n && is_xml_space(content[i]) {
            i += 1;
        }
        if i == n {
            return true;
        }
        let key_start = i;
        // Like quick-xml, the key's first byte is taken whatever it is (even `=`).
        i += 1;
        while i < n && !KEY_END[content[i] as usize] {
            i += 1;
        }
        let key_end = i;
        while i < n && is_xml_space(content[i]) {
            i += 1;
        }
        if i == n || content[i] != b'=' {
            return false;
        }
        i += 1;
        while i < n && is_xml_space(content[i]) {
            i += 1;
        }
        if i == n {
            return false;
        }
        let quote = content[i];
        if quote != b'"' && quote != b'\'' {
            return false;
        }
        let value_start = i + 1;
        let Some((len, has_ref)) = find_quote(&content[value_start..], quote) else {
            return false;
        };
        i = value_start + len;
        out.push(AttrSpan {
            key: (key_start as u32, key_end as u32),
            value: (value_start as u32, i as u32),
            has_ref,
        });
        i += 1;
    }
}
