//! What a run of a problem will allocate, estimated from the problem's
//! sizes before anything is allocated, and the budget it must fit.
//!
//! `solver.segments = 1e6` asked for a dense Jacobian of 9e6² numbers and
//! `continuation.intervals = 10000` for 24 GB before the process was
//! killed. The reader ([`super::Problem`], built by `input`) now refuses a problem whose
//! estimate exceeds the budget, naming the key that drives the largest item
//! and the estimate, so every command gets the check.
//!
//! The items (bytes; f64 = 8; n the state dimension of the model level, u
//! its free initial values, S = size_of RodSample = 176):
//!
//! | item | key | bytes |
//! |---|---|---|
//! | output samples | `solver.output_points` | points × 3 S (the samples and the HDF5 write buffers) |
//! | multiple shooting | `solver.segments` | 4 × 8 N², N = u + n (segments − 1) (dense Jacobian, its LU, Newton's copies) |
//! | collocation | `solver.max_intervals` | 2 × 8 K (m²n² + 2mn² + 2mn + (m+1)n), K = max_intervals, m = stages (per interval: the condensed LU, its right-hand sides, the stage Jacobians; the old and the new mesh during adaptation) |
//! | stability verdict | `stability.elements` | the finite elements below at the verdict's finest mesh, max(2E, min(32E, [`crate::stability::MAX_VERDICT_ELEMENTS`])) for E = elements (its first comparison, then [`crate::stability::REFINEMENTS`] doublings up to the cap), eigenvalues + 1 |
//! | continuation system | `continuation.intervals` (collocation) or `solver.segments` | N the family's unknowns: 6 × 8 (N+1)² (dense F_x, the bordered matrix, its LU, the SVD at branch points) for single shooting and N ≤ 200; above, 8 × 40 n (N+1) (band F_x, its copy and transpose, the bordered embedding, their LUs; the augmented systems of folds and branch points reuse them); plus the same for the refined family (2N unknowns on collocation) on which located points are located again |
//! | continuation points | `continuation.max_points` | points × branches × (8 (2N + 1 + 3k + 3 shape_points + measures) + S + 256), branches = (1 + both_directions)(1 + 6 k switch_depth) |
//! | tracked spectrum | `continuation.elements` | the finite elements below at `continuation.elements`, plus the previous point's 3k eigenvectors |
//! | arm's second variation | `arm.elements` | the finite elements below at 4 × arm.elements, 1 eigenvalue (a reported optimum is re-evaluated on finer meshes) |
//! | reach map | `arm.map_samples` | samples × (16 M + 160), M = arm.coefficients |
//! | sweep results | `sweep.axes` | points × families × (2048 + 16 M) (each point's named result columns) |
//!
//! Finite elements of E elements of order p with k eigenvalues: n_fe = 3 E p
//! unknowns over the blocks; 4 banded matrices (K, G, the LDLᵀ factor, a
//! shifted copy) of n_fe × (3(p + 1)) numbers; the Lanczos basis and its
//! G-image (kept so that a step needs one product by G), 2 n_fe (3k + 40)
//! (Sturm counts store no factor); and the shape at E (p + 1) quadrature
//! points (a sample and the form coefficients, S + 216):
//! 8 (4 · 3(p+1) + 2(3k + 40)) n_fe + E (p + 1)(S + 216). Measured (issue
//! 18, `/usr/bin/time -v`): the cantilever's verdict from 10⁵ elements
//! (meshes 10⁵ and 2·10⁵) peaks at 690 MB resident, 3.5 KB per element of
//! the finest mesh, where the formula gives 8.1 KB: an upper bound, as it
//! must be.
//!
//! The total is the sum of the items (an upper bound: the phases of one
//! run are not all alive at once). The budget is [`DEFAULT_BUDGET`] (4 GiB)
//! or `COSSERAT_MEMORY_BUDGET` in bytes, with an optional suffix K, M, G or
//! T (powers of 1024; `KiB`, `MB`, ... are read the same).

