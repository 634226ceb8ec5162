//! The spatial Kirchhoff rod: the 9-ODE system in (d1, d2, κ) of the paper
//! ((25)–(29) for the linear energy), for any stored energy, with the
//! position r by quadrature (r' = d3).
//!
//! With the Darboux vector k = κ_i d_i, d_i' = k × d_i gives
//!
//!   d1' = κ3 d2 − κ2 d3,   d2' = κ1 d3 − κ3 d1,   (d3 = d1 × d2)
//!
//! and the moment balance m' + d3 × n = 0 in body components (paper
//! (19)–(21) with n general) reads M' = M × κ + N × e3, N_i = n·d_i. Since
//! M' = H κ' + ∂s∇W, κ' = H⁻¹ (M × κ + N × e3 − ∂s∇W).
//!
//! State y = (d1, d2, κ, r), 12 numbers; three unknowns κ(0); three tip
//! conditions M_i(L) = C·d_i(L) (paper (22) with a tip couple C).
//!
//! The same equations carry the Cosserat level (shear and extension,
//! [`crate::model::Shearable`]): with the compliance c = S⁻¹ the strain is
//! ν = e3 + c∘N, the tangent r' = ν_i d_i and the moment balance
//! m' + r' × n = 0 reads M' = M × κ + N × ν. With c = 0 this is the
//! Kirchhoff rod exactly. A general energy W(s, κ, ν) ([`StrainEnergy`],
//! any coupling) runs the same states with ν from W_ν = N and κ' from the
//! 6 × 6 tangent stiffness (`strained.rs`); the quadratic energy of
//! [`crate::model::Shearable`] keeps the explicit ν = e3 + S⁻¹N as a fast
//! path, checked against the general one (tests/strain_energy.rs).

use nalgebra::{DMatrix, Matrix3, Vector3};

use std::sync::{Arc, Mutex};

use super::moment_jump::curvature_for_moment;
use super::planar::straight_rod_clamp_moment;
use super::strained::Strained;
use super::tip::{condition_rates, conditions, rates_cover, TipRates, TipState};
use super::{RodEquations, RodSample};
use crate::model::{
    ResidualScales, Rod, RodTangent, StoredEnergy, StrainEnergy, StrainError, TipSupport,
};
use crate::numerics::integrator::IntegrationError;
use crate::numerics::newton::{self, Convergence, Damping, Options, System};

/// The 9-ODE Kirchhoff equations (12 with the position), or the Cosserat
/// ones when the compliance is non-zero.
#[derive(Debug, Clone)]
pub struct KirchhoffEquations {
    rod: Rod,
    /// c = S⁻¹ (1/N): zero for the Kirchhoff rod.
    compliance: Vector3<f64>,
    /// The general path: ν from W_ν(s, κ, ν) = N by Newton.
    strained: bool,
    /// The first failure of that Newton, kept for the solver to name
    /// (the rates there are NaN, which no integrator accepts).
    failure: Arc<Mutex<Option<StrainError>>>,
    /// [`Rod::residual_scales`] computed once (it samples the energy at 65
    /// points; the tip residual needs it at every shooting evaluation).
    units: ResidualScales,
}

/// The state unpacked.
struct State {
    d1: Vector3<f64>,
    d2: Vector3<f64>,
    d3: Vector3<f64>,
    kappa: Vector3<f64>,
    /// The tip reaction R (states 12..15 when the support holds the tip's
    /// position; zero otherwise).
    reaction: Vector3<f64>,
}

impl State {
    fn read(y: &[f64]) -> State {
        let d1 = Vector3::new(y[0], y[1], y[2]);
        let d2 = Vector3::new(y[3], y[4], y[5]);
        State {
            d1,
            d2,
            d3: d1.cross(&d2),
            kappa: Vector3::new(y[6], y[7], y[8]),
            reaction: if y.len() > 12 {
                Vector3::new(y[12], y[13], y[14])
            } else {
                Vector3::zeros()
            },
        }
    }
}

/// The pieces of κ' shared by the right-hand side and its linearization.
struct Balance {
    /// H⁻¹ (LU-free: H is symmetric positive definite, 3 × 3).
    h_inv: Matrix3<f64>,
    /// H.
    h: Matrix3<f64>,
    /// M = ∇W.
    m: Vector3<f64>,
    /// κ'.
    rate: Vector3<f64>,
    /// n(s), global.
    n: Vector3<f64>,
    /// The strain ν = e3 + c∘N (e3 for the Kirchhoff rod).
    nu: Vector3<f64>,
}

