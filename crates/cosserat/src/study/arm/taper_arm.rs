//! The tapered longest arm: the loaded shape c2..cM and the section
//! profile A(s̄) ([`super::taper`]) optimized together under the material
//! budget ∫A ds̄ = 1, A ≥ A_min, B_i(s̄) = B_i A(s̄)².
//!
//! The reach R̂ = √γ_crit(c, A) |r̄(1; c)| is the prismatic arm's with the
//! critical load of the tapered rod; the chord depends on the shape alone
//! and γ_crit is in units of the prismatic B2, so R̂ compares directly with
//! the prismatic R*. The search starts from the prismatic optimum of the
//! same problem (the Sobol' + Nelder–Mead search of [`ArmProblem`], A ≡ 1)
//! with the strongest section of its shape ([`strongest_section`], the
//! optimality criterion), then maximizes R̂ over the shape and the section
//! together by projected BFGS ([`joint_ascent`]) on the box of c2..cM, the
//! bound A ≥ A_min and the volume Σ V_j a_j = 1, with the exact gradient:
//!
//!   ∂R̂/∂c_j = ½ R̂/λ (∂λ/∂c_j + ∂λ/∂c_1 ∂c1/∂c_j) + √λ ∂ρ/∂c_j,
//!   ∂R̂/∂a_j = ½ ρ/√λ ∂λ/∂a_j,
//!
//! ∂λ/∂c from [`critical_load_gradient`] on the tapered rod (its stiffness
//! B_i A² exact, [`Section::stiffness`]), the chord's rates as for the
//! prismatic arm (`gradient.rs`), ∂λ/∂a from the section's Rayleigh
//! quotient ([`SectionPencil`]), until the projected gradient is at most
//! [`ASCENT_TOLERANCE`] × R̂. The optimum is then polished again, from
//! itself, on 2N and 4N elements: R* on the three meshes gives the measured
//! order and Richardson's error ([`MeshStudy`]). (Block coordinate ascent —
//! the section, then Nelder–Mead on the shape, in turns — reached its cap
//! of 12 rounds still gaining 5e-4 a round.) The intrinsic curvature of the
//! design is (43) with the tapered stiffness: κ̄⁰2 = φ' − γ m̄2 / A(s̄)².

mod joint_ascent;

use std::sync::Arc;

pub use joint_ascent::{ascend, Feasible, JointAscent, JointEnd, Slope};

use super::design::intrinsic_shape;
use super::gradient::chord_rates;
use super::taper::{
    strongest_section_until, Section, SectionPencil, SectionSearch, Taper, TaperError,
};
use super::{continue_to_design, derivative, polynomial};
use super::{ArmDesign, ArmProblem, ArmScene, MeshStudy, SearchOptions, SearchProgress};
use crate::continuation::{ContinuationError, Diagram, Parameter};
use crate::model::{LinearElastic, ModelError, Profile, Rod};
use crate::stability::{
    critical_load, critical_load_gradient, Block, FixedShape, LoadGradient, StabilityOptions,
    TURN_PER_ELEMENT,
};

/// The joint ascent stops when its projected gradient is at most this × R̂:
/// near a smooth optimum with an O(1) Hessian R̂ is then within
/// ~½ (10⁻⁷ R̂)² ≈ 10⁻¹³ of its maximum, far below the discretization
/// error. (10⁻⁸, the prismatic polish's, lies at the round-off of R̂ here:
/// the shipped optimum's ascent ended at 1.2e-8 R̂ where a further step
/// predicted a rise of 10⁻¹⁴, below the eigenvalues' round-off.)
pub const ASCENT_TOLERANCE: f64 = 1e-7;

/// Largest number of joint-ascent iterations on one mesh.
const ASCENT_ITERATIONS: usize = 1000;

/// The tolerance of the designed rod's κ̄⁰ on each knot interval, relative
/// to its largest value there or 1/L ([`TaperedArm::designed_rod`]): a few
/// ulps above the rounding of the shape's moment (DOP853 at 10⁻¹²,
/// [`FixedShape::samples`]).
const KAPPA0_TOLERANCE: f64 = 1e-13;

/// Points of the reported shapes (as for the prismatic arm).
const SHAPE_POINTS: usize = 101;

