//! Checks of a stored energy's derivatives: what catches a wrong
//! hand-written moment, stiffness, s-rate or third derivative before it
//! can give an answer (a Hessian 2 % off still converges — to a wrong
//! tip).
//!
//! At sampled arc lengths and strains each derivative is compared with a
//! central difference of the quantity below it (M with W, H with M, the
//! s-rates with M and H in s, ∂(Hv)/∂κ with H v), of fourth order and
//! Richardson-checked: D(h) and D(h/2) differ by about the truncation
//! error of D(h) (15/16 of it), which bounds the reference's own error. A
//! derivative passes when it is within 100 such bounds plus 1e-9 of the
//! quantity's scale; where the two differences disagree by more than 1e-4
//! of the scale the energy is not smooth there (a kink of `abs`, `min`,
//! `max` or a table's knot) and the sample is *undecided*, not passed.
//! Also checked: H symmetric, H positive definite (where it is not, the
//! material itself is unstable there — a material instability, not a
//! structural one), and the planar claim (M1 = M3 = 0 on κ1 = κ3 = 0).
//!
//! An energy in all six strains ([`StoredEnergy::strain_energy`]) has the
//! same checks in z = (κ, ν) at strains ν = e3 + 0.05 d around the
//! unstrained state: ∇W = (m, N) against W, each column of the 6 × 6
//! Hessian (the coupling blocks H_κν included) against ∇W, ∂(H v)/∂z
//! against H v, the s-rates, H symmetric and positive definite (strong
//! ellipticity: no material instability in shear and extension either).
//!
//! Frame indifference needs no check: W is a function of the body strains
//! κ = axial(RᵀR') and ν = Rᵀr', which a superposed rigid motion
//! (R, r) → (QR, Qr + c) leaves unchanged, so every energy the trait can
//! express is objective by construction (Antman, *Nonlinear Problems of
//! Elasticity*, 2nd ed., §8.2). What an energy can claim wrongly are its
//! material symmetries, and those are checked: the planar claim and the
//! evenness per strain component (`StoredEnergy::even_components`).

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use super::{stack, Rod, StoredEnergy, StrainEnergy};

/// A typical curvature of a problem (1/m), the scale of the strains the
/// checks sample: 1/L, or the curvature the loads' moment scale gives the
/// softest section if larger.
pub fn typical_curvature(rod: &Rod) -> f64 {
    let zero = Vector3::zeros();
    let softest = (0..=8)
        .map(|i| {
            let s = rod.length() * f64::from(i) / 8.0;
            rod.energy()
                .stiffness(s, &zero)
                .symmetric_eigenvalues()
                .min()
        })
        .fold(f64::INFINITY, f64::min);
    let loaded = rod.loads().moment_scale(rod.length()) / softest;
    (1.0 / rod.length()).max(if loaded.is_finite() { loaded } else { 0.0 })
}

/// Which property a finding is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Property {
    /// M = ∂W/∂κ.
    Moment,
    /// H = ∂M/∂κ.
    Stiffness,
    /// ∂sM at fixed κ.
    MomentRate,
    /// ∂sH at fixed κ.
    StiffnessRate,
    /// ∂(H v)/∂κ.
    StiffnessDerivative,
    /// H = Hᵀ.
    Symmetry,
    /// H positive definite (material stability).
    Convexity,
    /// M1 = M3 = 0 on κ1 = κ3 = 0, claimed by `admits_planar_bending`.
    PlanarBending,
    /// W even in a strain component about κ⁰, claimed by `even_components`.
    Evenness,
    /// ∇W = (W_κ, W_ν) of an energy in six strains.
    StrainGradient,
    /// The 6 × 6 Hessian, coupling blocks included.
    StrainHessian,
    /// ∂(H v)/∂z in six strains.
    StrainThird,
    /// ∂s∇W and ∂sH in six strains.
    StrainRates,
    /// The 6 × 6 Hessian symmetric.
    StrainSymmetry,
    /// The 6 × 6 Hessian positive definite (material stability).
    StrainConvexity,
}

