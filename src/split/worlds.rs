//! Per-world rows of a superset's arrays, the one rule both faces keep them by: world 0's
//! bytes of every array are the base; an array gets one row per world once a world
//! differs from the base in it, or from the start where the caller always keeps it
//! (`qpos0`, each world's reference pose; `WorldBatch` keeps every array a patch may write,
//! since a world can be given another variant later); the statistics are kept for every
//! world. Every other array is the shared model's. The C face's `ModelCache::worlds`
//! and the Python face's `ModelCache.batch` and `WorldBatch` read their worlds through it.
//!
//! ```
//! use mjcf_forge::split::WorldRows;
//!
//! // Two arrays of world 0: `qpos0` (kept always) and `geom_rgba`.
//! let mut rows = WorldRows::new(vec![
//!     ("qpos0".to_string(), vec![0u8; 8], true),
//!     ("geom_rgba".to_string(), vec![1u8; 4], false),
//! ]);
//! rows.push(|_| None, [0.0; 7]); // world 0: as the base
//! rows.push(|k| (k == 1).then_some(&[2u8; 4][..]), [1.0; 7]); // world 1: another colour
//! let kept: Vec<_> = rows.kept().map(|(name, bytes)| (name, bytes.len())).collect();
//! assert_eq!(kept, [("qpos0", 16), ("geom_rgba", 8)]);
//! assert_eq!(rows.statistics().len(), 2);
//! ```

use super::Statistics;

/// One array's rows: world 0's bytes, and once kept every world's end to end.
struct Field {
    name: String,
    first: Vec<u8>,
    always: bool,
    rows: Option<Vec<u8>>,
}

/// Per-world rows of a superset's arrays (see the module).
pub struct WorldRows {
    fields: Vec<Field>,
    worlds: usize,
    statistics: Vec<Statistics>,
}

impl WorldRows {
    /// Rows of `fields`: each array's name, world 0's bytes, and whether every world's row
    /// is kept whatever it holds.
    pub fn new(fields: Vec<(String, Vec<u8>, bool)>) -> WorldRows {
        WorldRows {
            fields: fields
                .into_iter()
                .map(|(name, first, always)| Field {
                    name,
                    first,
                    always,
                    rows: None,
                })
                .collect(),
            worlds: 0,
            statistics: Vec::new(),
        }
    }

    /// How many worlds were pushed.
    pub fn worlds(&self) -> usize {
        self.worlds
    }

    /// The names of the arrays, in the order [`WorldRows::push`]'s `row` numbers them.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.fields.iter().map(|f| f.name.as_str())
    }

    /// Whether array `k` is kept for every world whatever it holds.
    pub fn always(&self, k: usize) -> bool {
        self.fields.get(k).is_some_and(|f| f.always)
    }

    /// The next world: `row(k)` its bytes of array `k` (`None`: not read, taken as world
    /// 0's), and its statistics.
    pub fn push<'a>(
        &mut self,
        mut row: impl FnMut(usize) -> Option<&'a [u8]>,
        statistics: Statistics,
    ) {
        let w = self.worlds;
        for (k, f) in self.fields.iter_mut().enumerate() {
            let b = row(k).unwrap_or(&f.first);
            match &mut f.rows {
                Some(rows) => rows.extend_from_slice(b),
                None if f.always || b != f.first.as_slice() => {
                    // The worlds before this one held world 0's row.
                    let mut rows = Vec::with_capacity((w + 1) * f.first.len());
                    for _ in 0..w {
                        rows.extend_from_slice(&f.first);
                    }
                    rows.extend_from_slice(b);
                    f.rows = Some(rows);
                }
                None => {}
            }
        }
        self.worlds += 1;
        self.statistics.push(statistics);
    }

    /// The arrays not kept per world in which a world (`row`, as for
    /// [`WorldRows::push`]) differs from world 0: what a world given another variant later
    /// may not change.
    pub fn differing<'a>(&self, mut row: impl FnMut(usize) -> Option<&'a [u8]>) -> Vec<&str> {
        let mut out = Vec::new();
        for (k, f) in self.fields.iter().enumerate() {
            if f.rows.is_none() && row(k).is_some_and(|b| b != f.first.as_slice()) {
                out.push(f.name.as_str());
            }
        }
        out
    }

    /// The arrays kept per world, in the order given, each with every world's row end to
    /// end.
    pub fn kept(&self) -> impl Iterator<Item = (&str, &[u8])> {
        self.fields
            .iter()
            .filter_map(|f| Some((f.name.as_str(), f.rows.as_deref()?)))
    }

    /// Every world's statistics (`STATISTIC_NAMES`' order).
    pub fn statistics(&self) -> &[Statistics] {
        &self.statistics
    }

    /// The kept arrays taken out, with the statistics.
    pub fn into_kept(self) -> (Vec<(String, Vec<u8>)>, Vec<Statistics>) {
        let kept = self
            .fields
            .into_iter()
            .filter_map(|f| Some((f.name, f.rows?)))
            .collect();
        (kept, self.statistics)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows() -> WorldRows {
        WorldRows::new(vec![
            ("qpos0".into(), vec![0; 2], true),
            ("a".into(), vec![1; 2], false),
            ("b".into(), vec![2; 2], false),
        ])
    }

    #[test]
    fn a_row_per_world_from_the_first_that_differs_with_the_earlier_worlds_as_world_0() {
        let mut r = rows();
        let worlds: [[&[u8]; 3]; 3] = [
            [&[0, 0], &[1, 1], &[2, 2]],
            [&[5, 5], &[1, 1], &[2, 2]],
            [&[6, 6], &[1, 1], &[9, 9]],
        ];
        for w in &worlds {
            r.push(|k| Some(w[k]), [w[0][0].into(); 7]);
        }
        let kept: Vec<(&str, &[u8])> = r.kept().collect();
        assert_eq!(
            kept,
            [
                ("qpos0", &[0, 0, 5, 5, 6, 6][..]),
                ("b", &[2, 2, 2, 2, 9, 9][..])
            ]
        );
        assert_eq!(r.statistics()[2][0], 6.0);
        // A later world: `a` differs (not kept), `b` is kept anyway, unread arrays are not.
        assert_eq!(
            r.differing(|k| [None, Some(&[3u8, 3][..]), Some(&[0u8, 0][..])][k]),
            ["a"]
        );
        assert!(r.differing(|_| None).is_empty());
    }

    #[test]
    fn an_unread_array_is_world_0_and_kept_ones_fill_in() {
        let mut r = rows();
        r.push(|_| None, [0.0; 7]);
        r.push(|k| (k == 2).then_some(&[7u8, 7][..]), [0.0; 7]);
        r.push(|_| None, [0.0; 7]);
        let (kept, stats) = r.into_kept();
        assert_eq!(kept[0], ("qpos0".to_string(), vec![0; 6]));
        assert_eq!(kept[1], ("b".to_string(), vec![2, 2, 7, 7, 2, 2]));
        assert_eq!((kept.len(), stats.len()), (2, 3));
    }
}
