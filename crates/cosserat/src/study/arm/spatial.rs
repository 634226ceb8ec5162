//! Longest arms with spatial loaded shapes (issue 20; the paper's Sec. 4.3
//! and 5 leave them open).
//!
//! The loaded shape is prescribed by its curvature–twist profiles
//! κ̄(s̄) = (κ̄1, κ̄2, κ̄3)(s̄): κ̄2 = φ' with φ = Σ_{i≥2} c_i s̄^{i−1} (the
//! planar design's c2..cM, bounds `arm.bounds`), κ̄1 = Σ a_i s̄^{i−1} and
//! κ̄3 = Σ t_i s̄^{i−1} (Taylor coefficients, bounds `arm.bend_bounds` and
//! `arm.twist_bounds`; none: the component is zero). Its critical load is
//! the smallest positive eigenvalue of the full 3-D second variation
//! ([`critical_load_spatial`]).
//!
//! The clamp's rigid rotation Q (the shape is first drawn from the
//! identity frame, d3(0) = e3, tip chord t) is fixed by the reach
//! direction, as c1 is in the plane. Gravity is −e1 (the loads point along
//! +e1, down); the tip's elevation is atan2(−x, √(y² + z²)) of its chord.
//! The design asks the chord to point at elevation α exactly: Q t̂ = τ =
//! (−sin α, 0, cos α). Rotations about the vertical leave the dead load and
//! so γ_crit unchanged (the tip's azimuth is free by symmetry; it is fixed
//! to the x–z plane). The one free rotation left is the roll ψ about the
//! chord: Q = Rot(τ, ψ) Q_p, where Q_p maps the frame (t̂, b̂, t̂ × b̂),
//! b̂ the part of e2 normal to t̂, to (τ, e2, τ × e2). For a planar shape
//! (t ⊥ e2) Q_p is the turn about e2 by the planar design's
//! c1 = −α − atan2(x, z), so ψ = 0 is the planar convention; ψ is a design
//! variable when `arm.roll_bounds` is given (a planar shape in a tilted
//! plane is a spatial design), else 0. The reach is R̂ = √γ_crit |t|, the
//! planar (54)–(55) when the shape is planar.
//!
//! The search reuses the planar stages: the Owen-scrambled Sobol' points
//! of the box (the planar sequence: with no bend, twist or roll the
//! samples are the planar search's), Nelder–Mead (argmin) from the best
//! few, then the mesh study of the optimum on N, 2N and 4N elements
//! ([`MeshStudy`]). Unlike the planar search it does not search again on a
//! finer mesh: an unresolved optimum is reported as
//! [`Verdict::Unresolved`] with its Richardson error.

use std::sync::Arc;

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

use super::design::derivative;
use super::polish::{box_simplex, polish_in_box};
use super::resolve::{MeshStudy, Resolution, Verdict, REACH_TOLERANCE};
use super::PATH_SEGMENTS;
use super::{continue_family, sampling, ArmProblem, ArmScene, SearchOptions};
use crate::continuation::{ContinuationError, Diagram, Family, Parameter, RunState};
use crate::model::{Clamp, Frame, LinearElastic, ModelError, ModelLevel, Profile, Rod};
use crate::numerics::integrator::Tolerances;
use crate::stability::{critical_load_spatial, SpatialShape, TURN_PER_ELEMENT};

/// The equal pieces of the designed rod's κ̄⁰ ([`SpatialArm::designed_rod`]).
pub const KAPPA0_PIECES: usize = 8;

/// The tolerance of the designed rod's κ̄⁰ on each piece, relative to its
/// largest value there or 1/L: the rounding of the loaded shape's moment
/// (DOP853 at 10⁻¹², the shape's samples).
pub const KAPPA0_TOLERANCE: f64 = 1e-12;

