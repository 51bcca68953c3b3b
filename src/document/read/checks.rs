//! What XML 1.0 allows, checked where both readers need it: the characters of a file, the
//! names of elements and attributes, the characters that references stand for.

use crate::document::limits::Limits;

/// Whether `b` may start a character XML 1.0 does not allow (its `Char` production): C0
/// controls other than tab, newline and carriage return, and 0xEF, the lead byte of U+FFFE
/// and U+FFFF (checked further in [`first_forbidden_char`]). Arithmetic, not a table, so
/// that a block of bytes is tested with vector instructions.
#[inline]
fn maybe_forbidden(b: u8) -> bool {
    (b < 0x20) & (b != b'\t') & (b != b'\n') & (b != b'\r') | (b == 0xEF)
}

/// The offset and description of the first character of `bytes` that XML 1.0 forbids.
/// Copied through, such a character makes the output unreadable to every XML 1.0 parser, so
/// it is refused where it stands (surrogates cannot occur: the text is UTF-8 or refused).
/// Every byte of every file passes here: blocks of 32 bytes with no suspect are passed
/// over with one branch.
pub(super) fn first_forbidden_char(bytes: &[u8]) -> Option<(usize, String)> {
    let blocks = bytes.chunks_exact(32);
    let tail = blocks.remainder();
    let suspect_at = blocks
        .enumerate()
        // A byte-wide OR over a fixed-size block vectorises; a fold over `bool` does not.
        .filter(|(_, block)| {
            block
                .iter()
                .fold(0u8, |any, &b| any | u8::from(maybe_forbidden(b)))
                != 0
        })
        .map(|(i, _)| i * 32)
        .chain((!tail.is_empty()).then_some(bytes.len() - tail.len()));
    for start in suspect_at {
        let end = (start + 32).min(bytes.len());
        for (i, &b) in bytes.iter().enumerate().take(end).skip(start) {
            match b {
                0 => return Some((i, "NUL byte (not allowed in XML)".into())),
                0xEF => {
                    if let [0xBF, b @ (0xBE | 0xBF), ..] = bytes[i + 1..] {
                        // EF BF BE is U+FFFE, EF BF BF is U+FFFF.
                        let c = 0xFFFE + u32::from(b - 0xBE);
                        return Some((i, format!("character U+{c:04X} (not allowed in XML)")));
                    }
                }
                b if maybe_forbidden(b) => {
                    let what = format!("control character U+{b:04X} (not allowed in XML)");
                    return Some((i, what));
                }
                _ => {}
            }
        }
    }
    None
}

/// XML 1.0's `Char` production.
fn is_xml_char(c: char) -> bool {
    matches!(c, '\t' | '\n' | '\r' | ' '..='\u{D7FF}' | '\u{E000}'..='\u{FFFD}' | '\u{10000}'..)
}

/// XML 1.0's `NameStartChar` production, without `:` (see [`name_problem`]).
fn is_name_start(c: char) -> bool {
    matches!(c,
        'A'..='Z' | '_' | 'a'..='z' | '\u{C0}'..='\u{D6}' | '\u{D8}'..='\u{F6}'
        | '\u{F8}'..='\u{2FF}' | '\u{370}'..='\u{37D}' | '\u{37F}'..='\u{1FFF}'
        | '\u{200C}'..='\u{200D}' | '\u{2070}'..='\u{218F}' | '\u{2C00}'..='\u{2FEF}'
        | '\u{3001}'..='\u{D7FF}' | '\u{F900}'..='\u{FDCF}' | '\u{FDF0}'..='\u{FFFD}'
        | '\u{10000}'..='\u{EFFFF}')
}

/// XML 1.0's `NameChar` production, without `:`.
fn is_name_char(c: char) -> bool {
    is_name_start(c)
        || matches!(c, '-' | '.' | '0'..='9' | '\u{B7}' | '\u{300}'..='\u{36F}' | '\u{203F}'..='\u{2040}')
}