impl Property {
    /// A name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Property::Moment => "moment M = ∂W/∂κ",
            Property::Stiffness => "stiffness H = ∂M/∂κ",
            Property::MomentRate => "moment rate ∂sM",
            Property::StiffnessRate => "stiffness rate ∂sH",
            Property::StiffnessDerivative => "third derivative ∂(Hv)/∂κ",
            Property::Symmetry => "symmetry of H",
            Property::Convexity => "positive definite H",
            Property::PlanarBending => "planar bending (M1 = M3 = 0 on κ1 = κ3 = 0)",
            Property::Evenness => "claimed evenness W(κ⁰ + u) = W(κ⁰ + R_i u)",
            Property::StrainGradient => "gradient (W_κ, W_ν) in six strains",
            Property::StrainHessian => "6 × 6 Hessian in (κ, ν)",
            Property::StrainThird => "third derivative ∂(Hv)/∂(κ, ν)",
            Property::StrainRates => "s-rates of ∇W and H in six strains",
            Property::StrainSymmetry => "symmetry of the 6 × 6 Hessian",
            Property::StrainConvexity => "positive definite 6 × 6 Hessian",
        }
    }
}

/// One failed or undecided sample.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    /// What was checked.
    pub property: Property,
    /// Where: arc length.
    pub s: f64,
    /// Where: strains κ.
    pub kappa: Vector3<f64>,
    /// Where: strains ν (e3 for the checks in κ alone).
    pub nu: Vector3<f64>,
    /// The largest difference from the reference, relative to the scale.
    pub error: f64,
    /// Whether the sample could not be decided (a non-smooth energy).
    pub undecided: bool,
}

/// The result of [`check`]: every sample that failed or could not be
/// decided; passed when there is no failure.
#[derive(Debug, Clone, PartialEq)]
pub struct EnergyCheck {
    /// The number of (s, κ) samples.
    pub samples: usize,
    /// Failures and undecided samples.
    pub findings: Vec<Finding>,
    /// The largest relative difference of a passed derivative.
    pub worst_passed: f64,
}

impl EnergyCheck {
    /// No failure (undecided samples allowed, and reported).
    pub fn passed(&self) -> bool {
        self.findings.iter().all(|f| f.undecided)
    }

    /// The failures.
    pub fn failures(&self) -> impl Iterator<Item = &Finding> {
        self.findings.iter().filter(|f| !f.undecided)
    }
}

impl std::fmt::Display for EnergyCheck {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let failed = self.failures().count();
        let undecided = self.findings.len() - failed;
        writeln!(
            f,
            "{} samples: {failed} failed, {undecided} undecided; worst passed derivative {:.1e} \
             (relative)",
            self.samples, self.worst_passed
        )?;
        for x in &self.findings {
            writeln!(
                f,
                "  {} {} at s = {:.6}, κ = ({:.4e}, {:.4e}, {:.4e}){}: off by {:.2e} relative",
                if x.undecided { "undecided" } else { "FAILED" },
                x.property.name(),
                x.s,
                x.kappa[0],
                x.kappa[1],
                x.kappa[2],
                if x.nu == Vector3::z() {
                    String::new()
                } else {
                    format!(", ν = ({:.4e}, {:.4e}, {:.4e})", x.nu[0], x.nu[1], x.nu[2])
                },
                x.error
            )?;
        }
        Ok(())
    }
}

/// The strain directions sampled around κ⁰(s), scaled by `scale`.
const DIRECTIONS: [[f64; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [0.3, -0.7, 0.2],
    [-0.9, 0.4, 0.6],
    [0.05, 1.1, -0.35],
    [0.0, -0.8, 0.0],
];

/// Checks `energy` on [0, `length`] at 9 arc lengths (off the ends and
/// the midpoint, where tables put knots) × 5 strains κ⁰(s) + `scale` d,
/// `scale` a typical curvature (1/m) of the problem.
pub fn check(energy: &dyn StoredEnergy, length: f64, scale: f64) -> EnergyCheck {
    let mut samples = Vec::new();
    for j in 0..9 {
        let s = length * (f64::from(j) + 0.37) / 9.0;
        let kappa0 = intrinsic(energy, s);
        for d in DIRECTIONS {
            samples.push((s, kappa0 + scale * Vector3::from(d)));
        }
    }
    check_at(energy, length, scale, &samples)
}

/// Checks `energy` at given (s, κ) samples, e.g. along a solution.
pub fn check_at(
    energy: &dyn StoredEnergy,
    length: f64,
    scale: f64,
    samples: &[(f64, Vector3<f64>)],
) -> EnergyCheck {
    let mut report = EnergyCheck {
        samples: samples.len(),
        findings: Vec::new(),
        worst_passed: 0.0,
    };
    for (n, &(s, kappa)) in samples.iter().enumerate() {
        let hk = 1e-3 * scale.max(kappa.amax()).max(1e-300);
        Sample {
            energy,
            s,
            kappa,
            hk,
            hs: 1e-3 * length,
        }
        .check(&mut report);
        if let Some(strain) = energy.strain_energy() {
            let nu = Vector3::z() + 0.05 * Vector3::from(DIRECTIONS[(n + 2) % 5]);
            StrainSample {
                energy: strain,
                s,
                kappa,
                nu,
                steps: Vector6::new(hk, hk, hk, 5e-5, 5e-5, 5e-5),
                hs: 1e-3 * length,
            }
            .check(&mut report);
        }
    }
    report
}

fn intrinsic(energy: &dyn StoredEnergy, s: f64) -> Vector3<f64> {
    super::intrinsic_profiles(energy)
        .map_or_else(Vector3::zeros, |p| Vector3::from_fn(|i, _| p[i].value(s)))
}

/// One (s, κ) and its difference steps in κ and in s.
struct Sample<'e> {
    energy: &'e dyn StoredEnergy,
    s: f64,
    kappa: Vector3<f64>,
    hk: f64,
    hs: f64,
}

