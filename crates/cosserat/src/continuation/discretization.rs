//! The discretization error of a special point located on the minimally
//! augmented system ([`Location::Augmented`]).
//!
//! The located point solves the family's discretized equations to the
//! corrector's tolerance, so its parameter carries the discretization's
//! error: O(h^{2m}) at the nodes of Gauss collocation with m points on
//! intervals h (1e-8 on the lateral-torsional cantilever's second branch
//! point with 32 intervals of order 6), the integrator's global error on
//! shooting. The point is located again, by the same augmented Newton,
//! on the family refined ([`Family::refined`]: twice the intervals, or
//! integration tolerances up to 100 times tighter), started from the
//! point carried onto it; with gain G the ratio of the two errors,
//!
//!   p − p* ≈ (p − p_fine) · G / (G − 1),
//!
//! which is the point's `parameter_error` (Richardson's estimate of the
//! coarse error; the located p itself is kept, since the branches
//! switched from it continue on the family's own discretization).
//!
//! A multiple branch point ([`Location::Bracketed`] on an entry of
//! Govaerts' bordered G, its bracket closed to the event tolerance) is
//! located again the same way it was found: the root of an entry of G on
//! the refined family, in p at fixed p (`bordered_root.rs`), from the
//! point carried onto it; the same Richardson scaling gives its error.
//! On the straight (twisted) branches of the shipped multiple points
//! every mesh represents the branch itself exactly, but not its
//! linearization (constant coefficients, trigonometric solutions): the
//! singular F_x, and so p, carries the discretization's error of the
//! linearized problem (4e-3 on 16 intervals of order 2 for the Kirchhoff
//! Euler column, 4e-11 of order 6; 1e-12 relative on shooting).
//!
//! A fold on a branch of symmetric copies (`slice.rs`) is the bracketed
//! root of τ_p — F_x keeps the copies' null vector, so the one-bordered
//! augmented system is singular there — and is located again the same
//! way: the step's start carried onto the refined family, put back on its
//! slice at its own parameter, and the root of τ_p bracketed again along
//! the same step (Greenhill's shaft's switched helical branches).
//!
//! An extrapolated crossing (an eigenvalue crossing the BVP does not
//! see, on three finite-element meshes, Richardson in the elements) is of
//! the family's discretized branch too: the crossing on the run's own mesh
//! is located again along the same step on the refined family, and its shift,
//! Richardson-scaled, is added to the finite elements' error.
//!
//! Neither refined location detects events or estimates an error: it is
//! one Newton solve (augmented) or one root in p (bordered), so a
//! location on the refined family never estimates its own error again.
//!
//! [`Family::refined`]: super::Family::refined

use super::diagram::{Location, Point, SpecialKind, SpecialPoint};
use super::Run;
use crate::stability::Block;

