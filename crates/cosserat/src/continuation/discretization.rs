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
//! Neither refined location detects events or estimates an error: it is
//! one Newton solve (augmented) or one root in p (bordered), so a
//! location on the refined family never estimates its own error again.
//!
//! [`Family::refined`]: super::Family::refined

use super::diagram::{Location, SpecialKind, SpecialPoint};
use super::Run;

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
        let Some(sp) = sp else {
            return (None, None);
        };
        if sp.location != Location::Augmented {
            return (Some(sp), None);
        }
        let error = self.relocated(&sp, radius);
        stated(sp, error)
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
        let Some(sp) = sp else {
            return (None, None);
        };
        let error = self.relocated_multiple(&sp, reach);
        stated(sp, error)
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