/// The spatial arm to design: the planar problem (stiffness ratios,
/// direction, κ̄2's bounds as c2..cM, mesh) and the bounds of the
/// out-of-plane components and the roll.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialArm {
    /// The planar problem: B̄1, B̄3, α, bounds of c2..cM (κ̄2 = φ'), mesh.
    pub planar: ArmProblem,
    /// Bounds of the Taylor coefficients of κ̄1 (empty: κ̄1 = 0).
    pub bend_bounds: Vec<(f64, f64)>,
    /// Bounds of the Taylor coefficients of κ̄3 (empty: κ̄3 = 0).
    pub twist_bounds: Vec<(f64, f64)>,
    /// Bounds of the roll ψ (rad) about the chord (None: ψ = 0).
    pub roll_bounds: Option<(f64, f64)>,
    /// Directions α (rad) at which to compare the planar and spatial
    /// optima (`arm.directions`; empty: none).
    pub directions: Vec<f64>,
}

/// One evaluated spatial design.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialDesign {
    /// R̂ = L̂(γ) |t| (√γ_crit |t| for the tip load alone).
    pub reach: f64,
    /// The design load factor γ_crit.
    pub gamma: f64,
    /// The design vector (c2..cM, a1.., t1.., ψ) as searched.
    pub parameters: Vec<f64>,
    /// Taylor coefficients of κ̄1, κ̄2, κ̄3 (increasing powers of s̄).
    pub curvature_coefficients: [Vec<f64>; 3],
    /// The roll ψ (rad).
    pub roll: f64,
    /// The clamp's frame Q (columns d1(0), d2(0), d3(0)).
    pub clamp_frame: Matrix3<f64>,
}

/// Whether continuation from the unloaded arm reaches its design.
#[derive(Debug, Clone, PartialEq)]
pub enum PathVerdict {
    /// The load path from λ = 10⁻³ reaches λ = 1 stably (Morse index 0 at
    /// every point below λ = 1 − 10⁻³) with the tip within `miss` of the
    /// design's tip (units of L).
    Reaches {
        /// |r_tip(1) − r_design(1)| / L.
        miss: f64,
    },
    /// The path leaves the design: it loses stability or turns back at a
    /// fold at `parameter` < 1, or ends at λ = 1 on another equilibrium.
    Misses {
        /// The load factor where it lost stability or turned back.
        parameter: f64,
        /// What happened.
        reason: String,
    },
    /// Continuation failed or stopped short without a fold or a loss of
    /// stability: no answer either way.
    Undecided(String),
}

impl PathVerdict {
    /// `reaches`, `misses` or `undecided` (HDF5 attribute).
    pub fn name(&self) -> &'static str {
        match self {
            PathVerdict::Reaches { .. } => "reaches",
            PathVerdict::Misses { .. } => "misses",
            PathVerdict::Undecided(_) => "undecided",
        }
    }
}

/// The planar and spatial optima in one direction (`arm.directions`).
#[derive(Debug, Clone, PartialEq)]
pub struct DirectionComparison {
    /// α (rad).
    pub alpha: f64,
    /// Planar R* and its Richardson error (NaN: none found / undecided).
    pub planar: (f64, f64),
    /// Spatial R* and its Richardson error (NaN: none found / undecided).
    pub spatial: (f64, f64),
    /// The spatial optimum's loading path.
    pub verdict: PathVerdict,
}

/// The reported spatial optimum.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialOptimum {
    /// The design.
    pub design: SpatialDesign,
    /// The arc lengths s̄ of the shape points (101, uniform).
    pub points: Vec<f64>,
    /// Loaded shape scaled by L̂(γ): (x̂, ŷ, ẑ).
    pub loaded_shape: Vec<[f64; 3]>,
    /// Unloaded shape (the intrinsic curvature integrated from the same
    /// clamp), same scaling.
    pub unloaded_shape: Vec<[f64; 3]>,
    /// κ̄⁰ = κ̄ − γ H̄⁻¹ M̄ at the points (per L).
    pub intrinsic_curvature: Vec<[f64; 3]>,
    /// Its discretization check (N, 2N, 4N).
    pub resolution: Resolution,
    /// Designs evaluated.
    pub evaluations: usize,
}

fn polynomial_profile(c: &[f64]) -> Profile {
    if c.is_empty() {
        Profile::Constant(0.0)
    } else {
        Profile::Polynomial(c.to_vec())
    }
}

