//! Snap-through of symmetric clamped rods posed on their left half, the
//! crown a guided clamp; B = ℓ = 1. The shallow circular arch under a
//! central point load (problems/shallow_arch_snap.toml: half-angle Θ, half
//! the load Q = P/2 on the crown) and the inverted buckled strip whose
//! clamps are turned (problems/bistable_strip_snap.toml: the clamp angle α
//! the parameter, no load). Two references, neither calling the solvers
//! under test.
//!
//! **The planar elastica by shooting** ([`arch_elastica_folds`]): θ the
//! tangent's angle above the horizontal, m the bending moment, H the
//! horizontal force in the rod,
//!
//!   θ' = −Θ + m,  m' = Q cos θ + H sin θ,  X' = cos θ,  Y' = sin θ,
//!
//! θ(0) = Θ, X(0) = Y(0) = 0; θ(1) = 0, X(1) = sin Θ/Θ, Y(1) = y. The
//! crown height y is the control: (m(0), H, Q) by Newton with the
//! sensitivities integrated alongside (RK4 on the augmented system, so
//! the Jacobian is exact for the discrete map), and the folds of Q are the
//! roots of dQ/dy = (J⁻¹ e₃)_Q, by Illinois in y. For the strip Θ = 0,
//! Q = 0 and the third unknown is θ(0) = α instead of Q
//! ([`strip_elastica_fold`]). Two step counts and
//! Richardson's extrapolation (RK4: error ∝ h⁴) give the folds to about
//! 1e-13.
//!
//! **Inextensible shallow-arch theory** ([`shallow_arch_fold`]), the limit
//! Θ → 0: with w the height over the half span [0, 1], ψ = w'/Θ − (1 − x)
//! the scaled change of slope, q = Q/Θ and the thrust k² = −H,
//!
//!   ψ'' + k² ψ = q − k² (1 − x),  ψ(0) = ψ(1) = 0,
//!   ∫₀¹ ψ (2(1 − x) + ψ) dx = 0   (the span is held: inextensible),
//!
//! so ψ = ψ₀ + q ψ₁ with ψ₀ = sin k(1 − x)/sin k − (1 − x), ψ₁ = (1 −
//! cos kx + (cos k − 1) sin kx / sin k)/k², and the constraint is a
//! quadratic in q. Along the loaded branch k passes π (the symmetric
//! buckling thrust of the clamped span, where both roots meet at q = π²/2)
//! and the fold is the maximum of the larger root over k > π: q* = 7.41543
//! at k = 4.263. This is the inextensible theory (the axial stiffness
//! infinite), as the rod model is; the extensible shallow-arch closed forms
//! (Pi & Bradford 2002) are not compared here.

use nalgebra::{Matrix3, Vector3};

/// The state (θ, m, X, Y) and its sensitivities to (m(0), H, p), row
/// after row: 4 + 4 × 3 numbers.
type State = [f64; 16];

/// The third unknown p of the shooting, beside m(0) and H: the parameter
/// whose folds are sought.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Third {
    /// The crown load Q (the clamp angle fixed).
    Load,
    /// The clamp angle θ(0) (no load).
    ClampAngle,
}

/// The planar elastica of a half rod — the left half of a symmetric
/// clamped rod, its crown a guided clamp at X = `span` — integrated by RK4
/// in `steps` equal steps: θ' = −`curvature` + m, θ(0) = `angle` or p.
struct HalfRod {
    curvature: f64,
    angle: f64,
    span: f64,
    third: Third,
    steps: usize,
}

impl HalfRod {
    /// (Q, θ(0)) for the third unknown p.
    fn load_and_angle(&self, p: f64) -> (f64, f64) {
        match self.third {
            Third::Load => (p, self.angle),
            Third::ClampAngle => (0.0, p),
        }
    }

    fn rhs(&self, u: &State, h: f64, q: f64) -> State {
        let (c, s) = (u[0].cos(), u[0].sin());
        let mut d = [0.0; 16];
        d[..4].copy_from_slice(&[-self.curvature + u[1], q * c + h * s, c, s]);
        let dq = if self.third == Third::Load { c } else { 0.0 };
        for j in 0..3 {
            let (dth, dm) = (u[4 + j], u[7 + j]);
            let explicit = [0.0, s, dq][j]; // ∂m'/∂(m(0), H, p)
            d[4 + j] = dm;
            d[7 + j] = (-q * s + h * c) * dth + explicit;
            d[10 + j] = -s * dth;
            d[13 + j] = c * dth;
        }
        d
    }

