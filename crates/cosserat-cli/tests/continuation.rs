//! Continuation on the shipped problem files: Euler's branch point and the
//! elastica, singular Hessian and BVP Jacobian at every special point, the
//! Morse index across special points, a fold that natural-parameter
//! stepping cannot pass, branch switching onto new branches, and the
//! collocation discretization's order (the `continue` command itself, its
//! file and interrupted runs: continuation_cli.rs).
mod common;

use std::f64::consts::PI;
use std::path::Path;
use std::sync::OnceLock;

use cosserat::bvp::integrator::Tolerances;
use cosserat::bvp::{equations, newton::NonlinearSystem, ShootingSystem};
use cosserat::continuation::{continuation, Diagram, Family, SpecialKind};
use cosserat::input::Problem;
use cosserat::model::ModelLevel;
use cosserat::references::{ellip_e, ellip_f};
use cosserat::stability::Block;
use nalgebra::{DMatrix, DVector};

const FILES: [&str; 4] = [
    "euler_column",
    "planar_clamp_angle",
    "lateral_torsional_buckling",
    "guided_column",
];

use common::problems::{load as problem, shipped};

/// Each shipped diagram, computed once.
fn diagram(name: &str) -> &'static (Problem, Diagram) {
    static CACHE: OnceLock<Vec<(Problem, Diagram)>> = OnceLock::new();
    let all = CACHE.get_or_init(|| {
        FILES
            .iter()
            .map(|f| {
                let p = problem(f);
                let (family, opts) = p.continuation.clone().unwrap();
                let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
                (p, d)
            })
            .collect()
    });
    &all[FILES.iter().position(|f| *f == name).unwrap()]
}

fn family(p: &Problem) -> &Family {
    &p.continuation.as_ref().unwrap().0
}

#[test]
fn euler_branch_point_and_the_elastica() {
    let (_, d) = diagram("euler_column");
    let bp = d
        .special_points
        .iter()
        .find(|s| s.kind == SpecialKind::BranchPoint && s.block == Block::InPlane)
        .expect("the in-plane branch point");
    let euler = PI * PI / 4.0;
    assert!(
        (bp.point.parameter - euler).abs() <= 1e-8 * euler,
        "{}",
        bp.point.parameter
    );
    assert!(bp.symmetry_breaking);
    assert_eq!(bp.children.len(), 2, "both halves of the pitchfork");
    // The buckled elastica: F L²/B = K(k)², k = sin(α/2), α the tip angle
    // (Timoshenko & Gere, Sec. 2.7).
    for &child in &bp.children {
        let b = &d.branches[child];
        assert!(
            b.stop_reason.to_string().contains("tip angle"),
            "{}",
            b.stop_reason
        );
        for p in b.points.iter().skip(1) {
            let k = (p.tip_angle / 2.0).sin();
            let exact = ellip_f(PI / 2.0, k).powi(2);
            assert!(
                (p.parameter - exact).abs() <= 1e-8 * exact,
                "α = {}: {} vs {exact}",
                p.tip_angle,
                p.parameter
            );
        }
        // The branch ends at the tip angle asked, not beyond it (it
        // stopped at 170.27° before the last step was shortened).
        let end = b.points.last().unwrap().tip_angle;
        assert!(
            (end - 170f64.to_radians()).abs() <= 1e-9,
            "the branch ends at {}°, not 170°",
            end.to_degrees()
        );
    }
}

