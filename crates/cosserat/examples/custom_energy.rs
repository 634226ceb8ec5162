//! A new stored energy written in Rust and used from a problem file by
//! name: a material that stiffens with curvature,
//!
//!   W(s, κ) = Σ_i B_i(s)/a² (cosh(a (κ_i − κ⁰_i(s))) − 1),
//!
//! which is the linear energy ½ Σ B_i (κ_i − κ⁰_i)² for small curvature
//! changes and stiffens exponentially beyond 1/a (a > 0, in metres).
//!
//! Run: `cargo run --release --example custom_energy [PROBLEM.toml]`
//! (default examples/hyperbolic_roll_up.toml, `kind = "hyperbolic"`).
//! The three steps for any energy: implement [`StoredEnergy`] (W, M = ∇W,
//! H, their s-derivatives and the third derivative ∂(Hv)/∂κ), register a
//! builder under a name, and read problem files through that catalog.

use std::path::PathBuf;
use std::sync::Arc;

use cosserat::bvp::solve;
use cosserat::input::Problem;
use cosserat::model::{EnergyCatalog, EnergySpecError, LinearElastic, StoredEnergy};
use nalgebra::{Matrix3, Vector3};

/// W = Σ B_i/a² (cosh(a u_i) − 1), u = κ − κ⁰(s).
#[derive(Debug, Clone)]
pub struct HyperbolicStiffening {
    /// The stiffness and intrinsic-curvature profiles.
    pub linear: LinearElastic,
    /// a (m): curvature changes beyond 1/a stiffen the rod.
    pub stiffening: f64,
}

impl HyperbolicStiffening {
    fn parts(&self, s: f64, kappa: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let a = self.stiffening;
        let u = kappa - self.linear.kappa0(s);
        let b = Vector3::from_fn(|i, _| self.linear.stiffness_profiles()[i].value(s));
        (u, b, u.map(|x| (a * x).sinh()))
    }

    fn rates(&self, s: f64) -> (Vector3<f64>, Vector3<f64>) {
        let db = Vector3::from_fn(|i, _| self.linear.stiffness_profiles()[i].derivative(s));
        let dk0 = Vector3::from_fn(|i, _| self.linear.intrinsic_curvature()[i].derivative(s));
        (db, dk0)
    }
}

impl StoredEnergy for HyperbolicStiffening {
    fn density(&self, s: f64, kappa: &Vector3<f64>) -> f64 {
        let a = self.stiffening;
        let (u, b, _) = self.parts(s, kappa);
        (0..3)
            .map(|i| b[i] / (a * a) * ((a * u[i]).cosh() - 1.0))
            .sum()
    }

    /// M_i = B_i/a sinh(a u_i).
    fn moment(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        let (_, b, sh) = self.parts(s, kappa);
        b.component_mul(&sh) / self.stiffening
    }

    /// H = diag(B_i cosh(a u_i)).
    fn stiffness(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        let (u, b, _) = self.parts(s, kappa);
        let a = self.stiffening;
        Matrix3::from_diagonal(&Vector3::from_fn(|i, _| b[i] * (a * u[i]).cosh()))
    }

    /// ∂sM_i = B_i'/a sinh(a u_i) − B_i cosh(a u_i) κ⁰_i'.
    fn moment_rate(&self, s: f64, kappa: &Vector3<f64>) -> Vector3<f64> {
        let (u, b, sh) = self.parts(s, kappa);
        let (db, dk0) = self.rates(s);
        let a = self.stiffening;
        Vector3::from_fn(|i, _| db[i] / a * sh[i] - b[i] * (a * u[i]).cosh() * dk0[i])
    }

    /// ∂sH_ii = B_i' cosh(a u_i) − B_i a sinh(a u_i) κ⁰_i'.
    fn stiffness_rate(&self, s: f64, kappa: &Vector3<f64>) -> Matrix3<f64> {
        let (u, b, sh) = self.parts(s, kappa);
        let (db, dk0) = self.rates(s);
        let a = self.stiffening;
        Matrix3::from_diagonal(&Vector3::from_fn(|i, _| {
            db[i] * (a * u[i]).cosh() - b[i] * a * sh[i] * dk0[i]
        }))
    }

    /// ∂(Hv)/∂κ = diag(B_i a sinh(a u_i) v_i).
    fn stiffness_derivative(&self, s: f64, kappa: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
        let (_, b, sh) = self.parts(s, kappa);
        let a = self.stiffening;
        Matrix3::from_diagonal(&Vector3::from_fn(|i, _| b[i] * a * sh[i] * v[i]))
    }

    /// M1 = M3 = 0 exactly when κ1 = κ⁰1 and κ3 = κ⁰3.
    fn admits_planar_bending(&self) -> bool {
        self.linear.admits_planar_bending()
    }

    fn name(&self) -> &'static str {
        "hyperbolic"
    }
}

/// The standard catalog plus "hyperbolic" with its parameter `stiffening`.
pub fn catalog() -> EnergyCatalog {
    let mut catalog = EnergyCatalog::standard();
    catalog.register("hyperbolic", |spec| {
        spec.only(&["stiffening"])?;
        let a = spec.parameter("stiffening")?;
        if a <= 0.0 {
            return Err(EnergySpecError {
                field: "energy.parameters.stiffening".into(),
                message: format!("must be positive, got {a}"),
            });
        }
        Ok(Arc::new(HyperbolicStiffening {
            linear: spec.linear()?,
            stiffening: a,
        }))
    });
    catalog
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/hyperbolic_roll_up.toml"),
        PathBuf::from,
    );
    let problem = Problem::from_path_in(&path, &[], &catalog())?;
    let eq = solve(&problem.rod, &problem.model, &problem.options)?;
    let tip = eq.tip();
    println!("energy    {}", problem.rod.energy().name());
    println!("model     {}", problem.model.reason);
    println!("tip       {:?}", tip.position.as_slice());
    println!("residual  {:.3e}", eq.residual);
    Ok(())
}
