//! The exact gradient of a fixed shape's critical load with respect to the
//! coefficients of its turning angle φ(s) = Σ c_i s^{i−1}.
//!
//! λ_crit is the smallest positive λ with (K0 + λK1) v = 0 ([`super::critical_load`]).
//! Differentiating (K0 + λK1) v = 0 and multiplying by vᵀ (K symmetric):
//!
//!   ∂λ/∂c_i = −vᵀ(∂K0/∂c_i + λ ∂K1/∂c_i) v / vᵀK1v,
//!
//! valid where λ is a simple eigenvalue (first-order perturbation of a
//! symmetric pencil). Both forms are sums over the quadrature points,
//! vᵀKv = Σ_q w_q q(ω_q, ω'_q) ([`super::factored`]), and the coefficients
//! of q are polynomials in the curvature κ, moment M and force N there
//! ([`FormCoefficients::at`]), so ∂q/∂c_i follows from ∂(κ, M, N)/∂c_i by
//! the product rule — exact, not a difference. Those come from the shape:
//! a variation δφ = s^{i−1} turns the frame (δd1 = −d3 δφ, δd3 = d1 δφ),
//! moves the points (δx' = cos φ δφ, δz' = −sin φ δφ, integrated with the
//! shape by the same DOP853 run), and changes κ2 = φ' by (i−1)s^{i−2}.
//!
//! Where another critical load lies within [`SIMPLE_GAP`] (relative) of the
//! lowest — the other block's, or a second mode of the same block — λ_crit
//! is a minimum of two smooth branches and has no gradient there: the
//! result says so ([`LoadGradient::Multiple`]) instead of giving one
//! branch's derivative or an average. The count is the inertia of
//! K0 + λ(1 + gap)K1 (Sylvester: K0 is positive definite, so its negative
//! pivots count the critical loads below that factor).

use nalgebra::{Matrix3, Vector3};

use super::eigen::smallest_positive_load_factor;
use super::factored;
use super::fixed_shape::{check_scene, split_coefficients};
use super::second_variation::{Block, FiniteElements, FormCoefficients};
use super::{StabilityError, StabilityOptions};
use crate::equations::RodSample;
use crate::model::{Profile, Rod};
use crate::numerics::integrator::{Dop853, Stops, Tolerances};

/// Relative distance from λ_crit within which another critical load makes
/// λ_crit not differentiable (a double eigenvalue to this precision).
pub const SIMPLE_GAP: f64 = 1e-6;

/// The lowest critical load of a polynomial fixed shape and its gradient.
#[derive(Debug, Clone, PartialEq)]
pub enum LoadGradient {
    /// A simple lowest critical load λ and ∂λ/∂c_i for i = 1..M.
    Simple {
        /// λ_crit (the same value as [`super::critical_load`]'s load factor).
        load_factor: f64,
        /// ∂λ/∂c_1, …, ∂λ/∂c_M.
        gradient: Vec<f64>,
    },
    /// `count` critical loads (both blocks) within [`SIMPLE_GAP`] of the
    /// lowest, λ: no gradient exists.
    Multiple {
        /// λ_crit.
        load_factor: f64,
        /// Critical loads in [λ, λ(1 + gap)] (at least 2 where the factor at
        /// λ(1 + gap) met a zero pivot: a critical load there).
        count: usize,
    },
    /// The shape is stable under any load.
    Stable,
}

/// ∂(κ, M, N)/∂c_i at one point, body components.
#[derive(Debug, Clone, Copy)]
struct SampleRate {
    kappa: Vector3<f64>,
    moment: Vector3<f64>,
    force: Vector3<f64>,
}

/// λ_crit of the shape φ = Σ c_i s^{i−1} under `rod.loads` and its exact
/// gradient in c (module doc); refused as [`super::critical_load`] refuses.
pub fn critical_load_gradient(
    rod: &Rod,
    coefficients: &[f64],
    opts: &StabilityOptions,
) -> Result<LoadGradient, StabilityError> {
    check_scene(rod)?;
    let fe = FiniteElements::new(rod.length(), opts.elements(), opts.order());
    let (samples, rates) = shape_rates(rod, coefficients, &fe.quadrature_points())?;
    let (c0, c1) = split_coefficients(rod, &samples);
    let mut lowest: Option<(Block, f64, Vec<f64>)> = None;
    let mut pencils = Vec::with_capacity(2);
    for block in [Block::InPlane, Block::OutOfPlane] {
        let (k0, k1) = (fe.stiffness(&c0, block), fe.stiffness(&c1, block));
        if let Some((l, v)) = smallest_positive_load_factor(&k0, &k1)? {
            let l = factored::load_factor(&fe, (&c0, &c1), block, &v).unwrap_or(l);
            if lowest.as_ref().is_none_or(|(_, m, _)| l < *m) {
                lowest = Some((block, l, v));
            }
        }
        pencils.push((k0, k1));
    }
    let Some((block, lambda, v)) = lowest else {
        return Ok(LoadGradient::Stable);
    };
    let above = lambda * (1.0 + SIMPLE_GAP);
    let mut count = 0;
    for (k0, k1) in &pencils {
        // A zero pivot: λ(1 + gap) itself is a critical load to round-off,
        // a second one within the gap (at least two in all).
        count += k0
            .combine(1.0, k1, above)
            .ldlt()
            .map_or(2, |factors| factors.negative_pivots());
    }
    if count != 1 {
        return Ok(LoadGradient::Multiple {
            load_factor: lambda,
            count,
        });
    }
    let shape = ShapeForms {
        fe: &fe,
        samples: &samples,
        rates: &rates,
        forms: (&c0, &c1),
    };
    Ok(LoadGradient::Simple {
        load_factor: lambda,
        gradient: shape.gradient(block, lambda, &v, coefficients.len()),
    })
}

