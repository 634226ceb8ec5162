//! The general Cosserat energy W(s, κ, ν) against independent references:
//! a nonlinear axial law against its closed-form stretch, the general path
//! against the quadratic fast path, a bending–extension coupling against
//! the closed-form circle of a pure couple, the buckling load of a column
//! whose bending stiffness moves with the stretch against its closed form
//! (Haringx's when the coupling vanishes), the second-variation
//! coefficients against differences of the exact pointwise potential, and
//! the variational equations and tip Jacobian against differences.
mod support;
use support::methods::methods;

use std::f64::consts::PI;
use std::sync::Arc;

use cosserat::bvp::{solve, Equilibrium, Method, SolveError, SolverOptions};
use cosserat::equations::{KirchhoffEquations, RodEquations};
use cosserat::model::{
    Clamp, DeadLoads, Frame, Freedom, LinearElastic, ModelChoice, ModelLevel, Rod, Shearable,
    StoredEnergy, StrainAutoDiff, StrainDensity, StrainEnergy, StrainJet, TipSupport,
};
use cosserat::stability::{analyze, FormCoefficients, StabilityOptions};
use nalgebra::{Matrix3, Rotation3, Vector3};
use num_dual::DualNum;

const METHODS: [Method; 3] = methods(8);

/// ½ Σ B_i κ_i² + ½ S1 ν1² + ½ S2 ν2² + ½ EA e² + ¼ c e⁴ (e = ν3 − 1):
/// a stiffening axial law, φ'(e) = EA e + c e³.
#[derive(Debug)]
struct StiffeningAxial {
    b: [f64; 3],
    shear: [f64; 2],
    ea: f64,
    c: f64,
}

impl StrainDensity for StiffeningAxial {
    fn strain_density<D: DualNum<Primitive = f64> + Copy>(&self, _s: D, k: [D; 3], v: [D; 3]) -> D {
        let e = v[2] - 1.0;
        let bending = (0..3).map(|i| k[i] * k[i] * (0.5 * self.b[i])).sum::<D>();
        bending
            + v[0] * v[0] * (0.5 * self.shear[0])
            + v[1] * v[1] * (0.5 * self.shear[1])
            + e * e * (0.5 * self.ea)
            + e.powi(4) * (0.25 * self.c)
    }
    fn name(&self) -> &'static str {
        "stiffening axial"
    }
}

/// ½ Σ B_i κ_i² + ½ Σ S_i (ν − e3)_i² + c κ2 (ν3 − 1) + d κ1 ν2, and with
/// `quartic` and `taper` a quartic term in all six strains and an
/// s-dependent factor: every block of H and of its derivatives non-zero.
#[derive(Debug, Clone)]
struct Coupled {
    b: [f64; 3],
    shear: [f64; 3],
    c: f64,
    d: f64,
    quartic: f64,
    taper: f64,
}

impl Coupled {
    fn plain(b: [f64; 3], shear: [f64; 3], c: f64) -> Self {
        Coupled {
            b,
            shear,
            c,
            d: 0.0,
            quartic: 0.0,
            taper: 0.0,
        }
    }
}

impl StrainDensity for Coupled {
    fn strain_density<D: DualNum<Primitive = f64> + Copy>(&self, s: D, k: [D; 3], v: [D; 3]) -> D {
        let e = [v[0], v[1], v[2] - 1.0];
        let quad = (0..3)
            .map(|i| k[i] * k[i] * (0.5 * self.b[i]) + e[i] * e[i] * (0.5 * self.shear[i]))
            .sum::<D>();
        let norm2 = (0..3).map(|i| k[i] * k[i] + e[i] * e[i]).sum::<D>();
        (quad + k[1] * e[2] * self.c + k[0] * e[1] * self.d + norm2 * norm2 * (0.25 * self.quartic))
            * (s * self.taper + 1.0)
    }
    fn name(&self) -> &'static str {
        "coupled"
    }
}

/// ½ 3B κ1² + ½ (B + β e) κ2² + ½ B κ3² + ½ S (ν1² + ν2²) + ½ S3 e²: a
/// bending stiffness about d2 that moves with the stretch e = ν3 − 1 (the
/// stiffer d1 keeps the buckling mode simple).
#[derive(Debug)]
struct StretchBending {
    b: f64,
    beta: f64,
    shear: f64,
    s3: f64,
}