/// One direction v of the variational equations at a state: the perturbed
/// frame δd1, δd2 (read from v), δd3 = δd1×d2 + d1×δd2, δκ; the
/// linearized director rates (of d1' = d2κ3 − d3κ2 and d2' = d3κ1 − d1κ3);
/// and the body components of δn — the frame turned under the internal
/// force n, plus the reaction's perturbation (v[12..15]) where the tip is
/// held. Shared by the quadratic and the general Cosserat linearizations,
/// which differ only in δκ' and δν.
struct FrameVariation {
    dd1: Vector3<f64>,
    dd2: Vector3<f64>,
    dd3: Vector3<f64>,
    dk: Vector3<f64>,
    rate1: Vector3<f64>,
    rate2: Vector3<f64>,
    dn: Vector3<f64>,
}

impl FrameVariation {
    fn at(st: &State, v: &[f64], n: &Vector3<f64>) -> Self {
        let k = st.kappa;
        let dreaction = if v.len() > 12 {
            Vector3::new(v[12], v[13], v[14])
        } else {
            Vector3::zeros()
        };
        let dd1 = Vector3::new(v[0], v[1], v[2]);
        let dd2 = Vector3::new(v[3], v[4], v[5]);
        let dk = Vector3::new(v[6], v[7], v[8]);
        let dd3 = dd1.cross(&st.d2) + st.d1.cross(&dd2);
        FrameVariation {
            rate1: st.d2 * dk[2] + dd2 * k[2] - st.d3 * dk[1] - dd3 * k[1],
            rate2: st.d3 * dk[0] + dd3 * k[0] - st.d1 * dk[2] - dd1 * k[2],
            dn: Vector3::new(
                n.dot(&dd1) + dreaction.dot(&st.d1),
                n.dot(&dd2) + dreaction.dot(&st.d2),
                n.dot(&dd3) + dreaction.dot(&st.d3),
            ),
            dd1,
            dd2,
            dd3,
            dk,
        }
    }

    /// Writes the rates of the direction: δd1', δd2', δκ' = `rk` and
    /// δr' = Σ δd_i ν_i + d_i δν_i; the reaction is constant (δR' = 0).
    fn write(
        &self,
        st: &State,
        nu: &Vector3<f64>,
        dnu: &Vector3<f64>,
        rk: &Vector3<f64>,
        out: &mut [f64],
    ) {
        let dr = self.dd1 * nu[0]
            + self.dd2 * nu[1]
            + self.dd3 * nu[2]
            + st.d1 * dnu[0]
            + st.d2 * dnu[1]
            + st.d3 * dnu[2];
        out[0..3].copy_from_slice(self.rate1.as_slice());
        out[3..6].copy_from_slice(self.rate2.as_slice());
        out[6..9].copy_from_slice(rk.as_slice());
        out[9..12].copy_from_slice(dr.as_slice());
        out[12..].fill(0.0);
    }
}

impl KirchhoffEquations {
    /// The spatial Kirchhoff equations of a rod (unshearable and
    /// inextensible, whatever the energy's shear part).
    pub fn new(rod: Rod) -> Self {
        KirchhoffEquations {
            units: rod.residual_scales(),
            rod,
            compliance: Vector3::zeros(),
            strained: false,
            failure: Arc::default(),
        }
    }

    /// The Cosserat equations: shear and extension from the energy's
    /// stiffnesses S where it gives them (the explicit quadratic fast
    /// path), else from its [`StrainEnergy`] (Kirchhoff when it has
    /// neither).
    pub fn cosserat(rod: Rod) -> Self {
        match rod.energy().shear_stiffness(0.0) {
            Some(s) => KirchhoffEquations {
                compliance: s.map(|v| 1.0 / v),
                ..Self::new(rod)
            },
            None => Self::general(rod),
        }
    }

    /// The Cosserat equations by the general path alone (ν by Newton from
    /// W_ν = N, the 6 × 6 tangent stiffness), also for an energy with a
    /// quadratic shear part: what the fast path is tested against.
    /// Kirchhoff when the energy has no [`StrainEnergy`].
    pub fn general(rod: Rod) -> Self {
        let strained = rod.energy().strain_energy().is_some();
        KirchhoffEquations {
            strained,
            ..Self::new(rod)
        }
    }

