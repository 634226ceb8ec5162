//! Whether a collocation branch's fixed mesh resolves its points.
//!
//! Continuation on collocation keeps one mesh (`continuation.intervals`)
//! for the whole diagram, while a collocation solve adapts its mesh until
//! its error estimate is below `solver.collocation_tolerance`. A branch
//! that deforms the rod far from its start can outgrow that mesh: on the
//! default 32 intervals the lateral-torsional cantilever's second branch
//! point is off by 1e-8. After each branch its most deformed point (the
//! largest √∫|κ|²) is solved again on the refined family
//! ([`Family::refined`]: twice the intervals, the error 2^{2m} times
//! smaller) at the same parameter, and the tip's position (in units of the
//! length) and tangent are compared: with gain G the point's error is
//! estimated as |tip − tip_fine| · G/(G − 1). Where that exceeds the
//! collocation tolerance the diagram says so, so that no point's digits
//! are trusted beyond its mesh. The most deformed point is a sentinel,
//! not a bound over the branch: a discretization's error grows with the
//! curvature's derivatives, which the deformation drives.
//!
//! [`Family::refined`]: super::Family::refined

use super::diagram::{Diagram, Point};
use super::{PointError, Run};
use crate::bvp::CollocationOptions;

impl Run<'_> {
    /// On a collocation family, a warning in `diagram` where branch
    /// `index`'s most deformed point carries a mesh error above
    /// `solver.collocation_tolerance`, or where it cannot be estimated.
    pub(super) fn check_mesh(&self, diagram: &mut Diagram, index: usize) {
        if self.family.stages().is_none() {
            return;
        }
        let points = &diagram.branches[index].points;
        let Some(point) = points.iter().max_by(|a, b| a.norm.total_cmp(&b.norm)) else {
            return;
        };
        let tolerance = self
            .opts
            .start_solver
            .as_ref()
            .map_or(CollocationOptions::default().tolerance, |s| {
                s.collocation.tolerance
            });
        let at = point.parameter;
        let intervals = self.family.intervals();
        match self.mesh_error(point) {
            Ok(error) if error > tolerance => diagram.warnings.push(format!(
                "branch {index}: its most deformed point (parameter {at:.6}) carries a mesh \
                 error of {error:.1e} on {intervals} collocation intervals (the tip against \
                 twice the intervals), above solver.collocation_tolerance = {tolerance:.1e}: \
                 raise continuation.intervals (each special point states its own error)"
            )),
            Ok(_) => {}
            Err(why) => diagram.warnings.push(format!(
                "branch {index}: the mesh error of its most deformed point (parameter {at:.6}) \
                 could not be estimated: {why}"
            )),
        }
    }

    /// |tip − tip_fine| · G/(G − 1) at `point`: its position over the
    /// length and its tangent, max-norm.
    fn mesh_error(&self, point: &Point) -> Result<f64, String> {
        let p = point.parameter;
        let (fine, gain) = self.family.refined()?;
        let fail = |e: PointError| e.to_string();
        let start = fine
            .carried(self.family, &point.unknowns, p)
            .map_err(|e| e.to_string())?;
        let run = Run::new(&fine, self.opts);
        let x = run.newton_at_fixed_p(start, p).map_err(fail)?;
        let tip = fine.tip(&x, p).map_err(fail)?;
        let length = fine.rod_at(p).map_err(|e| e.to_string())?.length();
        let moved = ((tip.position - point.tip.position) / length)
            .amax()
            .max((tip.directors[2] - point.tip.directors[2]).amax());
        Ok(moved * gain / (gain - 1.0))
    }
}
