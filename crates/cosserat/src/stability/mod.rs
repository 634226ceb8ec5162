//! Stability: the second variation of the potential energy at an
//! equilibrium (paper Sec. 2.1, 2.5, eqs. (23), (45), (50), (51)),
//! discretized by finite elements as a banded matrix K; its lowest
//! eigenvalues, its inertia (Morse index) and a verdict; and the critical
//! load of a fixed loaded shape, where K(λ) = K0 + λK1 is linear in the load
//! factor and λ_crit is a generalized eigenvalue (no root finder).

pub use crate::numerics::{banded, constrained, eigen};
pub mod factored;
mod fixed_shape;
mod fixed_shape_gradient;
mod fixed_shape_spatial;
mod second_variation;

pub use fixed_shape::{critical_load, CriticalLoad, FixedShape};
pub use fixed_shape_gradient::{
    critical_load_gradient, critical_load_gradients, BlockLoad, LoadGradient, SIMPLE_GAP,
};
pub use fixed_shape_spatial::{critical_load_spatial, SpatialShape};
pub use second_variation::{Block, FiniteElements, FormCoefficients, TipMotion};

use nalgebra::{Matrix3, Vector3};

use crate::bvp::{Equilibrium, SolveError, SolverOptions};
use crate::equations::RodSample;
use crate::model::{shear_strain, Freedom, ModelLevel, Rod, StrainEnergy};
use constrained::{count_below_constrained, lowest_eigenpairs_constrained_estimated, Constraints};
use eigen::{EigenError, Inertia, ShiftEstimate, UndecidedInertia};

/// How the second variation is discretized and how much of its spectrum is
/// computed: `elements` Lagrange elements of order `order` (1 to 3;
/// eigenvalues converge at order 2p), the `eigenvalues` lowest per block.
/// Checked when built, so that no analysis can receive options it would
/// have to clamp (an order 5 once ran silently at order 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StabilityOptions {
    elements: usize,
    order: usize,
    eigenvalues: usize,
}

impl StabilityOptions {
    /// At least one element, order 1, 2 or 3, at least one eigenvalue;
    /// otherwise [`StabilityError::Options`] saying which.
    pub fn new(elements: usize, order: usize, eigenvalues: usize) -> Result<Self, StabilityError> {
        if elements < 1 || !(1..=3).contains(&order) || eigenvalues < 1 {
            return Err(StabilityError::Options(format!(
                "{elements} elements of order {order} with {eigenvalues} eigenvalues: the \
                 elements need at least one element, order 1, 2 or 3 and at least one eigenvalue"
            )));
        }
        Ok(StabilityOptions {
            elements,
            order,
            eigenvalues,
        })
    }

    /// Number of finite elements.
    pub fn elements(&self) -> usize {
        self.elements
    }

    /// Lagrange order of the elements (1 to 3).
    pub fn order(&self) -> usize {
        self.order
    }

    /// Number of lowest eigenvalues reported per block.
    pub fn eigenvalues(&self) -> usize {
        self.eigenvalues
    }

    /// The same options on `elements` elements (checked as by [`Self::new`]).
    pub fn with_elements(self, elements: usize) -> Result<Self, StabilityError> {
        Self::new(elements, self.order, self.eigenvalues)
    }

    /// The same mesh with `eigenvalues` eigenvalues per block (checked).
    pub fn with_eigenvalues(self, eigenvalues: usize) -> Result<Self, StabilityError> {
        Self::new(self.elements, self.order, eigenvalues)
    }
}

impl Default for StabilityOptions {
    fn default() -> Self {
        StabilityOptions {
            elements: 100,
            order: 2,
            eigenvalues: 4,
        }
    }
}