impl StrainDensity for StretchBending {
    fn strain_density<D: DualNum<Primitive = f64> + Copy>(&self, _s: D, k: [D; 3], v: [D; 3]) -> D {
        let e = v[2] - 1.0;
        k[0] * k[0] * (1.5 * self.b)
            + k[1] * k[1] * (e * self.beta + self.b) * 0.5
            + k[2] * k[2] * (0.5 * self.b)
            + (v[0] * v[0] + v[1] * v[1]) * (0.5 * self.shear)
            + e * e * (0.5 * self.s3)
    }
    fn name(&self) -> &'static str {
        "stretch bending"
    }
}

fn rod(energy: Arc<dyn StoredEnergy>, loads: DeadLoads) -> Rod {
    Rod::new(1.0, energy, Clamp::paper(), loads, None).unwrap()
}

fn tip_force(f: Vector3<f64>) -> DeadLoads {
    DeadLoads {
        tip_force: f,
        ..Default::default()
    }
}

fn solve_cosserat(rod: &Rod, method: Method) -> Result<Equilibrium, SolveError> {
    let choice = ModelChoice::for_rod(rod);
    assert_eq!(choice.level, ModelLevel::Cosserat, "{}", choice.reason);
    let opts = SolverOptions {
        method,
        ..Default::default()
    };
    solve(rod, &choice, &opts)
}

/// The real root of c e³ + EA e − P = 0 by Cardano's formula (one real
/// root for EA, c > 0).
fn cardano(c: f64, ea: f64, p: f64) -> f64 {
    let (pp, q) = (ea / c, -p / c);
    let disc = (q / 2.0).powi(2) + (pp / 3.0).powi(3);
    (-q / 2.0 + disc.sqrt()).cbrt() + (-q / 2.0 - disc.sqrt()).cbrt()
}

/// Pure tension P on a straight rod: W_ν3 = φ'(e) = P, so every point
/// stretches by the root e of c e³ + EA e = P and the tip moves to
/// L (1 + e), with no curvature and no shear.
#[test]
fn nonlinear_axial_law_stretches_as_its_closed_form() {
    let (ea, c, p) = (4.0, 30.0, 6.0);
    let e = cardano(c, ea, p);
    assert!((c * e.powi(3) + ea * e - p).abs() < 1e-13, "Cardano {e}");
    let energy = StrainAutoDiff::new(StiffeningAxial {
        b: [1.0, 1.0, 2.0],
        shear: [5.0, 5.0],
        ea,
        c,
    });
    let r = rod(Arc::new(energy), tip_force(Vector3::new(0.0, 0.0, p)));
    for method in METHODS {
        let eq = solve_cosserat(&r, method).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        let tip = eq.tip().position;
        assert!(
            (tip[2] - (1.0 + e)).abs() < 1e-10 && tip.xy().norm() < 1e-12,
            "{method:?}: {tip:?} vs 1 + {e}"
        );
        // The stretch is far from the linear law's P/EA: the law is used.
        assert!((e - p / ea).abs() > 0.5);
    }
}

/// The quadratic shear energy written as a density: the general path
/// (Newton for ν, 6 × 6 stiffness) against the fast path of `Shearable`
/// (ν = e3 + S⁻¹N), on a spatial load, for every method and for the
/// stability spectrum.
#[test]
// Many six-strain solves: seconds in release, minutes in a debug build.
#[cfg_attr(debug_assertions, ignore = "heavy in a debug build: run in release")]
fn general_path_reproduces_the_quadratic_shearable() {
    let (b, s) = ([3.0, 1.0, 2.0], [10.0, 6.0, 20.0]);
    let bending: Arc<dyn StoredEnergy> = Arc::new(LinearElastic::uniform(b, [0.0; 3]).unwrap());
    let fast: Arc<dyn StoredEnergy> = Arc::new(Shearable::new(bending, Vector3::from(s)).unwrap());
    let general: Arc<dyn StoredEnergy> = Arc::new(StrainAutoDiff::new(Coupled::plain(b, s, 0.0)));
    let loads = tip_force(Vector3::new(1.2, 0.7, -0.8));
    let (rf, rg) = (rod(fast, loads.clone()), rod(general, loads));
    let opts = StabilityOptions::new(30, 2, 3).unwrap();
    for method in METHODS {
        let ef = solve_cosserat(&rf, method).unwrap();
        let eg = solve_cosserat(&rg, method).unwrap();
        let gap = (ef.tip().position - eg.tip().position).norm();
        let kgap = (ef.samples[0].curvature - eg.samples[0].curvature).norm();
        assert!(
            gap < 1e-12 && kgap < 1e-11,
            "{method:?}: tip {gap:e}, κ(0) {kgap:e}"
        );
        let so = SolverOptions {
            method,
            ..Default::default()
        };
        let (sf, sg) = (
            analyze(&rf, &ef, &so, &opts).unwrap(),
            analyze(&rg, &eg, &so, &opts).unwrap(),
        );
        for (a, b) in sf.blocks[0]
            .eigenvalues
            .iter()
            .zip(&sg.blocks[0].eigenvalues)
        {
            assert!(
                (a - b).abs() < 1e-9 * a.abs().max(1.0),
                "{method:?}: λ {a} vs {b}"
            );
        }
    }
}

