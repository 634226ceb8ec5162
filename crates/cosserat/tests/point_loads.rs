//! Interior point loads (`[[loads.point]]`) against closed forms: a
//! cantilever loaded at s₀ < L by a force and nothing at its tip is
//! Bisshopp and Drucker's cantilever of length s₀ (the elliptic integrals of
//! `cosserat::references::cantilever_tip`) followed by a straight piece —
//! an exact check that every method stops at the jump of n(s).
mod support;

use cosserat::bvp::{solve, Equilibrium, Method, SolverOptions};
use cosserat::model::{DeadLoads, ModelChoice, ModelLevel, PointForce, Rod};
use cosserat::references::CantileverTip;
use nalgebra::Vector3;

/// Every method; 8 segments and the default collocation mesh put no node at
/// s₀ = 0.61 of their own.
const METHODS: [Method; 4] = [
    Method::Shooting,
    Method::MultipleShooting { segments: 8 },
    Method::Collocation { stages: 2 },
    Method::Collocation { stages: 3 },
];
const LEVELS: [ModelLevel; 2] = [ModelLevel::Planar, ModelLevel::Kirchhoff];

/// L = 1, B = (10, 1, 10), the paper's clamp (d1(0) = e1 down), the force
/// F e1 at s₀.
fn loaded_at(s0: f64, force: f64) -> Rod {
    let loads = DeadLoads {
        point_forces: vec![PointForce {
            s: s0,
            force: Vector3::new(force, 0.0, 0.0),
        }],
        ..Default::default()
    };
    support::rods::uniform(1.0, [10.0, 1.0, 10.0], loads)
}

fn options(method: Method) -> SolverOptions {
    SolverOptions {
        method,
        ..Default::default()
    }
}

fn solve_with(rod: &Rod, level: ModelLevel, method: Method) -> Equilibrium {
    let choice = ModelChoice::forced(rod, level).unwrap();
    solve(rod, &choice, &options(method)).unwrap_or_else(|e| panic!("{level:?} {method:?}: {e}"))
}

/// The angle of d3 from e3 towards e1.
fn angle(d3: &Vector3<f64>) -> f64 {
    d3[0].atan2(d3[2])
}

#[test]
fn a_cantilever_loaded_inside_is_bisshopp_drucker_up_to_the_load() {
    let s0 = 0.61;
    for force in [2.0, 8.0, 20.0] {
        // The cantilever of length s₀: k = F s₀²/B, lengths scaled by s₀.
        let reference = CantileverTip::at(force * s0 * s0);
        let at_load = Vector3::new(reference.x * s0, 0.0, reference.z * s0);
        let d3 = Vector3::new(reference.angle.sin(), 0.0, reference.angle.cos());
        let tip = at_load + d3 * (1.0 - s0);
        let rod = loaded_at(s0, force);
        assert_eq!(ModelChoice::for_rod(&rod).level, ModelLevel::Planar);
        for level in LEVELS {
            for method in METHODS {
                let eq = solve_with(&rod, level, method);
                let samples = eq.resample(&rod, &options(method), &[s0, 1.0]).unwrap();
                let (load, end) = (&samples[0], &samples[1]);
                let errors = [
                    (load.position - at_load).norm(),
                    (angle(&load.directors[2]) - reference.angle).abs(),
                    (end.position - tip).norm(),
                    (angle(&end.directors[2]) - reference.angle).abs(),
                    end.curvature.norm(),
                ];
                let worst = errors.iter().copied().fold(0.0, f64::max);
                assert!(
                    worst <= 1e-9,
                    "F = {force}, {level:?}, {method:?}: errors {errors:?}"
                );
            }
        }
    }
}
