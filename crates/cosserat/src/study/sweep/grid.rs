//! The grid of a sweep: axes of problem-file keys and their values, the
//! Cartesian product in row-major order (the last axis fastest), and the
//! `--set` overrides that make each point of the base problem.

/// The largest grid a sweep accepts (its results are held in memory).
pub const MAX_POINTS: usize = 1_000_000;

/// One axis of the grid: a key and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepAxis {
    /// The overridden key.
    pub key: String,
    /// Its values, in order.
    pub values: Vec<f64>,
}

/// A checked `[sweep]` table.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// The axes, the last one varying fastest.
    pub axes: Vec<SweepAxis>,
    /// Families of local optima (arm sweeps).
    pub families: usize,
    /// Warm starts along the last axis (arm sweeps).
    pub warm_start: bool,
    /// Halton samples at a warm-started point.
    pub warm_samples: usize,
    /// Nelder–Mead iterations of a warm polish.
    pub warm_iterations: u64,
}

impl Sweep {
    /// Number of grid points.
    pub fn points(&self) -> usize {
        self.axes.iter().map(|a| a.values.len()).product()
    }

    /// The grid's shape, axis by axis.
    pub fn shape(&self) -> Vec<usize> {
        self.axes.iter().map(|a| a.values.len()).collect()
    }

    /// The multi-index of flat point `i` (row-major, last axis fastest).
    pub fn multi_index(&self, i: usize) -> Vec<usize> {
        grid_index(&self.shape(), i)
    }

    /// The axis values at flat point `i`.
    pub fn parameters(&self, i: usize) -> Vec<f64> {
        self.multi_index(i)
            .iter()
            .zip(&self.axes)
            .map(|(j, a)| a.values[*j])
            .collect()
    }

    /// The `--set` overrides that make point `i` of the base problem.
    pub fn overrides(&self, i: usize) -> Vec<String> {
        self.parameters(i)
            .iter()
            .zip(&self.axes)
            .map(|(v, a)| format!("{}={}", a.key, toml_number(*v)))
            .collect()
    }
}

/// A number as TOML text: integral values as integers (so that integer
/// keys such as `arm.coefficients` can be swept), others in Rust's
/// shortest round-trip form.
fn toml_number(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v:?}")
    }
}

/// The multi-index of flat point `i` on a grid of `shape` (row-major, the
/// last axis fastest) — the order of every sweep file.
pub fn grid_index(shape: &[usize], mut i: usize) -> Vec<usize> {
    let mut out = vec![0; shape.len()];
    for (k, n) in shape.iter().enumerate().rev() {
        out[k] = i % n;
        i /= n;
    }
    out
}