/// One block's lowest critical load and, where it is simple within its
/// block, its exact gradient in the shape's coefficients.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockLoad {
    /// The block.
    pub block: Block,
    /// Its lowest positive critical load factor.
    pub load_factor: f64,
    /// ∂λ/∂c_1, …, ∂λ/∂c_M; None where a second critical load of the same
    /// block lies within [`SIMPLE_GAP`].
    pub gradient: Option<Vec<f64>>,
}

/// Each block's lowest critical load with its gradient (module doc), in
/// block order (in-plane, out-of-plane); a block stable under any load is
/// left out. λ_crit = the least of them is the minimum of smooth branches
/// where two blocks' loads meet: an optimizer needs both branches' slopes
/// there (a max–min step), which [`critical_load_gradient`] withholds.
/// Refused as [`super::critical_load`] refuses.
pub fn critical_load_gradients(
    rod: &Rod,
    coefficients: &[f64],
    opts: &StabilityOptions,
) -> Result<Vec<BlockLoad>, StabilityError> {
    check_scene(rod)?;
    let fe = FiniteElements::new(rod.length(), opts.elements(), opts.order());
    let (samples, rates) = shape_rates(rod, coefficients, &fe.quadrature_points())?;
    let (c0, c1) = split_coefficients(rod, &samples);
    let shape = ShapeForms {
        fe: &fe,
        samples: &samples,
        rates: &rates,
        forms: (&c0, &c1),
    };
    let mut loads = Vec::with_capacity(2);
    for block in [Block::InPlane, Block::OutOfPlane] {
        let (k0, k1) = (fe.stiffness(&c0, block), fe.stiffness(&c1, block));
        let Some((l, v)) = smallest_positive_load_factor(&k0, &k1)? else {
            continue;
        };
        let l = factored::load_factor(&fe, (&c0, &c1), block, &v).unwrap_or(l);
        // A zero pivot: λ(1 + gap) is a critical load to round-off.
        let simple = k0
            .combine(1.0, &k1, l * (1.0 + SIMPLE_GAP))
            .ldlt()
            .is_ok_and(|factors| factors.negative_pivots() == 1);
        loads.push(BlockLoad {
            block,
            load_factor: l,
            gradient: simple.then(|| shape.gradient(block, l, &v, coefficients.len())),
        });
    }
    Ok(loads)
}

/// A shape's samples, their rates in the coefficients and its forms K0,
/// K1 at the quadrature points: what a mode's gradient is summed from.
struct ShapeForms<'a> {
    fe: &'a FiniteElements,
    samples: &'a [RodSample],
    rates: &'a [Vec<SampleRate>],
    forms: (&'a [FormCoefficients], &'a [FormCoefficients]),
}

impl ShapeForms<'_> {
    /// ∂λ/∂c_i (i = 1..m) of the critical load λ with null vector `v` in
    /// `block`: −vᵀ(∂K0/∂c_i + λ ∂K1/∂c_i)v / vᵀK1v (module doc).
    fn gradient(&self, block: Block, lambda: f64, v: &[f64], m: usize) -> Vec<f64> {
        let (c0, c1) = self.forms;
        let points = self.fe.interpolate(block, v);
        let weights = self.fe.quadrature_weights();
        let load_form = factored::form(self.fe, c1, block, v);
        (0..m)
            .map(|i| {
                let change: f64 = points
                    .iter()
                    .zip(&weights)
                    .enumerate()
                    .map(|(q, ((w, dw), weight))| {
                        let r = &self.rates[q][i];
                        let (d0, d1) = coefficient_rates(&c0[q], &self.samples[q], r);
                        weight * (d0.evaluate(w, dw) + lambda * d1.evaluate(w, dw))
                    })
                    .sum();
                -change / load_form
            })
            .collect()
    }
}

