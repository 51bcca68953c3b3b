//! The precedence rule: how an element's own attributes apply over its class's dummy (the
//! nearer one wins, numeric arrays overlaid, orientations replaced whole), and the case where
//! a class's value is not taken at all.

use super::Resolver;
use super::classes::AttrSet;
use crate::document::names::Sym;
use crate::document::tree::StrRef;
use crate::document::vocab::ElementSpec;

/// Attributes that together give one orientation: a new one replaces all of them.
pub(super) const ORIENTATION: [&str; 5] = ["quat", "axisangle", "xyaxes", "zaxis", "euler"];
/// Light: `directional` and `type` both set the light type; the nearer one wins.
pub(super) const LIGHT_TYPE: [&str; 2] = ["directional", "type"];

/// The number of words of `text` as `split_ascii_whitespace` splits it, counting no
/// further than `limit` (a byte loop: the iterator is slow on these short values).
fn count_tokens(text: &str, limit: usize) -> usize {
    let mut n = 0;
    let mut in_space = true;
    for b in text.bytes() {
        let space = b.is_ascii_whitespace();
        if in_space && !space {
            n += 1;
            if n == limit {
                break;
            }
        }
        in_space = space;
    }
    n
}

impl Resolver<'_> {
    /// Applies attributes onto a dummy, with MuJoCo's array overlay and orientation rules.
    /// With `accepts`, attributes the element kind cannot carry are reported by name.
    pub(super) fn apply(
        &mut self,
        set: &mut AttrSet,
        own: &[(Sym, StrRef)],
        _accepts: Option<&ElementSpec>,
    ) {
        for group in [&self.syms.orientation[..], &self.syms.light_type[..]] {
            if own.iter().any(|(n, _)| group.contains(n)) {
                for g in group {
                    set.remove(*g);
                }
            }
        }
        for &(name, value) in own {
            let value = match set.get(name) {
                Some(base) if name != self.syms.user => self.overlay(value, base),
                _ => value,
            };
            set.set(name, value);
        }
    }

    /// `own` over `base` for numeric arrays: MuJoCo reads a fixed-capacity array by
    /// overwriting as many leading entries as are given. Anything else: `own`.
    fn overlay(&mut self, own: StrRef, base: StrRef) -> StrRef {
        let own_s = self.doc.str(own);
        let base_s = self.doc.str(base);
        // Counted first: most values give at least as many numbers as their base.
        let own_len = count_tokens(own_s, usize::MAX);
        if own_len >= count_tokens(base_s, own_len + 1) {
            return own;
        }
        let numeric = |v: &str| v.split_ascii_whitespace().all(|t| t.parse::<f64>().is_ok());
        if own_len == 0 || !numeric(own_s) || !numeric(base_s) {
            return own;
        }
        let mut joined = std::mem::take(&mut self.scratch.text);
        joined.clear();
        for (i, t) in own_s.split_ascii_whitespace().enumerate() {
            if i > 0 {
                joined.push(' ');
            }
            joined.push_str(t);
        }
        for t in base_s.split_ascii_whitespace().skip(own_len) {
            joined.push(' ');
            joined.push_str(t);
        }
        let r = self.doc.push_str(&joined);
        self.scratch.text = joined;
        r
    }

    /// A texture that writes its own `gridsize`, other than its class's, does not take the
    /// class's `gridlayout` (the layout belongs to the class's grid). MuJoCo 3.17.0 and 4.0.0
    /// both compile such a texture (4.0.0's changelog, bug fix 60, names the reset); writing
    /// the class's layout next to the new size is rejected by both (`gridlayout length must
    /// match gridsize`). corpora/features/default_texture_gridsize_resets_layout.xml.
    pub(super) fn reset_gridlayout(&self, class_set: &mut AttrSet, own: &[(Sym, StrRef)]) {
        let (Some(gridsize), Some(gridlayout)) = (
            crate::document::names::known("gridsize"),
            crate::document::names::known("gridlayout"),
        ) else {
            return;
        };
        let own_value = |n: Sym| own.iter().find(|(m, _)| *m == n).map(|(_, v)| *v);
        let Some(size) = own_value(gridsize) else {
            return;
        };
        if own_value(gridlayout).is_some() {
            return;
        }
        let numbers = |v: StrRef| -> Vec<f64> {
            self.doc
                .str(v)
                .split_ascii_whitespace()
                .map(|t| t.parse().unwrap_or(f64::NAN))
                .collect()
        };
        let same = class_set
            .get(gridsize)
            .is_some_and(|c| numbers(c) == numbers(size));
        if !same {
            class_set.remove(gridlayout);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_tokens_like_split_ascii_whitespace() {
        for t in [
            "",
            " ",
            "1",
            " 1",
            "1 ",
            "1 2",
            "  1\t2\n3 \u{c}4\r",
            "a\u{a0}b",
            "\u{b}x y",
        ] {
            let n = t.split_ascii_whitespace().count();
            assert_eq!(count_tokens(t, usize::MAX), n, "{t:?}");
            for limit in 1..4 {
                assert_eq!(count_tokens(t, limit), n.min(limit), "{t:?} {limit}");
            }
        }
    }
}
