//! Poncin's density grid (section 4.4.4): favoured and forbidden cells for the leaves.
//!
//! A box (paper units) is divided into `Nx × Ny × Nz` cells; each cell has a weight `w` and
//! a target number of leaves `T` (default 15). The paper scores a cell holding `N` leaves
//! with [`f_cell`]:
//!
//! ```text
//! F_cell = w · (1 − |N − T| / (8T))   if w > 0   (best, = w, at N = T)
//! F_cell = w · (1 + N / (4T))         if w < 0   (best, = w, with no leaf)
//! F_cell = 0                          if w = 0   (the cell does not matter)
//! ```
//!
//! and averages `F_cell` over the cells: a score, higher is better. (The paper's formula says
//! `N_goal` where its text says `N_target`; both are the cell's target here.)
//!
//! **Cost.** The other terms of the fitness are costs to minimise, and Table 2 shows F_grid
//! at 100 while the grid is gated off and falling to 19.5 as the tree fills the grid. Sylva
//! turns the score into that kind of cost: each cell's shortfall from its best,
//! `w − F_cell`, is measured against the shortfall of an *empty* favoured cell, `|w| / 8`:
//!
//! ```text
//! e = |N − T| / T      favoured cell (1 when empty, 0 on target)
//! e = 2N / T           forbidden cell (0 when empty; 1 at T/2 leaves)
//! F_grid = min(100, 100 · Σ |w|·e / Σ |w|)
//! ```
//!
//! So F_grid is the weighted mean relative error of the cells, in percent: 100 for a tree
//! with no leaf in the grid (or no better), 0 when every favoured cell holds its target and
//! no forbidden cell a leaf. It is an affine, decreasing function of the paper's averaged
//! `F_cell` (until the cap), so minimising it maximises the paper's grid fitness, and it
//! keeps the paper's relative prices: a leaf in a forbidden cell costs twice what a missing
//! leaf in a favoured cell of the same weight costs. The cap of [`GRID_MAX`] = 100 makes
//! "gated off" the true maximum, so passing the gate never makes a tree worse.
//!
//! A grid is written in a config as defaults for every cell, then boxes of cells, then single
//! cells, later entries overriding earlier ones (see [`GridConfig`]). Cells are numbered
//! `x + Nx · (y + Ny · z)`.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use sylva_core::{OrganKind, Plant, ranged};
use thiserror::Error;

/// F_grid's maximum: its value while gated off, and its cap.
pub const GRID_MAX: f64 = 100.0;

/// The paper's target number of leaves per cell.
pub const PAPER_TARGET: u32 = 15;

/// Most cells a grid may have.
pub const MAX_CELLS: usize = 1 << 20;

sylva_core::ranged!(corner: DVec3, "grid corner", -1e6, 1e6, " paper units");
ranged!(weight: f64, "weight", -1e6, 1e6, "");
sylva_core::ranged!(target: u32, "target", 1, 1_000_000);

sylva_core::ranged!(divisions: [u32; 3], "divisions", 1, 1024);
sylva_core::ranged!(cell_index: [u32; 3], "cell index", 0, 1023);

fn some_target<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<u32>, D::Error> {
    target(d).map(Some)
}

fn default_weight() -> f64 {
    1.0
}

fn default_target() -> u32 {
    PAPER_TARGET
}

/// A grid as written in a config.
///
/// ```toml
/// min = [-150, 0, -150]
/// max = [150, 375, 150]
/// divisions = [5, 5, 5]
/// weight = 1.0                 # every cell, unless overridden
/// target = 15
/// [[boxes]]                    # the top layer is forbidden
/// from = [0, 4, 0]
/// to = [4, 4, 4]
/// weight = -1.0
/// [[cells]]                    # one favoured cell, with its own target
/// at = [2, 2, 2]
/// weight = 2.0
/// target = 30
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridConfig {
    /// Lowest corner of the grid's box, paper units.
    #[serde(deserialize_with = "corner")]
    pub min: DVec3,
    /// Highest corner, paper units; above `min` on every axis.
    #[serde(deserialize_with = "corner")]
    pub max: DVec3,
    /// Cells along x, y and z (1 to 1024 each, at most 2²⁰ in all).
    #[serde(deserialize_with = "divisions")]
    pub divisions: [u32; 3],
    /// Weight of every cell not overridden. Default 1.
    #[serde(default = "default_weight", deserialize_with = "weight")]
    pub weight: f64,
    /// Target leaves of every cell not overridden. Default 15, the paper's.
    #[serde(default = "default_target", deserialize_with = "target")]
    pub target: u32,
    /// Boxes of cells sharing a weight and target, applied in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub boxes: Vec<GridBox>,
    /// Single cells, applied after the boxes, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cells: Vec<GridCell>,
}

