//! The byte searches of the readers' inner loops, eight bytes to a `u64` word at a time:
//! attribute values and indentation are most of a model's bytes.

/// Whether character data is only white space (and so not kept). Most of it is ASCII
/// indentation, checked bytewise before Unicode's wider definition.
pub(super) fn is_blank(text: &str) -> bool {
    const LO: u64 = 0x0101_0101_0101_0101;
    const SPACES: [u8; 4] = [b' ', b'\t', b'\n', b'\r'];
    // Eight bytes at a time: blank when every byte matches one of the four.
    let blank_word = |w: &[u8]| {
        let w = u64::from_le_bytes(w.try_into().expect("8 bytes"));
        SPACES
            .iter()
            .fold(0, |m, &c| m | exact_zero_bytes(w ^ (LO * u64::from(c))))
            == LO << 7
    };
    let mut words = text.as_bytes().chunks_exact(8);
    (words.all(blank_word) && words.remainder().iter().all(|b| SPACES.contains(b)))
        || text.trim().is_empty()
}

/// XML white space, as quick-xml defines it.
#[inline]
pub(super) fn is_xml_space(b: u8) -> bool {
    // One bit per white-space byte below 33: no jump table, no branch.
    const SPACES: u64 = 1 << b' ' | 1 << b'\t' | 1 << b'\n' | 1 << b'\r';
    (b <= b' ') & (SPACES.wrapping_shr(u32::from(b)) & 1 != 0)
}

/// Marks exactly the zero bytes of `x` (no false marks, unlike [`zero_bytes`]).
fn exact_zero_bytes(x: u64) -> u64 {
    const LO: u64 = 0x0101_0101_0101_0101;
    let hi = LO << 7;
    // Bytes with the high bit clear: adding 0x7f sets it unless the byte is zero.
    !(((x & !hi).wrapping_add(!hi & (LO * 0x7f))) | x) & hi
}

/// Marks the zero bytes of `x`: the lowest marked byte is the first zero byte exactly
/// (higher marks can be false, from the borrow), and no mark means no zero byte.
fn zero_bytes(x: u64) -> u64 {
    const LO: u64 = 0x0101_0101_0101_0101;
    x.wrapping_sub(LO) & !x & (LO << 7)
}

/// The offset of the first `quote` in `value`, and whether an `&` or a newline comes
/// before it. Eight bytes at a time: attribute values are most of a model's bytes.
pub(super) fn find_quote(value: &[u8], quote: u8) -> Option<(usize, bool)> {
    const LO: u64 = 0x0101_0101_0101_0101;
    let (q, amp, nl) = (
        LO * u64::from(quote),
        LO * u64::from(b'&'),
        LO * u64::from(b'\n'),
    );
    let mut unusual = false;
    let mut words = value.chunks_exact(8);
    let mut at = 0;
    for w in &mut words {
        let w = u64::from_le_bytes(w.try_into().expect("8 bytes"));
        // Each mask's lowest mark is exact, so the lowest of the two is.
        let (mq, mu) = (zero_bytes(w ^ q), zero_bytes(w ^ amp) | zero_bytes(w ^ nl));
        if mq != 0 {
            let end = mq.trailing_zeros();
            unusual |= mu != 0 && mu.trailing_zeros() < end;
            return Some((at + end as usize / 8, unusual));
        }
        unusual |= mu != 0;
        at += 8;
    }
    for (i, &b) in words.remainder().iter().enumerate() {
        if b == quote {
            return Some((at + i, unusual));
        }
        unusual |= b == b'&' || b == b'\n';
    }
    None
}

/// The offset of the first byte of `bytes` that is one of `needles`, eight bytes at a time.
pub(super) fn find_any<const N: usize>(bytes: &[u8], needles: [u8; N]) -> Option<usize> {
    const LO: u64 = 0x0101_0101_0101_0101;
    let mut words = bytes.chunks_exact(8);
    let mut at = 0;
    for w in &mut words {
        let w = u64::from_le_bytes(w.try_into().expect("8 bytes"));
        // Each mask's lowest mark is its needle's first place, so the lowest of all is.
        let marks = needles
            .iter()
            .fold(0, |m, &n| m | zero_bytes(w ^ (LO * u64::from(n))));
        if marks != 0 {
            return Some(at + marks.trailing_zeros() as usize / 8);
        }
        at += 8;
    }
    words
        .remainder()
        .iter()
        .position(|b| needles.contains(b))
        .map(|i| at + i)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_closing_quote_like_a_byte_loop() {
        let samples: &[&[u8]] = &[
            b"",
            b"\"",
            b"abc\"",
            b"0 0 1\" x=\"",
            b"a&amp;b\"",
            b"12345678\"&",
            b"1234567&\"",
            b"1234567\"&",
            b"&",
            b"no quote here at all, long enough",
            b"'\"",
            b"\xc3\xa9\"",
            b"0.1 0.2 0.3 0.4 0.5&lt;0.6\"tail&",
            b"\x80\x80\x80\x80\x80\x80\x80\x80\"",
            b"0 0\n1\"",
            b"0 0 0 0 1\"\n",
            b"12345678\n\"",
            b"\n",
        ];
        for s in samples {
            for quote in [b'"', b'\''] {
                let naive = s
                    .iter()
                    .position(|&b| b == quote)
                    .map(|i| (i, s[..i].contains(&b'&') || s[..i].contains(&b'\n')));
                assert_eq!(
                    find_quote(s, quote),
                    naive,
                    "{:?}",
                    String::from_utf8_lossy(s)
                );
            }
        }
    }

    #[test]
    fn xml_space_is_quick_xmls() {
        for b in 0..=255u8 {
            assert_eq!(
                is_xml_space(b),
                matches!(b, b' ' | b'\r' | b'\n' | b'\t'),
                "{b}"
            );
        }
    }

    #[test]
    fn blank_is_unicode_white_space() {
        for t in [
            "",
            " ",
            "\n\t\r ",
            "        \n",
            "         x",
            "x",
            " \u{a0}",
            "\u{2003}\n",
            "\u{0}       ",
            "\u{b}",
        ] {
            for pad in 0..10 {
                let s = format!("{}{t}", " ".repeat(pad));
                assert_eq!(is_blank(&s), s.trim().is_empty(), "{s:?}");
            }
        }
        for b in 0..=255u8 {
            let w = u64::from_le_bytes([b, 0, 7, b, 255, 0x80, 1, b]);
            let naive = w
                .to_le_bytes()
                .iter()
                .fold(0u64, |m, &x| m << 8 | u64::from(x == 0) << 7);
            assert_eq!(
                exact_zero_bytes(w),
                u64::from_be_bytes(naive.to_le_bytes()),
                "{b}"
            );
        }
    }
}