/// The tapered arm to design: the prismatic arm's problem (weightless,
/// tip load) and the section's design space.
#[derive(Debug, Clone, PartialEq)]
pub struct TaperedArm {
    arm: ArmProblem,
    taper: Taper,
}

/// The best tapered arm with what a user keeps of it.
#[derive(Debug, Clone, PartialEq)]
pub struct TaperedOptimum {
    /// R̂, γ_crit (units of the prismatic B2) and c1..cM.
    pub design: ArmDesign,
    /// The section A(s̄) (unit volume).
    pub section: Section,
    /// The prismatic optimum the search started from (same mesh).
    pub prismatic: ArmDesign,
    /// The critical block of the design.
    pub block: Block,
    /// γ_crit of the designed rod by [`critical_load`] (its stiffness
    /// B_i A² exactly, as the loading path's): the check of `design.gamma`
    /// through the library's fixed-shape pencil.
    pub critical_load: f64,
    /// R* re-polished on N, 2N and 4N elements from the optimum on N.
    pub mesh: MeshStudy,
    /// How the joint ascent on N elements ended.
    pub ascent: AscentSummary,
    /// The loaded shape in scaled coordinates √γ (x̄, ȳ, z̄).
    pub loaded_shape: Vec<[f64; 3]>,
    /// The unloaded shape, same scaling and clamp.
    pub unloaded_shape: Vec<[f64; 3]>,
    /// κ̄⁰2 = φ' − γ m̄2/A² at the shape points.
    pub intrinsic_curvature: Vec<f64>,
    /// A(s̄) at the shape points.
    pub section_at_points: Vec<f64>,
    /// Designs evaluated (eigen solves), the mesh study's included.
    pub evaluations: usize,
    /// Elements of the mesh the design was optimized on.
    pub elements: usize,
    /// The taper's lower bound A_min.
    pub min_section: f64,
}

/// The end of a joint ascent, for reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AscentSummary {
    /// Why it ended ([`JointEnd::Converged`]: the projected gradient met
    /// [`ASCENT_TOLERANCE`] × R̂).
    pub end: JointEnd,
    /// max_i |x_i − P(x + ∇R̂)_i| at the optimum (NaN without a gradient).
    pub projected_gradient: f64,
    /// Quasi-Newton iterations.
    pub iterations: usize,
}

impl TaperedOptimum {
    /// Richardson's estimate of the mesh error of R* on N elements with the
    /// measured order (NaN where the order is undecided).
    pub fn reach_error(&self) -> f64 {
        self.mesh.error().unwrap_or(f64::NAN)
    }
}

/// What the loading path of a design shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LoadingVerdict {
    /// Loading from nearly unloaded reaches the design (its tip within
    /// 10⁻³ L) with no loss of stability before the design load.
    ReachesDesign,
    /// The path loses stability (Morse index > 0, a fold or a branch
    /// point) at this load factor below the design load.
    LosesStability(f64),
    /// The path reaches λ = 1 on another equilibrium: its tip this far
    /// (per L) from the design's.
    OtherEquilibrium(f64),
    /// The path ended (interrupted, or the continuation stopped) at this
    /// λ < 1: no verdict.
    Undecided(f64),
}

impl LoadingVerdict {
    /// The verdict's number: the load factor of the loss of stability, the
    /// miss per L, where the path ended; NaN when it reaches the design.
    pub fn value(self) -> f64 {
        match self {
            LoadingVerdict::ReachesDesign => f64::NAN,
            LoadingVerdict::LosesStability(v)
            | LoadingVerdict::OtherEquilibrium(v)
            | LoadingVerdict::Undecided(v) => v,
        }
    }

    /// The verdict's name in result files.
    pub fn name(self) -> &'static str {
        match self {
            LoadingVerdict::ReachesDesign => "reaches_design",
            LoadingVerdict::LosesStability(_) => "loses_stability",
            LoadingVerdict::OtherEquilibrium(_) => "other_equilibrium",
            LoadingVerdict::Undecided(_) => "undecided",
        }
    }
}

/// Load factors closer to 1 than this count as the design load.
const AT_DESIGN: f64 = 1e-3;

impl TaperedArm {
    /// The tapered version of `arm` (its scene must be the weightless arm
    /// under a tip load; the input refuses the others).
    pub fn new(arm: ArmProblem, taper: Taper) -> TaperedArm {
        TaperedArm { arm, taper }
    }