/// The smallest singular value of the 9-ODE shooting Jacobian at a point
/// of a family, relative to the largest (planar points are lifted to
/// κ(0) = (0, κ2(0), 0) and a planar tip reaction (R_x, R_z) to
/// R_x d1(0) + R_z d3(0)).
fn kirchhoff_singularity(f: &Family, x: &[f64], p: f64) -> f64 {
    let rod = f.rod_at(p).unwrap();
    let eq = equations(&rod, ModelLevel::Kirchhoff);
    let mut sys = ShootingSystem::new(eq.as_ref(), 1, Tolerances::default());
    let n = eq.unknowns();
    let u = if f.level() == ModelLevel::Planar {
        let mut u = vec![0.0, x[0], 0.0];
        if x.len() == 3 {
            let r = rod.clamp().director(0) * x[1] + rod.clamp().director(2) * x[2];
            u.extend_from_slice(r.as_slice());
        }
        u
    } else {
        x[..n].to_vec()
    };
    let (mut r, mut j) = (DVector::zeros(n), DMatrix::zeros(n, n));
    sys.evaluate(&u, &mut r, &mut j).unwrap();
    let sv = j.singular_values();
    sv.min() / sv.max()
}

/// The eigenvalue nearest zero of `block` at (x, p) on 480 elements of
/// order 2 (on the tip support's constraints): converged to ≈ 1e-7 also on
/// the looped post-buckled columns.
fn fine_eigenvalue(f: &Family, x: &[f64], p: f64, block: Block) -> f64 {
    use cosserat::stability::constrained::lowest_eigenpairs_constrained;
    use cosserat::stability::{coefficients, support_constraints, FiniteElements};
    let rod = f.rod_at(p).unwrap();
    let fe = FiniteElements::new(rod.length(), 480, 2);
    let mut points = fe.quadrature_points();
    points.push(rod.length());
    let mut samples = f.samples(x, p, &points).unwrap();
    let tip = samples.pop().unwrap();
    let c = coefficients(&rod, &samples);
    let constraints = support_constraints(&rod, &fe, block, &samples, &tip).unwrap();
    let (k, g) = (fe.stiffness(&c, block), fe.mass(block));
    let pairs = lowest_eigenpairs_constrained(&k, &g, &constraints, 4, None)
        .unwrap_or_else(|e| panic!("p = {p}, {block:?}: {e}"));
    pairs
        .values
        .into_iter()
        .min_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap()
}

#[test]
fn hessian_and_bvp_jacobian_are_singular_at_every_special_point() {
    for name in FILES {
        let (p, d) = diagram(name);
        assert!(!d.special_points.is_empty(), "{name}: no special points");
        for s in &d.special_points {
            // The Hessian on a mesh much finer than the tracking one, so that
            // what is checked is the second variation, not its mesh.
            let eigenvalue =
                fine_eigenvalue(family(p), &s.point.unknowns, s.point.parameter, s.block);
            assert!(
                eigenvalue.abs() <= 1e-6,
                "{name}: Hessian eigenvalue {eigenvalue} at {:?} p = {}",
                s.kind,
                s.point.parameter
            );
            let sing = kirchhoff_singularity(family(p), &s.point.unknowns, s.point.parameter);
            // Located by det F_x (to the integration tolerance) or, for
            // modes the model does not carry, by the finite-element
            // eigenvalue (to the mesh).
            assert!(
                sing <= 1e-5,
                "{name}: σ_min/σ_max = {sing} at {:?} p = {}",
                s.kind,
                s.point.parameter
            );
        }
    }
}

#[test]
fn morse_index_changes_by_the_number_of_special_points_crossed() {
    for name in FILES {
        let (_, d) = diagram(name);
        for (bi, b) in d.branches.iter().enumerate() {
            for i in 0..b.points.len().saturating_sub(1) {
                let crossed = d
                    .special_points
                    .iter()
                    .filter(|s| s.branch == bi && s.index == i)
                    .count();
                let jump = b.points[i]
                    .morse_index
                    .abs_diff(b.points[i + 1].morse_index);
                assert_eq!(
                    jump,
                    crossed,
                    "{name}: branch {bi} between points {i} and {}",
                    i + 1
                );
            }
        }
    }
}

