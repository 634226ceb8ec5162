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
        let Some(mut sp) = sp else {
            return (None, None);
        };
        if sp.location != Location::Augmented {
            return (Some(sp), None);
        }
        match self.relocated(&sp, radius) {
            Ok(error) => {
                sp.parameter_error = Some(error);
                (Some(sp), None)
            }
            Err(why) => {
                let note = format!(
                    "branch {}: the {} at parameter {:.12} carries an unknown discretization \
                     error: {why}",
                    sp.branch,
                    sp.kind.name().replace('_', " "),
                    sp.point.parameter
                );
                (Some(sp), Some(note))
            }
        }
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