    /// The prismatic problem.
    pub fn arm(&self) -> &ArmProblem {
        &self.arm
    }

    /// The section's design space.
    pub fn taper(&self) -> &Taper {
        &self.taper
    }

    /// The shape c2..cM with `section` on `mesh`: the design (R̂ = √γ |r̄(1)|)
    /// and the pencil of its shape; None when the shape has no critical
    /// load or its pencil fails.
    fn evaluate(
        &self,
        rest: &[f64],
        section: &Section,
        mesh: &StabilityOptions,
    ) -> Option<(ArmDesign, SectionPencil, Block)> {
        let (c, chord) = self.arm.full_coefficients(rest);
        let rod = self.arm.rod().ok()?;
        let shape = FixedShape {
            turning_angle: Profile::Polynomial(c.clone()),
        };
        let pencil = SectionPencil::new(&rod, &shape, mesh).ok()?;
        let load = pencil.critical(section).ok()?;
        let design = ArmDesign {
            reach: load.load_factor.sqrt() * chord,
            gamma: load.load_factor,
            shape_coefficients: c,
        };
        Some((design, pencil, load.block))
    }

    /// The best tapered arm, or None when no shape in the bounds has a
    /// critical load. Stops at the next evaluation once `stop()` turns
    /// true, returning None (the tapered search is short and not resumed).
    pub fn optimize(
        &self,
        opts: &SearchOptions,
        stop: &dyn Fn() -> bool,
    ) -> Result<Option<TaperedOptimum>, TaperError> {
        let scene = ArmScene::default();
        let (prismatic, progress, interrupted) =
            self.arm
                .search_on_mesh(&scene, opts, SearchProgress::default(), stop, &mut |_| {});
        if interrupted {
            return Ok(None);
        }
        let Some(prismatic) = prismatic else {
            return Ok(None);
        };
        let mut evaluations = progress.evaluations;
        let mesh = self.arm.stability;
        let rest = prismatic.design.shape_coefficients[1..].to_vec();
        let (section, _, used) =
            self.strongest_for(&rest, Section::prismatic(self.taper.knots()), &mesh, stop)?;
        evaluations += used;
        let run = self.ascend_on(&rest, &section, &mesh, stop);
        evaluations += run.evaluations;
        if stop() {
            return Ok(None);
        }
        let Some((x, _)) = run.best.clone() else {
            return Ok(None);
        };
        let ascent = AscentSummary {
            end: run.end,
            projected_gradient: run.projected_gradient,
            iterations: run.iterations,
        };
        let (study, used) = self.mesh_study(&x, run.best.map_or(f64::NAN, |b| b.1), stop)?;
        evaluations += used;
        if stop() {
            return Ok(None);
        }
        let (rest, section) = self.split(&x)?;
        self.finish(
            &rest,
            section,
            prismatic.design,
            (study, ascent, evaluations),
        )
    }

    /// The joint ascent of R̂ over (c2..cM, a_1..a_K) on `mesh` from the
    /// shape `rest` and `section` (module doc).
    pub fn ascend_on(
        &self,
        rest: &[f64],
        section: &Section,
        mesh: &StabilityOptions,
        stop: &dyn Fn() -> bool,
    ) -> JointAscent {
        let mut start = rest.to_vec();
        start.extend_from_slice(section.values());
        let scales: Vec<f64> = self
            .arm
            .bounds
            .iter()
            .map(|(lo, hi)| hi - lo)
            .chain(std::iter::repeat_n(1.0, section.values().len()))
            .collect();
        ascend(
            &start,
            &self.feasible(),
            &scales,
            (ASCENT_ITERATIONS, ASCENT_TOLERANCE),
            &|x| self.slope(x, mesh),
            stop,
        )
    }

    /// The design space of the joint ascent: the box of c2..cM, a_j ≥
    /// A_min, Σ V_j a_j = 1 (the trapezoid weights of the knots).
    pub fn feasible(&self) -> Feasible {
        let k = self.taper.knots();
        let m = self.arm.bounds.len();
        let lower = self
            .arm
            .bounds
            .iter()
            .map(|b| b.0)
            .chain(std::iter::repeat_n(self.taper.min_section(), k))
            .collect();
        let upper = self
            .arm
            .bounds
            .iter()
            .map(|b| b.1)
            .chain(std::iter::repeat_n(f64::INFINITY, k))
            .collect();
        let h = 1.0 / (k - 1) as f64;
        let weights = std::iter::repeat_n(0.0, m)
            .chain((0..k).map(|j| if j == 0 || j == k - 1 { 0.5 * h } else { h }))
            .collect();
        Feasible::new(lower, upper, weights, 1.0)
            .expect("A_min < 1 leaves the prismatic section feasible")
    }