/// Natural-parameter stepping (Newton at fixed clamp angle from the last
/// solution) cannot pass the fold that pseudo-arclength went round.
#[test]
fn natural_parameter_stepping_fails_at_a_fold() {
    let (p, d) = diagram("planar_clamp_angle");
    let fold = d
        .special_points
        .iter()
        .find(|s| s.kind == SpecialKind::Fold && s.branch == 0)
        .unwrap();
    let f = family(p);
    // Pseudo-arclength turned back at the fold: the parameter decreases
    // after it on the same branch.
    let b = &d.branches[0];
    let after = &b.points[fold.index + 1..];
    assert!(after
        .iter()
        .any(|q| q.parameter < fold.point.parameter - 0.1));
    // Natural stepping from just before the fold, in the same direction.
    let before = &b.points[fold.index];
    let direction = (fold.point.parameter - before.parameter).signum();
    let mut x = before.unknowns.clone();
    let mut angle = before.parameter;
    let mut reached_beyond = None;
    for _ in 0..40 {
        angle += direction * 0.01;
        let n = x.len();
        let (mut r, mut j) = (DVector::zeros(n), DMatrix::zeros(n, n));
        let mut ok = false;
        for _ in 0..30 {
            if f.residual(&x, angle, &mut r, &mut j).is_err() {
                break;
            }
            if r.amax() <= 1e-11 {
                ok = true;
                break;
            }
            let Some(dx) = j.clone().lu().solve(&(-&r)) else {
                break;
            };
            x.iter_mut().zip(dx.iter()).for_each(|(a, b)| *a += b);
        }
        if !ok {
            break;
        }
        if (angle - fold.point.parameter) * direction > 0.0 {
            reached_beyond = Some(f.tip(&x, angle).unwrap().position);
            break;
        }
    }
    // Either Newton fails past the fold, or it lands on a distant branch:
    // no solution continues the folded branch beyond the fold.
    if let Some(tip) = reached_beyond {
        let jump = (tip - fold.point.tip.position).norm();
        assert!(
            jump > 0.3,
            "natural stepping crossed the fold smoothly: jump {jump}"
        );
    }
}

#[test]
fn branch_switching_lands_on_new_branches() {
    for name in [
        "euler_column",
        "lateral_torsional_buckling",
        "guided_column",
    ] {
        let (_, d) = diagram(name);
        let switched: Vec<_> = d
            .special_points
            .iter()
            .filter(|s| !s.children.is_empty())
            .collect();
        assert!(!switched.is_empty(), "{name}: no branch switched");
        for s in switched {
            for &c in &s.children {
                let child = &d.branches[c];
                assert_eq!(
                    child.parent,
                    Some(d.special_points.iter().position(|x| x == s).unwrap())
                );
                // The child's points are off the parent branch: the old
                // branch is straight (Euler) or planar (lateral-torsional).
                let off = child.points.iter().skip(2).map(|p| match name {
                    "euler_column" => p.tip.position[0].abs(),
                    "guided_column" => (1.0 - p.tip.position[2]).abs(),
                    _ => p.tip.position[1].abs(),
                });
                assert!(
                    off.clone().all(|v| v > 1e-4),
                    "{name}: child {c} back on the parent"
                );
            }
        }
    }
}