/// A box of cells, `from` to `to` inclusive, sharing a weight and target.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridBox {
    /// First cell (x, y, z).
    #[serde(deserialize_with = "cell_index")]
    pub from: [u32; 3],
    /// Last cell (x, y, z), inclusive; not below `from` on any axis.
    #[serde(deserialize_with = "cell_index")]
    pub to: [u32; 3],
    /// Weight: > 0 favoured, < 0 forbidden, 0 ignored.
    #[serde(deserialize_with = "weight")]
    pub weight: f64,
    /// Target leaves; the grid's `target` when absent.
    #[serde(
        default,
        deserialize_with = "some_target",
        skip_serializing_if = "Option::is_none"
    )]
    pub target: Option<u32>,
}

/// One cell with its weight and target.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridCell {
    /// The cell (x, y, z).
    #[serde(deserialize_with = "cell_index")]
    pub at: [u32; 3],
    /// Weight: > 0 favoured, < 0 forbidden, 0 ignored.
    #[serde(deserialize_with = "weight")]
    pub weight: f64,
    /// Target leaves; the grid's `target` when absent.
    #[serde(
        default,
        deserialize_with = "some_target",
        skip_serializing_if = "Option::is_none"
    )]
    pub target: Option<u32>,
}

/// Why a grid is refused.
#[derive(Debug, Error, PartialEq)]
pub enum GridError {
    /// `max` not above `min`.
    #[error("grid `max` must be above `min` on every axis, got min {min:?} and max {max:?}")]
    EmptyBox {
        /// The lowest corner given.
        min: [f64; 3],
        /// The highest corner given.
        max: [f64; 3],
    },
    /// No cell, or more than [`MAX_CELLS`].
    #[error("a grid must have 1 to {MAX_CELLS} cells, {divisions:?} makes {cells}")]
    CellCount {
        /// The divisions given.
        divisions: [u32; 3],
        /// Their product.
        cells: u64,
    },
    /// A box or cell that leaves the grid.
    #[error("{what} {index} reaches cell {cell:?}, outside a grid of {divisions:?} cells")]
    OutOfGrid {
        /// `"box"` or `"cell"`.
        what: &'static str,
        /// Its position in its list, from 0.
        index: usize,
        /// The offending cell.
        cell: [u32; 3],
        /// The grid's divisions.
        divisions: [u32; 3],
    },
    /// A box whose `to` is below its `from`.
    #[error("box {index} runs from {from:?} down to {to:?}; `to` must not be below `from`")]
    ReversedBox {
        /// Its position in the list, from 0.
        index: usize,
        /// Its first cell.
        from: [u32; 3],
        /// Its last cell.
        to: [u32; 3],
    },
}

/// A checked grid with a weight and target per cell. Reads and writes as a [`GridConfig`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "GridConfig", into = "GridConfig")]
pub struct DensityGrid {
    config: GridConfig,
    cell_size: DVec3,
    weights: Vec<f64>,
    targets: Vec<f64>,
    weight_sum: f64,
}

impl TryFrom<GridConfig> for DensityGrid {
    type Error = GridError;
    fn try_from(config: GridConfig) -> Result<Self, GridError> {
        DensityGrid::new(config)
    }
}

impl From<DensityGrid> for GridConfig {
    fn from(grid: DensityGrid) -> GridConfig {
        grid.config
    }
}

/// The paper's fitness of one cell holding `leaves` leaves (see the module docs).
pub fn f_cell(weight: f64, leaves: u32, target: f64) -> f64 {
    let n = f64::from(leaves);
    if weight > 0.0 {
        weight * (1.0 - (n - target).abs() / (8.0 * target))
    } else if weight < 0.0 {
        weight * (1.0 + n / (4.0 * target))
    } else {
        0.0
    }
}