    /// (c2..cM, section) of a design vector.
    fn split(&self, x: &[f64]) -> Result<(Vec<f64>, Section), TaperError> {
        let (rest, values) = x.split_at(self.arm.bounds.len());
        Ok((
            rest.to_vec(),
            Section::new(values.to_vec(), self.taper.min_section())?,
        ))
    }

    /// The rod of the tapered arm under its unit load: the prismatic arm's
    /// with stiffness B_i A² (exact) and no intrinsic curvature (the
    /// fixed-shape pencil needs only the stiffness).
    fn tapered_rod(&self, section: &Section) -> Result<Rod, ModelError> {
        let energy = LinearElastic::new(
            [
                section.stiffness(self.arm.b1)?,
                section.stiffness(1.0)?,
                section.stiffness(self.arm.b3)?,
            ],
            [0.0; 3].map(Profile::Constant),
        )?;
        Ok(self.arm.rod()?.with_energy(Arc::new(energy)))
    }

    /// R̂ of the design vector x = (c2..cM, a_1..a_K) on `mesh` with its
    /// exact gradient (module doc); no gradient where λ_crit is not simple
    /// or the two pencils disagree; None without a critical load.
    pub fn slope(&self, x: &[f64], mesh: &StabilityOptions) -> Option<Slope> {
        let (rest, section) = self.split(x).ok()?;
        let (c, chord) = self.arm.full_coefficients(&rest);
        let rod = self.tapered_rod(&section).ok()?;
        let (lambda, dl) = match critical_load_gradient(&rod, &c, mesh).ok()? {
            LoadGradient::Stable => return None,
            LoadGradient::Multiple { load_factor, .. } => (load_factor, None),
            LoadGradient::Simple {
                load_factor,
                gradient,
            } => (load_factor, Some(gradient)),
        };
        let root = lambda.sqrt();
        let reach = root * chord;
        let Some(dl) = dl else {
            return Some((reach, None));
        };
        let shape = FixedShape {
            turning_angle: Profile::Polynomial(c.clone()),
        };
        let pencil = SectionPencil::new(&self.arm.rod().ok()?, &shape, mesh).ok()?;
        let load = pencil.critical(&section).ok()?;
        if (load.load_factor - lambda).abs() > 1e-9 * lambda {
            return Some((reach, None));
        }
        let (dchord, dc1) = chord_rates(&c);
        let gradient = (1..c.len())
            .map(|j| 0.5 * reach / lambda * (dl[j] + dl[0] * dc1[j - 1]) + root * dchord[j - 1])
            .chain(load.gradient.iter().map(|g| 0.5 * chord / root * g))
            .collect();
        Some((reach, Some(gradient)))
    }

    /// The optimum `x` (R̂ = `reach` on N elements) polished again on 2N and
    /// 4N from itself: the mesh study and the evaluations used.
    fn mesh_study(
        &self,
        x: &[f64],
        reach: f64,
        stop: &dyn Fn() -> bool,
    ) -> Result<(MeshStudy, usize), TaperError> {
        let n = self.arm.stability.elements();
        let (rest, section) = self.split(x)?;
        let mut values = [reach, f64::NAN, f64::NAN];
        let mut evaluations = 0;
        for (k, factor) in [(1, 2), (2, 4)] {
            let mesh = self
                .arm
                .stability
                .with_elements(factor * n)
                .map_err(|e| TaperError::Stability(e.to_string()))?;
            let run = self.ascend_on(&rest, &section, &mesh, stop);
            evaluations += run.evaluations;
            values[k] = run.best.map_or(f64::NAN, |b| b.1);
        }
        Ok((
            MeshStudy {
                elements: [n, 2 * n, 4 * n],
                reach: values,
                local_optima: true,
            },
            evaluations,
        ))
    }

