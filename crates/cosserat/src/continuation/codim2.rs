//! Two-parameter continuation of a singular point (codimension 2): the
//! curve of folds or branch points of a family in a second parameter —
//! the critical load as a function of a stiffness, the fold of a
//! snap-through as a function of the rise.
//!
//! The curve is followed by pseudo-arclength on Govaerts' minimally
//! augmented system (Govaerts, *Numerical Methods for Bifurcations of
//! Dynamical Equilibria*, SIAM 2000, Sec. 4.3; BifurcationKit's
//! `FoldProblemMinimallyAugmented`): unknowns z = (x, p₁, p₂),
//!
//!   F(x, p₁, p₂) = 0,   g(x, p₁, p₂) = 0,   [F_x b; cᵀ 0] [v; g] = [0; 1],
//!
//! where b, c approximate the left and right null vectors of F_x (updated
//! after every point). g vanishes exactly where F_x is singular, and is a
//! regular equation there while the kernel is simple, so the singular
//! point is located to the corrector's tolerance at every point of the
//! curve. F_x is exact; F_p₁, F_p₂ and the gradient of g are difference
//! quotients, which only steer Newton (the residual, and so the points,
//! are exact). A cusp of the curve — where the singular point changes
//! kind, e.g. two folds merge — is where the curve's projection on the
//! (p₁, p₂) plane turns back; it is reported between the two points whose
//! projected tangents point against each other.

mod error;

use std::sync::Arc;

use nalgebra::DVector;

use super::bordering::{curvature_row, low_rank_solve, BorderedJacobian, Singularity};
use super::corrector::Linearization;

use super::{ContinuationError, Family, FamilyError, Lens, PointError};
use crate::model::Rod;

/// Two numbers of a rod problem, varied together.
pub trait Lens2: std::fmt::Debug + Send + Sync {
    /// The keys of the first and the second number.
    fn keys(&self) -> [String; 2];
    /// The rod with the numbers set to p.
    fn rod_at(&self, p: [f64; 2]) -> Result<Rod, FamilyError>;
}

/// The first parameter of a [`Lens2`] at a fixed second one.
#[derive(Debug)]
struct Slice {
    pair: Arc<dyn Lens2>,
    second: f64,
}

impl Lens for Slice {
    fn key(&self) -> String {
        self.pair.keys()[0].clone()
    }

    fn rod_at(&self, p: f64) -> Result<Rod, FamilyError> {
        self.pair.rod_at([p, self.second])
    }
}

/// How the curve is followed.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveOptions {
    /// [min, max] of each parameter: the curve ends where it leaves them.
    pub bounds: [(f64, f64); 2],
    /// First arclength step, in (x, p₁, p₂).
    pub step: f64,
    /// Smallest step before the curve ends.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Points per direction at most.
    pub max_points: usize,
    /// Newton tolerance on the scaled residual (F, g).
    pub tolerance: f64,
}

impl Default for CurveOptions {
    fn default() -> Self {
        CurveOptions {
            bounds: [(f64::NEG_INFINITY, f64::INFINITY); 2],
            step: 0.05,
            min_step: 1e-7,
            max_step: 0.2,
            max_points: 200,
            tolerance: 1e-10,
        }
    }
}

/// One point of the curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvePoint {
    /// (p₁, p₂).
    pub parameters: [f64; 2],
    /// The family's unknowns x.
    pub unknowns: Vec<f64>,
    /// The unit tangent of the curve in (x, p₁, p₂).
    pub tangent: Vec<f64>,
    /// The null vector v of F_x (unit).
    pub null_vector: Vec<f64>,
    /// |g| at the point (zero to the tolerance).
    pub singularity: f64,
    /// The estimated discretization errors of (p₁ at this p₂, p₂ at this
    /// p₁): the point located again on the refined family (`error.rs`);
    /// None where that failed (the curve's warnings say why). Infinite
    /// for the parameter whose axis the curve runs parallel to.
    pub parameter_error: Option<[f64; 2]>,
}

