//! [`Layout`]: where each cell of a contact sheet is, and the gap between cells.

/// Pixels between cells.
pub const GAP: u32 = 2;
/// The colour between cells (and of the cells a grid does not use).
pub const GAP_COLOR: [u8; 3] = [32, 32, 32];

/// A grid of cells: where cell `k` of `n` is.
///
/// ```
/// use mjcf_forge::sheet::Layout;
///
/// let l = Layout::new(5, 100, 50, None);
/// assert_eq!((l.columns, l.rows), (3, 2));
/// assert_eq!(l.cell_origin(4), (102, 52));   // second row, second column; 2 px gaps
/// assert_eq!((l.width(), l.height()), (304, 102));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Cells per row.
    pub columns: u32,
    /// Rows.
    pub rows: u32,
    /// A cell's width.
    pub cell_width: u32,
    /// A cell's height.
    pub cell_height: u32,
}

impl Layout {
    /// `n` cells of `cell_width` x `cell_height`, `columns` per row (at most `n`); without
    /// `columns` (or with 0) the smallest number whose square holds every cell (16 cells:
    /// 4, 8 cells: 3).
    pub fn new(n: usize, cell_width: u32, cell_height: u32, columns: Option<u32>) -> Layout {
        let n = u32::try_from(n.max(1)).unwrap_or(u32::MAX);
        let columns = columns
            .filter(|c| *c > 0)
            .unwrap_or_else(|| (1..=n).find(|c| c.saturating_mul(*c) >= n).unwrap_or(n))
            .min(n);
        Layout {
            columns,
            rows: n.div_ceil(columns),
            cell_width,
            cell_height,
        }
    }

    /// The top left corner of cell `k` (row after row).
    pub fn cell_origin(&self, k: usize) -> (u32, u32) {
        let k = u32::try_from(k).unwrap_or(u32::MAX);
        (
            (k % self.columns) * (self.cell_width + GAP),
            (k / self.columns) * (self.cell_height + GAP),
        )
    }

    /// The sheet's width.
    pub fn width(&self) -> u32 {
        self.columns * (self.cell_width + GAP) - GAP
    }

    /// The sheet's height.
    pub fn height(&self) -> u32 {
        self.rows * (self.cell_height + GAP) - GAP
    }
}