/// The fourth-order central difference of f at 0 with step h, and the
/// bound of its error: the Richardson gap |D(h) − D(h/2)| (truncation)
/// plus the rounding of D(h/2), 16 ε max|f| / h (each of the four values
/// rounded within 4 ε of its size, the weights 18/12 over h/2). The
/// rounding term matters where a component's values are large against
/// its rate: a stiff extension S3 = 10¹² puts W near 10⁹ while W's
/// κ-rate is of order one, and D(h) and D(h/2) of such a W can agree by
/// chance while both are off by ε W/h — the scaling must not fool the
/// check, so that sample is undecided rather than failed.
fn derivative<const N: usize>(f: impl Fn(f64) -> [f64; N], h: f64) -> ([f64; N], [f64; N]) {
    let d = |h: f64| {
        let (a, b, c, e) = (f(-2.0 * h), f(-h), f(h), f(2.0 * h));
        let size: [f64; N] =
            std::array::from_fn(|i| a[i].abs().max(b[i].abs()).max(c[i].abs()).max(e[i].abs()));
        let value = std::array::from_fn(|i| (a[i] - 8.0 * b[i] + 8.0 * c[i] - e[i]) / (12.0 * h));
        (value, size)
    };
    let (coarse, _): ([f64; N], [f64; N]) = d(h);
    let (fine, size): ([f64; N], [f64; N]) = d(0.5 * h);
    let rounding = 16.0 * f64::EPSILON / h;
    (
        fine,
        std::array::from_fn(|i| (coarse[i] - fine[i]).abs() + rounding * size[i]),
    )
}

/// [`derivative`] in s, where profiles may have knots (tables, the ends
/// of the rod): the one-sided second-order differences
/// (−3f(0) + 4f(±h) − f(±2h))/(±2h) differ by O(h²) on a smooth profile,
/// so halving h divides their gap by four; at a knot the gap is the jump
/// of the rate and stays. There the rate is one-sided and the bound is set
/// to the gap (the sample is undecided unless the knot is negligible).
fn derivative_in_s<const N: usize>(f: impl Fn(f64) -> [f64; N], h: f64) -> ([f64; N], [f64; N]) {
    let (central, mut bound) = derivative(&f, h);
    let gap = |h: f64| -> [f64; N] {
        let (f0, fp, fp2, fm, fm2) = (f(0.0), f(h), f(2.0 * h), f(-h), f(-2.0 * h));
        std::array::from_fn(|i| {
            let ahead = (-3.0 * f0[i] + 4.0 * fp[i] - fp2[i]) / (2.0 * h);
            let behind = (3.0 * f0[i] - 4.0 * fm[i] + fm2[i]) / (2.0 * h);
            (ahead - behind).abs()
        })
    };
    let (coarse, fine) = (gap(h), gap(0.5 * h));
    for i in 0..N {
        if fine[i] > 0.5 * coarse[i] && fine[i] > 1e3 * bound[i] {
            bound[i] = bound[i].max(fine[i]);
        }
    }
    (central, bound)
}