/// Q_p Rot: the rotation taking the chord direction `t` to `tau` with e2
/// (its part normal to the chord) kept in the vertical plane of τ, then
/// rolled by ψ about τ. None when t is parallel to e2 or zero.
fn clamp_rotation(t: &Vector3<f64>, tau: &Vector3<f64>, roll: f64) -> Option<Matrix3<f64>> {
    let th = t.try_normalize(1e-300)?;
    let e2 = Vector3::y();
    let b = (e2 - th * th.dot(&e2)).try_normalize(1e-12)?;
    let from = Matrix3::from_columns(&[th, b, th.cross(&b)]);
    let to = Matrix3::from_columns(&[*tau, e2, tau.cross(&e2)]);
    let roll = Rotation3::from_axis_angle(&Unit::new_normalize(*tau), roll);
    Some(roll.matrix() * to * from.transpose())
}

impl SpatialArm {
    /// The bounds of the whole design vector: c2..cM, a.., t.., ψ.
    pub fn bounds(&self) -> Vec<(f64, f64)> {
        let mut b = self.planar.bounds.clone();
        b.extend(&self.bend_bounds);
        b.extend(&self.twist_bounds);
        b.extend(self.roll_bounds);
        b
    }

    /// The curvature profiles and roll of a design vector.
    fn unpack(&self, p: &[f64]) -> ([Vec<f64>; 3], f64) {
        let (m2, m1, m3) = (
            self.planar.bounds.len(),
            self.bend_bounds.len(),
            self.twist_bounds.len(),
        );
        let mut phi = vec![0.0];
        phi.extend_from_slice(&p[..m2]);
        let k1 = p[m2..m2 + m1].to_vec();
        let k3 = p[m2 + m1..m2 + m1 + m3].to_vec();
        let roll = if self.roll_bounds.is_some() {
            p[m2 + m1 + m3]
        } else {
            0.0
        };
        ([k1, derivative(&phi), k3], roll)
    }

    /// The shape of curvature coefficients `k`.
    pub fn shape(k: &[Vec<f64>; 3]) -> SpatialShape {
        SpatialShape {
            curvature: [
                polynomial_profile(&k[0]),
                polynomial_profile(&k[1]),
                polynomial_profile(&k[2]),
            ],
        }
    }

    /// The non-dimensional rod (the planar arm's loads) with the clamp
    /// frame `q`.
    fn rod_with(&self, scene: &ArmScene, q: Matrix3<f64>) -> Option<Rod> {
        let rod = self.planar.rod_in(scene).ok()?;
        let clamp = Clamp {
            frame: Frame::new(q).ok()?,
            ..Clamp::paper()
        };
        rod.with_clamp(clamp).ok()
    }

    /// This problem in the direction `alpha` (rad).
    #[must_use]
    pub fn towards(&self, alpha: f64) -> SpatialArm {
        let mut a = self.clone();
        a.planar.alpha = alpha;
        a
    }

    /// R̂ and γ_crit of the design vector `p`; None when the shape is stable
    /// under any load, its chord vanishes or lies along e2 (no clamp
    /// rotation defined), or its quadrature fails.
    pub fn design_in(&self, scene: &ArmScene, p: &[f64]) -> Option<SpatialDesign> {
        let (k, roll) = self.unpack(p);
        let shape = Self::shape(&k);
        let reference = self.rod_with(scene, Matrix3::identity())?;
        let t = shape.chord(&reference).ok()?;
        let (sin, cos) = self.planar.alpha.sin_cos();
        let tau = Vector3::new(-sin, 0.0, cos);
        let q = clamp_rotation(&t, &tau, roll)?;
        let rod = self.rod_with(scene, q)?;
        let crit = critical_load_spatial(&rod, &shape, &self.planar.stability).ok()?;
        let gamma = crit.load_factor?;
        Some(SpatialDesign {
            reach: scene.length(gamma) * t.norm(),
            gamma,
            parameters: p.to_vec(),
            curvature_coefficients: k,
            roll,
            clamp_frame: q,
        })
    }

