//! One predictor–corrector step of pseudo-arclength continuation (Keller
//! 1977) for any [`ContinuationProblem`]: from z₀ = (u₀, p₀) with unit
//! tangent τ₀, the predictor z_pred = z₀ + Δs τ₀, then Newton
//! ([`crate::numerics::newton`]) on the bordered system
//!
//!   F(u, p) = 0,   ⟨z − z_pred, τ₀⟩ = 0,
//!
//! whose Jacobian [F_u F_p; τ₀ᵀ] stays regular at a fold, where F_u alone
//! is singular. The new tangent is the null vector of [F_u F_p] oriented
//! along τ₀. Newton at a fixed p starts branches and lands them on bounds.

use nalgebra::DVector;

use super::{ContinuationProblem, Jacobian, StepFailure};
use crate::numerics::newton::{self, Damping, NewtonError, Options, System};
use crate::numerics::staircase::Border;

/// The absolute tolerance on the arclength constraint of the corrector.
const ARC_TOLERANCE: f64 = 1e-13;

/// A converged corrector: z = (u, p), its iterations and F_u there.
pub type Corrected<J> = (Vec<f64>, usize, J);

/// A corrected step: unknowns, parameter, tangent, corrector iterations.
pub type Stepped = (Vec<f64>, f64, Vec<f64>, usize);

/// F(u, p) = 0 in u at a fixed p, for [`crate::numerics::newton`].
struct FixedParameter<'a, P: ContinuationProblem> {
    problem: &'a P,
    p: f64,
    r: DVector<f64>,
    fu: P::Jacobian,
    factors: <P::Jacobian as Jacobian>::Factors,
}

impl<P: ContinuationProblem> System for FixedParameter<'_, P> {
    type Error = P::Error;

    fn size(&self) -> usize {
        self.r.len()
    }

    fn residual(&mut self, u: &[f64], r: &mut [f64]) -> Result<(), P::Error> {
        self.problem
            .evaluate(u, self.p, &mut self.r, &mut self.fu)?;
        r.copy_from_slice(self.r.as_slice());
        Ok(())
    }

    fn linearize(&mut self, _u: &[f64]) -> bool {
        self.fu.factor(&mut self.factors)
    }

    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        self.fu.newton_step(&mut self.factors, f, delta)
    }
}

/// The bordered system of a pseudo-arclength corrector in z = (u, p),
///
///   F(u, p) = 0,   ⟨z − z_pred, τ⟩ = 0,
///
/// with Jacobian [F_u F_p; τᵀ], F_p taken once at the predictor (a chord
/// in the parameter column) when the first Newton step linearizes there.
/// The constraint row is linear, so one step satisfies it to round-off; it
/// is measured against an absolute [`ARC_TOLERANCE`].
struct PseudoArclength<'a, P: ContinuationProblem> {
    problem: &'a P,
    pred: &'a [f64],
    tangent: &'a [f64],
    /// F_p at the predictor, from the first linearization.
    fp: Option<DVector<f64>>,
    /// Why F_p could not be had (the corrector's error).
    failure: Option<P::Error>,
    tolerance: f64,
    r: DVector<f64>,
    /// F_u at the last evaluated point (the corrected one on success).
    fu: P::Jacobian,
    factors: <P::Jacobian as Jacobian>::Factors,
    rhs: Vec<f64>,
}

impl<P: ContinuationProblem> PseudoArclength<'_, P> {
    fn border(&self) -> Option<Border<'_>> {
        let n = self.r.len();
        let fp = self.fp.as_ref()?;
        let (row, corner) = self.tangent.split_at(n);
        Some(Border {
            column: fp.as_slice(),
            row,
            corner: corner[0],
        })
    }
}