/// Why `name` cannot be an element or attribute name we write back, if it cannot: it must
/// be an XML name, within the length limit. A `:` is refused too: it would need a namespace
/// declaration that namespace-aware parsers (Python's, for one) check, and no MJCF name
/// has one.
///
/// A URDF file (`urdf`) may use `:` (`xmlns:xacro`, `<gazebo>` blocks): the reader reads
/// them and converts none of them to MJCF.
pub(super) fn name_problem(name: &str, limits: &Limits, urdf: bool) -> Option<String> {
    if name.len() > limits.max_name_len as usize {
        return Some(format!(
            "name of {} bytes, longer than {} (Limits::max_name_len)",
            name.len(),
            limits.max_name_len
        ));
    }
    let mut chars = name.chars();
    match chars.next() {
        None => Some("a tag without a name".into()),
        Some(c)
            if !(is_name_start(c) || urdf && c == ':')
                || !chars.all(|c| is_name_char(c) || urdf && c == ':') =>
        {
            Some(format!("'{}' is not an XML name", clip(name, 40)))
        }
        Some(_) => None,
    }
}

/// `text` cut to at most about `max` bytes (on a character boundary), marked when cut: for
/// quoting input in messages without echoing a huge value.
pub(crate) fn clip(text: &str, max: usize) -> std::borrow::Cow<'_, str> {
    if text.len() <= max {
        return text.into();
    }
    let mut end = max;
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}... ({} bytes)", &text[..end], text.len()).into()
}

/// Expands the entity and character references of `raw` (an attribute value), checking
/// that each character a reference yields is allowed in XML 1.0. On failure: the offset in
/// `raw` of the reference at fault and what is wrong with it. Linear: the end of each
/// reference is looked for only up to the next `&`.
pub(super) fn expand_refs(raw: &str) -> Result<std::borrow::Cow<'_, str>, (usize, String)> {
    let Some(first) = raw.find('&') else {
        return Ok(raw.into());
    };
    let mut out = String::with_capacity(raw.len());
    out.push_str(&raw[..first]);
    let mut i = first;
    while i < raw.len() {
        let rest = &raw[i + 1..];
        let end = rest
            .find([';', '&'])
            .filter(|&j| rest.as_bytes()[j] == b';');
        let Some(end) = end else {
            return Err((i, "'&' without its ';' (write '&amp;' for '&')".into()));
        };
        let reference = &raw[i..i + 1 + end + 1];
        let shown = clip(reference, 40);
        match quick_xml::escape::unescape(reference) {
            Ok(v) => {
                if let Some(c) = v.chars().find(|&c| !is_xml_char(c)) {
                    return Err((
                        i,
                        format!(
                            "'{shown}' stands for U+{:04X}, which XML 1.0 does not allow",
                            c as u32
                        ),
                    ));
                }
                out.push_str(&v);
            }
            Err(quick_xml::escape::EscapeError::InvalidCharRef(_)) => {
                return Err((i, format!("invalid character reference '{shown}'")));
            }
            Err(_) => return Err((i, format!("unknown entity '{shown}'"))),
        }
        i += 1 + end + 1;
        let next = raw[i..].find('&').map_or(raw.len(), |j| i + j);
        out.push_str(&raw[i..next]);
        i = next;
    }
    Ok(out.into())
}

/// A UTF-16 text (by its byte order mark, or by the zero bytes around the first `<`): MJCF
/// is read as UTF-8, and without this the first zero byte would be all the message says.
pub(super) fn is_utf16(bytes: &[u8]) -> bool {
    matches!(
        bytes,
        [0xFF, 0xFE, ..] | [0xFE, 0xFF, ..] | [b'<', 0, ..] | [0, b'<', ..]
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forbidden_characters_are_found_like_a_char_loop() {
        let mut samples: Vec<String> = vec![String::new(), "\u{FFFD}\u{FFFE}".into()];
        for c in [
            '\u{0}', '\u{1}', '\u{1F}', '\u{FFFE}', '\u{FFFF}', '\u{F000}', '\t', 'x',
        ] {
            for at in [0, 1, 31, 32, 33, 70] {
                let mut s: String = "\u{e9}a\n\r".repeat(at).chars().take(at).collect();
                s.push(c);
                s.push_str("tail");
                samples.push(s);
            }
        }
        for s in &samples {
            let naive = s
                .char_indices()
                .find(|&(_, c)| !is_xml_char(c))
                .map(|(i, _)| i);
            assert_eq!(
                first_forbidden_char(s.as_bytes()).map(|f| f.0),
                naive,
                "{s:?}"
            );
        }
    }
}
