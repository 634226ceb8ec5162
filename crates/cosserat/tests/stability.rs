//! The second variation: against finite differences of the exact potential,
//! against the singularity of the shooting Jacobian (which settles the sign
//! of the paper's (45)), mesh convergence at the measured order, and the
//! classical critical loads of Timoshenko and Euler from the shipped
//! problem files.
mod support;

use std::f64::consts::PI;
use std::sync::Arc;

use cosserat::bvp::{solve, Equilibrium, SolverOptions, Strategy};
use cosserat::input::Problem;
use cosserat::model::{
    Clamp, DeadLoads, LinearElastic, ModelChoice, ModelLevel, Profile, QuarticStiffening, Rod,
    StoredEnergy,
};
use cosserat::stability::eigen::{count_below, dense_pencil, lowest_eigenpairs};
use cosserat::stability::{
    analyze, coefficients, critical_load, Block, CriticalLoad, FiniteElements, FormCoefficients,
    StabilityOptions,
};
use nalgebra::{Matrix3, Vector3};
use support::rods::{cantilever, tip_force, uniform};

/// The shipped problem `name` (problems/<name>.toml).
fn shipped(name: &str) -> Problem {
    let path = format!(
        "{}/problems/{name}.toml",
        concat!(env!("CARGO_MANIFEST_DIR"), "/../..")
    );
    Problem::from_path(std::path::Path::new(&path), &[]).unwrap()
}

/// The critical load of a problem's fixed shape with its stability options.
fn fixed_shape_critical_load(problem: &Problem) -> CriticalLoad {
    critical_load(
        &problem.rod,
        problem.shape.as_ref().unwrap(),
        &problem.stability,
    )
    .unwrap()
}

fn so3_exp(w: &Vector3<f64>) -> Matrix3<f64> {
    let t = w.norm();
    let k = w.cross_matrix();
    if t < 1e-12 {
        return Matrix3::identity() + k;
    }
    Matrix3::identity() + k * (t.sin() / t) + k * k * ((1.0 - t.cos()) / (t * t))
}

/// exp(−x̂) d exp(x̂) = J_r(x) dx (the right Jacobian of SO(3)).
fn right_jacobian(x: &Vector3<f64>) -> Matrix3<f64> {
    let t = x.norm();
    let k = x.cross_matrix();
    if t < 1e-8 {
        return Matrix3::identity() - k * 0.5 + k * k / 6.0;
    }
    Matrix3::identity() - k * ((1.0 - t.cos()) / (t * t)) + k * k * ((t - t.sin()) / (t * t * t))
}

/// The exact energy density of the perturbed frame R exp(ŵ) with
/// ω' = dw: W(s, exp(−ŵ)κ + J_r(w) dw) − N·exp(ŵ)e3.
fn density(
    e: &dyn StoredEnergy,
    s: f64,
    kappa: &Vector3<f64>,
    force: &Vector3<f64>,
    w: &Vector3<f64>,
    dw: &Vector3<f64>,
) -> f64 {
    let k = so3_exp(&(-w)) * kappa + right_jacobian(w) * dw;
    e.density(s, &k) - force.dot(&(so3_exp(w) * Vector3::z()))
}

fn energies() -> Vec<Arc<dyn StoredEnergy>> {
    let linear = LinearElastic::new(
        [
            Profile::Constant(1.3),
            Profile::Polynomial(vec![2.0, -0.5]),
            Profile::Constant(0.8),
        ],
        [
            Profile::Constant(0.4),
            Profile::Polynomial(vec![-0.3, 1.0]),
            Profile::Constant(0.9),
        ],
    )
    .unwrap();
    vec![
        Arc::new(linear.clone()),
        Arc::new(QuarticStiffening::new(linear, 0.7).unwrap()),
    ]
}