    /// Sample `i` (from 1) of the box: the planar search's Sobol' sequence.
    fn sample_point(&self, i: usize) -> Vec<f64> {
        let b = self.bounds();
        sampling::unit_point(i - 1, b.len())
            .iter()
            .zip(&b)
            .map(|(u, (lo, hi))| lo + (hi - lo) * u)
            .collect()
    }

    fn project(&self, p: &[f64]) -> Vec<f64> {
        p.iter()
            .zip(self.bounds())
            .map(|(v, (lo, hi))| v.clamp(lo, hi))
            .collect()
    }

    /// The search on this problem's mesh: Sobol' samples, then Nelder–Mead
    /// from the best `starts`, steps 5 % of each bound's width (as the
    /// planar search). Returns the best design and the evaluations used.
    pub fn search_on_mesh(
        &self,
        scene: &ArmScene,
        opts: &SearchOptions,
        stop: &dyn Fn() -> bool,
    ) -> (Option<SpatialDesign>, usize) {
        self.search_seeded(scene, opts, &[], stop)
    }

    /// The planar design c2..cM embedded in this box: κ̄1 = κ̄3 = 0, ψ = 0,
    /// projected into the bounds (a seed for [`Self::search_seeded`]).
    pub fn embedded(&self, planar: &[f64]) -> Vec<f64> {
        let mut p = planar.to_vec();
        p.resize(self.bounds().len(), 0.0);
        self.project(&p)
    }

    /// As [`Self::search_on_mesh`], with `seeds` (design vectors, e.g. the
    /// planar optimum [`Self::embedded`]) polished too: the spatial search
    /// then cannot report less than the planar optimum it was given.
    pub fn search_seeded(
        &self,
        scene: &ArmScene,
        opts: &SearchOptions,
        seeds: &[Vec<f64>],
        stop: &dyn Fn() -> bool,
    ) -> (Option<SpatialDesign>, usize) {
        let keep = opts.starts.max(1);
        let mut leaders: Vec<(f64, Vec<f64>)> = vec![];
        let mut evaluations = 0;
        for i in 1..=opts.samples {
            if stop() {
                break;
            }
            let p = self.sample_point(i);
            evaluations += 1;
            if let Some(d) = self.design_in(scene, &p) {
                let at = leaders.partition_point(|(r, _)| *r >= d.reach);
                leaders.insert(at, (d.reach, p));
                leaders.truncate(keep);
            }
        }
        let mut best: Option<SpatialDesign> =
            leaders.first().and_then(|(_, p)| self.design_in(scene, p));
        let starts = leaders
            .iter()
            .take(opts.starts)
            .map(|(_, p)| p)
            .chain(seeds);
        for start in starts {
            if stop() {
                break;
            }
            let (d, used) = self.polish(scene, start, opts.iterations, stop);
            evaluations += used;
            if let Some(d) = d {
                if best.as_ref().is_none_or(|b| d.reach > b.reach) {
                    best = Some(d);
                }
            }
        }
        (best, evaluations)
    }

    /// Nelder–Mead on −R̂ from `start`, the simplex spanning 5 % of each
    /// bound's width (inwards at the upper bound).
    pub fn polish(
        &self,
        scene: &ArmScene,
        start: &[f64],
        iterations: u64,
        stop: &dyn Fn() -> bool,
    ) -> (Option<SpatialDesign>, usize) {
        let simplex = box_simplex(start, &self.bounds(), 0.05);
        let (best, calls) = polish_in_box(
            simplex,
            iterations,
            &|p| self.project(p),
            &|q| self.design_in(scene, q).map(|d| d.reach),
            stop,
        );
        let design = best.and_then(|q| self.design_in(scene, &q));
        (design, calls)
    }

    /// This problem on `elements` elements.
    #[must_use]
    pub fn on_mesh(&self, elements: usize) -> SpatialArm {
        let mut a = self.clone();
        a.planar.stability = a
            .planar
            .stability
            .with_elements(elements)
            .expect("a refined mesh of valid options is valid");
        a
    }