/// Why a stability analysis failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StabilityError {
    /// The loads have no potential (a dead tip couple in space).
    #[error("not conservative: {0}")]
    NonConservative(String),
    /// The equilibrium could not be resampled.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The eigensolver failed.
    #[error(transparent)]
    Eigen(#[from] EigenError),
    /// A fixed-shape scene the method does not cover.
    #[error("fixed shape: {0}")]
    FixedShape(String),
    /// Options no discretization can honour ([`StabilityOptions::new`]).
    #[error("stability options: {0}")]
    Options(String),
    /// A scene the second variation is not implemented for.
    #[error("not implemented: {0}")]
    Unsupported(String),
    /// The inertia of K could not be decided (K has a zero pivot at every
    /// nudge of the shift and is too large to recount densely).
    #[error("undecided: the inertia of the {0} block cannot be counted: {1} (K is singular to working precision: the equilibrium sits on a critical point)")]
    Undecided(&'static str, UndecidedInertia),
}

/// The spectrum of one block of K.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockSpectrum {
    /// Which components of ω.
    pub block: Block,
    /// The lowest eigenvalues of K v = λ G v (G the L² Gram matrix).
    pub eigenvalues: Vec<f64>,
    /// The eigenvectors as nodal rotations ω(s_i) (body components).
    pub modes: Vec<Vec<Vector3<f64>>>,
    /// The number of negative eigenvalues of K (its inertia).
    pub morse_index: usize,
}

/// The stability of an equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct Stability {
    /// One block (spatial scenes) or the in-plane and out-of-plane blocks
    /// (planar scenes, paper (50)/(51)).
    pub blocks: Vec<BlockSpectrum>,
    /// The Morse index of K (sum over blocks).
    pub morse_index: usize,
    /// K positive definite.
    pub stable: bool,
    /// The finite-element nodes.
    pub nodes: Vec<f64>,
}

/// The quadratic-form coefficients at equilibrium samples (with the shear
/// and extension terms when the energy has them: the Cosserat level).
/// Entries are NaN where a general energy's strain ν has no solution
/// of W_ν = N ([`try_coefficients`] names the failure instead).
pub fn coefficients(rod: &Rod, samples: &[RodSample]) -> Vec<FormCoefficients> {
    samples
        .iter()
        .map(|p| {
            coefficients_at(rod, p).unwrap_or(FormCoefficients {
                a: Matrix3::from_element(f64::NAN),
                b: Matrix3::from_element(f64::NAN),
                c: Matrix3::from_element(f64::NAN),
            })
        })
        .collect()
}

/// [`coefficients`], refused with the reason where the shear-extension
/// strain of a general energy has no solution at a sample.
pub fn try_coefficients(
    rod: &Rod,
    samples: &[RodSample],
) -> Result<Vec<FormCoefficients>, StabilityError> {
    samples.iter().map(|p| coefficients_at(rod, p)).collect()
}

/// The coefficients at one sample: the quadratic shear part's explicit
/// strain where the energy gives S, else (a general W(s, κ, ν)) ν from
/// W_ν = N by Newton and the 6 × 6 Hessian ([`FormCoefficients::strained`]).
fn coefficients_at(rod: &Rod, p: &RodSample) -> Result<FormCoefficients, StabilityError> {
    let frame = Matrix3::from_columns(&p.directors);
    let body_force = frame.transpose() * p.force;
    let energy = rod.energy();
    let general = energy
        .strain_energy()
        .filter(|_| energy.shear_stiffness(p.s).is_none());
    let Some(strain) = general else {
        let h = energy.stiffness(p.s, &p.curvature);
        let compliance = energy
            .shear_stiffness(p.s)
            .map_or_else(Vector3::zeros, |s| s.map(|v| 1.0 / v));
        return Ok(FormCoefficients::sheared(
            &h,
            &p.curvature,
            &p.moment,
            &body_force,
            &compliance,
        ));
    };
    strained_coefficients(strain, p, &body_force)
}

/// The coefficients at one sample of a general energy W(s, κ, ν): ν from
/// W_ν = N by Newton, then [`FormCoefficients::strained`] with the 6 × 6
/// Hessian there; refused with the reason where ν has no solution.
pub fn strained_coefficients(
    strain: &dyn StrainEnergy,
    p: &RodSample,
    body_force: &Vector3<f64>,
) -> Result<FormCoefficients, StabilityError> {
    let refused = |e: String| StabilityError::Unsupported(format!("shear-extension strain: {e}"));
    let (nu, jet) = shear_strain(strain, p.s, &p.curvature, body_force, &Vector3::z())
        .map_err(|e| refused(e.to_string()))?;
    FormCoefficients::strained(&jet.hessian, &p.curvature, &jet.moment(), body_force, &nu)
        .ok_or_else(|| refused(format!("W_νν is not positive definite at s = {}", p.s)))
}