use crate::bvp::{equations, Method};
use crate::equations::RodSample;
use crate::stability::{MAX_VERDICT_ELEMENTS, REFINEMENTS};

use super::problem::{invalid, Problem, ProblemError};

/// The budget when `COSSERAT_MEMORY_BUDGET` is not set: 4 GiB.
pub const DEFAULT_BUDGET: u64 = 4 << 30;

/// The environment variable that overrides [`DEFAULT_BUDGET`].
pub const BUDGET_VARIABLE: &str = "COSSERAT_MEMORY_BUDGET";

/// One item of the estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct MemoryItem {
    /// The key whose value drives it.
    pub field: String,
    /// Estimated bytes.
    pub bytes: f64,
    /// What is counted, with the numbers.
    pub formula: String,
}

/// The estimate of a problem's run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MemoryEstimate {
    /// The items, in the order of the table above.
    pub items: Vec<MemoryItem>,
}

impl MemoryEstimate {
    /// The sum of the items (bytes).
    pub fn total(&self) -> f64 {
        self.items.iter().map(|i| i.bytes).sum()
    }

    /// The largest item.
    pub fn largest(&self) -> Option<&MemoryItem> {
        self.items.iter().max_by(|a, b| a.bytes.total_cmp(&b.bytes))
    }

    fn add(&mut self, field: &str, bytes: f64, formula: String) {
        self.items.push(MemoryItem {
            field: field.into(),
            bytes,
            formula,
        });
    }
}

const SAMPLE: f64 = std::mem::size_of::<RodSample>() as f64;

/// Bytes of the finite elements of `elements` elements of order `order`
/// with `eigenvalues` eigenvalues (module docs).
fn finite_elements(elements: f64, order: f64, eigenvalues: f64) -> f64 {
    let n = 3.0 * elements * order;
    let band = 3.0 * (order + 1.0);
    let lanczos = 2.0 * (3.0 * eigenvalues + 40.0);
    8.0 * (4.0 * band + lanczos) * n + elements * (order + 1.0) * (SAMPLE + 216.0)
}

/// What a run of `problem` will allocate (module docs).
pub fn estimate(problem: &Problem) -> MemoryEstimate {
    let mut e = MemoryEstimate::default();
    let eq = equations(&problem.rod, problem.model.level);
    let (n, u) = (eq.dim() as f64, eq.unknowns() as f64);
    add_solver(&mut e, problem, n, u);
    add_stability(&mut e, problem);
    add_continuation(&mut e, problem);
    add_arm(&mut e, problem);
    e
}

/// The BVP solver's items: the output samples and the method's Jacobian.
fn add_solver(e: &mut MemoryEstimate, problem: &Problem, n: f64, u: f64) {
    let points = problem.options.output_points as f64;
    e.add(
        "solver.output_points",
        points * 3.0 * SAMPLE,
        format!("{points} points × 3 × {SAMPLE} bytes"),
    );
    match problem.options.method {
        Method::Shooting => {}
        Method::MultipleShooting { segments } => {
            let size = u + n * (segments as f64 - 1.0);
            e.add(
                "solver.segments",
                4.0 * 8.0 * size * size,
                format!("a dense Jacobian of {size} unknowns, 4 × 8 × {size}²"),
            );
        }
        Method::Collocation { stages } => {
            let k = problem.options.collocation.max_intervals as f64;
            let m = stages as f64;
            let per = 8.0 * (m * m * n * n + 2.0 * m * n * n + 2.0 * m * n + (m + 1.0) * n);
            e.add(
                "solver.max_intervals",
                2.0 * k * per,
                format!("{k} intervals × 2 × {per} bytes"),
            );
        }
    }
}