    /// R̂ of `design` on N (known), 2N and 4N elements, and the verdict at
    /// [`REACH_TOLERANCE`]: resolved, or unresolved with its error.
    pub fn mesh_check(&self, scene: &ArmScene, design: &SpatialDesign) -> Resolution {
        let n = self.planar.stability.elements();
        let reach = |m: usize| {
            self.on_mesh(m)
                .design_in(scene, &design.parameters)
                .map_or(f64::NAN, |d| d.reach)
        };
        let study = MeshStudy {
            elements: [n, 2 * n, 4 * n],
            reach: [design.reach, reach(2 * n), reach(4 * n)],
            local_optima: false,
        };
        Resolution {
            verdict: if study.resolved(REACH_TOLERANCE) {
                Verdict::Resolved
            } else {
                Verdict::Unresolved
            },
            study,
            rejected: vec![],
        }
    }

    /// The best design, its mesh check, loaded and unloaded shapes.
    pub fn optimize(
        &self,
        scene: &ArmScene,
        opts: &SearchOptions,
        stop: &dyn Fn() -> bool,
    ) -> Option<SpatialOptimum> {
        self.optimize_seeded(scene, opts, &[], stop)
    }

    /// As [`Self::optimize`], with `seeds` polished too.
    pub fn optimize_seeded(
        &self,
        scene: &ArmScene,
        opts: &SearchOptions,
        seeds: &[Vec<f64>],
        stop: &dyn Fn() -> bool,
    ) -> Option<SpatialOptimum> {
        let (design, evaluations) = self.search_seeded(scene, opts, seeds, stop);
        let design = design?;
        let resolution = self.mesh_check(scene, &design);
        self.finish(scene, design, resolution, evaluations + 2)
    }

    /// The optimum's shapes: loaded (the design's κ̄ from its clamp), its
    /// intrinsic curvature κ̄⁰ = κ̄ − γ H̄⁻¹ M̄, and the unloaded shape (κ̄⁰ as
    /// natural cubic splines through the points, from the same clamp).
    pub fn finish(
        &self,
        scene: &ArmScene,
        design: SpatialDesign,
        resolution: Resolution,
        evaluations: usize,
    ) -> Option<SpatialOptimum> {
        let rod = self.rod_with(scene, design.clamp_frame)?;
        let points: Vec<f64> = (0..=100).map(|i| f64::from(i) / 100.0).collect();
        let loaded = Self::shape(&design.curvature_coefficients)
            .samples(&rod, &points)
            .ok()?;
        let kappa0 = SpatialShape::intrinsic_curvature(&rod, &loaded, design.gamma);
        let unloaded_shape = intrinsic_shape(&points, &kappa0).ok()?;
        let unloaded = unloaded_shape.samples(&rod, &points).ok()?;
        let scale = scene.length(design.gamma);
        let scaled = |v: &Vector3<f64>| [v[0] * scale, v[1] * scale, v[2] * scale];
        Some(SpatialOptimum {
            loaded_shape: loaded.iter().map(|p| scaled(&p.position)).collect(),
            unloaded_shape: unloaded.iter().map(|p| scaled(&p.position)).collect(),
            intrinsic_curvature: kappa0.iter().map(|k| [k[0], k[1], k[2]]).collect(),
            points,
            design,
            resolution,
            evaluations,
        })
    }