/// An exact derivative against its difference `reference` with error
/// `bound`: passed (None, the worst passed difference kept), or (relative
/// error, undecided) — undecided where the bound exceeds 1e-4 of the
/// scale (a kink), failed where off by more than 100 bounds + 1e-9 scale.
fn judge(
    report: &mut EnergyCheck,
    exact: &[f64],
    reference: &[f64],
    bound: &[f64],
    scale: f64,
) -> Option<(f64, bool)> {
    let scale = scale.max(f64::MIN_POSITIVE);
    let mut error: f64 = 0.0;
    let mut undecided = false;
    for ((a, b), e) in exact.iter().zip(reference).zip(bound) {
        let off = (a - b).abs();
        if *e > 1e-4 * scale {
            undecided = true;
        } else if off > 100.0 * e + 1e-9 * scale {
            error = error.max(off / scale);
        } else {
            report.worst_passed = report.worst_passed.max(off / scale);
        }
    }
    (undecided || error > 0.0).then_some((error, undecided && error == 0.0))
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

fn flat(m: &Matrix3<f64>) -> [f64; 9] {
    std::array::from_fn(|i| m[(i % 3, i / 3)])
}

impl Sample<'_> {
    fn check(&self, report: &mut EnergyCheck) {
        let (e, s, k) = (self.energy, self.s, self.kappa);
        let m = e.moment(s, &k);
        let h = e.stiffness(s, &k);
        let m_scale = m.amax() + h.amax() * self.hk * 1e3;
        let h_scale = h.amax();
        for i in 0..3 {
            let (fd, bound) = derivative(|t| [e.density(s, &self.shifted(i, t))], self.hk);
            self.compare(report, Property::Moment, &[m[i]], &fd, &bound, m_scale);
            let (fd, bound) = derivative(|t| e.moment(s, &self.shifted(i, t)).into(), self.hk);
            let column: [f64; 3] = h.column(i).into();
            self.compare(report, Property::Stiffness, &column, &fd, &bound, h_scale);
            let v = Vector3::from(DIRECTIONS[(i + 1) % 5]);
            let (fd, bound) = derivative(
                |t| (e.stiffness(s, &self.shifted(i, t)) * v).into(),
                self.hk,
            );
            let third: [f64; 3] = e.stiffness_derivative(s, &k, &v).column(i).into();
            let third_scale = max_abs(&third) + h_scale / (1e3 * self.hk);
            self.compare(
                report,
                Property::StiffnessDerivative,
                &third,
                &fd,
                &bound,
                third_scale,
            );
        }
        // Rates are compared on the scale of the quantity over the length.
        let per_length = 1.0 / (1e3 * self.hs);
        let (fd, bound) = derivative_in_s(|t| e.moment(s + t, &k).into(), self.hs);
        let rate: [f64; 3] = e.moment_rate(s, &k).into();
        let scale = max_abs(&rate) + m_scale * per_length;
        self.compare(report, Property::MomentRate, &rate, &fd, &bound, scale);
        let (fd, bound) = derivative_in_s(|t| flat(&e.stiffness(s + t, &k)), self.hs);
        let rate = flat(&e.stiffness_rate(s, &k));
        let scale = max_abs(&rate) + h_scale * per_length;
        self.compare(report, Property::StiffnessRate, &rate, &fd, &bound, scale);
        self.structure(report, &h);
    }

    fn shifted(&self, i: usize, t: f64) -> Vector3<f64> {
        let mut k = self.kappa;
        k[i] += t;
        k
    }

    fn compare(
        &self,
        report: &mut EnergyCheck,
        property: Property,
        exact: &[f64],
        reference: &[f64],
        bound: &[f64],
        scale: f64,
    ) {
        if let Some((error, undecided)) = judge(report, exact, reference, bound, scale) {
            report.findings.push(Finding {
                property,
                s: self.s,
                kappa: self.kappa,
                nu: Vector3::z(),
                error,
                undecided,
            });
        }
    }

    fn structure(&self, report: &mut EnergyCheck, h: &Matrix3<f64>) {
        let mut finding = |property, error| {
            report.findings.push(Finding {
                property,
                s: self.s,
                kappa: self.kappa,
                nu: Vector3::z(),
                error,
                undecided: false,
            });
        };
        let asymmetry = (h - h.transpose()).amax() / h.amax().max(f64::MIN_POSITIVE);
        if asymmetry > 1e-12 {
            finding(Property::Symmetry, asymmetry);
        }
        if h.cholesky().is_none() {
            finding(Property::Convexity, h.symmetric_eigenvalues().min());
        }
        let kappa0 = intrinsic(self.energy, self.s);
        let w = self.energy.density(self.s, &self.kappa);
        for (i, even) in self.energy.even_components().into_iter().enumerate() {
            let mut mirrored = self.kappa;
            mirrored[i] = 2.0 * kappa0[i] - self.kappa[i];
            let off = (self.energy.density(self.s, &mirrored) - w).abs()
                / w.abs().max(h.amax() * self.hk * self.hk * 1e6);
            if even && off > 1e-12 {
                finding(Property::Evenness, off);
            }
        }
        if self.energy.admits_planar_bending() {
            let k = Vector3::new(0.0, self.kappa[1], 0.0);
            let m = self.energy.moment(self.s, &k);
            let off = m[0].abs().max(m[2].abs()) / m.amax().max(h.amax() * self.hk);
            if off > 1e-12 {
                finding(Property::PlanarBending, off);
            }
        }
    }
}

