//! The snap-through of a shallow circular arch under a central point load
//! (problems/shallow_arch_snap.toml): the left half of a clamped arch of
//! half-angle Θ, its crown a guided clamp carrying half the load Q = P/2;
//! B = ℓ = 1. Two references, neither calling the solvers under test.
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
//! roots of dQ/dy = (J⁻¹ e₃)_Q, by Illinois in y. Two step counts and
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

/// The state (θ, m, X, Y) and its sensitivities to (m(0), H, Q), row
/// after row: 4 + 4 × 3 numbers.
type State = [f64; 16];

/// The planar elastica of the half arch, integrated by RK4 in `steps`
/// equal steps.
struct HalfArch {
    theta: f64,
    steps: usize,
}

impl HalfArch {
    fn rhs(&self, u: &State, h: f64, q: f64) -> State {
        let (c, s) = (u[0].cos(), u[0].sin());
        let mut d = [0.0; 16];
        d[..4].copy_from_slice(&[-self.theta + u[1], q * c + h * s, c, s]);
        for j in 0..3 {
            let (dth, dm) = (u[4 + j], u[7 + j]);
            let explicit = [0.0, s, c][j]; // ∂m'/∂(m(0), H, Q)
            d[4 + j] = dm;
            d[7 + j] = (-q * s + h * c) * dth + explicit;
            d[10 + j] = -s * dth;
            d[13 + j] = c * dth;
        }
        d
    }

    fn shoot(&self, [m0, h, q]: [f64; 3]) -> State {
        let mut u = [0.0; 16];
        u[0] = self.theta;
        u[1] = m0;
        u[7] = 1.0;
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

    /// The end conditions (θ(1), X(1) − sin Θ/Θ, Y(1) − y) and their
    /// Jacobian in (m(0), H, Q).
    fn conditions(&self, z: [f64; 3], y: f64) -> (Vector3<f64>, Matrix3<f64>) {
        let u = self.shoot(z);
        let span = self.theta.sin() / self.theta;
        let g = Vector3::new(u[0], u[2] - span, u[3] - y);
        let jacobian = Matrix3::from_fn(|r, c| u[4 + 3 * [0, 2, 3][r] + c]);
        (g, jacobian)
    }

    /// (m(0), H, Q) with the crown at height y, by Newton from `guess`, and
    /// dQ/dy there; None where Newton does not converge to 1e-12.
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

    /// Q at the first two folds of the loaded branch (the snap and the
    /// restabilization), the crown going down from its unloaded height:
    /// the sign changes of dQ/dy on a grid of steps of a twentieth of the
    /// rise, each located by Illinois to 1e-13 in y.
    fn folds(&self) -> Option<[f64; 2]> {
        let rise = (1.0 - self.theta.cos()) / self.theta;
        let mut found = vec![];
        let (mut y, mut z) = (rise, [0.0; 3]);
        let (_, mut slope) = self.solve(y, z)?;
        while y > -rise && found.len() < 2 {
            let next = y - rise / 20.0;
            let (zn, sn) = self.solve(next, z)?;
            if sn * slope < 0.0 {
                found.push(self.fold_between((y, slope, z), (next, sn))?);
            }
            (y, z, slope) = (next, zn, sn);
        }
        found.try_into().ok()
    }

    /// Illinois on dQ/dy between y = lo and y = hi; Q at the root.
    fn fold_between(
        &self,
        (mut lo, mut f_lo, z): (f64, f64, [f64; 3]),
        (mut hi, mut f_hi): (f64, f64),
    ) -> Option<f64> {
        let mut q = f64::NAN;
        for _ in 0..100 {
            let mid = hi - f_hi * (hi - lo) / (f_hi - f_lo);
            let (zm, fm) = self.solve(mid, z)?;
            q = zm[2];
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
        Some(q)
    }
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

/// The folds of the half arch of half-angle Θ (rad, 0 < Θ < π/2); None
/// where the shooting does not converge.
pub fn arch_elastica_folds(theta: f64) -> Option<ArchFolds> {
    let coarse = HalfArch { theta, steps: 400 }.folds()?;
    let fine = HalfArch { theta, steps: 800 }.folds()?;
    let loads = std::array::from_fn(|i| fine[i] + (fine[i] - coarse[i]) / 15.0);
    let correction = (0..2)
        .map(|i| (fine[i] - coarse[i]).abs() / 15.0)
        .fold(0.0, f64::max);
    Some(ArchFolds { loads, correction })
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
