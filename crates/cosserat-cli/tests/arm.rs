//! The longest arm: limits with closed forms, and the paper's values (the
//! `optimize` command itself: arm_cli.rs).
mod common;
#[path = "../../cosserat/tests/support/mod.rs"]
mod support;

use cosserat::stability::StabilityOptions;
use cosserat::study::arm::{ArmOptimum, ArmProblem, SearchOptions, SearchProgress};
use support::quadrature::simpson;

fn problem(b1: f64, b3: f64, bounds: Vec<(f64, f64)>) -> ArmProblem {
    ArmProblem {
        b1,
        b3,
        alpha: 0.0,
        bounds,
        stability: StabilityOptions::new(100, 2, 1).unwrap(),
    }
}

/// The arm of the paper's Sec. 4.4 (problems/longest_arm.toml) and its
/// optimum.
fn section_4_4_optimum() -> (ArmProblem, ArmOptimum) {
    let (arm, search, _) = common::problems::load("longest_arm").arm.unwrap();
    let o = arm.optimize(&search).unwrap();
    (arm, o)
}

/// The straight horizontal arm is Timoshenko's cantilever: γ_crit =
/// 2 j₋₁/₄,₁ √(B̄1 B̄3), so R̂ = √γ_crit.
#[test]
fn straight_arm_reaches_the_timoshenko_length() {
    let p = problem(1.0, 2.0 / 3.0, vec![]);
    let d = p.design(&[]).unwrap();
    let gamma =
        2.0 * cosserat::references::bessel_first_zero(-0.25, 1.0, 3.0) * (2.0f64 / 3.0).sqrt();
    assert!(
        (d.reach - gamma.sqrt()).abs() < 1e-7,
        "{} vs {}",
        d.reach,
        gamma.sqrt()
    );
    assert!(d.shape_coefficients[0].abs() < 1e-14);
}

/// Sec. 4.4 of the paper from the shipped problem file: B̄1 = 4.00,
/// B̄3 = 1.27, M = 8, N = 100: R* ≈ 3.70 (the paper's value, two digits).
/// The search must find at least the paper's optimum (a better one is
/// welcome) and not more than 2 % above it with these bounds.
#[test]
fn section_4_4_reach_from_the_problem_file() {
    let (arm, o) = section_4_4_optimum();
    let r = o.design.reach;
    assert!((3.70 - 0.005..=3.70 * 1.02).contains(&r), "R* = {r}");
    // The design is what it claims: the tip is level (α = 0) and the
    // critical load of its shape reproduces R*.
    let again = arm.design(&o.design.shape_coefficients[1..]).unwrap();
    assert!((again.reach - r).abs() < 1e-12);
    let tip = o.loaded_shape.last().unwrap();
    assert!(tip[0].abs() < 1e-9 * r, "tip height {}", tip[0]);
    assert!((tip[2] - r).abs() < 1e-6 * r);
}

/// Intrinsic curvature helps (paper Sec. 4.1): for the circular section
/// with M = 4 and the bounds (60), R* exceeds the reach R0 of the
/// intrinsically straight arm; and out-of-plane modes can only lower R0:
/// the circular section reaches no farther than a section stiff out of the
/// plane (B̄1 = B̄3 = 100, the planar limit).
#[test]
fn curvature_beats_the_straight_arm() {
    let p = problem(1.0, 2.0 / 3.0, vec![(-4.0, 4.0), (-2.0, 2.0), (-0.5, 0.5)]);
    let o = p.optimize(&SearchOptions::default()).unwrap();
    let s = p.straight().unwrap();
    assert!(
        o.design.reach > s.reach,
        "R* = {}, R0 = {}",
        o.design.reach,
        s.reach
    );
    let planar = problem(100.0, 100.0, vec![]).straight().unwrap();
    assert!(
        s.reach <= planar.reach * (1.0 + 1e-9),
        "R0 = {} > planar {}",
        s.reach,
        planar.reach
    );
    // The tip is level.
    let tip = s.loaded_shape.last().unwrap();
    assert!(tip[0].abs() < 1e-9, "{tip:?}");
}

