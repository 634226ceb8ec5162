//! The Cosserat level (shear and extension) against closed forms:
//! Timoshenko's shear-deformable cantilever in the small-deflection limit,
//! exact axial extension, Haringx's critical load of a shearable column
//! (second variation and BVP Jacobian), convergence to the Kirchhoff rod as
//! the shear and extension stiffnesses grow, and the level chosen from a
//! problem file.
mod support;
use support::methods::methods;

use std::f64::consts::PI;
use std::sync::Arc;

use cosserat::bvp::{solve, Equilibrium, Method, SolverOptions};
use cosserat::input::Problem;
use cosserat::model::{
    Clamp, DeadLoads, LinearElastic, ModelChoice, ModelLevel, Rod, Shearable, StoredEnergy,
};
use cosserat::references::CantileverTip;
use cosserat::stability::{analyze, StabilityOptions};
use nalgebra::Vector3;

/// L = 1, B = (b1, 1, b3), shear and extension stiffnesses S, paper clamp
/// (d1 = e1, d3 = e3), tip force f.
fn rod(shear: [f64; 3], force: Vector3<f64>) -> Rod {
    let bending: Arc<dyn StoredEnergy> =
        Arc::new(LinearElastic::uniform([10.0, 1.0, 10.0], [0.0; 3]).unwrap());
    Rod::new(
        1.0,
        Arc::new(Shearable::new(bending, Vector3::from(shear)).unwrap()),
        Clamp::paper(),
        DeadLoads {
            tip_force: force,
            ..Default::default()
        },
        None,
    )
    .unwrap()
}

fn solve_cosserat(rod: &Rod, method: Method) -> Equilibrium {
    let choice = ModelChoice::for_rod(rod);
    assert_eq!(choice.level, ModelLevel::Cosserat, "{}", choice.reason);
    let opts = SolverOptions {
        method,
        ..Default::default()
    };
    solve(rod, &choice, &opts).unwrap_or_else(|e| panic!("{method:?}: {e}"))
}

const METHODS: [Method; 3] = methods(8);

/// Timoshenko beam theory: a tip force F across the rod deflects the tip by
/// F L³/(3 B2) + F L/S1 (bending plus shear), up to O(F³).
#[test]
fn small_deflection_matches_timoshenko_beam() {
    let f = 1e-4;
    let s1 = 10.0;
    let r = rod([s1, 50.0, 100.0], Vector3::new(f, 0.0, 0.0));
    let reference = f / 3.0 + f / s1;
    for method in METHODS {
        let tip = solve_cosserat(&r, method).tip().position;
        let rel = (tip[0] - reference).abs() / reference;
        assert!(rel < 1e-6, "{method:?}: {} vs {reference}: {rel:e}", tip[0]);
    }
}

/// Pure tension stretches the rod uniformly: ν3 = 1 + F/S3 exactly.
#[test]
fn axial_tension_stretches_exactly() {
    let s3 = 4.0;
    let f = 2.0;
    let r = rod([3.0, 3.0, s3], Vector3::new(0.0, 0.0, f));
    for method in METHODS {
        let tip = solve_cosserat(&r, method).tip().position;
        let expected = 1.0 + f / s3;
        assert!(
            (tip[2] - expected).abs() < 1e-10 && tip[0].abs() < 1e-12,
            "{method:?}: {tip:?}"
        );
    }
}

/// Haringx (Philips Res. Rep. 3, 1948; Bažant & Cedolin, *Stability of
/// Structures*, Sec. 1.7): a clamped–free column with shear stiffness S1
/// buckles at P with P (1 + P/S1) = P_E = π² B/(4L²) when it is
/// inextensible. Found twice: the lowest Hessian eigenvalue and the
/// shooting Jacobian's determinant both change sign there.
#[test]
fn shearable_column_buckles_at_haringx_load() {
    let s1 = 2.0;
    let p_euler = PI * PI / 4.0;
    let haringx = 0.5 * s1 * ((1.0 + 4.0 * p_euler / s1).sqrt() - 1.0);
    let column = |p: f64| rod([s1, 1e3, 1e12], Vector3::new(0.0, 0.0, -p));
    let opts = StabilityOptions::new(40, 3, 2).unwrap();
    let lowest = |p: f64| {
        let r = column(p);
        let eq = solve_cosserat(&r, Method::Shooting);
        let st = analyze(&r, &eq, &SolverOptions::default(), &opts).unwrap();
        (st.blocks[0].eigenvalues[0], eq.jacobian.determinant())
    };
    // Secant on the lowest eigenvalue from two loads around the estimate.
    let (mut a, mut b) = (0.9 * haringx, 1.1 * haringx);
    let (mut fa, mut fb) = (lowest(a).0, lowest(b).0);
    assert!(fa > 0.0 && fb < 0.0, "bracket: {fa} {fb}");
    for _ in 0..30 {
        if fb == fa || (b - a).abs() < 1e-14 {
            break;
        }
        let c = b - fb * (b - a) / (fb - fa);
        (a, fa) = (b, fb);
        (b, fb) = (c, lowest(c).0);
    }
    assert!(
        (b - haringx).abs() / haringx < 1e-10,
        "Hessian: {b} vs Haringx {haringx}"
    );
    let (_, below) = lowest(haringx * (1.0 - 1e-6));
    let (_, above) = lowest(haringx * (1.0 + 1e-6));
    assert!(below * above < 0.0, "det F_x {below} {above}");
    // The Kirchhoff column (no shear) would buckle at P_E, well above.
    assert!(p_euler - haringx > 0.3);
}

