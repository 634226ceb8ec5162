//! The intrinsically straight arm (κ⁰ = 0), the reference R̂0 of the
//! optimum: for each load γ the clamp angle that puts the tip at elevation
//! α (secant on the BVP solution), and the largest γ at which that level
//! equilibrium is stable (bisection on the Morse index of the verified
//! second variation); R̂0 = √γ |tip|.

use std::ops::ControlFlow;

use crate::model::Rod;
use crate::numerics::scalar::{bisect_or_break, golden_section_max};

use super::ArmProblem;

/// The intrinsically straight arm (κ⁰ = 0), solved directly: for each load
/// γ the clamp angle that puts the tip at elevation α (secant on the BVP
/// solution), and the largest γ at which that equilibrium is stable
/// (bisection on the Morse index of the verified second variation).
#[derive(Debug, Clone, PartialEq)]
pub struct StraightArm {
    /// R̂0 = √γ |tip|.
    pub reach: f64,
    /// The load γ of the farthest stable level equilibrium.
    pub gamma: f64,
    /// The clamp angle (rad, d3 turned towards d1).
    pub clamp_angle: f64,
    /// The loaded shape, scaled by √γ.
    pub loaded_shape: Vec<[f64; 3]>,
    /// Whether `stop()` ended the search early: then this is the farthest
    /// stable level equilibrium found so far, a lower bound of R̂0.
    pub interrupted: bool,
    /// What ended the stable level family beyond the largest load reached.
    pub limit: StraightLimit,
}

/// What ends the stable part of the straight arm's level family.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StraightLimit {
    /// The level equilibrium beyond it is unstable.
    StabilityLoss,
    /// No level equilibrium was found beyond it: a fold of the family, or
    /// a load the solver could not reach — R̂0 is then a lower bound, and
    /// said so (never taken silently for a stability limit).
    NoEquilibrium,
    /// The search was stopped before the end was found.
    Interrupted,
}

impl StraightLimit {
    /// `stability_loss`, `no_equilibrium` or `interrupted`.
    pub fn name(self) -> &'static str {
        match self {
            StraightLimit::StabilityLoss => "stability_loss",
            StraightLimit::NoEquilibrium => "no_equilibrium",
            StraightLimit::Interrupted => "interrupted",
        }
    }
}

impl ArmProblem {
    /// The straight rod at load γ with the clamp turned by θ.
    fn straight_rod(&self, gamma: f64, theta: f64) -> Option<Rod> {
        let rod = self.rod().ok()?;
        let loads = rod.loads().scaled(gamma);
        let mut clamp = rod.clamp().clone();
        clamp.frame = clamp.turned_frame(theta).ok()?;
        rod.with_loads(loads).ok()?.with_clamp(clamp).ok()
    }

    /// The equilibrium at (γ, θ), warm-started from a neighbouring one's
    /// clamp curvature (so that the level family is followed, not whatever
    /// branch a cold start from the straight rod falls onto), and its tip
    /// elevation error.
    fn straight_equilibrium(
        &self,
        gamma: f64,
        theta: f64,
        guess: Option<&[f64]>,
    ) -> Option<(crate::bvp::Equilibrium, f64)> {
        let rod = self.straight_rod(gamma, theta)?;
        let choice = crate::model::ModelChoice::for_rod(&rod);
        let opts = crate::bvp::SolverOptions {
            method: crate::bvp::Method::Shooting,
            strategy: if guess.is_some() {
                crate::bvp::Strategy::Direct
            } else {
                crate::bvp::Strategy::Auto
            },
            initial_guess: guess.map(<[f64]>::to_vec),
            output_points: 101,
            // The elevation must be met to 1e-12 by the secant in θ, also
            // near Euler's load where the column amplifies residuals.
            newton: crate::bvp::newton::NewtonOptions {
                tolerance: 1e-13,
                ..Default::default()
            },
            ..Default::default()
        };
        let eq = crate::bvp::solve(&rod, &choice, &opts).ok()?;
        let tip = eq.tip().position;
        let error = (-tip[0]).atan2(tip[2]) - self.alpha;
        Some((eq, error))
    }

    /// The clamp curvature of an equilibrium as three body components.
    fn clamp_curvature(eq: &crate::bvp::Equilibrium) -> Vec<f64> {
        eq.samples[0].curvature.as_slice().to_vec()
    }

    /// The clamp angle at load γ that puts the tip at elevation α, by the
    /// secant method from (θ, κ(0)) of a neighbouring level equilibrium.
    fn level_clamp(
        &self,
        gamma: f64,
        theta: f64,
        guess: Option<&[f64]>,
    ) -> Option<(f64, crate::bvp::Equilibrium)> {
        let (eq0, mut f0) = self.straight_equilibrium(gamma, theta, guess)?;
        let mut k = Self::clamp_curvature(&eq0);
        let (mut t0, mut t1) = (theta, theta - 0.01 * f0.signum());
        for _ in 0..60 {
            let (eq, f1) = self.straight_equilibrium(gamma, t1, Some(&k))?;
            // Converged when the elevation is met, or when the secant no
            // longer moves θ: near Euler's load the elevation of a column
            // is only as accurate as the BVP's residual times the growing
            // amplification 1/(1 − γ/γ_E), so 1e-12 may be out of reach.
            if f1.abs() < 1e-12 {
                return Some((t1, eq));
            }
            if (t1 - t0).abs() < 1e-12 {
                // A stalled secant is accepted only with the tip level to
                // a micro-radian (the amplified residual near Euler's
                // load); otherwise it is a failure, never a level arm.
                return (f1.abs() < 1e-6).then_some((t1, eq));
            }
            k = Self::clamp_curvature(&eq);
            let next = crate::numerics::scalar::secant_step(t0, f0, t1, f1);
            (t0, f0, t1) = (t1, f1, next.clamp(t1 - 0.1, t1 + 0.1));
        }
        None
    }