    /// The energy in six strains (the general path only).
    fn strain_energy(&self) -> &dyn StrainEnergy {
        self.rod
            .energy()
            .strain_energy()
            .expect("the general path is chosen only for an energy with strains")
    }

    /// The body force N and distributed force F (body components) at s.
    fn body_forces(&self, s: f64, st: &State) -> (Vector3<f64>, Vector3<f64>) {
        let n = self.rod.loads().internal_force(s, self.rod.length()) + st.reaction;
        let f = self.rod.loads().distributed_force;
        let body = |v: Vector3<f64>| Vector3::new(v.dot(&st.d1), v.dot(&st.d2), v.dot(&st.d3));
        (body(n), body(f))
    }

    /// The general path's balance at s, its failure recorded.
    fn strained_at(&self, s: f64, st: &State) -> Option<Strained> {
        let (force, distributed) = self.body_forces(s, st);
        match Strained::at(self.strain_energy(), s, &st.kappa, &force, &distributed) {
            Ok(p) => Some(p),
            Err(e) => {
                let mut kept = self
                    .failure
                    .lock()
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
                kept.get_or_insert(e);
                None
            }
        }
    }

    fn balance(&self, s: f64, st: &State) -> Balance {
        let e = &self.rod.energy();
        let h = e.stiffness(s, &st.kappa);
        let h_inv = h
            .try_inverse()
            .unwrap_or_else(|| Matrix3::from_element(f64::NAN));
        let m = e.moment(s, &st.kappa);
        let n = self.rod.loads().internal_force(s, self.rod.length()) + st.reaction;
        let body_n = Vector3::new(n.dot(&st.d1), n.dot(&st.d2), n.dot(&st.d3));
        let nu = Vector3::z() + self.compliance.component_mul(&body_n);
        let q = m.cross(&st.kappa) + body_n.cross(&nu);
        let rate = h_inv * (q - e.moment_rate(s, &st.kappa));
        Balance {
            h_inv,
            h,
            m,
            rate,
            n,
            nu,
        }
    }

    /// Whether the support holds the tip's position, so that the reaction R
    /// is carried as three constant states (R' = 0) with R(0) unknown.
    fn reacts(&self) -> bool {
        self.rod
            .support()
            .as_ref()
            .is_some_and(|s| s.holds_position())
    }

    fn write_rates(st: &State, b: &Balance, dy: &mut [f64]) {
        Self::write_strained_rates(st, &b.nu, &b.rate, dy);
    }

    fn write_strained_rates(st: &State, nu: &Vector3<f64>, rate: &Vector3<f64>, dy: &mut [f64]) {
        let k = st.kappa;
        let dd1 = st.d2 * k[2] - st.d3 * k[1];
        let dd2 = st.d3 * k[0] - st.d1 * k[2];
        let dr = st.d1 * nu[0] + st.d2 * nu[1] + st.d3 * nu[2];
        dy[0..3].copy_from_slice(dd1.as_slice());
        dy[3..6].copy_from_slice(dd2.as_slice());
        dy[6..9].copy_from_slice(rate.as_slice());
        dy[9..12].copy_from_slice(dr.as_slice());
        dy[12..].fill(0.0);
    }
}

impl KirchhoffEquations {
    /// The free tip's Jacobian with `h` = ∂M/∂κ at the tip (at fixed
    /// directors): ∂(C·d3)/∂d1 = d2 × C, ∂(C·d3)/∂d2 = C × d1.
    fn free_tip_jacobian(&self, st: &State, h: &Matrix3<f64>) -> DMatrix<f64> {
        let c = self.rod.loads().tip_couple;
        let mut g = DMatrix::zeros(3, self.dim());
        for j in 0..3 {
            g[(0, j)] = -c[j];
            g[(1, 3 + j)] = -c[j];
        }
        let (a, b) = (st.d2.cross(&c), c.cross(&st.d1));
        for j in 0..3 {
            g[(2, j)] = -a[j];
            g[(2, 3 + j)] = -b[j];
            for i in 0..3 {
                g[(i, 6 + j)] = h[(i, j)];
            }
        }
        let unit = self.units.moment;
        for i in 0..3 {
            g.row_mut(i).scale_mut(1.0 / unit[i]);
        }
        g
    }

