//! Non-prismatic arms: the section profile A(s̄) as a design variable
//! (issue 20; Sipos & Várkonyi 2019, Sec. 5, leave it open).
//!
//! The section is piecewise linear in s̄ through its values a_j at K
//! uniform knots s̄_j = j/(K − 1), normalized to the prismatic arm's
//! material, ∫₀¹ A ds̄ = Σ a_j V_j = 1 (trapezoid weights V_j, exact for a
//! piecewise-linear A), and bounded below, A ≥ A_min > 0 (a section
//! vanishing somewhere would leave a hinge there). Sections are
//! geometrically similar, so every stiffness scales with the square of
//! the area: B_i(s̄) = B_i A(s̄)² (I ∝ A² at a fixed aspect ratio). With
//! the prismatic arm's A ≡ 1, the critical load γ_crit = F L²/B2 stays in
//! units of the prismatic arm's B2, so that tapered and prismatic loads
//! and reaches compare directly.
//!
//! For a loaded shape held fixed the moments, and so K1 of the fixed-shape
//! pencil K0 + λK1 ([`crate::stability::critical_load`]), do not depend
//! on the section, while every coefficient of K0 (A = H, `B = H[κ]×`,
//! `C = [κ]×ᵀH[κ]×` at zero load) is linear in H ∝ A². So the critical load
//! of a section is a generalized Rayleigh quotient
//! λ(A) = Σ_q w_q A_q² e_q / D, e_q the K0 density of the prismatic rod at
//! the quadrature point s_q for the critical mode and D = −vᵀK1v > 0, and
//! its derivative is exact from one mode (Hellmann–Feynman):
//! ∂λ/∂a_j = Σ_q 2 w_q A_q e_q φ_j(s_q) / D, φ_j the hat function of knot j.
//! The best section of a shape maximizes λ under the volume and the lower
//! bound: the optimality criterion ∂λ/∂a_j = μ V_j (uniform strain energy
//! per unit material where A > A_min) reached by the classical fixed-point
//! update a_j ← a_j (∂λ/∂a_j / (μ V_j))^{1/2} with μ set so that the
//! volume stays 1 (bisection), clamped to A_min and a move limit that is
//! halved whenever λ would fall (Olhoff 1970; Bendsøe & Sigmund,
//! *Topology Optimization*, 2003, Sec. 1.2.1). This beats a
//! derivative-free search over the knots: one eigen solve per step, with
//! its exact gradient, for any number of knots.

use thiserror::Error;

/// The joint ascent of shape and section (`taper_arm.rs`), named here with
/// the section it optimizes: its result, its feasible set and its
/// stopping tolerance.
pub use super::taper_arm::{
    ascend, AscentSummary, Feasible, JointAscent, JointEnd, Slope, ASCENT_TOLERANCE,
};

use crate::model::{ModelError, Profile, Rod};
use crate::numerics::banded::SymmetricBanded;
use crate::numerics::eigen::smallest_positive_load_factor;
use crate::stability::{
    Block, FiniteElements, FixedShape, FormCoefficients, StabilityError, StabilityOptions,
};
use nalgebra::{Matrix3, Vector3};

/// Why a taper or section was refused, or a section could not be found.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TaperError {
    /// A taper or section that breaks its constraints (the message names
    /// which).
    #[error("{0}")]
    Invalid(String),
    /// The fixed-shape pencil failed (its quadrature or eigen solve).
    #[error("the fixed-shape critical load failed: {0}")]
    Stability(String),
    /// The shape is stable under any load: there is no critical load to
    /// raise.
    #[error("the shape is stable under any load: no critical load to maximize")]
    Unloaded,
}

impl From<StabilityError> for TaperError {
    fn from(e: StabilityError) -> Self {
        TaperError::Stability(e.to_string())
    }
}

/// The design space of the section: its knots and its lower bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Taper {
    knots: usize,
    min_section: f64,
}

impl Taper {
    /// K ≥ 2 knots and 0 < A_min < 1 (the lower bound in units of the
    /// prismatic section; A_min ≥ 1 leaves only the prismatic arm).
    pub fn new(knots: usize, min_section: f64) -> Result<Taper, TaperError> {
        if knots < 2 {
            return Err(TaperError::Invalid(format!(
                "a section profile needs at least 2 knots, got {knots}"
            )));
        }
        if !(min_section > 0.0 && min_section < 1.0) {
            return Err(TaperError::Invalid(format!(
                "the smallest section must lie in (0, 1) (units of the prismatic section), \
                 got {min_section}"
            )));
        }
        Ok(Taper { knots, min_section })
    }