    /// The rod of a design at its design load: κ̄⁰ = κ̄ − γ H⁻¹M of the
    /// loaded shape, interpolated on [`KAPPA0_PIECES`] equal pieces to
    /// [`KAPPA0_TOLERANCE`] ([`Profile::piecewise_interpolant`]: smooth on
    /// each, where a natural spline through many nodes has a third
    /// derivative that jumps at every node, which the integrator's error
    /// estimate misjudges — the noise floor of the loading path's
    /// corrector, docs/extensions.md), the design's clamp, the scene's
    /// loads scaled by γ_crit.
    pub fn designed_rod(&self, scene: &ArmScene, design: &SpatialDesign) -> Option<Rod> {
        let rod = self.rod_with(scene, design.clamp_frame)?;
        let shape = Self::shape(&design.curvature_coefficients);
        let breaks: Vec<f64> = (0..=KAPPA0_PIECES)
            .map(|i| i as f64 / KAPPA0_PIECES as f64)
            .collect();
        let component = |i: usize| {
            Profile::piecewise_interpolant(
                breaks.clone(),
                &mut |s| {
                    let loaded = shape
                        .samples(&rod, s)
                        .map_err(|e| ModelError::Profile(e.to_string()))?;
                    Ok(
                        SpatialShape::intrinsic_curvature(&rod, &loaded, design.gamma)
                            .iter()
                            .map(|k| k[i])
                            .collect(),
                    )
                },
                (KAPPA0_TOLERANCE, 1.0),
            )
        };
        let energy = LinearElastic::new(
            [self.planar.b1, 1.0, self.planar.b3].map(Profile::Constant),
            [component(0).ok()?, component(1).ok()?, component(2).ok()?],
        )
        .ok()?;
        let loads = rod.loads().scaled(design.gamma);
        rod.with_energy(Arc::new(energy)).with_loads(loads).ok()
    }

    /// The loading path: the designed rod continued (Kirchhoff level, the
    /// Hessian tracked on this problem's mesh) in the load factor from
    /// 10⁻³ to 1 (the design load), and whether it reaches the design.
    ///
    /// The run is repeated on finer shooting segments ([`PATH_SEGMENTS`])
    /// while it ends undecided: a branch that stops short with no fold and
    /// no loss of stability ("step size below 10⁻⁷: the corrector does not
    /// converge") has met the noise floor of its residual, not a property
    /// of the arm. Measured cause of that floor (issue 20): κ̄⁰ as a natural
    /// spline through 2001 nodes, whose third derivative jumps at every
    /// node, so that DOP853's error estimate failed there (the 45° optimum
    /// of the shipped arm stopped at λ = 0.0078 on 32 segments, decided
    /// only on 128); with κ̄⁰ smooth on each piece ([`Self::designed_rod`])
    /// the same path is decided on 32.
    pub fn loading_path(
        &self,
        scene: &ArmScene,
        optimum: &SpatialOptimum,
        stop: &dyn Fn() -> bool,
    ) -> (Option<Diagram>, PathVerdict) {
        let Some(rod) = self.designed_rod(scene, &optimum.design) else {
            return (
                None,
                PathVerdict::Undecided("the designed rod could not be built".into()),
            );
        };
        let elements = self.path_elements(optimum);
        let Ok(stability) = self.planar.stability.with_elements(elements) else {
            return (
                None,
                PathVerdict::Undecided(format!(
                    "the path's second variation needs {elements} elements, more than allowed"
                )),
            );
        };
        let tracked = ArmProblem {
            stability,
            ..self.planar.clone()
        };
        let mut undecided = None;
        let mut reasons = vec![];
        for segments in PATH_SEGMENTS {
            let family = Family::new(
                rod.clone(),
                Parameter::LoadScale,
                ModelLevel::Kirchhoff,
                segments,
                Tolerances::default(),
            );
            match continue_family(&tracked, &family, stop) {
                Ok(d) => {
                    let verdict = path_verdict(&d, optimum, scene);
                    let interrupted = d.stop_reason == RunState::Interrupted;
                    match &verdict {
                        PathVerdict::Undecided(why) if !interrupted => {
                            reasons.push(format!("{segments} segments: {why}"));
                            undecided = Some(d);
                        }
                        _ => return (Some(d), verdict),
                    }
                }
                Err(e @ ContinuationError::Start { .. }) => {
                    reasons.push(format!("{segments} segments: {}", path_error(&e)));
                }
                Err(e) => return (None, PathVerdict::Undecided(path_error(&e))),
            }
        }
        (undecided, PathVerdict::Undecided(reasons.join("; ")))
    }
}