/// The loading path of the circular Fig. 5 arm: continued in its load from
/// nearly unloaded with the design's intrinsic curvature and clamp angle,
/// it must arrive at the designed shape at the design load (the design is
/// an exact equilibrium there), and the design load must be marginal (the
/// lowest eigenvalue vanishes: λ = 1 is γ_crit of the shape).
#[test]
fn circular_arm_loading_path_arrives_at_the_design() {
    let p = problem(1.0, 2.0 / 3.0, vec![(-4.0, 4.0), (-2.0, 2.0), (-0.5, 0.5)]);
    let o = p.optimize(&SearchOptions::default()).unwrap();
    let d = cosserat::study::arm::loading_path(&p, &o.design, 2001).unwrap();
    let last = d.branches[0].points.last().unwrap();
    assert_eq!(last.parameter, 1.0);
    let designed = o
        .loaded_shape
        .last()
        .unwrap()
        .map(|v| v / o.design.gamma.sqrt());
    let miss = ((last.tip.position[0] - designed[0]).powi(2)
        + (last.tip.position[2] - designed[2]).powi(2))
    .sqrt();
    assert!(miss < 1e-8, "tip misses the design by {miss}");
    let lowest = last
        .eigenvalues
        .iter()
        .fold(f64::INFINITY, |a, b| a.min(b.abs()));
    assert!(
        lowest < 1e-4,
        "the design load is not marginal: {:?}",
        last.eigenvalues
    );
}

/// The designed tip (x̄(1), z̄(1)) of a loaded shape φ(s̄) = Σ c_i s̄^{i−1},
/// by composite Simpson quadrature of (sin φ, cos φ) — independent of the
/// library's shape integrator.
fn designed_tip(c: &[f64]) -> (f64, f64) {
    let phi = |s: f64| c.iter().rev().fold(0.0, |a, ci| a * s + ci);
    (
        simpson(|s| phi(s).sin(), 0.0, 1.0),
        simpson(|s| phi(s).cos(), 0.0, 1.0),
    )
}

fn circular_fig5() -> ArmProblem {
    problem(1.0, 2.0 / 3.0, vec![(-4.0, 4.0), (-2.0, 2.0), (-0.5, 0.5)])
}

/// The control path of the paper's Sec. 5 (κ⁰ = λ κ⁰_design raised with
/// the load λF) of the circular Fig. 5 arm: from the straight unloaded arm
/// it arrives at the designed shape (tip against the quadrature of φ), is
/// stable all the way, and the design load is marginal (λ = 1 is γ_crit).
#[test]
fn circular_arm_control_path_arrives_stably() {
    let p = circular_fig5();
    let o = p.optimize(&SearchOptions::default()).unwrap();
    let scene = cosserat::study::arm::ArmScene::default();
    let d = cosserat::study::arm::control_path(&p, &scene, &o.design, 2001).unwrap();
    let points = &d.branches[0].points;
    let last = points.last().unwrap();
    assert_eq!(last.parameter, 1.0);
    let (x, z) = designed_tip(&o.design.shape_coefficients);
    let miss = (last.tip.position[0] - x).hypot(last.tip.position[2] - z);
    assert!(miss < 1e-7, "tip misses the design by {miss}");
    let unstable = points[..points.len() - 1].iter().find(|q| !q.stable);
    assert!(
        unstable.is_none(),
        "unstable at λ = {:?}",
        unstable.map(|q| q.parameter)
    );
    let lowest = last
        .eigenvalues
        .iter()
        .fold(f64::INFINITY, |a, b| a.min(b.abs()));
    assert!(lowest < 1e-4, "not marginal: {:?}", last.eigenvalues);
}