/// The stability verdict's finest mesh.
fn add_stability(e: &mut MemoryEstimate, problem: &Problem) {
    let st = &problem.stability;
    let elements = st.elements() as f64;
    let refined = (elements * 2f64.powi(REFINEMENTS as i32)).min(MAX_VERDICT_ELEMENTS as f64);
    let finest = (2.0 * elements).max(refined);
    e.add(
        "stability.elements",
        finite_elements(finest, st.order() as f64, st.eigenvalues() as f64 + 1.0),
        format!(
            "the verdict's finest mesh, {finest} elements of order {}",
            st.order()
        ),
    );
}

/// Continuation's bordered systems, points and finite elements.
fn add_continuation(e: &mut MemoryEstimate, problem: &Problem) {
    if let Some((family, opts)) = &problem.continuation {
        let size = family.size() as f64 + 1.0;
        let field = if matches!(problem.options.method, Method::Collocation { .. }) {
            "continuation.intervals"
        } else {
            "solver.segments"
        };
        let n = equations(&problem.rod, problem.model.level).dim() as f64;
        // Each located fold or branch point is located again on the
        // refined family (twice the collocation intervals) while the run's
        // own systems are still held: its discretization error.
        let refined = match problem.options.method {
            Method::Collocation { .. } => 2.0 * family.size() as f64 + 1.0,
            _ => size,
        };
        let systems =
            continuation_system(family, size, n) + continuation_system(family, refined, n);
        e.add(field, systems, format!(
            "continuation systems of {size} unknowns (dense up to {}, band beyond, the augmented systems of folds and branch points too), and of {refined} on the refined family that states a located point's discretization error",
            crate::continuation::DENSE_UP_TO
        ));
        let k = opts.stability.eigenvalues() as f64;
        let branches = (1.0 + f64::from(u8::from(opts.both_directions)))
            * (1.0 + 6.0 * k * opts.switch_depth as f64);
        // The shape (3 per shape point) and the named measures.
        let stored = 3.0 * opts.shape_points as f64 + opts.measures.len() as f64;
        let per_point = 8.0 * (2.0 * size + 1.0 + 3.0 * k + stored) + SAMPLE + 256.0;
        let max_points = opts.max_points as f64;
        e.add(
            "continuation.max_points",
            max_points * branches * per_point,
            format!("{max_points} points × {branches} branches × {per_point} bytes"),
        );
        let (elements, order) = (
            opts.stability.elements() as f64,
            opts.stability.order() as f64,
        );
        e.add(
            "continuation.elements",
            finite_elements(elements, order, k) + 8.0 * 3.0 * k * 3.0 * elements * order,
            format!("{elements} elements of order {order}, {k} eigenvalues per block"),
        );
    }
}

/// The continuation's linear algebra for `size` = N + 1 unknowns of a
/// family of state dimension n: dense (6 × 8 (N+1)², F_x, the bordered
/// matrix, its LU, the SVD at branch points) up to
/// [`crate::continuation::DENSE_UP_TO`] unknowns or for single shooting;
/// above, band storage linear in N (F_x, its band copy and transpose, the
/// bordered embedding, their LUs: 8 × 40 n (N+1)); the augmented systems
/// of folds and branch points reuse the same band storage.
fn continuation_system(family: &crate::continuation::Family, size: f64, n: f64) -> f64 {
    let dense = |m: f64| 6.0 * 8.0 * m * m;
    if family.staircase().is_none() || size <= (crate::continuation::DENSE_UP_TO + 1) as f64 {
        return dense(size);
    }
    8.0 * 40.0 * n * size
}

/// The arm optimization's finite elements, map samples and sweep grid.
fn add_arm(e: &mut MemoryEstimate, problem: &Problem) {
    if let Some((arm, _, _)) = &problem.arm {
        let elements = 4.0 * arm.stability.elements() as f64;
        e.add(
            "arm.elements",
            finite_elements(elements, arm.stability.order() as f64, 1.0),
            format!(
                "4 × arm.elements = {elements} elements of order {}",
                arm.stability.order()
            ),
        );
    }
    let coefficients = problem
        .arm
        .as_ref()
        .map_or(0.0, |(a, _, _)| a.coefficients() as f64);
    if let Some((_, samples)) = &problem.arm_scene {
        let samples = *samples as f64;
        e.add(
            "arm.map_samples",
            samples * (16.0 * coefficients + 160.0),
            format!("{samples} samples × (16 × {coefficients} + 160) bytes"),
        );
    }
    if let Some(sweep) = &problem.sweep {
        let points = sweep.points() as f64;
        let per = sweep.families as f64 * (2048.0 + 16.0 * coefficients);
        e.add(
            "sweep.axes",
            points * per,
            format!("{points} grid points × {per} bytes"),
        );
    }
}