#[test]
fn form_is_the_second_derivative_of_the_exact_energy_density() {
    let (s, kappa, force) = (
        0.3,
        Vector3::new(0.7, -1.1, 0.4),
        Vector3::new(0.5, -0.8, 1.7),
    );
    let (w, dw) = (Vector3::new(0.3, -0.2, 0.5), Vector3::new(-0.6, 0.4, 0.25));
    for e in energies() {
        let c = FormCoefficients::at(
            &e.stiffness(s, &kappa),
            &kappa,
            &e.moment(s, &kappa),
            &force,
        );
        let f = |eps: f64| density(e.as_ref(), s, &kappa, &force, &(w * eps), &(dw * eps));
        let h = 1e-4;
        let fd = (f(h) - 2.0 * f(0.0) + f(-h)) / (h * h);
        let exact = c.evaluate(&w, &dw);
        assert!(
            (fd - exact).abs() <= 1e-6 * exact.abs().max(1.0),
            "{}: {fd} vs {exact}",
            e.name()
        );
    }
}

fn helix_scene(energy: Arc<dyn StoredEnergy>) -> Rod {
    Rod::new(
        1.5,
        energy,
        Clamp::paper(),
        DeadLoads {
            tip_force: Vector3::new(0.8, 0.3, -0.2),
            distributed_force: Vector3::new(0.4, 0.0, 0.1),
            ..Default::default()
        },
        None,
    )
    .unwrap()
}

fn solve_level(rod: &Rod, level: ModelLevel) -> Equilibrium {
    let choice = ModelChoice::forced(rod, level).unwrap();
    solve(rod, &choice, &SolverOptions::default()).unwrap()
}

/// K is the Hessian of the discrete potential V_h(v) = Σ_q w_q f_q(ω_q,
/// ω'_q) evaluated with the exact rotations, by central differences.
#[test]
fn assembled_matrix_is_the_hessian_of_the_discrete_potential() {
    for e in energies() {
        let rod = helix_scene(e.clone());
        let eq = solve_level(&rod, ModelLevel::Kirchhoff);
        let fe = FiniteElements::new(rod.length(), 6, 2);
        let samples = eq
            .resample(&rod, &SolverOptions::default(), &fe.quadrature_points())
            .unwrap();
        let k = fe.stiffness(&coefficients(&rod, &samples), Block::Full);
        let weights = fe.quadrature_weights();
        let potential = |v: &[f64]| -> f64 {
            fe.interpolate(Block::Full, v)
                .iter()
                .zip(&samples)
                .zip(&weights)
                .map(|(((w, dw), p), wq)| {
                    let frame = Matrix3::from_columns(&p.directors);
                    let force = frame.transpose() * p.force;
                    wq * density(e.as_ref(), p.s, &p.curvature, &force, w, dw)
                })
                .sum()
        };
        let n = fe.size(Block::Full);
        let unit = |f: &dyn Fn(usize) -> f64| {
            let v: Vec<f64> = (0..n).map(f).collect();
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.into_iter().map(|x| x / norm).collect::<Vec<f64>>()
        };
        let v1 = unit(&|i| ((i as f64) * 0.7).sin());
        let v2 = unit(&|i| ((i as f64) * 1.3 + 0.2).cos());
        let at = |h: f64, a: f64, b: f64| -> f64 {
            let v: Vec<f64> = v1
                .iter()
                .zip(&v2)
                .map(|(x, y)| h * (a * x + b * y))
                .collect();
            potential(&v)
        };
        // Central second differences, Richardson-extrapolated (error O(h⁴):
        // the quartic energy has a large fourth derivative).
        let mixed = |h: f64| {
            (at(h, 1.0, 1.0) - at(h, 1.0, -1.0) - at(h, -1.0, 1.0) + at(h, -1.0, -1.0))
                / (4.0 * h * h)
        };
        let diag = |h: f64| (at(h, 1.0, 0.0) - 2.0 * at(h, 0.0, 0.0) + at(h, -1.0, 0.0)) / (h * h);
        let h = 1e-3;
        let richardson = |d: &dyn Fn(f64) -> f64| (4.0 * d(h / 2.0) - d(h)) / 3.0;
        for (fd, exact) in [
            (richardson(&mixed), k.inner(&v1, &v2)),
            (richardson(&diag), k.inner(&v1, &v1)),
        ] {
            assert!(
                (fd - exact).abs() <= 1e-7 * exact.abs().max(1.0),
                "{}: {fd} vs {exact}",
                e.name()
            );
        }
    }
}