/// A tip couple C about d2 with the coupling c κ2 (ν3 − 1) and no force:
/// N = 0, so W_ν = 0 gives e = −c κ2/S3, and m2 = B2 κ2 + c e = C gives
/// κ2 = C/(B2 − c²/S3), constant. The rod is a circular arc of radius
/// 1/κ2 whose centreline is stretched by 1 + e: r(L) = (1 + e)
/// ((1 − cos κ2L)/κ2, 0, sin κ2L/κ2).
#[test]
fn coupled_energy_bends_a_circle_with_the_schur_stiffness() {
    let (b2, s3, c, couple) = (1.0, 10.0, 2.0, 0.5);
    let kappa = couple / (b2 - c * c / s3);
    let e = -c * kappa / s3;
    let expected = Vector3::new((1.0 - kappa.cos()) / kappa, 0.0, kappa.sin() / kappa) * (1.0 + e);
    let energy = StrainAutoDiff::new(Coupled::plain([2.0, b2, 3.0], [8.0, 8.0, s3], c));
    let loads = DeadLoads {
        tip_couple: Vector3::new(0.0, couple, 0.0),
        ..Default::default()
    };
    let r = rod(Arc::new(energy), loads);
    for method in METHODS {
        let eq = solve_cosserat(&r, method).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        let gap = (eq.tip().position - expected).norm();
        assert!(
            gap < 1e-10,
            "{method:?}: {:?} vs {expected:?}",
            eq.tip().position
        );
        for p in &eq.samples {
            assert!(
                (p.curvature[1] - kappa).abs() < 1e-10,
                "{method:?}: κ2 {p:?}"
            );
            assert!((p.moment[1] - couple).abs() < 1e-10, "{method:?}: m2 {p:?}");
        }
    }
}