/// A cusp of the curve: where its projection on (p₁, p₂) turns back,
/// located by bisection in the arclength between two points.
#[derive(Debug, Clone, PartialEq)]
pub struct Cusp {
    /// The index of the curve point before it.
    pub after: usize,
    /// The located point, where the projected tangent vanishes (to the
    /// bisection's 2⁻⁴⁰ of the step).
    pub point: CurvePoint,
    /// The estimated discretization errors of its (p₁, p₂): the cusp
    /// located again on the refined family; None where that failed.
    pub parameter_error: Option<[f64; 2]>,
}

/// A followed curve of singular points.
#[derive(Debug, Clone, PartialEq)]
pub struct SingularCurve {
    /// The two keys.
    pub keys: [String; 2],
    /// The points, from one end to the other.
    pub points: Vec<CurvePoint>,
    /// Cusps, located.
    pub cusps: Vec<Cusp>,
    /// Why each end stopped (the first end, then the second).
    pub ends: [String; 2],
    /// Why a point's or a cusp's discretization error is unknown.
    pub warnings: Vec<String>,
}

/// The minimally augmented system of one family.
struct Augmented<'a> {
    family: &'a Family,
    pair: Arc<dyn Lens2>,
    n: usize,
    /// A branch point: F + ψ b = 0 with the unknown ψ and the phase
    /// cᵀ(x − x_anchor) = 0, because at a symmetry-breaking branch point
    /// F_p lies in the range of F_x (on the symmetric branch F_p = 0) and
    /// the fold system is singular there (Govaerts 2000, Sec. 4.4). A fold
    /// uses F = 0.
    branch: bool,
}

/// A corrected point: z, the linearized system there, Newton iterations.
type Corrected = (Vec<f64>, Linearized, usize);

/// The augmented system linearized at z: its residual and the pieces of
/// its Jacobian, kept in F_x's shape (`bordering.rs`). In the unknowns'
/// order (x, [ψ,] p₁, p₂) the Jacobian of (F [+ ψb], [phase,] g), closed
/// by an arclength row, is diag(K, I) — K = [F_x b; cᵀ 0], whose border
/// row is the phase of a branch point — plus the columns F_p₁, F_p₂ (and
/// F_p₁ − b for a fold, whose p₁ takes K's border column) and the rows of
/// g and of the arclength: a Woodbury correction of rank ≤ 4 of K's
/// factors, O(N) per solve.
struct Linearized {
    residual: DVector<f64>,
    k: BorderedJacobian,
    /// F_p₁ and F_p₂.
    fp: [DVector<f64>; 2],
    /// ∇g = (g_x, [0,] g_p₁, g_p₂) in the unknowns' order.
    gradient: DVector<f64>,
}