    /// The residuals and Jacobian of a supported tip ([`super::tip`]).
    fn supported_tip(&self, support: &TipSupport, y: &[f64]) -> (Vec<f64>, DMatrix<f64>) {
        let st = State::read(y);
        let l = self.rod.length();
        let tip = TipState {
            d: [st.d1, st.d2, st.d3],
            r: Vector3::new(y[9], y[10], y[11]),
            m: self.tip_moment(&st),
            // The general path's Jacobian reads ∂g/∂M from the κ columns
            // and applies the chain rule itself (strained_tip_jacobian).
            h: if self.strained {
                Matrix3::identity()
            } else {
                self.rod.energy().stiffness(l, &st.kappa)
            },
            reaction: st.reaction,
            couple: &self.rod.loads().tip_couple,
        };
        conditions(support, &tip, &self.units, self.dim())
    }

    /// M(L): ∇W at the tip, W_κ(L, κ, ν) on the general path (NaN, the
    /// failure recorded, where ν has no solution).
    fn tip_moment(&self, st: &State) -> Vector3<f64> {
        let l = self.rod.length();
        if !self.strained {
            return self.rod.energy().moment(l, &st.kappa);
        }
        self.strained_at(l, st)
            .map_or_else(|| Vector3::from_element(f64::NAN), |p| p.moment())
    }

    /// ∂N(L)/∂y (3 × dim): N_i = n·d_i with n = n_loads + R, d3 = d1 × d2.
    fn tip_force_jacobian(&self, st: &State) -> DMatrix<f64> {
        let n = self
            .rod
            .loads()
            .internal_force(self.rod.length(), self.rod.length())
            + st.reaction;
        let mut j = DMatrix::zeros(3, self.dim());
        let (a, b) = (st.d2.cross(&n), n.cross(&st.d1));
        for c in 0..3 {
            j[(0, c)] = n[c];
            j[(1, 3 + c)] = n[c];
            j[(2, c)] = a[c];
            j[(2, 3 + c)] = b[c];
        }
        if self.reacts() {
            for (i, d) in [st.d1, st.d2, st.d3].iter().enumerate() {
                for c in 0..3 {
                    j[(i, 12 + c)] = d[c];
                }
            }
        }
        j
    }

    /// The tip Jacobian on the general path: M(L) = W_κ(κ, ν(κ, N)) moves
    /// with κ by the Schur complement and with the frame and reaction
    /// through N by H_κν H_νν⁻¹; the conditions' own Jacobian, built with
    /// ∂M/∂κ = I, gives ∂g/∂M in its κ columns.
    fn strained_tip_jacobian(&self, y: &[f64]) -> DMatrix<f64> {
        let st = State::read(y);
        let Some(p) = self.strained_at(self.rod.length(), &st) else {
            return DMatrix::from_element(self.unknowns(), self.dim(), f64::NAN);
        };
        let mut j = match &self.rod.support() {
            Some(support) => self.supported_tip(support, y).1,
            None => self.free_tip_jacobian(&st, &Matrix3::identity()),
        };
        let g = j.columns(6, 3).into_owned();
        let schur = p.moment_stiffness();
        let schur = DMatrix::from_fn(3, 3, |r, c| schur[(r, c)]);
        let x = p.moment_compliance();
        let x = DMatrix::from_fn(3, 3, |r, c| x[(r, c)]);
        j.columns_mut(6, 3).copy_from(&(&g * schur));
        j += &g * x * self.tip_force_jacobian(&st);
        j
    }

    /// f and its linearization on the general path (see `strained.rs`);
    /// NaN everywhere, the failure recorded, where ν has no solution.
    fn strained_linearized(
        &self,
        s: f64,
        st: &State,
        cols: usize,
        phi: &[f64],
        dy: &mut [f64],
        dphi: &mut [f64],
    ) {
        let Some(p) = self.strained_at(s, st) else {
            dy.fill(f64::NAN);
            dphi.fill(f64::NAN);
            return;
        };
        Self::write_strained_rates(st, &p.nu, &p.kappa_rate(), dy);
        let k = st.kappa;
        let third = p.third(self.strain_energy(), s, &k);
        let n = self.rod.loads().internal_force(s, self.rod.length()) + st.reaction;
        let f = self.rod.loads().distributed_force;
        let dim = self.dim();
        for c in 0..cols {
            let v = &phi[dim * c..dim * (c + 1)];
            let out = &mut dphi[dim * c..dim * (c + 1)];
            let w = FrameVariation::at(st, v, &n);
            let df = Vector3::new(f.dot(&w.dd1), f.dot(&w.dd2), f.dot(&w.dd3));
            let (rk, dnu) = p.linearized(&third, &k, &w.dk, &w.dn, &df);
            w.write(st, &p.nu, &dnu, &rk, out);
        }
    }
}