/// A clamped–free column under thrust P with ½ (B + β e) κ2²: the
/// straight rod has e = −P/S3, and δ²V = ∫ B(e) ζ'² − (P(1 + e) + P²/S)
/// ζ² ds for a turn ζ about d2 (Cosserat second variation at κ = 0, see
/// stability/second_variation.rs) vanishes first for ζ = sin(πs/2L):
/// (B − βP/S3)(π/2L)² = P (1 − P/S3) + P²/S, a quadratic in P. With β = 0
/// and S3 → ∞ this is Haringx's P (1 + P/S) = P_E (Bažant & Cedolin,
/// *Stability of Structures*, Sec. 1.7). Found as the sign change of the
/// lowest eigenvalue, and of the shooting Jacobian's determinant.
#[test]
// Many six-strain solves: seconds in release, minutes in a debug build.
#[cfg_attr(debug_assertions, ignore = "heavy in a debug build: run in release")]
fn stretch_dependent_column_buckles_at_its_closed_form() {
    let (b, beta, shear, s3) = (1.0, 3.0, 4.0, 20.0);
    let q = PI * PI / 4.0;
    // a P² + b' P − B q = 0 with a = 1/S − 1/S3.
    let (qa, qb, qc) = (1.0 / shear - 1.0 / s3, 1.0 + beta * q / s3, -b * q);
    let critical = (-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
    let energy: Arc<dyn StoredEnergy> =
        Arc::new(StrainAutoDiff::new(StretchBending { b, beta, shear, s3 }));
    let column = |p: f64| rod(energy.clone(), tip_force(Vector3::new(0.0, 0.0, -p)));
    let opts = StabilityOptions::new(40, 3, 2).unwrap();
    let lowest = |p: f64| {
        let r = column(p);
        let eq = solve_cosserat(&r, Method::Shooting).unwrap();
        let st = analyze(&r, &eq, &SolverOptions::default(), &opts).unwrap();
        (st.blocks[0].eigenvalues[0], eq.jacobian.determinant())
    };
    let (mut a, mut bb) = (0.9 * critical, 1.1 * critical);
    let (mut fa, mut fb) = (lowest(a).0, lowest(bb).0);
    assert!(fa > 0.0 && fb < 0.0, "bracket: {fa} {fb}");
    for _ in 0..30 {
        if fb == fa || (bb - a).abs() < 1e-14 {
            break;
        }
        let c = bb - fb * (bb - a) / (fb - fa);
        (a, fa) = (bb, fb);
        (bb, fb) = (c, lowest(c).0);
    }
    assert!(
        (bb - critical).abs() / critical < 1e-9,
        "Hessian: {bb} vs closed form {critical}"
    );
    let (_, below) = lowest(critical * (1.0 - 1e-6));
    let (_, above) = lowest(critical * (1.0 + 1e-6));
    assert!(below * above < 0.0, "det F_x {below} {above}");
}

/// The right Jacobian of SO(3): d/dt exp(φ(t)) = exp(φ) (J_r(φ) φ')^.
fn right_jacobian(phi: &Vector3<f64>) -> Matrix3<f64> {
    let t = phi.norm();
    let x = phi.cross_matrix();
    if t < 1e-8 {
        return Matrix3::identity() - x * 0.5 + x * x / 6.0;
    }
    Matrix3::identity() - x * ((1.0 - t.cos()) / (t * t)) + x * x * ((t - t.sin()) / t.powi(3))
}

/// The pointwise second variation of the exact potential density
/// g(ε) = W(κ_ε, ν + εη) − N·(exp(εω̂)(ν + εη)), with κ_ε the curvature of
/// R exp(εω̂(s)): exp(−εω̂)κ + J_r(εω) εω'. Its second ε-derivative
/// (central differences), minimized over η, is the form of
/// `FormCoefficients::strained` at (ω, ω') — checked at the closed-form
/// minimizer (value, and stationarity in every direction of η).
#[test]
fn strained_form_is_the_minimized_second_variation() {
    let energy = StrainAutoDiff::new(Coupled {
        b: [2.0, 1.5, 3.0],
        shear: [9.0, 7.0, 12.0],
        c: 0.8,
        d: -0.6,
        quartic: 0.7,
        taper: 0.0,
    });
    let (s, kappa, nu) = (
        0.3,
        Vector3::new(0.4, -0.7, 0.2),
        Vector3::new(0.05, -0.08, 1.1),
    );
    let jet = energy.strain_jet(s, &kappa, &nu);
    let (m, n) = (jet.moment(), jet.force());
    let form = FormCoefficients::strained(&jet.hessian, &kappa, &m, &n, &nu).unwrap();
    let g = |eps: f64, w: &Vector3<f64>, dw: &Vector3<f64>, eta: &Vector3<f64>| {
        let phi = w * eps;
        let q = Rotation3::from_scaled_axis(phi).into_inner();
        let k = q.transpose() * kappa + right_jacobian(&phi) * (dw * eps);
        let v = nu + eta * eps;
        energy.strain_density(s, &k, &v) - n.dot(&(q * v))
    };
    let second = |w: &Vector3<f64>, dw: &Vector3<f64>, eta: &Vector3<f64>| {
        let h = 1e-4;
        (g(h, w, dw, eta) - 2.0 * g(0.0, w, dw, eta) + g(-h, w, dw, eta)) / (h * h)
    };
    let h = jet.hessian;
    let (kn, nn) = (
        h.fixed_view::<3, 3>(0, 3).into_owned(),
        h.fixed_view::<3, 3>(3, 3).into_owned(),
    );
    for (w, dw) in [
        (Vector3::new(0.3, -0.2, 0.5), Vector3::new(-0.4, 0.1, 0.6)),
        (Vector3::new(-0.7, 0.4, 0.1), Vector3::new(0.2, 0.9, -0.3)),
    ] {
        let a = dw + kappa.cross(&w);
        let p = n.cross(&w);
        let eta = nn.try_inverse().unwrap() * (p - kn.transpose() * a);
        let want = form.evaluate(&w, &dw);
        let got = second(&w, &dw, &eta);
        assert!(
            (got - want).abs() < 1e-6 * want.abs().max(1.0),
            "{got} vs {want}"
        );
        for j in 0..3 {
            let bump = Vector3::ith(j, 1e-3);
            let (up, down) = (
                second(&w, &dw, &(eta + bump)),
                second(&w, &dw, &(eta - bump)),
            );
            // Stationary: the difference is O(bump²) with no linear part.
            assert!((up - down).abs() < 1e-6, "η{j}: {up} {down}");
            assert!(up > got - 1e-6, "a minimum: η{j}");
        }
    }
}

/// The general path's variational equations and tip Jacobian against
/// central differences, with every block of H and of its derivatives
/// non-zero, an s-dependent energy, a distributed force and a held tip
/// position (reaction states).
#[test]
fn general_linearization_matches_differences() {
    let energy: Arc<dyn StoredEnergy> = Arc::new(StrainAutoDiff::new(Coupled {
        b: [2.0, 1.5, 3.0],
        shear: [9.0, 7.0, 12.0],
        c: 0.8,
        d: -0.6,
        quartic: 0.7,
        taper: 0.4,
    }));
    let loads = DeadLoads {
        tip_force: Vector3::new(0.5, -0.3, 0.8),
        tip_couple: Vector3::zeros(),
        distributed_force: Vector3::new(0.2, 0.4, -0.3),
        point_loads: Vec::new(),
    };
    let free = rod(energy.clone(), loads.clone());
    let support = TipSupport {
        position: Vector3::new(0.3, 0.1, 0.9),
        frame: Frame::identity(),
        translation: Freedom::Fixed,
        rotation: Freedom::Free,
    };
    let held = free.clone().with_support(Some(support)).unwrap();
    for r in [free, held] {
        let eq = KirchhoffEquations::general(r);
        let dim = eq.dim();
        let mut u = vec![0.3, -0.5, 0.2];
        u.resize(eq.unknowns(), 0.1);
        let mut y = vec![0.0; dim];
        eq.initial_state(&u, &mut y);
        // A frame off the clamp's: turn the directors a little.
        let turn = Rotation3::from_scaled_axis(Vector3::new(0.2, -0.1, 0.3));
        for i in 0..2 {
            let d = turn * Vector3::new(y[3 * i], y[3 * i + 1], y[3 * i + 2]);
            y[3 * i..3 * i + 3].copy_from_slice(d.as_slice());
        }
        let s = 0.4;
        let phi = nalgebra::DMatrix::<f64>::identity(dim, dim);
        let (mut dy, mut dphi) = (vec![0.0; dim], vec![0.0; dim * dim]);
        eq.rhs_linearized(s, &y, dim, phi.as_slice(), &mut dy, &mut dphi);
        let h = 1e-6;
        for j in 0..dim {
            let (mut yp, mut ym) = (y.clone(), y.clone());
            yp[j] += h;
            ym[j] -= h;
            let (mut fp, mut fm) = (vec![0.0; dim], vec![0.0; dim]);
            eq.rhs(s, &yp, &mut fp);
            eq.rhs(s, &ym, &mut fm);
            for i in 0..dim {
                let fd = (fp[i] - fm[i]) / (2.0 * h);
                let exact = dphi[j * dim + i];
                assert!(
                    (fd - exact).abs() < 1e-7 * exact.abs().max(1.0),
                    "∂f{i}/∂y{j}: {exact} vs {fd}"
                );
            }
        }
        let jac = eq.tip_residual_jacobian(&y);
        let k = eq.unknowns();
        for j in 0..dim {
            let (mut yp, mut ym) = (y.clone(), y.clone());
            yp[j] += h;
            ym[j] -= h;
            let (mut gp, mut gm) = (vec![0.0; k], vec![0.0; k]);
            eq.tip_residual(&yp, &mut gp);
            eq.tip_residual(&ym, &mut gm);
            for i in 0..k {
                let fd = (gp[i] - gm[i]) / (2.0 * h);
                assert!(
                    (fd - jac[(i, j)]).abs() < 1e-7 * fd.abs().max(1.0),
                    "∂g{i}/∂y{j}: {} vs {fd}",
                    jac[(i, j)]
                );
            }
        }
        assert!(eq.failure().is_none());
    }
}

/// A material that cannot carry the force: φ(e) = EA (e²/2 − 10 e⁴/12)
/// softens, so φ'(e) = EA (e − 10 e³/3) has the maximum 0.21 EA at
/// e = 1/√10 (W_νν = 0 there) and W_ν3 = P has no solution for a larger
/// tension (EA = 4, P = 3). The solve stops with the
/// named failure of the strain's Newton, never a value.
#[test]
// Many six-strain solves: seconds in release, minutes in a debug build.
#[cfg_attr(debug_assertions, ignore = "heavy in a debug build: run in release")]
fn a_force_the_material_cannot_carry_is_a_named_failure() {
    #[derive(Debug)]
    struct Softening;
    impl StrainDensity for Softening {
        fn strain_density<D: DualNum<Primitive = f64> + Copy>(
            &self,
            _s: D,
            k: [D; 3],
            v: [D; 3],
        ) -> D {
            let e = v[2] - 1.0;
            (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]) * 0.5
                + (v[0] * v[0] + v[1] * v[1]) * 5.0
                + (e * e * 0.5 - e.powi(4) * (10.0 / 12.0)) * 4.0
        }
        fn name(&self) -> &'static str {
            "softening"
        }
    }
    let r = rod(
        Arc::new(StrainAutoDiff::new(Softening)),
        tip_force(Vector3::new(0.0, 0.0, 3.0)),
    );
    for method in METHODS {
        let err = solve_cosserat(&r, method).expect_err("no strain carries the force");
        let text = err.to_string();
        assert!(
            matches!(err, SolveError::ShearStrain { .. }) || text.contains("shear-extension"),
            "{method:?}: {text}"
        );
    }
}