    /// The strongest section of shape c2..cM from `start`: (section,
    /// converged, evaluations).
    fn strongest_for(
        &self,
        rest: &[f64],
        start: Section,
        mesh: &StabilityOptions,
        stop: &dyn Fn() -> bool,
    ) -> Result<(Section, bool, usize), TaperError> {
        let Some((_, pencil, _)) = self.evaluate(rest, &start, mesh) else {
            return Err(TaperError::Unloaded);
        };
        let o =
            strongest_section_until(&pencil, &self.taper, start, &SectionSearch::default(), stop)?;
        Ok((o.section, o.converged, o.iterations + 1))
    }

    /// The optimum with its shapes and its check by [`critical_load`] on
    /// the designed rod.
    fn finish(
        &self,
        rest: &[f64],
        section: Section,
        prismatic: ArmDesign,
        (mesh_study, ascent, evaluations): (MeshStudy, AscentSummary, usize),
    ) -> Result<Option<TaperedOptimum>, TaperError> {
        let mesh = self.arm.stability;
        let Some((design, _, block)) = self.evaluate(rest, &section, &mesh) else {
            return Ok(None);
        };
        let c = &design.shape_coefficients;
        let rod = self.arm.rod().map_err(|e| model(&e))?;
        let shape = FixedShape {
            turning_angle: Profile::Polynomial(c.clone()),
        };
        let points: Vec<f64> = (0..SHAPE_POINTS)
            .map(|i| i as f64 / (SHAPE_POINTS - 1) as f64)
            .collect();
        let samples = shape.samples(&rod, &points)?;
        let dphi = derivative(c);
        let kappa0: Vec<f64> = samples
            .iter()
            .map(|p| polynomial(&dphi, p.s) - design.gamma * p.moment[1] / section.at(p.s).powi(2))
            .collect();
        let scale = design.gamma.sqrt();
        let loaded = samples
            .iter()
            .map(|p| p.position.map(|v| v * scale).into())
            .collect();
        let unloaded = intrinsic_shape(c[0], &points, &kappa0, scale);
        let designed = self.tapered_rod(&section).map_err(|e| model(&e))?;
        let check = critical_load(&designed, &shape, &mesh)?
            .load_factor
            .ok_or(TaperError::Unloaded)?;
        Ok(Some(TaperedOptimum {
            section_at_points: points.iter().map(|s| section.at(*s)).collect(),
            design,
            section,
            prismatic,
            block,
            critical_load: check,
            mesh: mesh_study,
            ascent,
            loaded_shape: loaded,
            unloaded_shape: unloaded,
            intrinsic_curvature: kappa0,
            evaluations,
            elements: mesh.elements(),
            min_section: self.taper.min_section(),
        }))
    }

    /// The rod of a tapered design at its design load: stiffness B_i A²
    /// exactly ([`Section::stiffness`], quadratic between the knots),
    /// κ̄⁰2 = φ' − γ m̄2/(B2 A²) interpolated between the knots to
    /// `KAPPA0_TOLERANCE` ([`Profile::piecewise_interpolant`]; smooth
    /// there, kinked at the knots with A²), the clamp turned by c1, the
    /// tip load scaled by γ. The solvers stop at the knots, so the right
    /// side is smooth on every piece they integrate, and the designed
    /// shape is an equilibrium of this rod to the interpolation's
    /// tolerance.
    pub fn designed_rod(&self, design: &ArmDesign, section: &Section) -> Result<Rod, ModelError> {
        let rod0 = self.arm.rod()?;
        let c = &design.shape_coefficients;
        let shape = FixedShape {
            turning_angle: Profile::Polynomial(c.clone()),
        };
        let dphi = derivative(c);
        let stiffness = [
            section.stiffness(self.arm.b1)?,
            section.stiffness(1.0)?,
            section.stiffness(self.arm.b3)?,
        ];
        let bend = &stiffness[1];
        let kappa0 = Profile::piecewise_interpolant(
            section.knots(),
            &mut |s| {
                Ok(shape
                    .samples(&rod0, s)
                    .map_err(|e| ModelError::Profile(e.to_string()))?
                    .iter()
                    .map(|p| polynomial(&dphi, p.s) - design.gamma * p.moment[1] / bend.value(p.s))
                    .collect())
            },
            (KAPPA0_TOLERANCE, 1.0),
        )?;
        let energy = LinearElastic::new(
            stiffness,
            [Profile::Constant(0.0), kappa0, Profile::Constant(0.0)],
        )?;
        let mut clamp = rod0.clamp().clone();
        clamp.frame = clamp.turned_frame(c[0])?;
        let loads = rod0.loads().scaled(design.gamma);
        rod0.with_energy(Arc::new(energy))
            .with_clamp(clamp)?
            .with_loads(loads)
    }