/// The spectrum and inertia of K for one block, on the null space of the
/// tip support's constraints.
pub fn block_spectrum(
    fe: &FiniteElements,
    coeffs: &[FormCoefficients],
    block: Block,
    count: usize,
    constraints: &Constraints,
) -> Result<BlockSpectrum, StabilityError> {
    block_spectrum_estimated(fe, coeffs, block, count, constraints, None)
}

/// [`block_spectrum`] with the Lanczos shift placed by `estimate` (the
/// block's eigenvalues on a coarser mesh: [`ShiftEstimate`]). The Morse
/// index is the Sturm count of K at 0, unless the shift that certified
/// the eigenvalues is at or above 0: K − σG positive definite with σ ≥ 0
/// makes K positive definite, and the index 0, with no further count.
pub fn block_spectrum_estimated(
    fe: &FiniteElements,
    coeffs: &[FormCoefficients],
    block: Block,
    count: usize,
    constraints: &Constraints,
    estimate: Option<ShiftEstimate>,
) -> Result<BlockSpectrum, StabilityError> {
    let k = fe.stiffness(coeffs, block);
    let g = fe.mass(block);
    let bounded = lowest_eigenpairs_constrained_estimated(&k, &g, constraints, count, estimate)?;
    let morse_index = if bounded.lower_bound >= 0.0 {
        0
    } else {
        match count_below_constrained(&k, &g, constraints, 0.0) {
            Inertia::Below(n) => n,
            Inertia::Undecided(why) => return Err(StabilityError::Undecided(block.name(), why)),
        }
    };
    let pairs = factored::refined(fe, coeffs, block, constraints, bounded.pairs);
    Ok(BlockSpectrum {
        block,
        eigenvalues: pairs.values,
        modes: pairs
            .vectors
            .iter()
            .map(|v| fe.nodal_rotations(block, v))
            .collect(),
        morse_index,
    })
}

/// Rejects loads without a potential: a dead couple on a spatial rod,
/// unless the tip support holds every rotation it could do work in.
/// Rejects, too, the shear-strain elimination under a held position (the
/// constraint would couple the strain across the rod).
pub fn check_conservative(rod: &Rod) -> Result<(), StabilityError> {
    let couple = rod.loads().tip_couple;
    let held = match rod.support().as_ref().map(|s| s.rotation) {
        Some(Freedom::Fixed) => true,
        Some(Freedom::Axial(a)) => (couple - a * couple.dot(&a)).norm() <= 1e-12 * couple.norm(),
        _ => false,
    };
    if rod.loads().has_point_couples() {
        return Err(StabilityError::NonConservative(
            "a dead point couple (loads.point[k].couple) has no potential for spatial \
             rotations, so the second variation does not decide stability (as for a dead tip \
             couple); remove the couple to ask for stability"
                .into(),
        ));
    }
    if couple.norm() > 0.0 && !held {
        return Err(StabilityError::NonConservative(
            "a dead tip couple has no potential for spatial rotations, so the second \
             variation does not decide stability; remove loads.tip_couple, or hold the tip's \
             rotation (support.rotation = \"fixed\", or \"axial\" about the couple)"
                .into(),
        ));
    }
    Ok(())
}

/// The constraints of `rod`'s tip support on a block (none for a free
/// tip); `samples` at the quadrature points, `tip` at s = L. On a
/// shearable, extensible rod a held position is a spring, not a constraint
/// ([`FiniteElements::support_springs`]); refused with the reason where
/// its strain or compliance cannot be formed.
pub fn support_constraints(
    rod: &Rod,
    fe: &FiniteElements,
    block: Block,
    samples: &[RodSample],
    tip: &RodSample,
) -> Result<Constraints, StabilityError> {
    let Some(support) = rod.support() else {
        return Ok(Constraints::none(fe.size(block)));
    };
    if rod.energy().strain_energy().is_none() || !support.holds_position() {
        return Ok(fe.support_constraints(block, support, samples, tip));
    }
    let motions = samples
        .iter()
        .map(|p| tip_motion(rod, p))
        .collect::<Result<Vec<_>, _>>()?;
    fe.support_springs(block, support, samples, tip, &motions)
        .ok_or_else(|| {
            StabilityError::Unsupported(
                "the held position's compliance ∫ R H_νν⁻¹ Rᵀ ds is not positive definite".into(),
            )
        })
}