/// The Sec. 4.4 arm (flat ellipse, M = 8) does not arrive at its design
/// when loaded (κ⁰ fixed) nor along the proportional control (κ⁰ and load
/// raised together): both end, stably, on another equilibrium of the design
/// rod at the design load — the arm hangs below the clamp — far from the
/// designed level tip (quadrature of φ). Holding its shape (κ⁰ = φ' − λγm̄)
/// it does: the tip stays on the designed one at every λ, stable for λ < 1,
/// marginal at λ = 1 (the design load is γ_crit).
#[test]
fn section_4_4_arm_reaches_its_design_only_holding_its_shape() {
    let (arm, o) = section_4_4_optimum();
    let (x, z) = designed_tip(&o.design.shape_coefficients);
    assert!(x.abs() < 1e-6, "the design's tip is level: {x}");
    let scene = cosserat::study::arm::ArmScene::default();
    let miss =
        |q: &cosserat::continuation::Point| (q.tip.position[0] - x).hypot(q.tip.position[2] - z);
    for d in [
        cosserat::study::arm::loading_path(&arm, &o.design, 2001).unwrap(),
        cosserat::study::arm::control_path(&arm, &scene, &o.design, 2001).unwrap(),
    ] {
        let last = d.branches[0].points.last().unwrap();
        assert_eq!(last.parameter, 1.0);
        assert!(last.stable);
        assert!(miss(last) > 0.5, "arrived within {}", miss(last));
        assert!(
            last.tip.position[0] > 0.3,
            "does not hang: {:?}",
            last.tip.position
        );
    }
    let d = cosserat::study::arm::shape_holding_path(&arm, &scene, &o.design, 2001).unwrap();
    let points = &d.branches[0].points;
    assert_eq!(points.last().unwrap().parameter, 1.0);
    for q in points {
        assert!(
            miss(q) < 1e-7,
            "off the design by {} at λ = {}",
            miss(q),
            q.parameter
        );
    }
    assert!(points[..points.len() - 1].iter().all(|q| q.stable));
    let lowest = points
        .last()
        .unwrap()
        .eigenvalues
        .iter()
        .fold(f64::INFINITY, |a, b| a.min(b.abs()));
    assert!(lowest < 1e-4, "not marginal: {lowest}");
}

fn straight_rod(b: [f64; 3], phi: f64) -> (cosserat::model::Rod, cosserat::stability::FixedShape) {
    let rod = ArmProblem {
        b1: b[0],
        b3: b[2],
        ..problem(1.0, 1.0, vec![])
    }
    .rod_in(&cosserat::study::arm::ArmScene {
        weight: cosserat::study::arm::ArmWeight::Alone,
        max_curvature: None,
    })
    .unwrap()
    .with_energy(std::sync::Arc::new(
        cosserat::model::LinearElastic::uniform(b, [0.0; 3]).unwrap(),
    ));
    let shape = cosserat::stability::FixedShape {
        turning_angle: cosserat::model::Profile::Constant(phi),
    };
    (rod, shape)
}

fn fine() -> StabilityOptions {
    StabilityOptions::new(200, 2, 1).unwrap()
}

/// Greenhill's standing column under its own weight (the fixed shape
/// pointing up, φ = −π/2): q L³/B = (9/4) j²_{−1/3,1} ≈ 7.837 for bending
/// in the plane (B2) and out of it (B1), torsion not involved.
#[test]
fn fixed_shape_greenhill_column_under_own_weight() {
    let j = cosserat::references::bessel_first_zero(-1.0 / 3.0, 1.0, 3.0);
    let greenhill = 2.25 * j * j;
    assert!((greenhill - 7.837).abs() < 5e-4, "{greenhill}");
    let (rod, shape) = straight_rod([2.0, 1.0, 0.7], -std::f64::consts::FRAC_PI_2);
    let c = cosserat::stability::critical_load(&rod, &shape, &fine()).unwrap();
    let blocks: Vec<f64> = c.blocks.iter().map(|b| b.1.unwrap()).collect();
    assert!(
        (blocks[0] - greenhill).abs() < 1e-6 * greenhill,
        "{blocks:?}"
    );
    assert!(
        (blocks[1] - 2.0 * greenhill).abs() < 1e-6 * greenhill,
        "{blocks:?}"
    );
    assert!((c.gamma.unwrap() - greenhill).abs() < 1e-6 * greenhill);
}