impl<P: ContinuationProblem> System for PseudoArclength<'_, P> {
    type Error = P::Error;

    fn size(&self) -> usize {
        self.pred.len()
    }

    fn residual(&mut self, z: &[f64], r: &mut [f64]) -> Result<(), P::Error> {
        let n = self.r.len();
        self.problem
            .evaluate(&z[..n], z[n], &mut self.r, &mut self.fu)?;
        let arc: f64 = self
            .tangent
            .iter()
            .zip(z.iter().zip(self.pred))
            .map(|(t, (a, b))| t * (a - b))
            .sum();
        r[..n].copy_from_slice(self.r.as_slice());
        r[n] = arc;
        Ok(())
    }

    fn linearize(&mut self, z: &[f64]) -> bool {
        let n = self.r.len();
        if self.fp.is_none() {
            match self.problem.parameter_derivative(&z[..n], z[n]) {
                Ok(fp) => self.fp = Some(fp),
                Err(e) => {
                    self.failure = Some(e);
                    return false;
                }
            }
        }
        let mut factors = std::mem::take(&mut self.factors);
        let done = match self.border() {
            Some(border) => {
                self.fu.factor_bordered(&mut factors, &border);
                true
            }
            None => false,
        };
        self.factors = factors;
        done
    }

    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        let mut rhs = std::mem::take(&mut self.rhs);
        rhs.iter_mut().zip(f).for_each(|(r, v)| *r = -v);
        let mut factors = std::mem::take(&mut self.factors);
        let solved = match self.border() {
            Some(border) => self.fu.solve_bordered(&mut factors, &border, &rhs, delta),
            None => false,
        };
        self.factors = factors;
        self.rhs = rhs;
        solved
    }

    fn residual_scales(&self) -> Vec<f64> {
        let mut scales = vec![1.0; self.size()];
        scales[self.r.len()] = ARC_TOLERANCE / self.tolerance;
        scales
    }
}

/// Newton in u at a fixed p from a guess already close: plain Newton steps
/// ([`Damping::Full`]), at most 29 of them (30 tests).
pub fn newton_at_fixed_p<P: ContinuationProblem>(
    problem: &P,
    mut u: Vec<f64>,
    p: f64,
    tolerance: f64,
) -> Result<Vec<f64>, StepFailure<P::Error>> {
    let mut system = FixedParameter {
        problem,
        p,
        r: DVector::zeros(u.len()),
        fu: problem.jacobian(),
        factors: Default::default(),
    };
    let opts = Options {
        tolerance,
        max_iterations: 29,
        damping: Damping::Full,
    };
    match newton::solve(&mut system, &mut u, &opts) {
        Ok(_) => Ok(u),
        Err(NewtonError::BadStart(e) | NewtonError::Evaluation { error: e, .. }) => {
            Err(StepFailure::Problem(e))
        }
        Err(_) => Err(StepFailure::NoConvergence(p)),
    }
}

/// The unit tangent at (u, p): the null vector of [F_u F_p], oriented
/// along `previous`.
pub fn tangent<P: ContinuationProblem>(
    problem: &P,
    u: &[f64],
    p: f64,
    previous: &[f64],
) -> Result<Vec<f64>, StepFailure<P::Error>> {
    let mut fu = problem.jacobian();
    problem
        .evaluate(u, p, &mut DVector::zeros(u.len()), &mut fu)
        .map_err(StepFailure::Problem)?;
    tangent_from(problem, &fu, u, p, previous)
}

/// The tangent with F_u already known at (u, p): the solution of
/// [F_u F_p; previousᵀ] t = (0, 1), normalized (so ⟨t, previous⟩ > 0).
pub fn tangent_from<P: ContinuationProblem>(
    problem: &P,
    fu: &P::Jacobian,
    u: &[f64],
    p: f64,
    previous: &[f64],
) -> Result<Vec<f64>, StepFailure<P::Error>> {
    let n = u.len();
    let fp = problem
        .parameter_derivative(u, p)
        .map_err(StepFailure::Problem)?;
    let (row, corner) = previous.split_at(n);
    let border = Border {
        column: fp.as_slice(),
        row,
        corner: corner[0],
    };
    let mut rhs = vec![0.0; n + 1];
    rhs[n] = 1.0;
    let mut factors = Default::default();
    fu.factor_bordered(&mut factors, &border);
    let mut t = DVector::zeros(n + 1);
    let solved = fu.solve_bordered(&mut factors, &border, &rhs, t.as_mut_slice());
    if !solved || !t.iter().all(|v| v.is_finite()) || t.norm() == 0.0 {
        return Err(StepFailure::SingularTangent(p));
    }
    Ok(t.normalize().as_slice().to_vec())
}

