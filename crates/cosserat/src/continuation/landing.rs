//! A branch that ends at a stop value ends exactly there. A step that
//! turns the tip past `tip_angle_limit` is shortened: the arclength h of
//! the step (from the last point, along its tangent) is found with
//! θ(h) = limit, θ the angle between the tip and clamp tangents, by the
//! Illinois method on g(h) = θ(h) − limit with g(0) < 0 ≤ g(Δs). Each
//! trial is a full predictor–corrector step of length h, so the landed
//! point is an equilibrium like any other. (Steps that leave the parameter
//! bounds land on the bound by Newton at fixed p: `driver.rs`.)

use super::corrector::Stepped;
use super::tracking::Modes;
use super::{tip_angle, ContinuationError, Point};
use crate::numerics::scalar::Illinois;

use super::driver::Run;

/// How close the landed tip angle comes to the limit (rad), from above.
pub const ANGLE_TOLERANCE: f64 = 1e-10;

/// Trials of the shortened step at most.
const TRIALS: usize = 60;

impl Run<'_> {
    /// The tip angle at (x, p), or None where it cannot be evaluated.
    fn tip_angle_at(&self, x: &[f64], p: f64) -> Option<f64> {
        let rod = self.family.rod_at(p).ok()?;
        let tip = self.family.tip(x, p).ok()?;
        Some(tip_angle(&rod.clamp().frame, &tip))
    }

    /// The point of a step of length `ds` from `last` in direction `sign`
    /// that ended at (x, p, tangent), measured; if it turned the tip past
    /// the limit, the point of the step shortened so that the tip angle
    /// lies in [limit, limit + [`ANGLE_TOLERANCE`]] instead. Only the point
    /// kept is remembered by the tracker, so both are matched to `last`'s
    /// modes. Should a trial step fail, the full step is kept: the branch
    /// then stops at the angle it reached, which the stop reason reports.
    pub(super) fn next_point(
        &mut self,
        last: &Point,
        sign: f64,
        ds: f64,
        x: Vec<f64>,
        p: f64,
        tangent: Vec<f64>,
    ) -> Result<Point, ContinuationError> {
        let (mut point, mut modes) = self.measured(x, p, tangent)?;
        if let Some(limit) = self.opts.tip_angle_limit {
            let crossed = last.tip_angle < limit && point.tip_angle - limit > ANGLE_TOLERANCE;
            let landed = crossed
                .then(|| self.shortened(last, sign, ds, limit, point.tip_angle - limit))
                .flatten();
            if let Some((x, p, tangent, _)) = landed {
                (point, modes) = self.measured(x, p, tangent)?;
            }
        }
        self.tracker.remember(&point.eigenvalues, modes);
        Ok(point)
    }

    /// The point at (x, p) with its spectrum matched to the remembered
    /// modes, and its own modes (not yet remembered).
    fn measured(
        &self,
        x: Vec<f64>,
        p: f64,
        tangent: Vec<f64>,
    ) -> Result<(Point, Modes), ContinuationError> {
        let mut spectrum = self.tracker.evaluate(self.family, &x, p)?;
        let modes = std::mem::take(&mut spectrum.vectors);
        Ok((self.point_from(x, p, tangent, spectrum)?, modes))
    }

    /// Illinois on g(h) = θ(step(h)) − limit over (0, ds): the trial step
    /// with g ∈ [0, tolerance], or the upper end of the bracket once it
    /// can shrink no more.
    fn shortened(
        &self,
        last: &Point,
        sign: f64,
        ds: f64,
        limit: f64,
        g_full: f64,
    ) -> Option<Stepped> {
        let mut bracket = Illinois::new(0.0, ds, last.tip_angle - limit, g_full)?;
        let mut above: Option<Stepped> = None;
        for _ in 0..TRIALS {
            let h = bracket.next_point();
            let trial = self.step(last, sign, h).ok()??;
            let g = self.tip_angle_at(&trial.0, trial.1)? - limit;
            if (0.0..=ANGLE_TOLERANCE).contains(&g) {
                return Some(trial);
            }
            if g > 0.0 {
                above = Some(trial);
            }
            bracket.update(h, g);
            if bracket.width() <= 4.0 * f64::EPSILON * ds {
                break;
            }
        }
        above
    }
}