/// Sylva's relative error of one cell, `e` in the module docs (0 is perfect).
pub fn cell_error(weight: f64, leaves: u32, target: f64) -> f64 {
    let n = f64::from(leaves);
    if weight > 0.0 {
        (n - target).abs() / target
    } else if weight < 0.0 {
        2.0 * n / target
    } else {
        0.0
    }
}

impl DensityGrid {
    /// Checks a config and fills in every cell.
    pub fn new(config: GridConfig) -> Result<Self, GridError> {
        let (min, max) = (config.min, config.max);
        if !(min.cmplt(max).all()) {
            return Err(GridError::EmptyBox {
                min: min.to_array(),
                max: max.to_array(),
            });
        }
        let dims = config.divisions;
        let cells = dims.iter().map(|&n| u64::from(n)).product::<u64>();
        if cells == 0 || cells > MAX_CELLS as u64 {
            return Err(GridError::CellCount {
                divisions: dims,
                cells,
            });
        }
        let inside = |c: [u32; 3]| (0..3).all(|a| c[a] < dims[a]);
        let len = cells as usize;
        let mut weights = vec![config.weight; len];
        let mut targets = vec![f64::from(config.target); len];
        let index = |c: [u32; 3]| {
            c[0] as usize + dims[0] as usize * (c[1] as usize + dims[1] as usize * c[2] as usize)
        };
        for (i, b) in config.boxes.iter().enumerate() {
            for cell in [b.from, b.to] {
                if !inside(cell) {
                    return Err(GridError::OutOfGrid {
                        what: "box",
                        index: i,
                        cell,
                        divisions: dims,
                    });
                }
            }
            if (0..3).any(|a| b.to[a] < b.from[a]) {
                return Err(GridError::ReversedBox {
                    index: i,
                    from: b.from,
                    to: b.to,
                });
            }
            let t = f64::from(b.target.unwrap_or(config.target));
            for z in b.from[2]..=b.to[2] {
                for y in b.from[1]..=b.to[1] {
                    for x in b.from[0]..=b.to[0] {
                        let k = index([x, y, z]);
                        weights[k] = b.weight;
                        targets[k] = t;
                    }
                }
            }
        }
        for (i, c) in config.cells.iter().enumerate() {
            if !inside(c.at) {
                return Err(GridError::OutOfGrid {
                    what: "cell",
                    index: i,
                    cell: c.at,
                    divisions: dims,
                });
            }
            let k = index(c.at);
            weights[k] = c.weight;
            targets[k] = f64::from(c.target.unwrap_or(config.target));
        }
        let weight_sum = weights.iter().map(|w| w.abs()).sum();
        Ok(DensityGrid {
            cell_size: (max - min) / DVec3::from_array(dims.map(f64::from)),
            config,
            weights,
            targets,
            weight_sum,
        })
    }