impl Augmented<'_> {
    fn slice(&self, second: f64) -> Family {
        self.family.with_lens(Arc::new(Slice {
            pair: Arc::clone(&self.pair),
            second,
        }))
    }

    /// F and F_x at z, F_x in the corrector's shape.
    fn evaluate(&self, z: &[f64]) -> Result<(DVector<f64>, Linearization), PointError> {
        let n = self.n;
        let family = self.slice(z[n + 1]);
        let mut fx = Linearization::of(&family);
        let mut r = DVector::zeros(n);
        fx.evaluate(&family, &z[..n], z[n], &mut r)?;
        Ok((r, fx))
    }

    /// Unknowns: x, p₁, p₂ and, at a branch point, ψ.
    fn unknowns(&self) -> usize {
        self.n + 2 + usize::from(self.branch)
    }

    /// Where p₁ and p₂ sit in the solver's order (x, [ψ,] p₁, p₂).
    fn parameter_slots(&self) -> (usize, usize) {
        let m = self.unknowns();
        (m - 2, m - 1)
    }

    /// z = (x, p₁, p₂, [ψ]) in the solver's order (x, [ψ,] p₁, p₂), and
    /// back ([`Self::in_z_order`]).
    fn in_solver_order(&self, z: &[f64]) -> DVector<f64> {
        let n = self.n;
        let mut y = DVector::from_column_slice(z);
        if self.branch {
            y[n] = z[n + 2];
            y[n + 1] = z[n];
            y[n + 2] = z[n + 1];
        }
        y
    }

    fn in_z_order(&self, y: &DVector<f64>) -> Vec<f64> {
        let n = self.n;
        let mut z = y.as_slice().to_vec();
        if self.branch {
            z[n] = y[n + 1];
            z[n + 1] = y[n + 2];
            z[n + 2] = y[n];
        }
        z
    }

    /// The residual (F [+ ψ b], [phase,] g) at z, in the equations' order
    /// (F, [phase,] g), and its linearization; `anchor` is the x the phase
    /// is measured from. g and its gradient come from K = [F_x b; cᵀ 0]:
    /// K[v; g] = e, Kᵀ[w; ·] = e, g_z = −wᵀF_xz v (Govaerts 2000, §3.2;
    /// `fold.rs`), the second derivatives by central differences of the
    /// exact F_x.
    fn system(
        &self,
        z: &[f64],
        b: &DVector<f64>,
        c: &DVector<f64>,
        anchor: &[f64],
    ) -> Result<Linearized, PointError> {
        let n = self.n;
        let m = self.unknowns();
        let singular = || PointError::SingularTangent(z[n]);
        let (x, p1, p2) = (&z[..n], z[n], z[n + 1]);
        let (mut f, fx) = self.evaluate(z)?;
        let mut k = BorderedJacobian::new(fx, b.clone(), c.clone()).ok_or_else(singular)?;
        let Singularity { g, v, w } = k.singularity().ok_or_else(singular)?;
        let here = self.slice(p2);
        let fp1 = here.parameter_derivative(x, p1)?;
        let h2 = 1e-6 * p2.abs().max(1.0);
        let (up2, down2) = (self.slice(p2 + h2), self.slice(p2 - h2));
        let (mut up, mut down) = (DVector::zeros(n), DVector::zeros(n));
        up2.residual_only(x, p1, &mut up)?;
        down2.residual_only(x, p1, &mut down)?;
        let fp2 = (up - down) / (2.0 * h2);
        let linearized =
            |family: &Family, x: &[f64], p: f64| -> Result<Linearization, PointError> {
                let mut fx = Linearization::of(family);
                let mut r = DVector::zeros(n);
                fx.evaluate(family, x, p, &mut r)?;
                Ok(fx)
            };
        let gx = -curvature_row(|y: &[f64]| linearized(&here, y, p1), x, &v, &w)?;
        let h1 = 1e-6 * p1.abs().max(1.0);
        let gp1 = -w.dot(
            &(linearized(&here, x, p1 + h1)?.mul(&v) - linearized(&here, x, p1 - h1)?.mul(&v)),
        ) / (2.0 * h1);
        let gp2 = -w.dot(&(linearized(&up2, x, p1)?.mul(&v) - linearized(&down2, x, p1)?.mul(&v)))
            / (2.0 * h2);
        let mut residual = DVector::zeros(m - 1);
        let mut gradient = DVector::zeros(m);
        gradient.rows_mut(0, n).copy_from(&gx);
        let (s1, s2) = self.parameter_slots();
        gradient[s1] = gp1;
        gradient[s2] = gp2;
        if self.branch {
            f += b * z[n + 2];
            residual[n] = c
                .iter()
                .zip(x)
                .zip(anchor)
                .map(|((c, x), a)| c * (x - a))
                .sum();
        }
        residual.rows_mut(0, n).copy_from(&f);
        residual[m - 2] = g;
        Ok(Linearized {
            residual,
            k,
            fp: [fp1, fp2],
            gradient,
        })
    }

    /// The solution y (solver's order) of [J; rowᵀ] y = rhs, J the
    /// Jacobian of `at`, by Woodbury on diag(K, I) (see [`Linearized`]).
    fn solve(
        &self,
        at: &mut Linearized,
        row: &DVector<f64>,
        rhs: &DVector<f64>,
    ) -> Option<DVector<f64>> {
        let n = self.n;
        let m = self.unknowns();
        let (s1, s2) = self.parameter_slots();
        let unit = |k: usize| super::fold::unit(m, k);
        let padded = |v: &DVector<f64>| {
            DVector::from_iterator(m, v.iter().copied().chain(std::iter::repeat(0.0)).take(m))
        };
        // K occupies rows and columns 0..=n; the identity the rest.
        let mut u = vec![padded(&at.fp[1])];
        let mut v = vec![unit(s2)];
        if self.branch {
            // Columns p₁ (slot n + 1), p₂ (n + 2); rows g (n + 1), arc (n + 2).
            u.push(padded(&at.fp[0]));
            v.push(unit(s1));
            let mut g_row = at.gradient.clone();
            g_row[s1] -= 1.0;
            u.push(unit(n + 1));
            v.push(g_row);
        } else {
            // p₁ takes K's border column b; g takes K's border row c.
            let b = at.k.column().clone();
            u.push(padded(&(&at.fp[0] - b)));
            v.push(unit(s1));
            let mut g_row = at.gradient.clone();
            g_row.rows_mut(0, n).axpy(-1.0, at.k.row(), 1.0);
            u.push(unit(n));
            v.push(g_row);
        }
        let mut arc = row.clone();
        arc[m - 1] -= 1.0;
        u.push(unit(m - 1));
        v.push(arc);
        let k = &mut at.k;
        let solve_k = |r: &DVector<f64>| -> Option<DVector<f64>> {
            let head = k.solve(&r.rows(0, n + 1).into_owned())?;
            Some(DVector::from_iterator(
                m,
                head.iter().copied().chain(r.iter().skip(n + 1).copied()),
            ))
        };
        low_rank_solve(solve_k, &u, &v, rhs)
    }

    /// The left and right null vectors of F_x at a point of parameter p₁
    /// (`bordering.rs`).
    fn null_vectors(
        fx: &Linearization,
        p: f64,
    ) -> Result<(DVector<f64>, DVector<f64>), PointError> {
        let (right, left) =
            super::bordering::null_vectors(fx).ok_or(PointError::SingularTangent(p))?;
        Ok((left, right))
    }

    /// Newton on (F, g) = 0 and ⟨z − z_pred, τ⟩ = 0 from z_pred.
    fn correct(
        &self,
        pred: &[f64],
        tau: &[f64],
        borders: (&DVector<f64>, &DVector<f64>),
        anchor: &[f64],
        tolerance: f64,
    ) -> Result<Option<Corrected>, PointError> {
        let m = self.unknowns();
        let mut z = pred.to_vec();
        let row = self.in_solver_order(tau);
        for iteration in 1..=10 {
            let mut at = self.system(&z, borders.0, borders.1, anchor)?;
            let mut rhs = DVector::zeros(m);
            rhs.rows_mut(0, m - 1).copy_from(&at.residual);
            rhs[m - 1] = z
                .iter()
                .zip(pred)
                .zip(tau)
                .map(|((a, b), t)| (a - b) * t)
                .sum();
            let Some(dy) = self.solve(&mut at, &row, &rhs) else {
                return Ok(None);
            };
            let dz = self.in_z_order(&dy);
            for (zi, d) in z.iter_mut().zip(&dz) {
                *zi -= d;
            }
            // A corrector that moves a parameter by half its size (or by
            // 1/2 near zero) from the predictor has diverged: stop before
            // it evaluates a rod hundreds of lengths long.
            let n = self.n;
            if (n..n + 2).any(|k| (z[k] - pred[k]).abs() > 0.5 * pred[k].abs().max(1.0)) {
                return Ok(None);
            }
            let size = z.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            if Self::converged(&at, tolerance) && dy.amax() <= 100.0 * tolerance * size {
                let at = self.system(&z, borders.0, borders.1, anchor)?;
                if Self::converged(&at, tolerance) {
                    return Ok(Some((z, at, iteration)));
                }
            }
        }
        Ok(None)
    }

    /// F within the tolerance (scaled residual, as every Newton here) and
    /// the point within the tolerance of the singular set: |g| over the
    /// length of its gradient, a distance in z — g itself has the scale of
    /// F_x's smallest singular value, which says nothing of how far the
    /// point is.
    fn converged(at: &Linearized, tolerance: f64) -> bool {
        let r = &at.residual;
        let row = r.len() - 1;
        r.rows(0, row).amax() <= tolerance && r[row].abs() <= tolerance * at.gradient.norm()
    }

    /// The unit null vector of the Jacobian at `at` (z's order), oriented
    /// along `previous`: [J; previousᵀ] t = e_last.
    fn tangent(&self, at: &mut Linearized, previous: &[f64]) -> Option<Vec<f64>> {
        let m = self.unknowns();
        let rhs = super::fold::unit(m, m - 1);
        let y = self.solve(at, &self.in_solver_order(previous), &rhs)?;
        let t = DVector::from_vec(self.in_z_order(&y));
        (t.iter().all(|v| v.is_finite()) && t.norm() > 0.0)
            .then(|| t.normalize().as_slice().to_vec())
    }

    /// g and v at z with the borders (b, c).
    fn singularity(
        &self,
        z: &[f64],
        b: &DVector<f64>,
        c: &DVector<f64>,
    ) -> Result<(f64, DVector<f64>), PointError> {
        let n = self.n;
        let singular = PointError::SingularTangent(z[n]);
        let (_, fx) = self.evaluate(z)?;
        let mut k = BorderedJacobian::new(fx, b.clone(), c.clone()).ok_or(singular.clone())?;
        let vg = k.solve(&super::fold::unit(n + 1, n)).ok_or(singular)?;
        Ok((vg[n], vg.rows(0, n).into_owned()))
    }
}