impl RodEquations for KirchhoffEquations {
    fn dim(&self) -> usize {
        if self.reacts() {
            15
        } else {
            12
        }
    }

    fn unknowns(&self) -> usize {
        self.dim() - 9
    }

    fn length(&self) -> f64 {
        self.rod.length()
    }

    fn jumps(&self) -> Vec<f64> {
        self.rod.breaks()
    }

    fn state_jumps(&self) -> bool {
        self.rod.loads().has_point_couples()
    }

    /// A point couple C drops the moment by C (global): M⁺ = M⁻ + J with
    /// J_i = −C·d_i, the directors continuous; κ⁺ from ∇W(s, κ⁺) = M⁺ by
    /// Newton, and dκ⁺ = H⁺⁻¹ (H⁻ dκ⁻ + dJ), dJ_i = −C·δd_i (δd3 =
    /// δd1 × d2 + d1 × δd2). Not on the general Cosserat path, whose
    /// moment also depends on the strain ν (refused by name).
    fn jump(
        &self,
        s: f64,
        y: &mut [f64],
        cols: usize,
        phi: &mut [f64],
    ) -> Result<(), IntegrationError> {
        let drop = self.rod.loads().moment_jump(s);
        if drop == Vector3::zeros() {
            return Ok(());
        }
        if self.strained {
            return Err(IntegrationError::JumpWithoutValue {
                s,
                reason: "a point couple is not carried on the general W(s, κ, ν) path",
            });
        }
        let n = self.dim();
        let st = State::read(y);
        let e = self.rod.energy();
        let left = s.next_down();
        let body = |v: &Vector3<f64>| Vector3::new(v.dot(&st.d1), v.dot(&st.d2), v.dot(&st.d3));
        let target = e.moment(left, &st.kappa) + body(&drop);
        let (kappa, h_after) = curvature_for_moment(e.as_ref(), s, &st.kappa, &target)
            .map_err(|reason| IntegrationError::JumpWithoutValue { s, reason })?;
        let h_before = e.stiffness(left, &st.kappa);
        let lu = h_after.lu();
        for c in 0..cols {
            let v = &mut phi[n * c..n * (c + 1)];
            let dd1 = Vector3::new(v[0], v[1], v[2]);
            let dd2 = Vector3::new(v[3], v[4], v[5]);
            let dd3 = dd1.cross(&st.d2) + st.d1.cross(&dd2);
            let dk = Vector3::new(v[6], v[7], v[8]);
            let dm = h_before * dk + Vector3::new(drop.dot(&dd1), drop.dot(&dd2), drop.dot(&dd3));
            let dk_after = lu.solve(&dm).ok_or(IntegrationError::JumpWithoutValue {
                s,
                reason: "the energy's Hessian is singular after the jump",
            })?;
            v[6..9].copy_from_slice(dk_after.as_slice());
        }
        y[6..9].copy_from_slice(kappa.as_slice());
        Ok(())
    }

    fn initial_state(&self, u: &[f64], y0: &mut [f64]) {
        let c = &self.rod.clamp();
        y0[0..3].copy_from_slice(c.director(0).as_slice());
        y0[3..6].copy_from_slice(c.director(1).as_slice());
        y0[6..9].copy_from_slice(&u[..3]);
        y0[9..12].copy_from_slice(c.position.as_slice());
        if self.reacts() {
            y0[12..15].copy_from_slice(&u[3..6]);
        }
    }