    /// R̂0 of the intrinsically straight arm: the largest √γ |tip| over the
    /// stable level equilibria. The level family is followed in γ with warm
    /// starts (steps of 5 %) until its equilibrium loses stability or the
    /// family ends (the limit then bisected); R̂ need not grow all the way,
    /// so its largest value on the stable part is refined by golden-section
    /// search around the best step.
    pub fn straight(&self) -> Option<StraightArm> {
        self.straight_until(&|| false)
    }

    /// As [`Self::straight`], stopping early when `stop()` turns true
    /// (checked before every load step): the result is then the farthest
    /// stable level equilibrium found so far, marked interrupted.
    pub fn straight_until(&self, stop: &dyn Fn() -> bool) -> Option<StraightArm> {
        type Level = (f64, Vec<f64>);
        let opts = crate::bvp::SolverOptions::default();
        let reach =
            |gamma: f64, eq: &crate::bvp::Equilibrium| gamma.sqrt() * eq.tip().position.norm();
        let level = |gamma: f64, from: &Level| -> Option<(bool, Level, f64)> {
            let (theta, eq) = self.level_clamp(gamma, from.0, Some(&from.1))?;
            let rod = self.straight_rod(gamma, theta)?;
            let st = crate::stability::analyze(&rod, &eq, &opts, &self.stability).ok()?;
            Some((
                st.stable,
                (theta, Self::clamp_curvature(&eq)),
                reach(gamma, &eq),
            ))
        };
        let first = self.level_clamp(0.25, 0.0, None)?;
        let mut state: Level = (first.0, Self::clamp_curvature(&first.1));
        // (γ, state, R̂) of every stable step.
        let mut marched: Vec<(f64, Level, f64)> =
            vec![(0.25, state.clone(), reach(0.25, &first.1))];
        let best_of = |marched: &[(f64, Level, f64)]| {
            (0..marched.len()).max_by(|&a, &b| marched[a].2.total_cmp(&marched[b].2))
        };
        let interrupted = |marched: &[(f64, Level, f64)]| {
            let best = best_of(marched)?;
            self.straight_at(
                marched[best].0,
                &marched[best].1,
                StraightLimit::Interrupted,
            )
        };
        let reason = |found: &Option<(bool, Level, f64)>| match found {
            Some(_) => StraightLimit::StabilityLoss,
            None => StraightLimit::NoEquilibrium,
        };
        let mut limit: StraightLimit;
        let (mut lo, mut hi) = (0.25, 0.25 * 1.05);
        // A load where no level equilibrium is found counts as beyond the
        // limit, like an unstable one.
        loop {
            if stop() {
                return interrupted(&marched);
            }
            let found = level(hi, &state);
            let Some((true, next, r)) = found else {
                limit = reason(&found);
                break;
            };
            marched.push((hi, next.clone(), r));
            (lo, state) = (hi, next);
            hi *= 1.05;
            if hi > 1e4 {
                return None;
            }
        }
        let side = |mid: f64| {
            if stop() {
                return ControlFlow::Break(());
            }
            ControlFlow::Continue(match level(mid, &state) {
                Some((true, next, r)) => {
                    marched.push((mid, next.clone(), r));
                    state = next;
                    true
                }
                found => {
                    limit = reason(&found);
                    false
                }
            })
        };
        if bisect_or_break(lo, hi, 40, side, |lo, hi| hi - lo < 1e-10 * hi).is_break() {
            return interrupted(&marched);
        }
        let best = best_of(&marched)?;
        let (mut gamma, mut from) = (marched[best].0, marched[best].1.clone());
        if best > 0 && best + 1 < marched.len() {
            // Golden-section search for the largest R̂ between the neighbours.
            let (a, b) = (marched[best - 1].0, marched[best + 1].0);
            let f = |x: f64| {
                if stop() {
                    return ControlFlow::Break(());
                }
                ControlFlow::Continue(level(x, &from).map_or(f64::NEG_INFINITY, |l| l.2))
            };
            let ControlFlow::Continue((a, b)) =
                golden_section_max(a, b, 60, f, |a, b| b - a < 1e-9 * b)
            else {
                return interrupted(&marched);
            };
            gamma = 0.5 * (a + b);
            if let Some((_, l, _)) = level(gamma, &from) {
                from = l;
            }
        }
        self.straight_at(gamma, &from, limit)
    }

    /// The level equilibrium at load γ from a neighbouring one's state
    /// (θ, κ(0)), as a [`StraightArm`].
    fn straight_at(
        &self,
        gamma: f64,
        from: &(f64, Vec<f64>),
        limit: StraightLimit,
    ) -> Option<StraightArm> {
        let (theta, eq) = self.level_clamp(gamma, from.0, Some(&from.1))?;
        let scale = gamma.sqrt();
        Some(StraightArm {
            reach: scale * eq.tip().position.norm(),
            gamma,
            clamp_angle: theta,
            loaded_shape: eq
                .samples
                .iter()
                .map(|p| {
                    [
                        p.position[0] * scale,
                        p.position[1] * scale,
                        p.position[2] * scale,
                    ]
                })
                .collect(),
            interrupted: limit == StraightLimit::Interrupted,
            limit,
        })
    }
}
