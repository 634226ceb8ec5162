//! `cosserat.stability`: the stability of the problem's equilibrium
//! (spectra, Morse index, a verdict decided on refined meshes) or the
//! critical load of its fixed `[shape]`, as `cosserat stability` computes
//! them.

use std::collections::BTreeMap;
use std::path::PathBuf;

use cosserat::input::Problem;
use cosserat::output::StabilityResult;
use cosserat::stability::{critical_load, decide, Verdict};
use numpy::PyArray1;
use pyo3::prelude::*;

use crate::arrays::column;
use crate::errors::Failure;
use crate::output::{write_claimed, Written};

/// How the verdict was reached on an equilibrium's meshes.
struct Refinement {
    verdict: String,
    elements: usize,
    eigenvalue_error: f64,
}

/// The analysis `cosserat stability` makes of the problem.
fn analyze(problem: &Problem) -> Result<(StabilityResult, Option<Refinement>), Failure> {
    let opts = &problem.stability;
    if let Some(shape) = &problem.shape {
        let c = critical_load(&problem.rod, shape, opts)
            .map_err(|e| Failure::NoResult(e.to_string()))?;
        return Ok((StabilityResult::FixedShape(c), None));
    }
    let (eq, _) = crate::equilibrium::run(problem)?;
    let decision = decide(&problem.rod, &eq, &problem.options, opts)
        .map_err(|e| Failure::NoResult(e.to_string()))?;
    let verdict = match &decision.verdict {
        Verdict::Stable => "stable".to_string(),
        Verdict::Unstable { .. } => "unstable".to_string(),
        Verdict::Undecided { reason } => {
            return Err(Failure::NoResult(format!("stability undecided: {reason}")))
        }
    };
    let Some(st) = decision.stability.clone() else {
        return Err(Failure::NoResult(
            "stability undecided: no mesh was analysed".into(),
        ));
    };
    let refinement = Refinement {
        verdict,
        elements: decision.elements,
        eigenvalue_error: decision.eigenvalue_error,
    };
    Ok((
        StabilityResult::Equilibrium(Box::new(eq), st),
        Some(refinement),
    ))
}

/// The stability of an equilibrium, or the critical load of a fixed shape
/// (`kind` says which; the other's attributes are None).
#[pyclass(module = "cosserat", frozen)]
pub struct Stability {
    result: StabilityResult,
    refinement: Option<Refinement>,
    written: Written,
}

impl Stability {
    /// Analyzes the problem read from `input` (if a file).
    pub fn compute(problem: &Problem, input: Option<PathBuf>) -> Result<Self, Failure> {
        let (result, refinement) = analyze(problem)?;
        Ok(Stability {
            result,
            refinement,
            written: Written::new(problem.text.clone(), input),
        })
    }
}

#[pymethods]
impl Stability {
    /// "equilibrium" (spectra of a solved equilibrium) or "fixed_shape"
    /// (the critical load of the problem's [shape]).
    #[getter]
    fn kind(&self) -> &'static str {
        match self.result {
            StabilityResult::Equilibrium(..) => "equilibrium",
            StabilityResult::FixedShape(_) => "fixed_shape",
        }
    }

    /// "stable" or "unstable" (decided on meshes that agree); for a fixed
    /// shape, "critical" when a positive critical load exists, else "stable".
    #[getter]
    fn verdict(&self) -> &str {
        match (&self.result, &self.refinement) {
            (_, Some(r)) => &r.verdict,
            (StabilityResult::FixedShape(c), None) if c.load_factor.is_some() => "critical",
            _ => "stable",
        }
    }

    /// The Morse index (negative eigenvalues of the second variation).
    #[getter]
    fn morse_index(&self) -> Option<usize> {
        match &self.result {
            StabilityResult::Equilibrium(_, st) => Some(st.morse_index),
            StabilityResult::FixedShape(_) => None,
        }
    }

    /// The lowest eigenvalues of each block ("in_plane", "out_of_plane",
    /// or "spatial"), on the finest mesh used.
    #[getter]
    fn eigenvalues<'py>(
        &self,
        py: Python<'py>,
    ) -> BTreeMap<&'static str, Bound<'py, PyArray1<f64>>> {
        match &self.result {
            StabilityResult::Equilibrium(_, st) => st
                .blocks
                .iter()
                .map(|b| (b.block.name(), column(py, b.eigenvalues.clone())))
                .collect(),
            StabilityResult::FixedShape(_) => BTreeMap::new(),
        }
    }

    /// Elements of the finest mesh used for the verdict.
    #[getter]
    fn elements(&self) -> Option<usize> {
        self.refinement.as_ref().map(|r| r.elements)
    }

    /// The eigenvalues' discretization error bound on that mesh.
    #[getter]
    fn eigenvalue_error(&self) -> Option<f64> {
        self.refinement.as_ref().map(|r| r.eigenvalue_error)
    }

    /// Fixed shape: the smallest critical load factor (multiplies the
    /// problem's loads); None when stable under any positive load.
    #[getter]
    fn load_factor(&self) -> Option<f64> {
        match &self.result {
            StabilityResult::FixedShape(c) => c.load_factor,
            StabilityResult::Equilibrium(..) => None,
        }
    }

    /// Fixed shape: the dimensionless critical load γ = λ|P|L²/B2(0).
    #[getter]
    fn gamma(&self) -> Option<f64> {
        match &self.result {
            StabilityResult::FixedShape(c) => c.gamma,
            StabilityResult::Equilibrium(..) => None,
        }
    }

    /// Fixed shape: the critical load factor of each block (None: none).
    #[getter]
    fn block_load_factors(&self) -> BTreeMap<&'static str, Option<f64>> {
        match &self.result {
            StabilityResult::FixedShape(c) => {
                c.blocks.iter().map(|(b, f, _)| (b.name(), *f)).collect()
            }
            StabilityResult::Equilibrium(..) => BTreeMap::new(),
        }
    }

    /// The effective problem text (overrides applied).
    #[getter]
    fn problem(&self) -> &str {
        self.written.text()
    }

    /// Writes the report as `cosserat stability -o` does; an existing
    /// file is replaced only with `force=True`.
    #[pyo3(signature = (path, force = false))]
    #[allow(clippy::needless_pass_by_value)] // pyo3 hands arguments over owned
    fn to_hdf5(&self, py: Python<'_>, path: PathBuf, force: bool) -> PyResult<()> {
        let text = self.written.text();
        write_claimed(py, &self.written, &path, force, |p| {
            cosserat::output::write_stability(p, text, &self.result, true)
        })
    }

    fn __repr__(&self) -> String {
        match (&self.result, self.morse_index()) {
            (StabilityResult::FixedShape(c), _) => {
                let shown = |v: Option<f64>| v.map_or("None".to_string(), |v| format!("{v:.10}"));
                format!(
                    "Stability(fixed_shape, load_factor {}, gamma {})",
                    shown(c.load_factor),
                    shown(c.gamma)
                )
            }
            (_, morse) => format!(
                "Stability({}, Morse index {}, {} elements)",
                self.verdict(),
                morse.unwrap_or(0),
                self.elements().unwrap_or(0)
            ),
        }
    }
}