/// The budget: `COSSERAT_MEMORY_BUDGET` or [`DEFAULT_BUDGET`].
pub fn budget() -> Result<u64, ProblemError> {
    match std::env::var(BUDGET_VARIABLE) {
        Err(std::env::VarError::NotPresent) => Ok(DEFAULT_BUDGET),
        Err(std::env::VarError::NotUnicode(_)) => Err(invalid(
            BUDGET_VARIABLE,
            "is not text; give bytes, e.g. 4G or 4294967296",
        )),
        Ok(v) => parse_bytes(&v).ok_or_else(|| {
            invalid(
                BUDGET_VARIABLE,
                format!(
                    "`{v}` is not a size; give bytes with an optional suffix K, M, G or T \
                     (powers of 1024), e.g. 4G or 4294967296"
                ),
            )
        }),
    }
}

/// "4294967296", "4G", "4 GiB", "512MB", "1.5T" → bytes (1024-based).
pub fn parse_bytes(text: &str) -> Option<u64> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, suffix) = t.split_at(split);
    let number: f64 = number.parse().ok()?;
    let unit = match suffix.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1u64,
        "k" | "kb" | "kib" => 1 << 10,
        "m" | "mb" | "mib" => 1 << 20,
        "g" | "gb" | "gib" => 1 << 30,
        "t" | "tb" | "tib" => 1 << 40,
        _ => return None,
    };
    let bytes = number * unit as f64;
    (bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64).then_some(bytes as u64)
}

/// A size for messages: "3.2 GiB".
pub fn human(bytes: f64) -> String {
    let units = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = bytes;
    let mut i = 0;
    while v >= 1024.0 && i + 1 < units.len() {
        v /= 1024.0;
        i += 1;
    }
    if i == 0 {
        format!("{v:.0} bytes")
    } else if v >= 1024.0 {
        format!("{v:.2e} {}", units[i])
    } else {
        format!("{v:.1} {}", units[i])
    }
}

/// Refuses a problem whose estimate exceeds the budget, naming the key of
/// the largest item.
pub fn check(problem: &Problem) -> Result<(), ProblemError> {
    let budget = budget()?;
    let e = estimate(problem);
    let total = e.total();
    if total <= budget as f64 {
        return Ok(());
    }
    let largest = e.largest().expect("the output item is always there");
    Err(invalid(
        largest.field.clone(),
        format!(
            "this run would allocate about {} ({}; {} in all), above the memory budget of {} \
             ({BUDGET_VARIABLE}, default 4 GiB): lower {}, or raise the budget if the machine \
             has the memory",
            human(largest.bytes),
            largest.formula,
            human(total),
            human(budget as f64),
            largest.field
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_binary_suffixes() {
        assert_eq!(parse_bytes("4294967296"), Some(4 << 30));
        assert_eq!(parse_bytes("4G"), Some(4 << 30));
        assert_eq!(parse_bytes("4 GiB"), Some(4 << 30));
        assert_eq!(parse_bytes("512mb"), Some(512 << 20));
        assert_eq!(parse_bytes("1.5K"), Some(1536));
        for bad in ["", "G", "-1G", "4X", "1e3", "nan", "0"] {
            assert_eq!(parse_bytes(bad), None, "{bad}");
        }
        assert_eq!(human(3.5 * (1u64 << 30) as f64), "3.5 GiB");
    }
}