    /// The loading path of a tapered design (as [`super::loading_path`]):
    /// κ⁰ held at the design, the tip load raised from λ = 10⁻³ to 1 with
    /// the Hessian tracked; and its verdict.
    pub fn loading_path(
        &self,
        optimum: &TaperedOptimum,
        stop: &dyn Fn() -> bool,
    ) -> Result<(Diagram, LoadingVerdict), ContinuationError> {
        let rod = self
            .designed_rod(&optimum.design, &optimum.section)
            .map_err(|e| ContinuationError::Start {
                p: 0.0,
                message: format!("the designed rod cannot be built: {e}"),
            })?;
        let elements = path_elements(&self.arm, optimum);
        let arm = ArmProblem {
            stability: self.arm.stability.with_elements(elements).map_err(|e| {
                ContinuationError::Start {
                    p: 0.0,
                    message: format!("the path's second variation needs {elements} elements: {e}"),
                }
            })?,
            ..self.arm.clone()
        };
        let diagram = continue_to_design(&arm, &rod, Parameter::LoadScale, stop)?;
        let verdict = loading_verdict(&diagram, optimum);
        Ok((diagram, verdict))
    }
}

/// Elements of the loading path's tracked second variation: the search's,
/// or more where the unloaded (κ̄⁰) or the loaded (φ') shape turns the
/// material frame by more than [`TURN_PER_ELEMENT`] per element (rod length
/// 1), as for spatial arms: the continuation ends a branch whose mesh turns
/// it by more than twice that (the shipped design: |κ̄⁰| = 62 at the thin
/// tip, 1.25 rad per element of the search's 50).
fn path_elements(arm: &ArmProblem, optimum: &TaperedOptimum) -> usize {
    let dphi = derivative(&optimum.design.shape_coefficients);
    let points = optimum.intrinsic_curvature.len().max(2);
    let loaded = (0..points).map(|i| polynomial(&dphi, i as f64 / (points - 1) as f64).abs());
    let kappa = optimum
        .intrinsic_curvature
        .iter()
        .map(|k| k.abs())
        .chain(loaded)
        .fold(0.0, f64::max);
    let needed = (kappa / TURN_PER_ELEMENT).ceil();
    let needed = if needed.is_finite() {
        needed as usize
    } else {
        usize::MAX
    };
    arm.stability.elements().max(needed)
}

/// The verdict of a loading path: the first loss of stability below the
/// design load, else where the path ends against the design's tip.
pub fn loading_verdict(diagram: &Diagram, optimum: &TaperedOptimum) -> LoadingVerdict {
    let Some(branch) = diagram.branches.first() else {
        return LoadingVerdict::Undecided(0.0);
    };
    let below = |p: f64| p < 1.0 - AT_DESIGN;
    if let Some(p) = branch
        .points
        .iter()
        .find(|p| below(p.parameter) && p.morse_index > 0)
    {
        return LoadingVerdict::LosesStability(p.parameter);
    }
    if let Some(s) = diagram
        .special_points
        .iter()
        .find(|s| below(s.point.parameter))
    {
        return LoadingVerdict::LosesStability(s.point.parameter);
    }
    let Some(last) = branch.points.last() else {
        return LoadingVerdict::Undecided(0.0);
    };
    if below(last.parameter) {
        return LoadingVerdict::Undecided(last.parameter);
    }
    let scale = optimum.design.gamma.sqrt();
    let Some(tip) = optimum.loaded_shape.last() else {
        return LoadingVerdict::Undecided(last.parameter);
    };
    let miss = (last.tip.position[0] - tip[0] / scale).hypot(last.tip.position[2] - tip[2] / scale);
    if miss < AT_DESIGN {
        LoadingVerdict::ReachesDesign
    } else {
        LoadingVerdict::OtherEquilibrium(miss)
    }
}

fn model(e: &ModelError) -> TaperError {
    TaperError::Invalid(e.to_string())
}