impl Run<'_> {
    /// `sp` with its discretization error where it was located on the
    /// augmented system, else as it is. Where the refined location fails
    /// the error stays unknown (None) and the note says why — never a
    /// guessed bound.
    pub(super) fn with_discretization_error(
        &self,
        sp: Option<SpecialPoint>,
        radius: f64,
    ) -> (Option<SpecialPoint>, Option<String>) {
        match sp {
            Some(sp) if sp.location == Location::Augmented => {
                with_estimate(Some(sp), |sp| self.relocated(sp, radius))
            }
            other => (other, None),
        }
    }

    /// `sp`, a multiple branch point located on an entry of Govaerts'
    /// bordered G with its bracket closed to the event tolerance, with its
    /// discretization error |p − p_fine| · G/(G − 1): p_fine the root of
    /// the same test on the refined family within `reach` (the step's
    /// length in p) of p. Where that fails the error stays unknown (None)
    /// and the note says why.
    pub(super) fn with_multiple_discretization_error(
        &self,
        sp: Option<SpecialPoint>,
        reach: f64,
    ) -> (Option<SpecialPoint>, Option<String>) {
        with_estimate(sp, |sp| self.relocated_multiple(sp, reach))
    }

    /// An extrapolated crossing `sp` (its error the finite elements')
    /// with the BVP discretization's part `bvp` added, or with its error
    /// unknown and the note saying why.
    pub(super) fn with_bvp_part(
        sp: Option<SpecialPoint>,
        bvp: Result<f64, String>,
    ) -> (Option<SpecialPoint>, Option<String>) {
        let Some(mut sp) = sp else {
            return (None, None);
        };
        let elements = sp.parameter_error.take();
        match (elements, bvp) {
            (Some(e), Ok(b)) => stated(sp, Ok(e + b)),
            (_, Err(why)) => stated(
                sp,
                Err(format!("its BVP discretization's part is unknown: {why}")),
            ),
            (None, Ok(_)) => (Some(sp), None),
        }
    }

    /// The BVP discretization's part of an extrapolated crossing's error:
    /// the crossing on the run's own finite-element mesh, at the parameter
    /// `p1` on the family, located again along the same step on the
    /// refined family, from `a` carried onto it; |p1 − p_fine| · G/(G − 1).
    /// The discretization moves the equilibrium, and the crossing on any
    /// fixed mesh moves with it by the same amount to leading order, so
    /// the run's own mesh, the cheapest of the three, serves.
    pub(super) fn crossing_bvp_error(
        &self,
        a: &Point,
        (sign, p_b, span): (f64, f64, f64),
        block: Block,
        p1: f64,
    ) -> Result<f64, String> {
        let (fine, gain) = self.family.refined()?;
        let run = Run::new(&fine, self.opts);
        let (x, forward) = self.carried_onto(&fine, a)?;
        let x = run
            .newton_at_fixed_p(x, a.parameter)
            .map_err(|e| refined(&e))?;
        let tangent = run
            .tangent(&x, a.parameter, &forward)
            .map_err(|e| refined(&e))?;
        let start = restarted(a, x, a.parameter, tangent);
        let fine_p = run
            .crossing_root(&start, (sign, p_b), span, (block, 1))
            .map_err(|why| format!("on the refined discretization {why}"))?;
        Ok((p1 - fine_p).abs() * gain / (gain - 1.0))
    }

    /// `a`'s unknowns and direction of travel carried onto the refined
    /// family `fine` (not yet on its branch: off by the discretization's
    /// error).
    fn carried_onto(
        &self,
        fine: &super::Family,
        a: &Point,
    ) -> Result<(Vec<f64>, Vec<f64>), String> {
        let x = fine
            .carried(self.family, &a.unknowns, a.parameter)
            .map_err(|e| format!("the point cannot be carried onto the refined family: {e}"))?;
        let forward = fine
            .carried_direction(self.family, &a.tangent)
            .ok_or("the step's tangent cannot be carried onto the refined family")?;
        Ok((x, forward))
    }

    /// `sp` as it is, with the note that its discretization error is
    /// unknown and why.
    pub(super) fn without_discretization_error(
        sp: Option<SpecialPoint>,
        why: &str,
    ) -> (Option<SpecialPoint>, Option<String>) {
        with_estimate(sp, |_| Err(why.to_string()))
    }

    /// `sp`, a fold bracketed on a branch of symmetric copies in the step
    /// from `a` (`sign`, towards the parameter `p_b`, arclength `span`),
    /// with its discretization error |p − p_fine| · G/(G − 1): p_fine the
    /// root of τ_p along the same step on the refined family's slice.
    /// Where that fails the error stays unknown (None) and the note says
    /// why.
    pub(super) fn with_sliced_fold_error(
        &self,
        sp: Option<SpecialPoint>,
        a: &Point,
        step: (f64, f64, f64),
    ) -> (Option<SpecialPoint>, Option<String>) {
        with_estimate(sp, |sp| self.relocated_sliced_fold(sp, a, step))
    }

    /// The refined family's p at the root of τ_p in the step from `a`
    /// carried onto it, Richardson-scaled against `sp`'s.
    fn relocated_sliced_fold(
        &self,
        sp: &SpecialPoint,
        a: &Point,
        (sign, p_b, span): (f64, f64, f64),
    ) -> Result<f64, String> {
        self.relocated_on_slice(sp, a, &|run, start| run.fold_root(start, (sign, p_b), span))
    }

    /// |p − p_fine| · G/(G − 1) of `sp`, located on a branch of symmetric
    /// copies in the step from `a`: p_fine the `root` of the same test
    /// along the same step on the refined family's slice, from `a` carried
    /// onto it and put back on its slice at its own parameter.
    pub(super) fn relocated_on_slice(
        &self,
        sp: &SpecialPoint,
        a: &Point,
        root: &dyn Fn(&Run, &Point) -> Result<f64, String>,
    ) -> Result<f64, String> {
        let (fine, gain) = self.family.refined()?;
        let mut run = Run::new(&fine, self.opts);
        run.sliced = true;
        let start = self.start_on_refined_slice(&run, &fine, a)?;
        let fine_p =
            root(&run, &start).map_err(|why| format!("on the refined discretization {why}"))?;
        Ok((sp.point.parameter - fine_p).abs() * gain / (gain - 1.0))
    }

    /// `a` carried onto the refined family `fine` of `run` and put back on
    /// its slice at its own parameter, with its tangent there.
    fn start_on_refined_slice(
        &self,
        run: &Run,
        fine: &super::Family,
        a: &Point,
    ) -> Result<Point, String> {
        let (x, forward) = self.carried_onto(fine, a)?;
        // The carried point is off the refined branch by the coarse
        // discretization's error, so F_x's copies' singular value there is
        // small but not yet persistent: its smallest pair sets the slice
        // the point is put back on, and the persistent kernel is asked for
        // at the corrected point.
        let too_large = "the refined family is too large for the dense slice";
        let near = run.nearest_kernel(&x, a.parameter).ok_or(too_large)?;
        let n = x.len();
        let mut pred = x.clone();
        pred.push(a.parameter);
        let mut hold = vec![0.0; n + 1];
        hold[n] = 1.0;
        let (z, _) = run
            .correct_sliced(&x, &pred, &hold, &near)
            .map_err(|e| refined(&e))?
            .ok_or(
                "on the refined discretization the step's start did not converge on its slice",
            )?;
        let kernel = run.symmetric_kernel(&z[..n], z[n]).ok_or(
            "on the refined discretization F_x has no persistent null vector of the copies",
        )?;
        let tangent = run
            .sliced_tangent(&z[..n], z[n], &kernel, &forward)
            .map_err(|e| refined(&e))?;
        Ok(restarted(a, z[..n].to_vec(), z[n], tangent))
    }

    /// |p − p_fine| · G/(G − 1), p_fine the root in p of an entry of G on
    /// the refined family (`bordered_root.rs`). A branch of symmetric
    /// copies (a slice) keeps a null vector of F_x, so Newton at fixed p
    /// is singular on it: refused, saying so.
    fn relocated_multiple(&self, sp: &SpecialPoint, reach: f64) -> Result<f64, String> {
        if self.sliced {
            return Err(
                "it lies on a branch of symmetric copies, whose F_x keeps a null vector \
                        at every p, so it is not located again at fixed p"
                    .into(),
            );
        }
        let (fine, gain) = self.family.refined()?;
        let p = sp.point.parameter;
        let start = fine
            .carried(self.family, &sp.point.unknowns, p)
            .map_err(|e| format!("the point cannot be carried onto the refined family: {e}"))?;
        let run = Run::new(&fine, self.opts);
        let fine_p = run
            .bordered_root_in_p(&start, p, sp.multiplicity, reach)
            .map_err(|why| format!("on the refined discretization {why}"))?;
        Ok((p - fine_p).abs() * gain / (gain - 1.0))
    }

    /// |p − p_fine| · G/(G − 1), p_fine the same special point located on
    /// the refined family.
    fn relocated(&self, sp: &SpecialPoint, radius: f64) -> Result<f64, String> {
        let (fine, gain) = self.family.refined()?;
        let p = sp.point.parameter;
        let start = fine
            .carried(self.family, &sp.point.unknowns, p)
            .map_err(|e| format!("the point cannot be carried onto the refined family: {e}"))?;
        let run = Run::new(&fine, self.opts);
        let located = match sp.kind {
            SpecialKind::Fold => run.refine_fold(&start, p, radius),
            SpecialKind::BranchPoint => run.refine_branch_point(&start, p, radius),
        }
        .map_err(|why| format!("on the refined discretization {why}"))?;
        Ok((p - located.1).abs() * gain / (gain - 1.0))
    }
}