    fn initial_sensitivity(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.dim(), self.unknowns());
        for i in 0..3 {
            m[(6 + i, i)] = 1.0;
            if self.reacts() {
                m[(12 + i, 3 + i)] = 1.0;
            }
        }
        m
    }

    fn rhs(&self, s: f64, y: &[f64], dy: &mut [f64]) {
        let st = State::read(y);
        if self.strained {
            match self.strained_at(s, &st) {
                Some(p) => Self::write_strained_rates(&st, &p.nu, &p.kappa_rate(), dy),
                None => dy.fill(f64::NAN),
            }
            return;
        }
        let b = self.balance(s, &st);
        Self::write_rates(&st, &b, dy);
    }

    /// The linearization along (δd1, δd2, δκ, δr):
    /// δd3 = δd1 × d2 + d1 × δd2, δd1' = δκ3 d2 + κ3 δd2 − δκ2 d3 − κ2 δd3,
    /// δd2' = δκ1 d3 + κ1 δd3 − δκ3 d1 − κ3 δd1, δr' = δ(ν_i d_i), and
    /// δκ' = H⁻¹ (Hδκ × κ + M × δκ + δN × ν + N × δν − ∂sH δκ − ∂κ(Hκ')δκ),
    /// δN_i = n·δd_i + δR·d_i, δν = c∘δN, δR' = 0.
    fn rhs_linearized(
        &self,
        s: f64,
        y: &[f64],
        cols: usize,
        phi: &[f64],
        dy: &mut [f64],
        dphi: &mut [f64],
    ) {
        let st = State::read(y);
        if self.strained {
            self.strained_linearized(s, &st, cols, phi, dy, dphi);
            return;
        }
        let b = self.balance(s, &st);
        Self::write_rates(&st, &b, dy);
        let body_n = Vector3::new(b.n.dot(&st.d1), b.n.dot(&st.d2), b.n.dot(&st.d3));
        let e = &self.rod.energy();
        let k = st.kappa;
        let kappa_jac = e.stiffness_rate(s, &k) + e.stiffness_derivative(s, &k, &b.rate);
        let n = self.dim();
        for c in 0..cols {
            let v = &phi[n * c..n * (c + 1)];
            let out = &mut dphi[n * c..n * (c + 1)];
            let w = FrameVariation::at(&st, v, &b.n);
            let (dk, dn) = (w.dk, w.dn);
            let dnu = self.compliance.component_mul(&dn);
            let dq = (b.h * dk).cross(&k) + b.m.cross(&dk) + dn.cross(&b.nu) + body_n.cross(&dnu);
            let rk = b.h_inv * (dq - kappa_jac * dk);
            w.write(&st, &b.nu, &dnu, &rk, out);
        }
    }

    fn tip_residual(&self, y: &[f64], r: &mut [f64]) {
        if let Some(support) = &self.rod.support() {
            r.copy_from_slice(&self.supported_tip(support, y).0);
            return;
        }
        let st = State::read(y);
        let m = self.tip_moment(&st);
        let c = self.rod.loads().tip_couple;
        let unit = self.units.moment;
        r[0] = (m[0] - c.dot(&st.d1)) / unit[0];
        r[1] = (m[1] - c.dot(&st.d2)) / unit[1];
        r[2] = (m[2] - c.dot(&st.d3)) / unit[2];
    }

    /// ∂/∂κ = H(L); ∂(C·d3)/∂d1 = d2 × C, ∂(C·d3)/∂d2 = C × d1.
    fn tip_residual_jacobian(&self, y: &[f64]) -> DMatrix<f64> {
        if self.strained {
            return self.strained_tip_jacobian(y);
        }
        if let Some(support) = &self.rod.support() {
            return self.supported_tip(support, y).1;
        }
        let st = State::read(y);
        let h = self.rod.energy().stiffness(self.rod.length(), &st.kappa);
        self.free_tip_jacobian(&st, &h)
    }

    /// Gram–Schmidt on (d1, d2): an O(tolerance) correction after each step
    /// that keeps the directors orthonormal to round-off without changing
    /// the order of the method (Hairer, Lubich & Wanner, GNI IV.4).
    fn project(&self, y: &mut [f64]) {
        let d1 = Vector3::new(y[0], y[1], y[2]).normalize();
        let d2 = Vector3::new(y[3], y[4], y[5]);
        let d2 = (d2 - d1 * d1.dot(&d2)).normalize();
        y[0..3].copy_from_slice(d1.as_slice());
        y[3..6].copy_from_slice(d2.as_slice());
    }

    /// M(0) balancing the loads on the straight rod, in body components at
    /// the clamp, then κ(0) from ∇W(0, κ) = M(0) by Newton from κ = 0.
    /// R, the unknowns after κ(0).
    fn set_reaction(&self, u: &mut [f64], r: &Vector3<f64>) -> bool {
        if !self.reacts() {
            return false;
        }
        u[3..6].copy_from_slice(r.as_slice());
        true
    }

    fn initial_guess(&self) -> Vec<f64> {
        let m = self.rod.clamp().frame.transpose() * straight_rod_clamp_moment(&self.rod);
        let e = self.rod.energy();
        let mut k = [0.0; 3];
        let mut system = ClampCurvature {
            energy: e.as_ref(),
            moment: m,
            h_inv: None,
        };
        let opts = Options {
            tolerance: 0.0,
            max_iterations: 50,
            damping: Damping::Full,
        };
        // A singular Hessian or the budget spent leaves the last iterate,
        // a guess like any other; converged, the last correction is applied.
        if let Ok(report) = newton::solve(&mut system, &mut k, &opts) {
            k.iter_mut()
                .zip(&report.correction)
                .for_each(|(a, b)| *a += b);
        }
        let mut u = k.to_vec();
        u.resize(self.unknowns(), 0.0);
        u
    }

    fn failure(&self) -> Option<String> {
        let kept = self
            .failure
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        kept.as_ref().map(ToString::to_string)
    }

    fn unknowns_of(&self, y0: &[f64]) -> Vec<f64> {
        let mut u = y0[6..9].to_vec();
        u.extend_from_slice(&y0[12..]);
        u
    }

    fn sample(&self, s: f64, y: &[f64]) -> RodSample {
        let st = State::read(y);
        RodSample {
            s,
            position: Vector3::new(y[9], y[10], y[11]),
            directors: [st.d1, st.d2, st.d3],
            curvature: st.kappa,
            moment: if self.strained {
                self.strained_at(s, &st)
                    .map_or_else(|| Vector3::from_element(f64::NAN), |p| p.moment())
            } else {
                self.rod.energy().moment(s, &st.kappa)
            },
            force: self.rod.loads().internal_force(s, self.rod.length()) + st.reaction,
        }
    }

    fn straight_state(&self, s: f64) -> Vec<f64> {
        let c = &self.rod.clamp();
        let mut y = vec![0.0; self.dim()];
        self.initial_state(&vec![0.0; self.unknowns()], &mut y);
        let r = c.position + c.director(2) * s;
        y[9..12].copy_from_slice(r.as_slice());
        y
    }

    fn state_scales(&self) -> Vec<f64> {
        let l = self.rod.length();
        let mut scales = vec![1.0; self.dim()];
        scales[6..9].fill(1.0 / l);
        scales[9..12].fill(l);
        scales[12..].fill(self.units.force);
        scales
    }

    /// The position r: f reads only the directors, the curvature and the
    /// reaction.
    fn quadrature_components(&self) -> std::ops::Range<usize> {
        9..12
    }

    /// A tangent whose energy rates are exact for this rod, and a support
    /// whose motion the support conditions' rates (`tip.rs`) cover.
    fn differentiates(&self, t: &RodTangent) -> bool {
        // The general path's p-derivatives are not written: continuation
        // differentiates it by differences, and says so.
        !self.strained
            && t.fits(&self.rod)
            && self
                .rod
                .support()
                .is_none_or(|s| rates_cover(s, t.support_spin()))
    }

    /// (L'/L) f, plus the balance H κ' = M × κ + N × ν − ∂sM moved at
    /// fixed y: δκ' = H⁻¹ (δM × κ + δN × ν + N × δν − δ∂sM − δH κ'),
    /// δN_i = δn·d_i, δν = c∘δN, and δr' = δν_i d_i.
    fn rhs_parameter(&self, s: f64, y: &[f64], f: &[f64], t: &RodTangent, out: &mut [f64]) {
        let st = State::read(y);
        let b = self.balance(s, &st);
        let stretch = t.length() / self.rod.length();
        for (o, v) in out.iter_mut().zip(f) {
            *o = v * stretch;
        }
        let dn = t.internal_force_rate(&self.rod, s);
        let body_n = Vector3::new(b.n.dot(&st.d1), b.n.dot(&st.d2), b.n.dot(&st.d3));
        let d_body_n = Vector3::new(dn.dot(&st.d1), dn.dot(&st.d2), dn.dot(&st.d3));
        let dnu = self.compliance.component_mul(&d_body_n);
        let de = t.energy_rate(self.rod.energy().as_ref(), s, &st.kappa);
        let dq = de.moment.cross(&st.kappa) + d_body_n.cross(&b.nu) + body_n.cross(&dnu);
        let drate = b.h_inv * (dq - de.moment_rate - de.stiffness * b.rate);
        let dr = st.d1 * dnu[0] + st.d2 * dnu[1] + st.d3 * dnu[2];
        for i in 0..3 {
            out[6 + i] += drate[i];
            out[9 + i] += dr[i];
        }
    }

    /// The clamp's spin turns d1(0), d2(0): δd_i = ω × d_i.
    fn initial_state_parameter(&self, _u: &[f64], t: &RodTangent, out: &mut [f64]) {
        out.fill(0.0);
        let c = self.rod.clamp();
        let w = t.clamp_spin();
        out[0..3].copy_from_slice(w.cross(&c.director(0)).as_slice());
        out[3..6].copy_from_slice(w.cross(&c.director(1)).as_slice());
    }

    /// g_i = (M_i(L) − C·d_i)/M_s,i: δg_i = (δM_i − δC·d_i)/M_s,i −
    /// g_i δM_s,i/M_s,i; a support's conditions by their rates in
    /// `tip.rs` (`condition_rates`).
    fn tip_residual_parameter(&self, y: &[f64], t: &RodTangent, out: &mut [f64]) {
        let st = State::read(y);
        let l = self.rod.length();
        let e = self.rod.energy();
        let m = e.moment(l, &st.kappa);
        let dm = t.energy_rate(e.as_ref(), l, &st.kappa).moment;
        let (c, dc) = (&self.rod.loads().tip_couple, &t.loads().tip_couple);
        if let Some(support) = self.rod.support() {
            let tip = TipState {
                d: [st.d1, st.d2, st.d3],
                r: Vector3::new(y[9], y[10], y[11]),
                m,
                h: e.stiffness(l, &st.kappa),
                reaction: st.reaction,
                couple: c,
            };
            let rates = TipRates {
                m: dm,
                couple: dc,
                position: t.support_shift(),
                spin: t.support_spin(),
                scales: t.residual_scales_rate(&self.rod),
            };
            let scales = self.units;
            out.copy_from_slice(&condition_rates(support, &tip, &scales, &rates));
            return;
        }
        let unit = self.units.moment;
        let dunit = t.residual_scales_rate(&self.rod).moment;
        let d = [st.d1, st.d2, st.d3];
        for i in 0..3 {
            let g = (m[i] - c.dot(&d[i])) / unit[i];
            out[i] = (dm[i] - dc.dot(&d[i])) / unit[i] - g * dunit[i] / unit[i];
        }
    }

    fn state_scales_parameter(&self, t: &RodTangent) -> Vec<f64> {
        let (l, dl) = (self.rod.length(), t.length());
        let mut rates = vec![0.0; self.dim()];
        rates[6..9].fill(-dl / (l * l));
        rates[9..12].fill(dl);
        rates[12..].fill(t.residual_scales_rate(&self.rod).force);
        rates
    }
}