/// λ where f changes sign, by bisection in (lo, hi).
fn crossing(mut lo: f64, mut hi: f64, f: impl Fn(f64) -> f64) -> f64 {
    let f_lo = f(lo);
    assert!(f_lo * f(hi) < 0.0, "no crossing in ({lo}, {hi})");
    for _ in 0..45 {
        let mid = 0.5 * (lo + hi);
        if f(mid) * f_lo > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// A deep cantilever (B2 = 10 ≫ B1 = B3 = 1) under a vertical tip force:
/// planar and bent (κ2, M2 ≠ 0) until it buckles sideways. The shooting
/// Jacobian of the 9-ODE model is singular at the load where the
/// out-of-plane block of K has a zero eigenvalue; the printed (45), with
/// +χ²κ2, is singular elsewhere.
#[test]
fn zero_eigenvalue_is_where_the_shooting_jacobian_is_singular_on_a_bent_rod() {
    let rod = |load: f64| uniform(1.0, [1.0, 10.0, 1.0], tip_force(load, 0.0, 0.0));
    let det = |load: f64| {
        solve_level(&rod(load), ModelLevel::Kirchhoff)
            .jacobian
            .determinant()
    };
    let from_jacobian = crossing(3.0, 6.0, det);
    let fe = FiniteElements::new(1.0, 80, 2);
    let out_of_plane_count = |load: f64, printed: bool| {
        let r = rod(load);
        let eq = solve_level(&r, ModelLevel::Planar);
        let samples = eq
            .resample(&r, &SolverOptions::default(), &fe.quadrature_points())
            .unwrap();
        let mut c = coefficients(&r, &samples);
        if printed {
            // The printed (45) has +M2κ2χ² (χ = ω3) where the derivation
            // gives −M2κ2χ².
            for (ci, p) in c.iter_mut().zip(&samples) {
                ci.c[(2, 2)] += 2.0 * p.moment[1] * p.curvature[1];
            }
        }
        let (k, g) = (
            fe.stiffness(&c, Block::OutOfPlane),
            fe.mass(Block::OutOfPlane),
        );
        count_below(&k, &g, 0.0).below().expect("a decided inertia") as f64 - 0.5
    };
    let from_hessian = crossing(3.0, 6.0, |l| out_of_plane_count(l, false));
    let from_printed = crossing(3.0, 8.0, |l| out_of_plane_count(l, true));
    let rel = (from_hessian - from_jacobian).abs() / from_jacobian;
    assert!(rel <= 1e-7, "K: {from_hessian}, J: {from_jacobian}");
    let off = (from_printed - from_jacobian).abs() / from_jacobian;
    assert!(
        off >= 1e-2,
        "printed sign: {from_printed}, J: {from_jacobian}"
    );
    // Bending matters here: the straight-rod (Timoshenko) value is 4.0126.
    assert!((from_jacobian - 4.0126).abs() > 0.05, "{from_jacobian}");
}

/// Straight shapes: the Euler column (in-plane, planar shooting Jacobian)
/// and Timoshenko's cantilever (fixed shape, κ⁰ from the load).
#[test]
fn zero_eigenvalue_is_where_the_shooting_jacobian_is_singular_on_straight_rods() {
    // Euler: −λ e3 on a straight column, B2 = 1 (in plane), B1 = 2.
    let column = |load: f64| uniform(1.0, [2.0, 1.0, 1.0], tip_force(0.0, 0.0, -load));
    // The shooting Jacobian is as accurate as the integration; its
    // singularity is located to about the integrator's tolerance.
    let direct = SolverOptions {
        strategy: Strategy::Direct,
        integration: cosserat::bvp::integrator::Tolerances {
            rtol: 1e-13,
            atol: 1e-13,
            ..Default::default()
        },
        ..Default::default()
    };
    let det = |load: f64| {
        let r = column(load);
        let choice = ModelChoice::forced(&r, ModelLevel::Kirchhoff).unwrap();
        solve(&r, &choice, &direct).unwrap().jacobian.determinant()
    };
    let euler = PI * PI / 4.0;
    let in_plane = crossing(2.0, 3.0, det);
    let out_of_plane = crossing(4.5, 5.5, det);
    assert!((in_plane - euler).abs() <= 1e-8 * euler, "{in_plane}");
    assert!(
        (out_of_plane - 2.0 * euler).abs() <= 1e-8 * euler,
        "{out_of_plane}"
    );
    let problem = Problem::from_str_with(
        include_str!("../../../problems/euler_column.toml"),
        &["energy.stiffness=[2.0, 1.0, 1.0]".into()],
    )
    .unwrap();
    let c = fixed_shape_critical_load(&problem);
    let by_block = |b: Block| c.blocks.iter().find(|x| x.0 == b).unwrap().1.unwrap();
    assert!((by_block(Block::InPlane) - in_plane).abs() <= 1e-8 * euler);
    assert!((by_block(Block::OutOfPlane) - out_of_plane).abs() <= 1e-8 * euler);

    // Timoshenko: κ⁰2(s) = −λF(L − s)/B2 keeps the rod straight under λF e1.
    let ltb = |load: f64| {
        Rod::new(
            1.0,
            Arc::new(
                LinearElastic::new(
                    [1.0, 1.0, 1.0].map(Profile::Constant),
                    [
                        Profile::Constant(0.0),
                        Profile::Polynomial(vec![-load, load]),
                        Profile::Constant(0.0),
                    ],
                )
                .unwrap(),
            ),
            Clamp::paper(),
            DeadLoads {
                tip_force: Vector3::new(load, 0.0, 0.0),
                ..Default::default()
            },
            None,
        )
        .unwrap()
    };
    let det = |load: f64| {
        let r = ltb(load);
        let choice = ModelChoice::forced(&r, ModelLevel::Kirchhoff).unwrap();
        let eq = solve(&r, &choice, &direct).unwrap();
        assert!(eq.tip().position[0].abs() < 1e-9, "the rod stays straight");
        eq.jacobian.determinant()
    };
    let from_jacobian = crossing(3.5, 4.5, det);
    let problem = shipped("timoshenko_ltb");
    let c = fixed_shape_critical_load(&problem);
    let from_hessian = c.load_factor.unwrap();
    assert!(
        (from_hessian - from_jacobian).abs() <= 1e-7 * from_jacobian,
        "{from_hessian} vs {from_jacobian}"
    );
}

/// −(Bζ')' − Fζ = λζ, ζ(0) = 0, ζ'(L) = 0 on the straight column below
/// its critical load: λ_1 = B(π/2L)² − F exactly. Fit the order.
#[test]
fn eigenvalues_converge_at_order_two_p() {
    let force = 1.0;
    let rod = uniform(1.0, [1.0, 1.0, 1.0], tip_force(0.0, 0.0, -force));
    let eq = solve_level(&rod, ModelLevel::Planar);
    let exact = PI * PI / 4.0 - force;
    for (order, meshes) in [(1, [4, 8, 16, 32]), (2, [2, 4, 8, 16])] {
        let errors: Vec<f64> = meshes
            .iter()
            .map(|&elements| {
                let opts = StabilityOptions::new(elements, order, 1).unwrap();
                let st = analyze(&rod, &eq, &SolverOptions::default(), &opts).unwrap();
                (st.blocks[0].eigenvalues[0] - exact).abs()
            })
            .collect();
        let xs: Vec<f64> = meshes.iter().map(|&n| (n as f64).ln()).collect();
        let ys: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
        let (mx, my) = (xs.iter().sum::<f64>() / 4.0, ys.iter().sum::<f64>() / 4.0);
        let slope = -xs
            .iter()
            .zip(&ys)
            .map(|(x, y)| (x - mx) * (y - my))
            .sum::<f64>()
            / xs.iter().map(|x| (x - mx).powi(2)).sum::<f64>();
        let expected = 2.0 * order as f64;
        assert!(
            (slope - expected).abs() <= 0.3,
            "order {order}: slope {slope}, errors {errors:?}"
        );
    }
}

#[test]
fn timoshenko_constant_from_the_problem_file() {
    let problem = shipped("timoshenko_ltb");
    let c = fixed_shape_critical_load(&problem);
    // θ'' + (γ²/(B1B3)) (L − s)² θ = 0 with θ(0) = 0, θ'(L) = 0 is solved
    // by √x J₋₁/₄(γx²/2√(B1B3)), x = L − s: γL²/√(B1B3) = 2 j₋₁/₄,₁.
    let reference = 2.0 * cosserat::references::bessel_first_zero(-0.25, 1.0, 3.0);
    let gamma = c.gamma.unwrap();
    assert!(
        (gamma - reference).abs() <= 1e-6 * reference,
        "{gamma} vs {reference}"
    );
    assert!((reference - 4.0126).abs() < 1e-4);
    // Lateral-torsional, not in-plane: the in-plane block never buckles.
    assert!(c
        .blocks
        .iter()
        .any(|b| b.0 == Block::InPlane && b.1.is_none()));
}

#[test]
fn euler_load_from_the_problem_file() {
    let problem = shipped("euler_column");
    let c = fixed_shape_critical_load(&problem);
    let gamma = c.gamma.unwrap();
    assert!(
        (gamma - PI * PI / 4.0).abs() <= 1e-8 * PI * PI / 4.0,
        "{gamma}"
    );
}

#[test]
fn banded_lanczos_agrees_with_the_dense_solver() {
    let rod = cantilever(3.0);
    let eq = solve_level(&rod, ModelLevel::Planar);
    let fe = FiniteElements::new(1.0, 200, 2);
    let samples = eq
        .resample(&rod, &SolverOptions::default(), &fe.quadrature_points())
        .unwrap();
    let c = coefficients(&rod, &samples);
    for block in [Block::InPlane, Block::OutOfPlane] {
        let (k, g) = (fe.stiffness(&c, block), fe.mass(block));
        assert!(k.size() > cosserat::stability::eigen::DENSE_LIMIT);
        let banded = lowest_eigenpairs(&k, &g, 4).unwrap();
        let dense = dense_pencil(&k.to_dense(), &g.to_dense(), 4).unwrap();
        for (a, b) in banded.values.iter().zip(&dense.values) {
            assert!(
                (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                "{block:?}: {a} vs {b}"
            );
        }
    }
}

/// Beyond the Euler load the straight column is an equilibrium with Morse
/// index 2 (one in-plane and one out-of-plane mode, B1 = B2); below it is
/// stable.
#[test]
fn morse_index_counts_the_unstable_modes() {
    let direct = SolverOptions {
        strategy: Strategy::Direct,
        ..Default::default()
    };
    for (load, morse) in [(2.0, 0), (3.0, 2)] {
        let rod = uniform(1.0, [1.0, 1.0, 1.0], tip_force(0.0, 0.0, -load));
        let choice = ModelChoice::for_rod(&rod);
        let eq = solve(&rod, &choice, &direct).unwrap();
        let st = analyze(&rod, &eq, &direct, &StabilityOptions::default()).unwrap();
        assert_eq!(st.morse_index, morse, "load {load}");
        assert_eq!(st.stable, morse == 0);
        let lowest = st.blocks[0].eigenvalues[0];
        assert!((lowest - (PI * PI / 4.0 - load)).abs() < 1e-8, "{lowest}");
    }
}