/// The start `a` of a step moved to (x, p) with `tangent` on another
/// family: a step reads only its start's unknowns, parameter and tangent.
fn restarted(a: &Point, unknowns: Vec<f64>, parameter: f64, tangent: Vec<f64>) -> Point {
    Point {
        parameter,
        unknowns,
        tangent,
        ..a.clone()
    }
}

/// The message of a failure on the refined family.
fn refined(e: &super::PointError) -> String {
    format!("on the refined discretization {e}")
}

/// `sp` (where there is one) with the discretization error `estimate`
/// gives it, added to the error it already carries (an interpolated
/// root's own; none for a closed bracket or an augmented point), or with
/// that error unknown and the note saying why.
pub(super) fn with_estimate(
    sp: Option<SpecialPoint>,
    estimate: impl FnOnce(&SpecialPoint) -> Result<f64, String>,
) -> (Option<SpecialPoint>, Option<String>) {
    let Some(sp) = sp else {
        return (None, None);
    };
    let located = sp.parameter_error.unwrap_or(0.0);
    let error = estimate(&sp).map(|e| e + located);
    stated(sp, error)
}

/// `sp` with its estimated error, or without one and the note saying why.
fn stated(
    mut sp: SpecialPoint,
    error: Result<f64, String>,
) -> (Option<SpecialPoint>, Option<String>) {
    match error {
        Ok(e) => {
            sp.parameter_error = Some(e);
            (Some(sp), None)
        }
        Err(why) => {
            let note = unknown_error(&sp, &why);
            (Some(sp), Some(note))
        }
    }
}

/// The warning for a special point whose discretization error could not
/// be estimated, and why.
fn unknown_error(sp: &SpecialPoint, why: &str) -> String {
    format!(
        "branch {}: the {} at parameter {:.12} carries an unknown discretization error: {why}",
        sp.branch,
        sp.kind.name().replace('_', " "),
        sp.point.parameter
    )
}
