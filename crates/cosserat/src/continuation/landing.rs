//! A branch that ends at a stop value ends exactly there. A step that
//! turns the tip past `tip_angle_limit` is shortened: the arclength h of
//! the step (from the last point, along its tangent) is found with
//! θ(h) = limit, θ the angle between the tip and clamp tangents, by the
//! Illinois method on g(h) = θ(h) − limit with g(0) < 0 ≤ g(Δs). Each
//! trial is a full predictor–corrector step of length h, so the landed
//! point is an equilibrium like any other. A step in which a measure of
//! `stop_at` passes its value is shortened the same way, on
//! g(h) = m(h) − value, to |g| ≤ 1e-10 max(1, |value|); where several pass,
//! onto the one passed first. (Steps that leave the parameter bounds land
//! on the bound by Newton at fixed p: `driver.rs`.)

use super::corrector::Stepped;
use super::tracking::Modes;
use super::{tip_angle, BranchEnd, ContinuationError, Point};
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
            let gap = |x: &[f64], p: f64| Some(self.tip_angle_at(x, p)? - limit);
            let gaps = (last.tip_angle - limit, point.tip_angle - limit);
            let landed = crossed
                .then(|| {
                    self.shortened(last, sign, ds, gaps, &gap, &|g: f64| {
                        (0.0..=ANGLE_TOLERANCE).contains(&g)
                    })
                })
                .flatten();
            if let Some((x, p, tangent, _)) = landed {
                (point, modes) = self.measured(x, p, tangent)?;
            }
        }
        if let Some((x, p, tangent, _)) = self.landed_on_stop(last, sign, ds, &point) {
            (point, modes) = self.measured(x, p, tangent)?;
        }
        self.tracker.remember(&point.eigenvalues, modes);
        Ok(point)
    }

    /// The stop of `continuation.stop_at` that the step from `last` to
    /// `next` reached or passed (its gap m − value changed sign, or `next`
    /// lies on it to the stop's tolerance), the first in the list where
    /// several did: the branch ends at `next`.
    pub(super) fn passed_stop(&self, last: &Point, next: &Point) -> Option<BranchEnd> {
        self.opts.stops.iter().find_map(|stop| {
            let (before, after) = (stop.gap(&last.measures)?, stop.gap(&next.measures)?);
            let landed = after.abs() <= stop.tolerance();
            (landed || before * after < 0.0).then(|| BranchEnd::ReachedValue {
                measure: self.opts.measures[stop.measure].name(),
                value: stop.value,
                landed,
            })
        })
    }

    /// The step from `last` shortened onto the stop value that the full
    /// step to `point` passed first (the shortest of the landed steps), or
    /// None where none was passed or no shortened step landed (the branch
    /// then ends at the full step, and its end says so).
    fn landed_on_stop(&self, last: &Point, sign: f64, ds: f64, point: &Point) -> Option<Stepped> {
        self.opts
            .stops
            .iter()
            .filter_map(|stop| {
                let (before, after) = (stop.gap(&last.measures)?, stop.gap(&point.measures)?);
                if before * after >= 0.0 || after.abs() <= stop.tolerance() {
                    return None;
                }
                let gap = |x: &[f64], p: f64| stop.gap(&self.measures(x, p).ok()?);
                let tolerance = stop.tolerance();
                self.shortened(last, sign, ds, (before, after), &gap, &|g: f64| {
                    g.abs() <= tolerance
                })
            })
            .min_by(|a, b| {
                let along = |s: &Stepped| (s.1 - last.parameter).abs();
                along(a).total_cmp(&along(b))
            })
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

    /// Illinois on g(step(h)) over (0, ds), g(0) and g(ds) the `gaps` of
    /// opposite signs: the trial step where `accept(g)`, or the last trial
    /// on the far side of the root (the sign of g(ds)) once the bracket
    /// can shrink no more.
    fn shortened(
        &self,
        last: &Point,
        sign: f64,
        ds: f64,
        (g_last, g_full): (f64, f64),
        gap: &dyn Fn(&[f64], f64) -> Option<f64>,
        accept: &dyn Fn(f64) -> bool,
    ) -> Option<Stepped> {
        let mut bracket = Illinois::new(0.0, ds, g_last, g_full)?;
        let mut beyond: Option<Stepped> = None;
        for _ in 0..TRIALS {
            let h = bracket.next_point();
            let trial = self.step(last, sign, h).ok()??;
            let g = gap(&trial.0, trial.1)?;
            if accept(g) {
                return Some(trial);
            }
            if g * g_full > 0.0 {
                beyond = Some(trial);
            }
            bracket.update(h, g);
            if bracket.width() <= 4.0 * f64::EPSILON * ds {
                break;
            }
        }
        beyond
    }
}