    /// K, the knots of the piecewise-linear section.
    pub fn knots(&self) -> usize {
        self.knots
    }

    /// A_min in units of the prismatic section.
    pub fn min_section(&self) -> f64 {
        self.min_section
    }
}

/// The tolerance on the volume ∫A ds̄ = 1 of a section.
const VOLUME_TOLERANCE: f64 = 1e-9;

/// A section profile A(s̄): piecewise linear through its values at uniform
/// knots, unit volume, bounded below. Built by [`Section::new`] or
/// [`Section::prismatic`].
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    values: Vec<f64>,
}

impl Section {
    /// The prismatic section A ≡ 1 on `knots` knots (at least 2).
    pub fn prismatic(knots: usize) -> Section {
        Section {
            values: vec![1.0; knots.max(2)],
        }
    }

    /// The section through `values` at uniform knots; refused unless there
    /// are at least two, every value is finite and ≥ `min_section` > 0,
    /// and the volume is 1 to 10⁻⁹.
    pub fn new(values: Vec<f64>, min_section: f64) -> Result<Section, TaperError> {
        if values.len() < 2 {
            return Err(TaperError::Invalid(
                "a section needs at least 2 knots".into(),
            ));
        }
        if let Some(v) = values
            .iter()
            .find(|v| !(v.is_finite() && **v >= min_section && **v > 0.0))
        {
            return Err(TaperError::Invalid(format!(
                "section value {v} is below the smallest section {min_section} (or not finite)"
            )));
        }
        let section = Section { values };
        let volume = section.volume();
        if (volume - 1.0).abs() > VOLUME_TOLERANCE {
            return Err(TaperError::Invalid(format!(
                "the section's volume ∫A ds̄ is {volume}, not 1 (the prismatic arm's)"
            )));
        }
        Ok(section)
    }

    /// The values a_j at the knots.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The knots s̄_j = j/(K − 1).
    pub fn knots(&self) -> Vec<f64> {
        let k = self.values.len() - 1;
        (0..=k).map(|j| j as f64 / k as f64).collect()
    }

    /// ∫₀¹ A ds̄ (the trapezoid rule, exact for a piecewise-linear A).
    pub fn volume(&self) -> f64 {
        self.values
            .iter()
            .zip(volume_weights(self.values.len()))
            .map(|(a, w)| a * w)
            .sum()
    }

    /// A(s̄), held constant outside [0, 1].
    pub fn at(&self, s: f64) -> f64 {
        let (j, t) = interval(self.values.len(), s);
        self.values[j] * (1.0 - t) + self.values[j + 1] * t
    }

    /// The stiffness profile b·A(s̄)² on a rod of unit length, for the
    /// equilibrium solvers, exactly: a quadratic on each knot interval
    /// (A = m + d t there, t ∈ [−1, 1], so A² = (m² + d²/2) T0 + 2md T1 +
    /// (d²/2) T2), kinked at the knots, where the solvers stop
    /// ([`crate::model::Rod::breaks`]). A natural spline through samples of
    /// A² rang at the kinks instead, and its intrinsic curvature with it
    /// (docs/extensions.md, "Loading path").
    pub fn stiffness(&self, b: f64) -> Result<Profile, ModelError> {
        let pieces = self
            .values
            .windows(2)
            .map(|w| {
                let (m, d) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
                vec![b * (m * m + 0.5 * d * d), b * 2.0 * m * d, b * 0.5 * d * d]
            })
            .collect();
        Profile::piecewise(self.knots(), pieces)
    }
}

/// The trapezoid weights V_j of uniform knots on [0, 1].
fn volume_weights(knots: usize) -> Vec<f64> {
    let h = 1.0 / (knots - 1) as f64;
    (0..knots)
        .map(|j| if j == 0 || j == knots - 1 { 0.5 * h } else { h })
        .collect()
}

/// The knot interval j of s̄ and the fraction t ∈ [0, 1] into it.
fn interval(knots: usize, s: f64) -> (usize, f64) {
    let k = (knots - 1) as f64;
    let x = (s.clamp(0.0, 1.0)) * k;
    let j = (x.floor() as usize).min(knots - 2);
    (j, x - j as f64)
}