/// A hand-written six-strain energy whose coupling entry H_κ2ν3 is 2 %
/// off (everything else from automatic differentiation).
#[derive(Debug)]
struct WrongCoupling(StrainAutoDiff<Coupled>);

impl StrainEnergy for WrongCoupling {
    fn strain_density(&self, s: f64, kappa: &Vector3<f64>, nu: &Vector3<f64>) -> f64 {
        self.0.strain_density(s, kappa, nu)
    }
    fn strain_jet(&self, s: f64, kappa: &Vector3<f64>, nu: &Vector3<f64>) -> StrainJet {
        let mut jet = self.0.strain_jet(s, kappa, nu);
        jet.hessian[(1, 5)] *= 1.02;
        jet.hessian[(5, 1)] *= 1.02;
        jet
    }
    fn strain_hessian_derivative(
        &self,
        s: f64,
        kappa: &Vector3<f64>,
        nu: &Vector3<f64>,
        v: &nalgebra::Vector6<f64>,
    ) -> nalgebra::Matrix6<f64> {
        self.0.strain_hessian_derivative(s, kappa, nu, v)
    }
}

impl StoredEnergy for WrongCoupling {
    fn density(&self, s: f64, kappa: &Vector3<f64>) -> f64 {
        self.0.density(s, kappa)
    }
    fn moment(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        self.0.moment(s, kappa)
    }
    fn stiffness(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        self.0.stiffness(s, kappa)
    }
    fn moment_rate(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        self.0.moment_rate(s, kappa)
    }
    fn stiffness_rate(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        self.0.stiffness_rate(s, kappa)
    }
    fn stiffness_derivative(&self, s: f64, kappa: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
        self.0.stiffness_derivative(s, kappa, v)
    }
    fn admits_planar_bending(&self) -> bool {
        false
    }
    fn name(&self) -> &'static str {
        "wrong coupling"
    }
    fn strain_energy(&self) -> Option<&dyn StrainEnergy> {
        Some(self)
    }
}