/// As S grows the Cosserat tip converges to the Kirchhoff elastica
/// (Bisshopp–Drucker), at first order in 1/S.
#[test]
fn converges_to_kirchhoff_at_first_order() {
    let k = 3.0;
    let reference = CantileverTip::at(k);
    let stiffnesses = [1e3, 1e4, 1e5, 1e6];
    let errors: Vec<f64> = stiffnesses
        .iter()
        .map(|&s| {
            let r = rod([s, s, s], Vector3::new(k, 0.0, 0.0));
            let tip = solve_cosserat(&r, Method::Shooting).tip().position;
            ((tip[0] - reference.x).powi(2) + (tip[2] - reference.z).powi(2)).sqrt()
        })
        .collect();
    for (w, s) in errors.windows(2).zip(stiffnesses.windows(2)) {
        let order = (w[0] / w[1]).ln() / (s[1] / s[0]).ln();
        assert!((order - 1.0).abs() < 0.02, "order {order}: {errors:?}");
    }
    assert!(errors[3] < 1e-5, "{errors:?}");
}

/// Shear in the file selects the Cosserat level and says why; forcing a
/// lower level drops it and says so; forcing Cosserat without it, or a
/// non-positive stiffness, is an error naming the field.
#[test]
fn problem_file_chooses_the_cosserat_level() {
    let text = "[rod]\nlength = 1.0\n[energy]\nstiffness = [1.0, 1.0, 1.0]\n\
                shear = [100.0, 100.0, 300.0]\n[loads]\ntip_force = [1.0, 0.0, 0.0]\n";
    let p = Problem::from_str_with(text, &[]).unwrap();
    assert_eq!(p.model.level, ModelLevel::Cosserat);
    assert!(
        p.model.reason.contains("energy.shear"),
        "{}",
        p.model.reason
    );
    let forced = Problem::from_str_with(text, &["solver.model=\"kirchhoff\"".into()]).unwrap();
    assert_eq!(forced.model.level, ModelLevel::Kirchhoff);
    assert!(forced.rod.energy().shear_stiffness(0.0).is_none());
    assert!(
        forced.model.reason.contains("ignored"),
        "{}",
        forced.model.reason
    );
    let plain = text.replace("shear = [100.0, 100.0, 300.0]\n", "");
    let err = Problem::from_str_with(&plain, &["solver.model=\"cosserat\"".into()])
        .unwrap_err()
        .to_string();
    assert!(err.contains("solver.model"), "{err}");
    let err = Problem::from_str_with(text, &["energy.shear=[100.0, -1.0, 300.0]".into()])
        .unwrap_err()
        .to_string();
    assert!(err.contains("energy.shear[1]"), "{err}");
}

/// The Cosserat level through the continuation interface: `cosserat
/// continue` on a shearable clamped–free column finds its branch point at
/// Haringx's load (the BVP Jacobian's sign change, the Hessian eigenvalue
/// agreeing) and switches onto the buckled branch.
#[test]
fn continuation_finds_haringx_branch_point() {
    use cosserat::continuation::{continuation, SpecialKind};
    let text = "[rod]\nlength = 1.0\n[energy]\nstiffness = [2.0, 1.0, 1.0]\n\
                shear = [2.0, 1e3, 1e12]\n[loads]\ntip_force = [0.0, 0.0, -1.0]\n\
                [stability]\nelements = 40\norder = 3\n\
                [continuation]\nparameter = \"load_scale\"\nstart = 0.5\nbounds = [0.0, 3.0]\n\
                step = 0.2\nmax_step = 0.4\nelements = 40\norder = 3\neigenvalues = 2\n\
                tip_angle_limit = 60.0\n";
    let p = Problem::from_str_with(text, &[]).unwrap();
    assert_eq!(p.model.level, ModelLevel::Cosserat);
    let (family, opts) = p.continuation.clone().unwrap();
    let d = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let haringx = 0.5 * 2.0 * ((1.0 + 4.0 * PI * PI / 4.0 / 2.0).sqrt() - 1.0);
    let bp = d
        .special_points
        .iter()
        .find(|s| s.kind == SpecialKind::BranchPoint)
        .expect("a branch point");
    assert!(
        (bp.point.parameter - haringx).abs() < 1e-8 * haringx,
        "{} vs {haringx}",
        bp.point.parameter
    );
    assert!(!bp.children.is_empty(), "switched onto the buckled branch");
}