/// ∂/∂c_i of K0's and K1's coefficients at a point: with A = H fixed (a
/// quadratic energy), B0 = H[κ]×, C0 = [κ]×ᵀH[κ]×; B1 = −½[M]×,
/// C1 = sym(Mκᵀ) − (M·κ)I − sym(N e3ᵀ) + (N·e3)I ([`FormCoefficients::at`]).
fn coefficient_rates(
    k0: &FormCoefficients,
    sample: &RodSample,
    rate: &SampleRate,
) -> (FormCoefficients, FormCoefficients) {
    let sym = |m: Matrix3<f64>| (m + m.transpose()) * 0.5;
    let h = k0.a;
    let (kappa, moment) = (sample.curvature, sample.moment);
    let (dk, dm, dn) = (rate.kappa, rate.moment, rate.force);
    let k = kappa.cross_matrix();
    let dkx = dk.cross_matrix();
    let id = Matrix3::identity();
    let stiffness = FormCoefficients {
        a: Matrix3::zeros(),
        b: h * dkx,
        c: sym(dkx.transpose() * h * k) * 2.0,
    };
    let e3 = Vector3::z();
    let load = FormCoefficients {
        a: Matrix3::zeros(),
        b: -dm.cross_matrix() * 0.5,
        c: sym(dm * kappa.transpose() + moment * dk.transpose())
            - id * (dm.dot(&kappa) + moment.dot(&dk))
            - sym(dn * e3.transpose())
            + id * dn.dot(&e3),
    };
    (stiffness, load)
}

/// The shape sampled at sorted `points` as [`super::FixedShape::samples`]
/// samples it, with ∂(κ, M, N)/∂c_i at each point for i = 1..M: the
/// positions' sensitivities δx' = cos φ s^{i−1}, δz' = −sin φ s^{i−1} and
/// their running integrals ride along in the same DOP853 run, with the
/// step control on the positions alone (the steps, hence the samples, are
/// those of the shape without them).
fn shape_rates(
    rod: &Rod,
    c: &[f64],
    points: &[f64],
) -> Result<(Vec<RodSample>, Vec<Vec<SampleRate>>), StabilityError> {
    let m = c.len();
    let phi = Profile::Polynomial(c.to_vec());
    let shape = super::FixedShape {
        turning_angle: phi.clone(),
    };
    let samples = shape.samples(rod, points)?;
    let rhs = |s: f64, y: &[f64], d: &mut [f64]| {
        let (sin, cos) = phi.value(s).sin_cos();
        d[..4].copy_from_slice(&[sin, cos, y[0], y[1]]);
        let mut p = 1.0;
        for i in 0..m {
            let k = 4 + 4 * i;
            d[k] = cos * p;
            d[k + 1] = -sin * p;
            d[k + 2] = y[k];
            d[k + 3] = y[k + 1];
            p *= s;
        }
    };
    let l = rod.length();
    let mut stops = points.to_vec();
    stops.push(l);
    let n = 4 + 4 * m;
    let mut states: Vec<Vec<f64>> = Vec::with_capacity(stops.len());
    let mut y = vec![0.0; n];
    Dop853::new(n)
        .integrate_serving(
            rhs,
            (0.0, l, 4),
            &mut y,
            &Tolerances::default(),
            &stops,
            Stops::Interpolated,
            |_, y| states.push(y.to_vec()),
            |_| {},
        )
        .map_err(|e| StabilityError::FixedShape(format!("the shape's quadrature failed: {e}")))?;
    let tip = states.last().expect("the tip is a stop").clone();
    let clamp = rod.clamp();
    let (ex, ez) = (clamp.director(0), clamp.director(2));
    let global = |a: f64, b: f64| ex * a + ez * b;
    let loads = rod.loads();
    let rates = samples
        .iter()
        .zip(&states)
        .map(|(sample, state)| {
            let s = sample.s;
            let [d1, d2, d3] = sample.directors;
            let rest = l - s;
            let to_tip = global(tip[0] - state[0], tip[1] - state[1]);
            let lever = global(
                tip[2] - state[2] - rest * state[0],
                tip[3] - state[3] - rest * state[1],
            );
            let moment = to_tip.cross(&loads.tip_force) + lever.cross(&loads.distributed_force);
            let force = loads.internal_force(s, l);
            (0..m)
                .map(|i| {
                    let k = 4 + 4 * i;
                    let p = s.powi(i as i32);
                    let dto_tip = global(tip[k] - state[k], tip[k + 1] - state[k + 1]);
                    let dlever = global(
                        tip[k + 2] - state[k + 2] - rest * state[k],
                        tip[k + 3] - state[k + 3] - rest * state[k + 1],
                    );
                    let dm =
                        dto_tip.cross(&loads.tip_force) + dlever.cross(&loads.distributed_force);
                    // δd1 = −d3 δφ, δd2 = 0, δd3 = d1 δφ.
                    let (dd1, dd3) = (-d3 * p, d1 * p);
                    let dkappa = if i == 0 {
                        0.0
                    } else {
                        i as f64 * s.powi(i as i32 - 1)
                    };
                    SampleRate {
                        kappa: Vector3::new(0.0, dkappa, 0.0),
                        moment: Vector3::new(
                            dd1.dot(&moment) + d1.dot(&dm),
                            d2.dot(&dm),
                            dd3.dot(&moment) + d3.dot(&dm),
                        ),
                        force: Vector3::new(dd1.dot(&force), 0.0, dd3.dot(&force)),
                    }
                })
                .collect()
        })
        .collect();
    Ok((samples, rates))
}