/// The derivative checker covers the six strains: a correct coupled,
/// tapered energy passes every check; the same energy with the coupling
/// entry of H 2 % off fails on the 6 × 6 Hessian (and on the derivatives
/// differenced from it), and the solver refuses
/// it (an untrusted energy) instead of converging to a wrong tip.
#[test]
fn the_checker_covers_the_six_strains() {
    use cosserat::model::energy_check::{check, Property};
    let coupled = Coupled {
        b: [2.0, 1.5, 3.0],
        shear: [9.0, 7.0, 12.0],
        c: 0.8,
        d: -0.6,
        quartic: 0.7,
        taper: 0.4,
    };
    let good = StrainAutoDiff::new(coupled.clone());
    let report = check(&good, 1.0, 1.0);
    assert!(report.passed() && report.findings.is_empty(), "{report}");
    assert!(report.worst_passed < 1e-7, "{report}");
    let wrong = WrongCoupling(StrainAutoDiff::new(coupled));
    let report = check(&wrong, 1.0, 1.0);
    assert!(!report.passed(), "{report}");
    // The Hessian itself, and what is differenced from it (its
    // derivative along v and in s), are caught; nothing in κ alone.
    assert!(
        report
            .failures()
            .any(|f| f.property == Property::StrainHessian),
        "{report}"
    );
    assert!(
        report.failures().all(|f| matches!(
            f.property,
            Property::StrainHessian | Property::StrainThird | Property::StrainRates
        )),
        "{report}"
    );
    let r = rod(Arc::new(wrong), tip_force(Vector3::new(0.3, 0.0, 0.5)));
    let err = solve_cosserat(&r, Method::Shooting).expect_err("a wrong Hessian is refused");
    assert!(err.to_string().contains("6 × 6 Hessian"), "{err}");
}