/// The critical load of one section, with its exact gradient.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionLoad {
    /// λ_crit (the smallest over both blocks).
    pub load_factor: f64,
    /// The block whose mode is critical.
    pub block: Block,
    /// ∂λ_crit/∂a_j at the knots (of the critical block's mode).
    pub gradient: Vec<f64>,
}

/// The fixed-shape pencil of one loaded shape with the section left open:
/// the K1 of each block (independent of the section) and the K0
/// coefficients of the prismatic rod at the quadrature points.
#[derive(Debug, Clone)]
pub struct SectionPencil {
    fe: FiniteElements,
    points: Vec<f64>,
    weights: Vec<f64>,
    stiff: Vec<FormCoefficients>,
    load: Vec<FormCoefficients>,
    k1: [SymmetricBanded; 2],
}

/// The two blocks of a planar shape, in the order of `SectionPencil::k1`.
const BLOCKS: [Block; 2] = [Block::InPlane, Block::OutOfPlane];

impl SectionPencil {
    /// The pencil of `shape` on `rod` (the prismatic arm: L = 1, a unit
    /// load, constant stiffness) on the mesh of `opts`.
    pub fn new(
        rod: &Rod,
        shape: &FixedShape,
        opts: &StabilityOptions,
    ) -> Result<SectionPencil, TaperError> {
        let fe = FiniteElements::new(rod.length(), opts.elements(), opts.order());
        let points = fe.quadrature_points();
        let samples = shape.samples(rod, &points)?;
        let zero = Vector3::zeros();
        let (stiff, load): (Vec<_>, Vec<_>) = samples
            .iter()
            .map(|p| {
                let frame = Matrix3::from_columns(&p.directors);
                let force = frame.transpose() * p.force;
                let h = rod.energy().stiffness(p.s, &p.curvature);
                (
                    FormCoefficients::at(&h, &p.curvature, &zero, &zero),
                    FormCoefficients::at(&Matrix3::zeros(), &p.curvature, &p.moment, &force),
                )
            })
            .unzip();
        let k1 = BLOCKS.map(|b| fe.stiffness(&load, b));
        Ok(SectionPencil {
            weights: fe.quadrature_weights(),
            fe,
            points,
            stiff,
            load,
            k1,
        })
    }

    /// λ_crit of the arm with `section` and its gradient; refused when the
    /// eigen solve fails, [`TaperError::Unloaded`] when no load is critical.
    pub fn critical(&self, section: &Section) -> Result<SectionLoad, TaperError> {
        let squares: Vec<f64> = self.points.iter().map(|s| section.at(*s).powi(2)).collect();
        let scaled: Vec<FormCoefficients> = self
            .stiff
            .iter()
            .zip(&squares)
            .map(|(c, f)| FormCoefficients {
                a: c.a * *f,
                b: c.b * *f,
                c: c.c * *f,
            })
            .collect();
        let mut best: Option<(f64, Block, Vec<f64>)> = None;
        for (block, k1) in BLOCKS.iter().zip(&self.k1) {
            let k0 = self.fe.stiffness(&scaled, *block);
            let found = smallest_positive_load_factor(&k0, k1)
                .map_err(|e| TaperError::Stability(e.to_string()))?;
            if let Some((lambda, v)) = found {
                if best.as_ref().is_none_or(|b| lambda < b.0) {
                    best = Some((lambda, *block, v));
                }
            }
        }
        let (load_factor, block, v) = best.ok_or(TaperError::Unloaded)?;
        Ok(SectionLoad {
            load_factor,
            block,
            gradient: self.gradient(section, block, &v),
        })
    }

    /// ∂λ/∂a_j = Σ_q 2 w_q A_q e_q φ_j(s_q) / D for the mode v.
    fn gradient(&self, section: &Section, block: Block, v: &[f64]) -> Vec<f64> {
        let modes = self.fe.interpolate(block, v);
        let denominator: f64 = -modes
            .iter()
            .zip(&self.load)
            .zip(&self.weights)
            .map(|(((w, dw), c), q)| q * c.evaluate(w, dw))
            .sum::<f64>();
        let knots = section.values().len();
        let mut gradient = vec![0.0; knots];
        for ((((w, dw), c), q), s) in modes
            .iter()
            .zip(&self.stiff)
            .zip(&self.weights)
            .zip(&self.points)
        {
            let density = 2.0 * q * section.at(*s) * c.evaluate(w, dw) / denominator;
            let (j, t) = interval(knots, *s);
            gradient[j] += density * (1.0 - t);
            gradient[j + 1] += density * t;
        }
        gradient
    }
}