    fn shoot(&self, [m0, h, p]: [f64; 3]) -> State {
        let (q, angle) = self.load_and_angle(p);
        let mut u = [0.0; 16];
        u[0] = angle;
        u[1] = m0;
        u[7] = 1.0;
        if self.third == Third::ClampAngle {
            u[6] = 1.0;
        }
        let dt = 1.0 / self.steps as f64;
        let add =
            |u: &State, k: &State, a: f64| -> State { std::array::from_fn(|i| u[i] + a * k[i]) };
        for _ in 0..self.steps {
            let k1 = self.rhs(&u, h, q);
            let k2 = self.rhs(&add(&u, &k1, dt / 2.0), h, q);
            let k3 = self.rhs(&add(&u, &k2, dt / 2.0), h, q);
            let k4 = self.rhs(&add(&u, &k3, dt), h, q);
            u = std::array::from_fn(|i| {
                u[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        u
    }

    /// The end conditions (θ(1), X(1) − span, Y(1) − y) and their Jacobian
    /// in (m(0), H, p).
    fn conditions(&self, z: [f64; 3], y: f64) -> (Vector3<f64>, Matrix3<f64>) {
        let u = self.shoot(z);
        let g = Vector3::new(u[0], u[2] - self.span, u[3] - y);
        let jacobian = Matrix3::from_fn(|r, c| u[4 + 3 * [0, 2, 3][r] + c]);
        (g, jacobian)
    }

    /// (m(0), H, p) with the crown at height y, by Newton from `guess`, and
    /// dp/dy there; None where Newton does not converge to 1e-12.
    fn solve(&self, y: f64, guess: [f64; 3]) -> Option<([f64; 3], f64)> {
        let mut z = guess;
        for _ in 0..40 {
            let (g, j) = self.conditions(z, y);
            let dz = j.lu().solve(&g)?;
            z = std::array::from_fn(|i| z[i] - dz[i]);
            if dz.amax() < 1e-14 {
                break;
            }
        }
        let (g, j) = self.conditions(z, y);
        let dz = j.lu().solve(&Vector3::z())?;
        (g.amax() < 1e-12).then_some((z, dz[2]))
    }

    /// p at the first `count` folds met as the crown height goes from `y`
    /// (solved from `guess`) by steps `dy` through at most 40 steps: the sign
    /// changes of dp/dy, each located by Illinois to 1e-13 in y.
    fn folds(&self, (mut y, guess): (f64, [f64; 3]), dy: f64, count: usize) -> Option<Vec<f64>> {
        let mut found = vec![];
        let (mut z, mut slope) = self.solve(y, guess)?;
        for _ in 0..40 {
            if found.len() == count {
                return Some(found);
            }
            let next = y + dy;
            let (zn, sn) = self.solve(next, z)?;
            if sn * slope < 0.0 {
                found.push(self.fold_between((y, slope, z), (next, sn))?);
            }
            (y, z, slope) = (next, zn, sn);
        }
        (found.len() == count).then_some(found)
    }

    /// Illinois on dp/dy between y = lo and y = hi; p at the root.
    fn fold_between(
        &self,
        (mut lo, mut f_lo, z): (f64, f64, [f64; 3]),
        (mut hi, mut f_hi): (f64, f64),
    ) -> Option<f64> {
        let mut p = f64::NAN;
        for _ in 0..100 {
            let mid = hi - f_hi * (hi - lo) / (f_hi - f_lo);
            let (zm, fm) = self.solve(mid, z)?;
            p = zm[2];
            if fm * f_hi < 0.0 {
                (lo, f_lo) = (hi, f_hi);
            } else {
                f_lo /= 2.0;
            }
            (hi, f_hi) = (mid, fm);
            if (hi - lo).abs() < 1e-13 {
                break;
            }
        }
        Some(p)
    }
}

/// Richardson's extrapolation of `folds` from 400 and 800 RK4 steps: the
/// values and the larger correction.
fn extrapolated(folds: impl Fn(usize) -> Option<Vec<f64>>) -> Option<(Vec<f64>, f64)> {
    let (coarse, fine) = (folds(400)?, folds(800)?);
    let values = coarse
        .iter()
        .zip(&fine)
        .map(|(c, f)| f + (f - c) / 15.0)
        .collect();
    let correction = coarse
        .iter()
        .zip(&fine)
        .map(|(c, f)| (f - c).abs() / 15.0)
        .fold(0.0, f64::max);
    Some((values, correction))
}

/// The two folds of the half arch's elastica, Q = P/2 in units of B/ℓ²
/// (the snap-through and the restabilization of the inverted arch).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArchFolds {
    /// Q at the two folds, Richardson-extrapolated from 400 and 800 RK4
    /// steps.
    pub loads: [f64; 2],
    /// The larger Richardson correction: the error of the 800-step values,
    /// a bound well above the extrapolated values' own.
    pub correction: f64,
}

/// The folds of the half arch of half-angle Θ (rad, 0 < Θ < π/2), the
/// crown going down from its unloaded height by twentieths of the rise;
/// None where the shooting does not converge.
pub fn arch_elastica_folds(theta: f64) -> Option<ArchFolds> {
    let rise = (1.0 - theta.cos()) / theta;
    let (loads, correction) = extrapolated(|steps| {
        let arch = HalfRod {
            curvature: theta,
            angle: theta,
            span: theta.sin() / theta,
            third: Third::Load,
            steps,
        };
        arch.folds((rise, [0.0; 3]), -rise / 20.0, 2)
    })?;
    Some(ArchFolds {
        loads: [loads[0], loads[1]],
        correction,
    })
}

/// The fold of the inverted buckled strip under clamp rotation
/// (problems/bistable_strip_snap.toml): the left half of a straight strip
/// of length 2, clamped at both ends `2 span` apart and buckled downwards;
/// both clamps turned upwards by α (mirror-symmetric), the crown a guided
/// clamp. Returns (α at the fold, the Richardson correction). The scan
/// starts at α ≈ 0 from the shallow buckled shape w = (A/2)(1 − cos πs),
/// A = 4√(1 − span)/π (Newton then lands on the elastica), and raises the
/// crown by steps of A/20.
pub fn strip_elastica_fold(span: f64) -> Option<(f64, f64)> {
    let depth = 4.0 * (1.0 - span).sqrt() / std::f64::consts::PI;
    let guess = [
        -depth * std::f64::consts::PI.powi(2) / 2.0,
        -std::f64::consts::PI.powi(2),
        0.0,
    ];
    let (angles, correction) = extrapolated(|steps| {
        let strip = HalfRod {
            curvature: 0.0,
            angle: 0.0,
            span,
            third: Third::ClampAngle,
            steps,
        };
        strip.folds((-depth, guess), depth / 20.0, 1)
    })?;
    Some((angles[0], correction))
}

/// The larger root q(k) of the shallow arch's constraint, its integrals by
/// composite Simpson on 4000 intervals.
fn shallow_load(k: f64) -> f64 {
    let (s, c) = (k.sin(), k.cos());
    let psi0 = |x: f64| (k * (1.0 - x)).sin() / s - (1.0 - x);
    let psi1 = |x: f64| (1.0 - (k * x).cos() + (c - 1.0) * (k * x).sin() / s) / (k * k);
    let m: u32 = 4000;
    let h = 1.0 / f64::from(m);
    let (mut a, mut b, mut c0) = (0.0, 0.0, 0.0);
    for i in 0..=m {
        let x = f64::from(i) * h;
        let weight = match i {
            _ if i == 0 || i == m => 1.0,
            _ if i % 2 == 1 => 4.0,
            _ => 2.0,
        };
        let w = h / 3.0 * weight;
        let (p0, p1, base) = (psi0(x), psi1(x), 2.0 * (1.0 - x));
        a += w * p1 * p1;
        b += w * p1 * (base + 2.0 * p0);
        c0 += w * p0 * (base + p0);
    }
    (-b + (b * b - 4.0 * a * c0).sqrt()) / (2.0 * a)
}

/// The inextensible shallow arch's fold q* = lim Q/Θ (Θ → 0) = 7.41543:
/// the maximum over k in (3.6, 4.6) of the larger root, by golden section
/// to 1e-9 in k.
pub fn shallow_arch_fold() -> f64 {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (3.6, 4.6);
    while hi - lo > 1e-9 {
        let (a, b) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
        if shallow_load(a) < shallow_load(b) {
            lo = a;
        } else {
            hi = b;
        }
    }
    shallow_load(0.5 * (lo + hi))
}