/// One (s, κ, ν) of an energy in six strains, its steps in z = (κ, ν)
/// and in s.
struct StrainSample<'e> {
    energy: &'e dyn StrainEnergy,
    s: f64,
    kappa: Vector3<f64>,
    nu: Vector3<f64>,
    steps: Vector6<f64>,
    hs: f64,
}

fn flat6(m: &Matrix6<f64>) -> [f64; 36] {
    std::array::from_fn(|i| m[(i % 6, i / 6)])
}

impl StrainSample<'_> {
    /// z + t e_j split back into (κ, ν).
    fn shifted(&self, j: usize, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let mut z = stack(&self.kappa, &self.nu);
        z[j] += t;
        (
            z.fixed_rows::<3>(0).into_owned(),
            z.fixed_rows::<3>(3).into_owned(),
        )
    }

    fn check(&self, report: &mut EnergyCheck) {
        let (e, s, k, n) = (self.energy, self.s, &self.kappa, &self.nu);
        let jet = e.strain_jet(s, k, n);
        let (g, h) = (jet.gradient, jet.hessian);
        // A direction of typical size in every strain (steps × 10³).
        let v = Vector6::from_fn(|i, _| DIRECTIONS[(i + 1) % 5][i % 3] * self.steps[i] * 1e3);
        let third = e.strain_hessian_derivative(s, k, n, &v);
        for j in 0..6 {
            let hj = self.steps[j];
            let at = |t: f64| self.shifted(j, t);
            let (fd, bound) = derivative(
                |t| {
                    let (kk, nn) = at(t);
                    [e.strain_density(s, &kk, &nn)]
                },
                hj,
            );
            let scale = g[j].abs() + h[(j, j)].abs() * hj * 1e3;
            self.compare(
                report,
                Property::StrainGradient,
                &[g[j]],
                &fd,
                &bound,
                scale,
            );
            let (fd, bound) = derivative(
                |t| {
                    let (kk, nn) = at(t);
                    e.strain_jet(s, &kk, &nn).gradient.into()
                },
                hj,
            );
            let column: [f64; 6] = h.column(j).into();
            let scale = max_abs(&column) + h[(j, j)].abs();
            self.compare(report, Property::StrainHessian, &column, &fd, &bound, scale);
            let (fd, bound) = derivative(
                |t| {
                    let (kk, nn) = at(t);
                    (e.strain_jet(s, &kk, &nn).hessian * v).into()
                },
                hj,
            );
            let column: [f64; 6] = third.column(j).into();
            let scale = max_abs(&column) + max_abs((h * v).as_slice()) / (1e3 * hj);
            self.compare(report, Property::StrainThird, &column, &fd, &bound, scale);
        }
        let per_length = 1.0 / (1e3 * self.hs);
        let (fd, bound) = derivative_in_s(|t| e.strain_jet(s + t, k, n).gradient.into(), self.hs);
        let rate: [f64; 6] = jet.gradient_rate.into();
        let scale = max_abs(&rate) + max_abs(g.as_slice()) * per_length + h.amax() * 1e-3;
        self.compare(report, Property::StrainRates, &rate, &fd, &bound, scale);
        let (fd, bound) = derivative_in_s(|t| flat6(&e.strain_jet(s + t, k, n).hessian), self.hs);
        let rate = flat6(&jet.hessian_rate);
        let scale = max_abs(&rate) + h.amax() * per_length;
        self.compare(report, Property::StrainRates, &rate, &fd, &bound, scale);
        let asymmetry = (h - h.transpose()).amax() / h.amax().max(f64::MIN_POSITIVE);
        if asymmetry > 1e-12 {
            self.record(report, Property::StrainSymmetry, asymmetry, false);
        }
        if h.cholesky().is_none() {
            self.record(
                report,
                Property::StrainConvexity,
                h.symmetric_eigenvalues().min(),
                false,
            );
        }
    }

    fn record(&self, report: &mut EnergyCheck, property: Property, error: f64, undecided: bool) {
        report.findings.push(Finding {
            property,
            s: self.s,
            kappa: self.kappa,
            nu: self.nu,
            error,
            undecided,
        });
    }

    /// As [`Sample::compare`].
    fn compare(
        &self,
        report: &mut EnergyCheck,
        property: Property,
        exact: &[f64],
        reference: &[f64],
        bound: &[f64],
        scale: f64,
    ) {
        if let Some((error, undecided)) = judge(report, exact, reference, bound, scale) {
            self.record(report, property, error, undecided);
        }
    }
}