/// Newton on the bordered system F(u, p) = 0, τᵀ(z − z_pred) = 0 from the
/// predictor z_pred: plain Newton steps, at most 9 (10 tests). No damping
/// on purpose: a corrector that does not converge fast means the step was
/// too long, and the caller shortens the arclength step instead, which
/// keeps the points evenly spaced along the branch. Ok(None): no
/// convergence; Err: the problem could not be evaluated.
pub fn correct<P: ContinuationProblem>(
    problem: &P,
    pred: &[f64],
    tangent: &[f64],
    tolerance: f64,
) -> Result<Option<Corrected<P::Jacobian>>, P::Error> {
    correct_from(problem, pred, tangent, pred, tolerance)
}

/// [`correct`] on the same plane τᵀ(z − z_pred) = 0, Newton starting
/// from `start` (a point of that plane nearer the branch than z_pred, e.g.
/// [`curved_start`]): the same point to the Newton tolerance, in fewer
/// iterations.
pub fn correct_from<P: ContinuationProblem>(
    problem: &P,
    pred: &[f64],
    tangent: &[f64],
    start: &[f64],
    tolerance: f64,
) -> Result<Option<Corrected<P::Jacobian>>, P::Error> {
    let n = pred.len() - 1;
    let mut system = PseudoArclength {
        problem,
        pred,
        tangent,
        fp: None,
        failure: None,
        tolerance,
        r: DVector::zeros(n),
        fu: problem.jacobian(),
        factors: Default::default(),
        rhs: vec![0.0; n + 1],
    };
    let opts = Options {
        tolerance,
        max_iterations: 9,
        damping: Damping::Full,
    };
    let mut z = start.to_vec();
    let outcome = newton::solve(&mut system, &mut z, &opts);
    if let Some(e) = system.failure {
        return Err(e);
    }
    Ok(match outcome {
        Ok(report) => Some((z, report.iterations, system.fu)),
        // Not evaluable at the predictor: the error F_p there gave
        // before Newton started, as when it was taken first.
        Err(NewtonError::BadStart(e)) => return Err(e),
        Err(_) => None,
    })
}

/// The step of arclength `ds` from (u, p) along the unit tangent `t`
/// (oriented along the travel): the corrected point and its tangent,
/// oriented along `t`, or None when the corrector does not converge.
pub fn step<P: ContinuationProblem>(
    problem: &P,
    u: &[f64],
    p: f64,
    t: &[f64],
    ds: f64,
    tolerance: f64,
) -> Result<Option<Stepped>, StepFailure<P::Error>> {
    step_after(problem, None, u, p, t, ds, tolerance)
}

/// [`step`], Newton started from [`curved_start`] through the point
/// `before` (the branch's point before (u, p), as (u, p) concatenated)
/// where there is one: the same plane, so the same point to the Newton
/// tolerance, reached in fewer iterations on a curved branch.
pub fn step_after<P: ContinuationProblem>(
    problem: &P,
    before: Option<&[f64]>,
    u: &[f64],
    p: f64,
    t: &[f64],
    ds: f64,
    tolerance: f64,
) -> Result<Option<Stepped>, StepFailure<P::Error>> {
    let z0: Vec<f64> = u.iter().copied().chain([p]).collect();
    let pred: Vec<f64> = z0.iter().zip(t).map(|(a, b)| a + ds * b).collect();
    let start = before.and_then(|b| curved_start(b, &z0, t, ds));
    let start = start.as_deref().unwrap_or(&pred);
    let Some((z, iterations, fu)) =
        correct_from(problem, &pred, t, start, tolerance).map_err(StepFailure::Problem)?
    else {
        return Ok(None);
    };
    let n = z.len() - 1;
    let tangent = tangent_from(problem, &fu, &z[..n], z[n], t)?;
    Ok(Some((z[..n].to_vec(), z[n], tangent, iterations)))
}