    /// The config it was made from.
    pub fn config(&self) -> &GridConfig {
        &self.config
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// Always false: a grid has at least one cell.
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// The number of cell `(x, y, z)`, which must be inside the grid.
    pub fn index(&self, [x, y, z]: [u32; 3]) -> usize {
        let [nx, ny, _] = self.config.divisions.map(|n| n as usize);
        x as usize + nx * (y as usize + ny * z as usize)
    }

    /// `(x, y, z)` of cell number `i`.
    pub fn coords(&self, i: usize) -> [u32; 3] {
        let [nx, ny, _] = self.config.divisions.map(|n| n as usize);
        [
            (i % nx) as u32,
            ((i / nx) % ny) as u32,
            (i / (nx * ny)) as u32,
        ]
    }

    /// Weight of cell `i`.
    pub fn weight(&self, i: usize) -> f64 {
        self.weights[i]
    }

    /// Target leaves of cell `i`.
    pub fn target(&self, i: usize) -> f64 {
        self.targets[i]
    }

    /// Lowest and highest corners of cell `i`, paper units (for drawing forbidden cells).
    pub fn cell_bounds(&self, i: usize) -> (DVec3, DVec3) {
        let lo =
            self.config.min + DVec3::from_array(self.coords(i).map(f64::from)) * self.cell_size;
        (lo, lo + self.cell_size)
    }

    /// The cell holding `p` (paper units); cells include their low faces, and the grid's
    /// high faces belong to the last cells. `None` outside the grid or for NaN.
    pub fn cell_of(&self, p: DVec3) -> Option<usize> {
        let f = (p - self.config.min) / self.cell_size;
        let mut c = [0u32; 3];
        for a in 0..3 {
            let n = self.config.divisions[a];
            if !(f[a] >= 0.0 && f[a] <= f64::from(n)) {
                return None;
            }
            c[a] = (f[a] as u32).min(n - 1);
        }
        Some(self.index(c))
    }

    /// Counts the plant's leaves per cell into `counts` (resized to the grid, reused without
    /// allocating once large enough); returns how many leaves fell inside the grid.
    /// Positions are divided by `unit` (metres per paper unit).
    pub fn count_leaves(&self, plant: &Plant, unit: f64, counts: &mut Vec<u32>) -> usize {
        counts.clear();
        counts.resize(self.len(), 0);
        let mut inside = 0;
        for organ in plant.organs().iter().filter(|o| o.kind == OrganKind::Leaf) {
            if let Some(i) = self.cell_of(organ.position.as_dvec3() / unit) {
                counts[i] += 1;
                inside += 1;
            }
        }
        inside
    }

    /// The paper's grid fitness: the mean of [`f_cell`] over the cells (higher is better).
    pub fn paper_score(&self, counts: &[u32]) -> f64 {
        let sum: f64 = (0..self.len())
            .map(|i| f_cell(self.weights[i], counts[i], self.targets[i]))
            .sum();
        sum / self.len() as f64
    }

    /// F_grid as a cost in `0..=100` (see the module docs); 0 for a grid whose weights are
    /// all 0.
    pub fn cost(&self, counts: &[u32]) -> f64 {
        if self.weight_sum == 0.0 {
            return 0.0;
        }
        let sum: f64 = (0..self.len())
            .map(|i| {
                self.weights[i].abs() * cell_error(self.weights[i], counts[i], self.targets[i])
            })
            .sum();
        (GRID_MAX * sum / self.weight_sum).min(GRID_MAX)
    }

    /// Leaves in cells of negative weight.
    pub fn forbidden_leaves(&self, counts: &[u32]) -> usize {
        (0..self.len())
            .filter(|&i| self.weights[i] < 0.0)
            .map(|i| counts[i] as usize)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(boxes: Vec<GridBox>, cells: Vec<GridCell>) -> DensityGrid {
        DensityGrid::new(GridConfig {
            min: DVec3::ZERO,
            max: DVec3::new(10.0, 20.0, 30.0),
            divisions: [2, 2, 3],
            weight: 1.0,
            target: 15,
            boxes,
            cells,
        })
        .unwrap()
    }

    #[test]
    fn cells_number_and_locate() {
        let g = grid(vec![], vec![]);
        assert_eq!(g.len(), 12);
        assert_eq!(g.index([1, 0, 2]), 9);
        assert_eq!(g.coords(9), [1, 0, 2]);
        assert_eq!(g.cell_of(DVec3::new(7.0, 3.0, 25.0)), Some(9));
        assert_eq!(g.cell_of(DVec3::new(10.0, 20.0, 30.0)), Some(11)); // the far corner
        assert_eq!(g.cell_of(DVec3::new(10.1, 3.0, 25.0)), None);
        assert_eq!(g.cell_of(DVec3::new(f64::NAN, 3.0, 25.0)), None);
        let (lo, hi) = g.cell_bounds(9);
        assert_eq!(
            (lo, hi),
            (DVec3::new(5.0, 0.0, 20.0), DVec3::new(10.0, 10.0, 30.0))
        );
    }

    #[test]
    fn paper_cell_formulas() {
        // Favoured: best on target, a penalty past 9T leaves.
        assert_eq!(f_cell(2.0, 15, 15.0), 2.0);
        assert_eq!(f_cell(2.0, 0, 15.0), 2.0 * 7.0 / 8.0);
        assert_eq!(f_cell(2.0, 135, 15.0), 0.0);
        assert!(f_cell(2.0, 200, 15.0) < 0.0);
        // Forbidden: best (= w) with no leaf, worse with every leaf.
        assert_eq!(f_cell(-1.0, 0, 15.0), -1.0);
        assert_eq!(f_cell(-1.0, 60, 15.0), -2.0);
        assert_eq!(f_cell(0.0, 99, 15.0), 0.0);
    }

    #[test]
    fn cost_of_both_signs() {
        let g = grid(
            vec![GridBox {
                from: [0, 0, 2],
                to: [1, 1, 2],
                weight: -1.0,
                target: None,
            }],
            vec![],
        );
        // 8 favoured cells of weight 1 and 4 forbidden of weight -1: Σ|w| = 12.
        let mut counts = vec![0u32; 12];
        assert_eq!(g.cost(&counts), 100.0 * 8.0 / 12.0);
        for c in counts.iter_mut().take(8) {
            *c = 15;
        }
        assert_eq!(g.cost(&counts), 0.0);
        counts[8] = 3; // 3 leaves in a forbidden cell: e = 2·3/15 = 0.4
        assert!((g.cost(&counts) - 100.0 * 0.4 / 12.0).abs() < 1e-12);
        assert_eq!(g.forbidden_leaves(&counts), 3);
        counts[9] = 10_000;
        assert_eq!(g.cost(&counts), GRID_MAX);
    }

    #[test]
    fn cost_is_affine_in_the_papers_score() {
        let g = grid(
            vec![GridBox {
                from: [0, 1, 0],
                to: [1, 1, 1],
                weight: -2.0,
                target: Some(5),
            }],
            vec![GridCell {
                at: [1, 1, 2],
                weight: 3.0,
                target: Some(30),
            }],
        );
        let states: [[u32; 12]; 3] = [
            [0, 1, 0, 1, 4, 5, 0, 0, 8, 9, 10, 11],
            [15, 15, 0, 0, 15, 15, 0, 0, 15, 15, 20, 40],
            [3, 30, 1, 1, 9, 12, 0, 2, 14, 16, 15, 30],
        ];
        let (s, c): (Vec<f64>, Vec<f64>) =
            states.iter().map(|k| (g.paper_score(k), g.cost(k))).unzip();
        assert!(c.iter().all(|&c| c < GRID_MAX), "{c:?}"); // below the cap
        let slope = (c[1] - c[0]) / (s[1] - s[0]);
        assert!(slope < 0.0);
        assert!((c[2] - (c[0] + slope * (s[2] - s[0]))).abs() < 1e-9);
    }

    #[test]
    fn later_entries_override_and_bad_ones_are_refused() {
        let g = grid(
            vec![GridBox {
                from: [0, 0, 0],
                to: [1, 1, 2],
                weight: -1.0,
                target: None,
            }],
            vec![GridCell {
                at: [1, 1, 1],
                weight: 4.0,
                target: Some(2),
            }],
        );
        let k = g.index([1, 1, 1]);
        assert_eq!((g.weight(k), g.target(k)), (4.0, 2.0));
        assert_eq!((g.weight(0), g.target(0)), (-1.0, 15.0));
        let base = g.config().clone();
        let out = GridConfig {
            cells: vec![GridCell {
                at: [2, 0, 0],
                weight: 1.0,
                target: None,
            }],
            ..base.clone()
        };
        assert!(matches!(
            DensityGrid::new(out),
            Err(GridError::OutOfGrid { what: "cell", .. })
        ));
        let reversed = GridConfig {
            boxes: vec![GridBox {
                from: [1, 0, 0],
                to: [0, 0, 0],
                weight: 1.0,
                target: None,
            }],
            ..base.clone()
        };
        assert!(matches!(
            DensityGrid::new(reversed),
            Err(GridError::ReversedBox { .. })
        ));
        let flat = GridConfig {
            max: DVec3::new(10.0, 0.0, 30.0),
            ..base
        };
        assert!(matches!(
            DensityGrid::new(flat),
            Err(GridError::EmptyBox { .. })
        ));
    }
}