/// The clamped–guided column: the branch point at 4π² and the buckled
/// branch as four clamped–free quarters, P L²/B = 16 K(k)² and
/// z(L)/L = 2E(k)/K(k) − 1 (Timoshenko & Gere, Sec. 2.7), k from P.
#[test]
fn guided_column_branch_point_and_its_elastica() {
    let (_, d) = diagram("guided_column");
    let bp = &d.special_points[0];
    let exact = 4.0 * PI * PI;
    assert!((bp.point.parameter - exact).abs() <= 1e-8 * exact);
    assert_eq!(bp.children.len(), 2);
    for &child in &bp.children {
        for p in d.branches[child].points.iter().skip(1) {
            // Bisection for k with 16 K(k)² = P.
            let (mut lo, mut hi) = (0.0, 1.0 - 1e-15);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if 16.0 * ellip_f(PI / 2.0, mid).powi(2) < p.parameter {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let k = 0.5 * (lo + hi);
            let z = 2.0 * ellip_e(PI / 2.0, k) / ellip_f(PI / 2.0, k) - 1.0;
            assert!(
                (p.tip.position[2] - z).abs() < 1e-8,
                "P = {}: z = {} vs {z}",
                p.parameter,
                p.tip.position[2]
            );
        }
    }
}

#[test]
fn lateral_torsional_branch_point_is_out_of_plane_and_above_timoshenko() {
    let (_, d) = diagram("lateral_torsional_buckling");
    let first = &d.special_points[0];
    assert_eq!(first.kind, SpecialKind::BranchPoint);
    assert!(first.symmetry_breaking);
    // The out-of-plane null mode: ω1, ω3 dominate ω2.
    let (oop, ip): (f64, f64) = first.null_mode.iter().fold((0.0, 0.0), |(a, b), w| {
        (a + w[0].abs() + w[2].abs(), b + w[1].abs())
    });
    assert!(oop > 100.0 * ip, "{oop} vs {ip}");
    // The straight-rod value is 2 j₋₁/₄,₁ √(B1B3)/L² = 0.40126; in-plane
    // pre-buckling bending raises it (B2 is only 10× B1 here).
    let timoshenko = 2.0 * cosserat::references::bessel_first_zero(-0.25, 1.0, 3.0) * 0.1;
    assert!(first.point.parameter > timoshenko && first.point.parameter < 1.3 * timoshenko);
}

/// Continuation on the collocation discretization (Gauss–Legendre on a
/// fixed mesh, node states as unknowns): Euler's branch point converges to
/// π²/4 at the method's order (a convergence study: orders 4 and 6 measured
/// from 4, 8, 16 intervals), and on 32 intervals of order 6 the buckled
/// branch follows the elastica F L²/B = K(sin α/2)².
#[test]
fn collocation_continuation_converges_at_the_method_order() {
    let euler = PI * PI / 4.0;
    let branch_point = |stages: usize, intervals: usize| {
        let p = Problem::from_path(
            Path::new(&shipped("euler_column")),
            &[
                "solver.method=\"collocation\"".into(),
                format!("solver.stages={stages}"),
                format!("continuation.intervals={intervals}"),
                "continuation.switch_depth=0".into(),
            ],
        )
        .unwrap();
        let (family, opts) = p.continuation.clone().unwrap();
        let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
        d.special_points[0].point.parameter - euler
    };
    for (stages, expected) in [(2, 4.0), (3, 6.0)] {
        let e: Vec<f64> = [4, 8, 16]
            .iter()
            .map(|&n| branch_point(stages, n))
            .collect();
        let order = (e[0] / e[1]).log2();
        assert!((order - expected).abs() < 0.1, "{stages} stages: {e:?}");
        if stages == 2 {
            let order = (e[1] / e[2]).log2();
            assert!((order - expected).abs() < 0.1, "{stages} stages: {e:?}");
        }
    }
    let p = problem("euler_column");
    let p = Problem::from_str_with(
        &p.text,
        &[
            "solver.method=\"collocation\"".into(),
            "continuation.intervals=32".into(),
        ],
    )
    .unwrap();
    let (family, opts) = p.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let bp = &d.special_points[0];
    assert!((bp.point.parameter - euler).abs() < 1e-10 * euler);
    let mut worst: f64 = 0.0;
    for &child in &bp.children {
        for p in d.branches[child].points.iter().skip(1) {
            let k = (p.tip_angle / 2.0).sin();
            let exact = ellip_f(PI / 2.0, k).powi(2);
            worst = worst.max((p.parameter - exact).abs() / exact);
        }
    }
    // Measured 2.4e-10 (32 intervals, order 6).
    assert!(worst < 1e-9, "{worst}");
}