/// Newton's start on the plane τᵀ(z − z₀) = Δs from the parabola through
/// the branch's last two points: z(σ) = z₀ + σ τ + σ² c with
/// z(−h) = z₋₁, h = τᵀ(z₀ − z₋₁), so c = (z₋₁ − z₀ + h τ)/h² is normal to
/// τ and z(Δs) lies on the plane (the branch's curvature, which the
/// tangent predictor z₀ + Δs τ misses by O(Δs²), taken into account). None
/// where the parabola is not to be trusted: the last chord not along τ
/// (h below a quarter of its length: a corner, a switch) or a bend of more
/// than half the step (‖Δs² c‖ > Δs / 2, a fold or a turn the parabola
/// would overshoot), and a straight branch (‖Δs² c‖ ≤ 1e-12 Δs, round-off
/// of points on a line, where the tangent predictor is exact) — the
/// tangent predictor then starts Newton.
#[must_use]
pub fn curved_start(before: &[f64], z0: &[f64], t: &[f64], ds: f64) -> Option<Vec<f64>> {
    let chord: Vec<f64> = z0.iter().zip(before).map(|(a, b)| a - b).collect();
    let h: f64 = chord.iter().zip(t).map(|(c, v)| c * v).sum();
    let length = chord.iter().map(|c| c * c).sum::<f64>().sqrt();
    if !(h > 0.25 * length && h.is_finite()) {
        return None;
    }
    let c: Vec<f64> = chord
        .iter()
        .zip(t)
        .map(|(d, v)| (h * v - d) / (h * h))
        .collect();
    let bend = ds * ds * c.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(bend <= 0.5 * ds && bend > 1e-12 * ds) {
        return None;
    }
    Some(
        z0.iter()
            .zip(t)
            .zip(&c)
            .map(|((z, v), w)| z + ds * v + ds * ds * w)
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::curved_start;

    /// The branch p = eᵘ (curvature varying along it) from u = 0: the
    /// branch point at u, the unit tangent there, and where the plane
    /// τ₀ᵀ(z − z₀) = Δs cuts the branch (Newton in u).
    fn branch(u: f64) -> Vec<f64> {
        vec![u, u.exp()]
    }

    fn unit_tangent(u: f64) -> Vec<f64> {
        let norm = (1.0 + (2.0 * u).exp()).sqrt();
        vec![1.0 / norm, u.exp() / norm]
    }

    fn cut(z0: &[f64], t: &[f64], ds: f64) -> Vec<f64> {
        let mut u = 0.0;
        for _ in 0..50 {
            let z = branch(u);
            let g = (z[0] - z0[0]) * t[0] + (z[1] - z0[1]) * t[1] - ds;
            u -= g / (t[0] + u.exp() * t[1]);
        }
        branch(u)
    }

    /// The parabola's start lies on the plane and misses the branch by
    /// O(Δs³), the tangent predictor by O(Δs²) (the branch's curvature).
    #[test]
    fn the_parabola_starts_on_the_plane_an_order_closer() {
        let (z0, t) = (branch(0.0), unit_tangent(0.0));
        let miss = |ds: f64| {
            // The point before, a step ds back along the branch.
            let before = branch(-ds / 2f64.sqrt());
            let start = curved_start(&before, &z0, &t, ds).expect("a smooth branch");
            let along: f64 = start
                .iter()
                .zip(&z0)
                .zip(&t)
                .map(|((s, z), v)| (s - z) * v)
                .sum();
            assert!((along - ds).abs() < 1e-15, "on the plane: {along} vs {ds}");
            let exact = cut(&z0, &t, ds);
            let dist = |z: &[f64]| {
                z.iter()
                    .zip(&exact)
                    .map(|(a, b)| (a - b).powi(2))
                    .sum::<f64>()
                    .sqrt()
            };
            let linear: Vec<f64> = z0.iter().zip(&t).map(|(z, v)| z + ds * v).collect();
            (dist(&start), dist(&linear))
        };
        let (coarse, coarse_linear) = miss(0.1);
        let (fine, fine_linear) = miss(0.05);
        let order = (coarse / fine).log2();
        let linear_order = (coarse_linear / fine_linear).log2();
        assert!((2.7..3.3).contains(&order), "order {order}");
        assert!((1.8..2.2).contains(&linear_order), "order {linear_order}");
        assert!(coarse < 0.1 * coarse_linear, "{coarse} vs {coarse_linear}");
    }

    /// A corner (the last chord across the tangent) and a straight branch
    /// keep the tangent predictor.
    #[test]
    fn corners_and_lines_keep_the_tangent_predictor() {
        let (z0, t) = (vec![0.0, 0.0], vec![1.0, 0.0]);
        assert!(curved_start(&[0.0, -1.0], &z0, &t, 0.1).is_none());
        assert!(curved_start(&[-0.5, 0.0], &z0, &t, 0.1).is_none());
    }
}