/// Lateral-torsional buckling of a horizontal cantilever under its own
/// weight (load at the centroid): torsion C ψ'' + M²/B1 ψ = 0 with
/// M = q(L − s)²/2 gives q L³ = 6 j_{−1/6,1} √(B1 B3), the 12.85 of
/// Timoshenko & Gere, Theory of Elastic Stability (2nd ed., Sec. 6.3).
#[test]
fn fixed_shape_lateral_torsional_buckling_under_own_weight() {
    let j = cosserat::references::bessel_first_zero(-1.0 / 6.0, 1.0, 3.0);
    assert!((6.0 * j - 12.85).abs() < 5e-3, "{}", 6.0 * j);
    for b in [[1.0, 1.0, 2.0 / 3.0], [0.5, 3.0, 0.4]] {
        let (rod, shape) = straight_rod(b, 0.0);
        let c = cosserat::stability::critical_load(&rod, &shape, &fine()).unwrap();
        // The load factor multiplies q = 1: q_crit itself, whatever B2.
        let expected = 6.0 * j * (b[0] * b[2]).sqrt();
        let got = c.blocks[1].1.unwrap();
        assert!(
            (got - expected).abs() < 1e-6 * expected,
            "{got} vs {expected}"
        );
    }
}

/// The horizontal straight arm under its own weight alone: R̂ = L̂ =
/// λ_crit^{1/3} in units of (B2/q)^{1/3}, with λ_crit the closed form above.
#[test]
fn straight_arm_under_own_weight_reaches_the_closed_form() {
    let j = cosserat::references::bessel_first_zero(-1.0 / 6.0, 1.0, 3.0);
    let p = problem(1.0, 2.0 / 3.0, vec![]);
    let scene = cosserat::study::arm::ArmScene {
        weight: cosserat::study::arm::ArmWeight::Alone,
        max_curvature: None,
    };
    let d = p.design_in(&scene, &[]).unwrap();
    let lambda = 6.0 * j * (2.0f64 / 3.0).sqrt();
    assert!(
        (d.reach - lambda.cbrt()).abs() < 1e-6,
        "{} vs {}",
        d.reach,
        lambda.cbrt()
    );
}

/// Actuator limits (paper Sec. 5): with |κ⁰| bounded, the optimum respects
/// the bound with the constraint active, R* falls as the bound tightens,
/// and a bound looser than the unconstrained optimum's peak |κ⁰| gives the
/// unconstrained R*.
#[test]
fn actuator_limit_constrains_the_optimum() {
    let p = circular_fig5();
    let free = p.optimize(&SearchOptions::default()).unwrap();
    let length = |o: &cosserat::study::arm::ArmOptimum| o.scene.length(o.design.gamma);
    let peak = |o: &cosserat::study::arm::ArmOptimum| {
        o.intrinsic_curvature
            .iter()
            .fold(0.0f64, |a, k| a.max(k.abs()))
            / length(o)
    };
    let free_peak = peak(&free);
    let mut last = f64::INFINITY;
    for factor in [1.5, 0.8, 0.5, 0.25] {
        let limit = factor * free_peak;
        let scene = cosserat::study::arm::ArmScene {
            max_curvature: Some(limit),
            ..Default::default()
        };
        let (o, _, _) = p.search(
            &scene,
            &SearchOptions::default(),
            SearchProgress::default(),
            &|| false,
            &mut |_| {},
        );
        let o = o.unwrap();
        let r = o.design.reach;
        assert!(r <= last, "R* = {r} rose above {last} at the bound {limit}");
        if factor > 1.0 {
            assert!(
                (r - free.design.reach).abs() < 1e-9,
                "{r} vs {}",
                free.design.reach
            );
        } else {
            assert!(r < free.design.reach);
            assert!(peak(&o) <= limit * (1.0 + 1e-9), "{} > {limit}", peak(&o));
            assert!(
                peak(&o) >= limit * (1.0 - 1e-3),
                "inactive: {} < {limit}",
                peak(&o)
            );
        }
        last = r;
    }
}