/// How a rotation field moves the tip at one sample of a shearable rod
/// ([`TipMotion`]): the quadratic shear part's explicit strain, or ν from
/// W_ν = N and the 6 × 6 Hessian of a general W(s, κ, ν).
fn tip_motion(rod: &Rod, p: &RodSample) -> Result<TipMotion, StabilityError> {
    let frame = Matrix3::from_columns(&p.directors);
    let body_force = frame.transpose() * p.force;
    let energy = rod.energy();
    if let Some(stiffness) = energy.shear_stiffness(p.s) {
        return Ok(TipMotion::sheared(&stiffness.map(|v| 1.0 / v), &body_force));
    }
    let refused = |e: String| StabilityError::Unsupported(format!("shear-extension strain: {e}"));
    let strain = energy
        .strain_energy()
        .ok_or_else(|| refused("no strain energy".into()))?;
    let (nu, jet) = shear_strain(strain, p.s, &p.curvature, &body_force, &Vector3::z())
        .map_err(|e| refused(e.to_string()))?;
    TipMotion::strained(&jet.hessian, &p.curvature, &nu, &body_force)
        .ok_or_else(|| refused(format!("W_νν is not positive definite at s = {}", p.s)))
}

/// The stability of an equilibrium of `rod` (from [`crate::bvp::solve`]).
///
/// On [`COARSE_ESTIMATE_FROM`] elements or more, the lowest eigenvalues
/// of each block are first computed on a mesh [`COARSE_RATIO`] times
/// coarser (one more than asked, so that λ_{k+1} is estimated too) to
/// place the shift of each block's Lanczos ([`ShiftEstimate`]): the
/// factors of the shifted K certify it, and a coarse mesh that fails
/// (an error, or eigenvalues the fine mesh contradicts) leaves the Sturm
/// bisection to place it, so the result is that of the mesh asked for
/// either way. The coarse solve costs ~1/[`COARSE_RATIO`] of the fine
/// one; the bisection it replaces cost ~10 factorizations per block.
pub fn analyze(
    rod: &Rod,
    eq: &Equilibrium,
    solver: &SolverOptions,
    opts: &StabilityOptions,
) -> Result<Stability, StabilityError> {
    check_conservative(rod)?;
    let estimates = if opts.elements >= COARSE_ESTIMATE_FROM {
        coarse_estimates(rod, eq, solver, opts)
    } else {
        Vec::new()
    };
    analyze_estimated(rod, eq, solver, opts, &estimates)
}