/// How hard to look for the strongest section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionSearch {
    /// Largest number of optimality-criterion steps.
    pub iterations: usize,
    /// Stop when no knot value moves by more than this.
    pub tolerance: f64,
}

impl Default for SectionSearch {
    fn default() -> Self {
        SectionSearch {
            iterations: 400,
            tolerance: 1e-7,
        }
    }
}

/// The strongest section of one shape.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionOptimum {
    /// The section.
    pub section: Section,
    /// Its λ_crit (in units of the prismatic arm's).
    pub load_factor: f64,
    /// The critical block.
    pub block: Block,
    /// Steps taken.
    pub iterations: usize,
    /// The last step moved no knot value by more than the tolerance (else
    /// the step budget ran out: the section is a true design, its load a
    /// true load, but maybe not the best one).
    pub converged: bool,
}

/// The section of largest λ_crit for the pencil's shape under the taper's
/// bounds, by the optimality-criterion iteration from `start` (module
/// doc). Every λ returned is the eigenvalue of the section returned.
pub fn strongest_section(
    pencil: &SectionPencil,
    taper: &Taper,
    start: Section,
    opts: &SectionSearch,
) -> Result<SectionOptimum, TaperError> {
    strongest_section_until(pencil, taper, start, opts, &|| false)
}

/// [`strongest_section`], stopping at the next step once `stop()` turns
/// true (an interrupt): the section so far, not converged.
pub fn strongest_section_until(
    pencil: &SectionPencil,
    taper: &Taper,
    start: Section,
    opts: &SectionSearch,
    stop: &dyn Fn() -> bool,
) -> Result<SectionOptimum, TaperError> {
    let mut section = start;
    let mut current = pencil.critical(&section)?;
    let mut moving = 0.2;
    let mut converged = false;
    let mut iterations = 0;
    while iterations < opts.iterations && !stop() {
        iterations += 1;
        let trial = criterion_step(&section, &current.gradient, taper.min_section, moving);
        let next = pencil.critical(&trial)?;
        if next.load_factor >= current.load_factor {
            let change = trial
                .values
                .iter()
                .zip(&section.values)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            section = trial;
            current = next;
            moving = (moving * 1.5_f64).min(0.2);
            if change < opts.tolerance {
                converged = true;
                break;
            }
        } else {
            moving *= 0.5;
            if moving < opts.tolerance {
                converged = true;
                break;
            }
        }
    }
    Ok(SectionOptimum {
        section,
        load_factor: current.load_factor,
        block: current.block,
        iterations,
        converged,
    })
}

/// One optimality-criterion step: a_j (g_j/(μV_j))^{1/2}, within the move
/// limit a_j(1 ± m) and above A_min, μ by bisection on log μ so that the
/// volume is 1.
fn criterion_step(section: &Section, gradient: &[f64], min: f64, moving: f64) -> Section {
    let a = &section.values;
    let weights = volume_weights(a.len());
    let trial = |log_mu: f64| -> Vec<f64> {
        let mu = log_mu.exp();
        a.iter()
            .zip(gradient)
            .zip(&weights)
            .map(|((a, g), w)| {
                let factor = (g.max(0.0) / (mu * w)).sqrt();
                (a * factor).clamp((a * (1.0 - moving)).max(min), a * (1.0 + moving))
            })
            .collect()
    };
    let volume = |v: &[f64]| -> f64 { v.iter().zip(&weights).map(|(a, w)| a * w).sum() };
    let scale: f64 = gradient
        .iter()
        .map(|g| g.abs())
        .sum::<f64>()
        .max(f64::MIN_POSITIVE);
    let (mut lo, mut hi) = (scale.ln() - 60.0, scale.ln() + 60.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if volume(&trial(mid)) > 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let mut values = trial(0.5 * (lo + hi));
    // The bisection leaves the volume within a few ulps of 1; the knots off
    // the bounds absorb the rest.
    let free: f64 = values
        .iter()
        .zip(&weights)
        .filter(|(v, _)| **v > min)
        .map(|(v, w)| v * w)
        .sum();
    let fixed = volume(&values) - free;
    if free > 0.0 {
        let f = (1.0 - fixed) / free;
        for v in values.iter_mut().filter(|v| **v > min) {
            *v *= f;
        }
    }
    Section { values }
}