/// Follows the singular point of `family` at (x, p₁) with the second
/// parameter at `second`, in both parameters of `pair` (its first
/// parameter is the family's own), both ways from the start. The start
/// must be a singular point with a simple kernel: a point of a diagram's
/// fold or branch point located by det F_x.
pub fn follow_singular(
    family: &Family,
    pair: &Arc<dyn Lens2>,
    kind: super::SpecialKind,
    x: &[f64],
    p: [f64; 2],
    opts: &CurveOptions,
) -> Result<SingularCurve, ContinuationError> {
    let n = family.size();
    let start_err = |message: String| ContinuationError::Start { p: p[0], message };
    if x.len() != n {
        return Err(start_err(format!(
            "the point has {} unknowns, the family {n}",
            x.len()
        )));
    }
    let aug = Augmented {
        family,
        pair: Arc::clone(pair),
        n,
        branch: kind == super::SpecialKind::BranchPoint,
    };
    let m = aug.unknowns();
    let mut z0 = x.to_vec();
    z0.extend_from_slice(&p);
    z0.resize(m, 0.0);
    let (_, fx) = aug.evaluate(&z0)?;
    let (b, c) = Augmented::null_vectors(&fx, p[0])?;
    // Land on the curve at the given p₂ (the constraint row fixes p₂).
    let mut fix = vec![0.0; m];
    fix[n + 1] = 1.0;
    let (z, mut at, _) = aug
        .correct(&z0, &fix, (&b, &c), x, opts.tolerance)?
        .ok_or_else(|| {
            start_err("no singular point near the given one at this second parameter".into())
        })?;
    let tau = aug
        .tangent(&mut at, &fix)
        .ok_or_else(|| start_err("the curve has no tangent at the start".into()))?;
    let first = curve_point(&aug, &z, tau, &b, &c)?;
    let mut halves = vec![];
    let mut ends = [String::new(), String::new()];
    for (side, sign) in [1.0, -1.0].into_iter().enumerate() {
        let (points, end) = walk(&aug, &first, sign, opts)?;
        halves.push(points);
        ends[side] = end;
    }
    let mut points: Vec<CurvePoint> = halves[1].iter().rev().cloned().collect();
    points.push(first);
    points.extend(halves[0].iter().cloned());
    let mut cusps = (0..points.len().saturating_sub(1))
        .filter(|&i| projected(&points[i], n).dot(&projected(&points[i + 1], n)) < 0.0)
        .map(|i| {
            locate_cusp(&aug, &points[i], &points[i + 1], opts).map(|point| Cusp {
                after: i,
                point,
                parameter_error: None,
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let errors = error::estimate(&aug, &points, &cusps, opts);
    for (point, e) in points.iter_mut().zip(errors.points) {
        point.parameter_error = e;
    }
    for (cusp, e) in cusps.iter_mut().zip(errors.cusps) {
        cusp.parameter_error = e;
    }
    Ok(SingularCurve {
        keys: pair.keys(),
        points,
        cusps,
        ends: [ends[1].clone(), ends[0].clone()],
        warnings: errors.notes,
    })
}

/// The cusp between `a` and `b` (whose projected tangents point against
/// each other): bisection in the arclength s from `a` along its tangent
/// on the sign of proj τ_a · proj τ(s), each τ(s) at the point corrected
/// from z_a + s τ_a with a's borders. Refused (an error, not a guess)
/// when a corrector along the way does not converge.
fn locate_cusp(
    aug: &Augmented,
    a: &CurvePoint,
    b: &CurvePoint,
    opts: &CurveOptions,
) -> Result<CurvePoint, ContinuationError> {
    let n = aug.n;
    let m = aug.unknowns();
    let za = |p: &CurvePoint| {
        let mut z = p.unknowns.clone();
        z.extend_from_slice(&p.parameters);
        z.resize(m, 0.0);
        z
    };
    let (z0, z1) = (za(a), za(b));
    let mut tau = a.tangent.clone();
    tau.resize(m, 0.0);
    let span: f64 = z0
        .iter()
        .zip(&z1)
        .zip(&tau)
        .map(|((x, y), t)| (y - x) * t)
        .sum();
    let (_, fx) = aug.evaluate(&z0)?;
    let (left, right) = Augmented::null_vectors(&fx, a.parameters[0])?;
    let along = projected(a, n);
    let at = |s: f64| -> Result<(Vec<f64>, Vec<f64>), ContinuationError> {
        let pred: Vec<f64> = z0.iter().zip(&tau).map(|(z, t)| z + s * t).collect();
        let (z, mut at, _) = aug
            .correct(&pred, &tau, (&left, &right), &a.unknowns, opts.tolerance)?
            .ok_or_else(|| ContinuationError::Start {
                p: a.parameters[0],
                message: "the cusp could not be located: a corrector did not converge".into(),
            })?;
        let t = aug
            .tangent(&mut at, &tau)
            .ok_or(PointError::SingularTangent(z[n]))?;
        Ok((z, t))
    };
    let (mut lo, mut hi) = (0.0, span);
    let mut found = None;
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        let (z, t) = at(mid)?;
        let turned = along.dot(&nalgebra::Vector2::new(t[n], t[n + 1])) < 0.0;
        if turned {
            hi = mid;
        } else {
            lo = mid;
        }
        found = Some((z, t));
    }
    let (z, t) = found.expect("forty halvings");
    Ok(curve_point(aug, &z, t, &left, &right)?)
}

/// The curve's tangent projected on (p₁, p₂), oriented along the stored
/// order of the points.
fn projected(point: &CurvePoint, n: usize) -> nalgebra::Vector2<f64> {
    nalgebra::Vector2::new(point.tangent[n], point.tangent[n + 1])
}

fn curve_point(
    aug: &Augmented,
    z: &[f64],
    tangent: Vec<f64>,
    b: &DVector<f64>,
    c: &DVector<f64>,
) -> Result<CurvePoint, PointError> {
    let n = aug.n;
    let (g, v) = aug.singularity(z, b, c)?;
    Ok(CurvePoint {
        parameters: [z[n], z[n + 1]],
        unknowns: z[..n].to_vec(),
        tangent,
        null_vector: v.normalize().as_slice().to_vec(),
        singularity: g.abs(),
        parameter_error: None,
    })
}

/// Steps from `first` along sign·τ until a bound, the point budget or a
/// step too small; the points in order of travel (tangents oriented along
/// the whole curve's order) and why it stopped.
fn walk(
    aug: &Augmented,
    first: &CurvePoint,
    sign: f64,
    opts: &CurveOptions,
) -> Result<(Vec<CurvePoint>, String), ContinuationError> {
    let n = aug.n;
    let mut points: Vec<CurvePoint> = vec![];
    let mut ds = opts.step;
    let mut failure: Option<String> = None;
    loop {
        let last = points.last().unwrap_or(first);
        let [p1, p2] = last.parameters;
        let inside = |v: f64, (lo, hi): (f64, f64)| (lo..=hi).contains(&v);
        let within = inside(p1, opts.bounds[0]) && inside(p2, opts.bounds[1]);
        if !points.is_empty() && !within {
            return Ok((points, "left the bounds".into()));
        }
        if points.len() >= opts.max_points {
            return Ok((points, format!("{} points", opts.max_points)));
        }
        let tau: Vec<f64> = last.tangent.iter().map(|t| t * sign).collect();
        let mut z: Vec<f64> = last.unknowns.clone();
        z.extend_from_slice(&last.parameters);
        z.resize(aug.unknowns(), 0.0);
        let pred: Vec<f64> = z.iter().zip(&tau).map(|(a, t)| a + ds * t).collect();
        // Borders: the last point's null vectors (right v; left from Fᵀ).
        let (_, fx) = aug.evaluate(&z)?;
        let (b, c) = Augmented::null_vectors(&fx, p1)?;
        // A corrector whose iterate leaves the rods that can be evaluated
        // (a Newton step that diverged: a length of hundreds, an
        // integration that cannot finish) failed as one that did not
        // converge: the step is halved, and the last such failure named
        // where the curve ends for it.
        match aug.correct(&pred, &tau, (&b, &c), &last.unknowns, opts.tolerance) {
            Ok(Some((z, mut at, iterations))) => {
                let t = aug
                    .tangent(&mut at, &tau)
                    .ok_or(PointError::SingularTangent(z[n]))?;
                let stored: Vec<f64> = t.iter().map(|v| v * sign).collect();
                points.push(curve_point(aug, &z, stored, &b, &c)?);
                if iterations <= 3 {
                    ds = (ds * 1.5).min(opts.max_step);
                }
                failure = None;
            }
            outcome => {
                if let Err(e) = outcome {
                    failure = Some(e.to_string());
                }
                ds *= 0.5;
                if ds < opts.min_step {
                    let why = failure.map_or(String::new(), |e| format!(" (last: {e})"));
                    return Ok((points, format!("step size below {:e}{why}", opts.min_step)));
                }
            }
        }
    }
}

/// A library [`Parameter`](super::Parameter) of the rod another lens
/// gives: p₂ sets the second lens's number, p₁ the parameter on that rod.
#[derive(Debug)]
pub struct ParameterOn {
    first: super::Parameter,
    second: Arc<dyn Lens>,
}

impl ParameterOn {
    /// `first` on the rods of `second`.
    pub fn new(first: super::Parameter, second: Arc<dyn Lens>) -> Self {
        ParameterOn { first, second }
    }
}

impl Lens2 for ParameterOn {
    fn keys(&self) -> [String; 2] {
        [self.first.to_string(), self.second.key()]
    }

    fn rod_at(&self, p: [f64; 2]) -> Result<Rod, FamilyError> {
        let rod = self.second.rod_at(p[1])?;
        super::RodLens::new(rod, self.first).rod_at(p[0])
    }
}