/// [`analyze`] with each block's shift placed by `estimates` (by block, in
/// the order of the blocks; a missing one leaves that block's shift to
/// the Sturm bisection). The estimates only save counts: the factors of
/// the shifted K certify each shift, and a shift they do not certify, or
/// a Lanczos run from it that fails, falls back to the bisection.
fn analyze_estimated(
    rod: &Rod,
    eq: &Equilibrium,
    solver: &SolverOptions,
    opts: &StabilityOptions,
    estimates: &[Option<ShiftEstimate>],
) -> Result<Stability, StabilityError> {
    check_conservative(rod)?;
    let fe = FiniteElements::new(rod.length(), opts.elements, opts.order)
        .with_breaks(&rod.breaks())
        .with_hinged_base(rod.clamp().hinge);
    let mut points = fe.quadrature_points();
    points.push(rod.length());
    let mut samples = eq.resample(rod, solver, &points)?;
    let tip = samples.pop().expect("the tip sample");
    let coeffs = try_coefficients(rod, &samples)?;
    let blocks = match eq.model.level {
        ModelLevel::Planar => vec![Block::InPlane, Block::OutOfPlane],
        ModelLevel::Kirchhoff | ModelLevel::Cosserat => vec![Block::Full],
    };
    let blocks = blocks
        .into_iter()
        .enumerate()
        .map(|(i, b)| {
            let c = support_constraints(rod, &fe, b, &samples, &tip)?;
            let estimate = estimates.get(i).copied().flatten();
            block_spectrum_estimated(&fe, &coeffs, b, opts.eigenvalues, &c, estimate)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let morse_index = blocks.iter().map(|b| b.morse_index).sum();
    Ok(Stability {
        blocks,
        morse_index,
        stable: morse_index == 0,
        nodes: fe.nodes(),
    })
}

/// The fewest elements on which [`analyze`] estimates the shifts from a
/// coarser mesh.
pub const COARSE_ESTIMATE_FROM: usize = 2048;

/// How much coarser that mesh is.
pub const COARSE_RATIO: usize = 64;

/// Per block, λ_1 and λ_{k+1} on the mesh [`COARSE_RATIO`] times coarser
/// (k = `opts`' eigenvalues); an empty list where that analysis fails
/// (the fine one then places its shifts by bisection).
fn coarse_estimates(
    rod: &Rod,
    eq: &Equilibrium,
    solver: &SolverOptions,
    opts: &StabilityOptions,
) -> Vec<Option<ShiftEstimate>> {
    let count = opts.eigenvalues;
    let Ok(coarse) = opts
        .with_elements(opts.elements / COARSE_RATIO)
        .and_then(|o| o.with_eigenvalues(count + 1))
    else {
        return Vec::new();
    };
    let Ok(st) = analyze(rod, eq, solver, &coarse) else {
        return Vec::new();
    };
    estimates_from(&st, count)
}

/// Per block of `st`, λ_1 and λ_{count+1} (the highest computed where
/// fewer were) as shift estimates for the same blocks on a finer mesh.
fn estimates_from(st: &Stability, count: usize) -> Vec<Option<ShiftEstimate>> {
    st.blocks
        .iter()
        .map(|b| {
            let values = &b.eigenvalues;
            let next = values.get(count).or(values.last())?;
            ShiftEstimate::new(*values.first()?, *next)
        })
        .collect()
}

/// A stability verdict that states its own certainty.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// K positive definite on meshes that agree, every computed eigenvalue's
    /// sign beyond its discretization error.
    Stable,
    /// K has this many negative eigenvalues, on meshes that agree.
    Unstable {
        /// The Morse index.
        morse_index: usize,
    },
    /// The meshes tried disagree, or an eigenvalue is within its
    /// discretization error of zero: the answer is not known.
    Undecided {
        /// Why.
        reason: String,
    },
}

/// The verdict of [`decide`] with the evidence behind it.
#[derive(Debug, Clone, PartialEq)]
pub struct Decision {
    /// Stable, unstable or undecided.
    pub verdict: Verdict,
    /// The analysis on the finest mesh used.
    pub stability: Option<Stability>,
    /// Elements of the finest mesh.
    pub elements: usize,
    /// The largest change of a computed eigenvalue between the last two
    /// meshes: the discretization error estimate of the coarser one, an
    /// upper bound for the finer (eigenvalues converge at order 2p).
    pub eigenvalue_error: f64,
}

/// Meshes tried by [`decide`]: `opts.elements` doubled up to this many
/// times.
pub const REFINEMENTS: usize = 5;

/// The finest mesh [`decide`] doubles to beyond its first comparison (N
/// and 2N): a verdict from 10⁵ elements doubled 5 times would need 3.2·10⁶
/// elements (9 GB), which no memory plan can promise; a plan of
/// max(2N, min(32N, this)) elements (`input::memory`) covers every mesh
/// the verdict may use, and meshes that still disagree there are
/// undecided.
pub const MAX_VERDICT_ELEMENTS: usize = 400_000;

/// The stability of an equilibrium on a mesh resolved for its shape:
/// [`analyze`] on N, 2N, 4N, … elements (N from `opts`) until two
/// successive meshes give the same Morse index in every block and no
/// computed eigenvalue lies within its change between them of zero; the
/// eigenvalue just above the Morse index is always among those computed,
/// so that the sign nearest to changing is the one checked. Undecided when
/// that does not happen within [`REFINEMENTS`] doublings, or when the
/// inertia itself cannot be counted.
pub fn decide(
    rod: &Rod,
    eq: &Equilibrium,
    solver: &SolverOptions,
    opts: &StabilityOptions,
) -> Result<Decision, StabilityError> {
    decide_from(rod, eq, solver, opts, |_, first| first)
}

/// The fewest elements [`decide_verdict`] starts from.
pub const VERDICT_ELEMENTS: usize = 12;

/// [`decide`] where only the verdict is wanted (`cosserat solve`, which
/// prints it and writes no spectrum): the same test on the same doubling
/// meshes, from the coarsest that resolves the frame's turn — at least
/// [`VERDICT_ELEMENTS`], at most `opts`' — up to the same finest mesh
/// [`decide`] may reach, computing the lowest eigenvalue above the Morse
/// index in each block (the one nearest to changing sign; [`decide`] also
/// checks the higher ones it computes for its report, which lie farther
/// from zero). Where that eigenvalue is far from zero, two coarse meshes
/// already agree to less than its distance from zero and settle it — by
/// the same test as [`decide`]'s: the Morse index unchanged and the
/// eigenvalue's change between the meshes (an upper bound of the finer
/// mesh's error: quadratic elements converge at O(h⁴), so it is ~15× that
/// error) smaller than the eigenvalue; near zero the doubling goes on to
/// [`decide`]'s finest mesh (the last doubling within it), so a verdict
/// [`decide`] reaches only on its finest meshes is reached too. The
/// reported spectrum, elements and eigenvalue error are those of the
/// meshes where it settled (coarser than [`decide`]'s: a larger error
/// estimate, printed with the verdict).
pub fn decide_verdict(
    rod: &Rod,
    eq: &Equilibrium,
    solver: &SolverOptions,
    opts: &StabilityOptions,
) -> Result<Decision, StabilityError> {
    // The eigenvalue just above the Morse index is the sign nearest to
    // changing, and the only one the verdict needs: decide_from raises the
    // count to the Morse index + 1 after each mesh.
    let opts = opts.with_eigenvalues(1)?;
    decide_from(rod, eq, solver, &opts, |needed, first| {
        // Halvings of decide's first mesh, so that the doublings meet its
        // meshes' sizes (to rounding) and end at its finest.
        let floor = needed.max(VERDICT_ELEMENTS);
        let mut begin = first;
        while begin / 2 >= floor {
            begin /= 2;
        }
        begin
    })
}

/// [`decide`] from `start(needed, first)` elements (needed: the mesh that
/// resolves the frame's turn; first: the mesh [`decide`] starts from,
/// max(`opts`' elements, needed)), doubling up to [`decide`]'s finest
/// mesh.
fn decide_from(
    rod: &Rod,
    eq: &Equilibrium,
    solver: &SolverOptions,
    opts: &StabilityOptions,
    start: impl Fn(usize, usize) -> usize,
) -> Result<Decision, StabilityError> {
    let mut opts = *opts;
    let needed = resolved_elements(rod, eq, solver, &opts)?;
    if needed > MAX_RESOLVED_ELEMENTS {
        return Ok(undecided(
            format!(
                "the material frame turns too fast to be resolved: {needed} elements would be \
                 needed to keep the turn per element within {TURN_PER_ELEMENT} rad, more than \
                 {MAX_RESOLVED_ELEMENTS}"
            ),
            None,
            opts.elements,
        ));
    }
    let first = opts.elements.max(needed);
    let finest = (first << REFINEMENTS).min(MAX_VERDICT_ELEMENTS.max(2 * first));
    opts = opts.with_elements(start(needed, first).clamp(needed.max(1), first))?;
    let mut previous: Option<Stability> = None;
    let mut last_error = f64::INFINITY;
    while opts.elements <= finest {
        // The previous mesh's eigenvalues place this one's shifts (no
        // Sturm bisection, ~13 inertia counts per block on the verdict's
        // small meshes); the first mesh is analyzed on its own.
        let analyzed = match &previous {
            Some(prev) => {
                let estimates = estimates_from(prev, opts.eigenvalues);
                analyze_estimated(rod, eq, solver, &opts, &estimates)
            }
            None => analyze(rod, eq, solver, &opts),
        };
        let current = match analyzed {
            Ok(st) => st,
            Err(StabilityError::Undecided(block, why)) => {
                return Ok(undecided(
                    format!(
                        "the inertia of the {block} block cannot be counted on {} elements: {why}",
                        opts.elements
                    ),
                    previous,
                    opts.elements,
                ))
            }
            Err(e) => return Err(e),
        };
        if let Some(prev) = &previous {
            if let Some(error) = settled(prev, &current) {
                let verdict = if current.morse_index == 0 {
                    Verdict::Stable
                } else {
                    Verdict::Unstable {
                        morse_index: current.morse_index,
                    }
                };
                return Ok(Decision {
                    verdict,
                    stability: Some(current),
                    elements: opts.elements,
                    eigenvalue_error: error,
                });
            }
            last_error = eigenvalue_change(prev, &current);
        }
        let most = current
            .blocks
            .iter()
            .map(|b| b.morse_index)
            .max()
            .unwrap_or(0);
        opts.eigenvalues = opts.eigenvalues.max(most + 1);
        previous = Some(current);
        opts.elements *= 2;
    }
    let elements = opts.elements / 2;
    let mut decision = undecided(
        format!("the Morse index or the sign of an eigenvalue still changes between {} and {elements} elements", elements / 2),
        previous,
        elements,
    );
    decision.eigenvalue_error = last_error;
    Ok(decision)
}

/// The largest turn of the material frame across one element (rad) that
/// the elements resolve: the second variation is written in the material
/// frame, so a mode that is smooth in space oscillates there at the
/// frame's rate |κ| (a twisted shaft: κ3 = M/C). Two meshes that both turn
/// the frame several radians per element agree with each other and are
/// both wrong (a Greenhill shaft with C = B/100 read as stable), so the
/// first mesh is made fine enough before meshes are compared.
pub const TURN_PER_ELEMENT: f64 = 0.5;

/// The turn per element beyond which a single mesh's eigenvalues are not
/// trusted at all (continuation's tracked spectrum ends its branch there,
/// naming the mesh it needs).
pub const MAX_TURN_PER_ELEMENT: f64 = 1.0;

/// The most elements [`decide`] starts from for the resolution above (then
/// doubled up to [`REFINEMENTS`] times); beyond it the verdict is
/// undecided.
pub const MAX_RESOLVED_ELEMENTS: usize = 20_000;

/// Elements that keep the frame's turn per element within
/// [`TURN_PER_ELEMENT`]: L max|κ| / θ, max|κ| over 8 samples per element of
/// `opts`' mesh (at least 64).
fn resolved_elements(
    rod: &Rod,
    eq: &Equilibrium,
    solver: &SolverOptions,
    opts: &StabilityOptions,
) -> Result<usize, StabilityError> {
    let count = (8 * opts.elements).max(64);
    let length = rod.length();
    // L·(i/count): the last point is L exactly, never an ulp beyond it.
    let points: Vec<f64> = (0..=count)
        .map(|i| length * (i as f64 / count as f64))
        .collect();
    let kappa = eq.max_curvature(rod, solver, &points)?;
    let needed = (length * kappa / TURN_PER_ELEMENT).ceil();
    // A non-finite curvature is no mesh: refuse rather than saturate.
    if !needed.is_finite() {
        return Ok(usize::MAX);
    }
    Ok(needed.min(usize::MAX as f64) as usize)
}

fn undecided(reason: String, stability: Option<Stability>, elements: usize) -> Decision {
    Decision {
        verdict: Verdict::Undecided { reason },
        stability,
        elements,
        eigenvalue_error: f64::INFINITY,
    }
}

/// The eigenvalue error estimate when `fine` confirms `coarse` (same Morse
/// index in every block, every computed eigenvalue of `fine` farther from
/// zero than its change), else None.
fn settled(coarse: &Stability, fine: &Stability) -> Option<f64> {
    let same_index = coarse
        .blocks
        .iter()
        .zip(&fine.blocks)
        .all(|(a, b)| a.morse_index == b.morse_index && b.eigenvalues.len() > b.morse_index);
    if !same_index {
        return None;
    }
    let mut worst: f64 = 0.0;
    for (a, b) in coarse.blocks.iter().zip(&fine.blocks) {
        for (x, y) in a.eigenvalues.iter().zip(&b.eigenvalues) {
            let change = (x - y).abs();
            // (a NaN on either side is not a settled sign either)
            if y.abs().partial_cmp(&change) != Some(std::cmp::Ordering::Greater) {
                return None;
            }
            worst = worst.max(change);
        }
    }
    Some(worst)
}

/// The largest change of a computed eigenvalue between two meshes.
fn eigenvalue_change(coarse: &Stability, fine: &Stability) -> f64 {
    coarse
        .blocks
        .iter()
        .zip(&fine.blocks)
        .flat_map(|(a, b)| a.eigenvalues.iter().zip(&b.eigenvalues))
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}