/// ∇W(0, κ) = M in κ: the clamp curvature whose moment is M, by Newton
/// from κ = 0 with the Hessian H = ∂²W/∂κ² inverted (3 × 3, symmetric
/// positive definite where the energy is admissible).
///
/// Its stopping rule differs from [`Convergence`] on purpose: the residual
/// is a moment with no natural unit here, so only the correction is
/// measured, |δ| ≤ 1e-14 max(|κ + δ|, 1) against the corrected iterate, and
/// the caller applies that last correction — the loop this replaced did
/// both, and the initial guesses (hence every solution started from them)
/// stay bit-identical.
struct ClampCurvature<'a> {
    energy: &'a dyn StoredEnergy,
    moment: Vector3<f64>,
    h_inv: Option<Matrix3<f64>>,
}

impl System for ClampCurvature<'_> {
    type Error = std::convert::Infallible;

    fn size(&self) -> usize {
        3
    }

    fn residual(&mut self, k: &[f64], r: &mut [f64]) -> Result<(), Self::Error> {
        let k = Vector3::from_column_slice(k);
        r.copy_from_slice((self.energy.moment(0.0, &k) - self.moment).as_slice());
        Ok(())
    }

    fn linearize(&mut self, k: &[f64]) -> bool {
        let k = Vector3::from_column_slice(k);
        self.h_inv = self.energy.stiffness(0.0, &k).try_inverse();
        self.h_inv.is_some()
    }

    fn solve(&mut self, f: &[f64], delta: &mut [f64]) -> bool {
        let Some(h_inv) = self.h_inv else {
            return false;
        };
        let d = h_inv * -Vector3::from_column_slice(f);
        delta.copy_from_slice(d.as_slice());
        true
    }

    fn converged(&self, _test: &Convergence, _residual: f64, k: &[f64], delta: &[f64]) -> bool {
        let delta = Vector3::from_column_slice(delta);
        let corrected = Vector3::from_column_slice(k) + delta;
        delta.norm() <= 1e-14 * corrected.norm().max(1.0)
    }
}
