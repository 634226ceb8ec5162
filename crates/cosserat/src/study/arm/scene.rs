//! What the paper's conclusion (Sec. 5) names as extensions of the longest
//! arm: the arm's own weight as a distributed dead load, and actuator
//! limits on the intrinsic curvature |κ⁰|.
//!
//! The loads are scaled together by one factor λ, so that the second
//! variation of a fixed shape stays linear in λ (K = K0 + λK1, paper (47)
//! with m̄ the moment of all loads) and λ_crit is still one generalized
//! eigenvalue. Units: with a tip load, λ = γ = F L²/B2 and lengths are in
//! √(B2/F) (the paper's (54)–(55)); with the weight q per length alone,
//! λ = q L³/B2 and lengths are in (B2/q)^{1/3}. The rod length in those
//! units is L̂ = λ^e (e = 1/2 resp. 1/3) and the reach R̂ = λ^e |r̄(1)|.

use nalgebra::Vector3;

use crate::model::DeadLoads;

/// The loads of the arm (all pointing down, e1).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ArmWeight {
    /// The paper's scene: a tip load F, the arm weightless.
    #[default]
    Weightless,
    /// A tip load F and the arm's weight q per length, in the fixed ratio
    /// w = qL/F (the arm's weight over the payload).
    WithTipLoad(f64),
    /// The arm's weight alone (no payload).
    Alone,
}

/// The arm's loads and its actuator limit.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ArmScene {
    /// Which dead loads act.
    pub weight: ArmWeight,
    /// The largest |κ⁰| the actuators can produce, in the units of the
    /// reach's inverse (κ⁰_max √(B2/F) with a tip load, κ⁰_max (B2/q)^{1/3}
    /// with the weight alone); None: unlimited, as in the paper.
    pub max_curvature: Option<f64>,
}

impl ArmScene {
    /// The non-dimensional loads per unit λ on the rod of length 1.
    pub fn loads(&self) -> DeadLoads {
        let down = Vector3::new(1.0, 0.0, 0.0);
        let (tip, weight) = match self.weight {
            ArmWeight::Weightless => (1.0, 0.0),
            ArmWeight::WithTipLoad(w) => (1.0, w),
            ArmWeight::Alone => (0.0, 1.0),
        };
        DeadLoads {
            tip_force: down * tip,
            distributed_force: down * weight,
            ..Default::default()
        }
    }

    /// The exponent e of L̂ = λ^e: 1/2 with a tip load, 1/3 without.
    pub fn length_exponent(&self) -> f64 {
        match self.weight {
            ArmWeight::Alone => 1.0 / 3.0,
            _ => 0.5,
        }
    }

    /// The rod length L̂ = λ^e in the reach's units.
    pub fn length(&self, lambda: f64) -> f64 {
        lambda.powf(self.length_exponent())
    }

    /// The largest load factor λ ≤ λ_crit at which the actuators can hold
    /// the shape: |κ̄⁰(s̄)| = |φ'(s̄) − λ m̄2(s̄)| ≤ κ̂_max L̂(λ) at every
    /// sample (κ̄⁰ = κ⁰L, paper (43) integrated). `dphi` and `moment` are
    /// φ' and m̄2 at the same points. None when no load in (0, λ_crit] is
    /// feasible.
    pub fn operating_load(&self, lambda_crit: f64, dphi: &[f64], moment: &[f64]) -> Option<f64> {
        let Some(limit) = self.max_curvature else {
            return Some(lambda_crit);
        };
        let excess = |l: f64| -> f64 {
            let worst = dphi
                .iter()
                .zip(moment)
                .map(|(d, m)| (d - l * m).abs())
                .fold(0.0, f64::max);
            worst - limit * self.length(l)
        };
        if excess(lambda_crit) <= 0.0 {
            return Some(lambda_crit);
        }
        // The largest feasible load on a grid going down from λ_crit, then
        // bisection between it and its infeasible neighbour above.
        let steps = 256;
        let grid = |j: usize| lambda_crit * j as f64 / steps as f64;
        let j = (1..steps).rev().find(|&j| excess(grid(j)) <= 0.0)?;
        let feasible = |mid: f64| excess(mid) <= 0.0;
        let (lo, _) =
            crate::numerics::scalar::bisect(grid(j), grid(j + 1), 60, feasible, |_, _| false);
        Some(lo)
    }
}