/// The checker is not fooled by a stiff extension: with S3 = 10¹² the
/// density is near 10⁹ at the sampled stretches while its κ-rates are of
/// order one, so a difference of W in κ carries rounding ε W/h; the
/// correct quadratic energy must not fail (undecided is allowed where
/// rounding hides the rate). It failed before the rounding entered the
/// difference's error bound, and every debug-build solve of such a rod
/// (Haringx's column, tests/cosserat.rs) was refused.
#[test]
fn the_checker_is_not_fooled_by_a_stiff_extension() {
    use cosserat::model::energy_check::{check, typical_curvature};
    let bending = Arc::new(LinearElastic::uniform([1.0, 1.0, 0.8], [0.0; 3]).unwrap());
    let stiff: Arc<dyn StoredEnergy> =
        Arc::new(Shearable::new(bending, Vector3::new(2.0, 1e3, 1e12)).unwrap());
    // Haringx's column near its critical thrust (tests/cosserat.rs), with
    // the strains the solver's own check samples.
    let r = rod(stiff.clone(), tip_force(Vector3::new(0.0, 0.0, -1.9)));
    let report = check(stiff.as_ref(), 1.0, typical_curvature(&r));
    assert!(report.passed(), "{report}");
}

/// Continuation in the load on the general path: the column with a
/// stretch-dependent bending stiffness (as in
/// `stretch_dependent_column_buckles_at_its_closed_form`, written as a
/// formula in v) branches where the closed form says, located on the
/// continuation's own augmented system.
#[test]
// Many six-strain solves: seconds in release, minutes in a debug build.
#[cfg_attr(debug_assertions, ignore = "heavy in a debug build: run in release")]
fn continuation_finds_the_stretch_dependent_column_branch_point() {
    use cosserat::continuation::continuation;
    let text = r#"
[rod]
length = 1.0
[energy]
kind = "formula"
density = "0.5*(3*k1^2 + (1 + beta*(v3 - 1))*k2^2 + k3^2) + 0.5*S*(v1^2 + v2^2) + 0.5*S3*(v3 - 1)^2"
parameters = { beta = 3.0, S = 4.0, S3 = 20.0 }
stiffness = [1.0, 1.0, 1.0]
[clamp]
d1 = [1.0, 0.0, 0.0]
d3 = [0.0, 0.0, 1.0]
[loads]
tip_force = [0.0, 0.0, -1.0]
[continuation]
parameter = "load_scale"
start = 0.1
bounds = [0.0, 2.0]
step = 0.1
max_step = 0.5
elements = 16
eigenvalues = 2
measure = "tip_x"
"#;
    let (b, beta, shear, s3) = (1.0, 3.0, 4.0, 20.0);
    let q = PI * PI / 4.0;
    let (qa, qb, qc) = (1.0 / shear - 1.0 / s3, 1.0 + beta * q / s3, -b * q);
    let critical = (-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
    let problem =
        cosserat::input::Problem::from_str_with(text, &["continuation.switch_depth=0".into()])
            .unwrap();
    let (family, opts) = problem.continuation.clone().unwrap();
    let diagram = continuation(&family, &opts, &mut |_, _| true).unwrap();
    let found = diagram
        .special_points
        .iter()
        .map(|p| p.point.parameter)
        .min_by(|a, b| (a - critical).abs().total_cmp(&(b - critical).abs()))
        .expect("a special point");
    assert!(
        (found - critical).abs() < 1e-8 * critical,
        "{found} vs {critical}"
    );
}