impl SpatialArm {
    /// Elements of the loading path's tracked second variation: the
    /// search's, or more where the unloaded (κ̄⁰) or the designed (κ̄)
    /// shape turns the material frame by more than [`TURN_PER_ELEMENT`]
    /// per element (rod length 1): the continuation ends a branch whose
    /// mesh turns it by more than twice that (B̄1 = 16 at 0°: 1.08 rad per
    /// element on the search's 50 elements at λ = 10⁻³). On the finer mesh
    /// λ = 1 is γ_crit to that mesh's error (the verdict counts no
    /// stability loss above 1 − 10⁻³).
    fn path_elements(&self, optimum: &SpatialOptimum) -> usize {
        let norm = |k: [f64; 3]| (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]).sqrt();
        let shape = Self::shape(&optimum.design.curvature_coefficients);
        let loaded = optimum
            .points
            .iter()
            .map(|s| norm([0, 1, 2].map(|i| shape.curvature[i].value(*s))));
        let kappa = optimum
            .intrinsic_curvature
            .iter()
            .map(|k| norm(*k))
            .chain(loaded)
            .fold(0.0, f64::max);
        let needed = (kappa / TURN_PER_ELEMENT).ceil();
        let needed = if needed.is_finite() {
            needed as usize
        } else {
            usize::MAX
        };
        self.planar.stability.elements().max(needed)
    }
}

fn path_error(e: &ContinuationError) -> String {
    format!("continuation failed: {e}")
}

/// Reaches when the first branch ends at λ ≥ 1 − 10⁻⁶ within 10⁻⁴ L of the
/// design's tip and is stable below λ = 1 − 10⁻³ (at λ = 1 the design is
/// critical, so its Morse index there is not counted).
fn path_verdict(d: &Diagram, optimum: &SpatialOptimum, scene: &ArmScene) -> PathVerdict {
    let Some(branch) = d.branches.first() else {
        return PathVerdict::Undecided("no branch".into());
    };
    if let Some(p) = branch
        .points
        .iter()
        .find(|p| p.parameter < 1.0 - 1e-3 && !p.stable)
    {
        return PathVerdict::Misses {
            parameter: p.parameter,
            reason: format!(
                "unstable (Morse index {}) before the design load",
                p.morse_index
            ),
        };
    }
    let Some(last) = branch.points.last() else {
        return PathVerdict::Undecided("an empty branch".into());
    };
    let top = branch
        .points
        .iter()
        .map(|p| p.parameter)
        .fold(f64::NEG_INFINITY, f64::max);
    if last.parameter < 1.0 - 1e-6 && top > last.parameter + 1e-9 {
        return PathVerdict::Misses {
            parameter: top,
            reason: format!(
                "the path turns back at λ = {top:.4} (a fold) and ends at λ = {:.4}",
                last.parameter
            ),
        };
    }
    if last.parameter < 1.0 - 1e-6 {
        // Stopped short without a fold or a loss of stability: the
        // continuation gave up, which says nothing about the arm.
        let mut why = vec![branch.stop_reason.to_string()];
        why.extend(d.warnings.iter().cloned());
        return PathVerdict::Undecided(format!(
            "the continuation stopped at λ = {:.4} ({})",
            last.parameter,
            why.join("; ")
        ));
    }
    let scale = scene.length(optimum.design.gamma);
    let tip = optimum
        .loaded_shape
        .last()
        .map_or(Vector3::zeros(), |r| Vector3::new(r[0], r[1], r[2]) / scale);
    let miss = (last.tip.position - tip).norm();
    if miss > 1e-4 {
        return PathVerdict::Misses {
            parameter: last.parameter,
            reason: format!(
                "it ends at λ = 1 on another equilibrium, its tip at ({:.4}, {:.4}, {:.4}) L, \
                 {miss:.3} L from the design's tip",
                last.tip.position[0], last.tip.position[1], last.tip.position[2]
            ),
        };
    }
    PathVerdict::Reaches { miss }
}

/// The shape of curvature samples κ⁰(s) at `s`: natural cubic splines.
fn intrinsic_shape(
    s: &[f64],
    kappa: &[Vector3<f64>],
) -> Result<SpatialShape, crate::model::ModelError> {
    let component = |i: usize| Profile::spline(s.to_vec(), kappa.iter().map(|k| k[i]).collect());
    Ok(SpatialShape {
        curvature: [component(0)?, component(1)?, component(2)?],
    })
}
