//! The `cosserat` command with one extra energy, written once for any
//! number type and without a single derivative: every command (`solve`,
//! `stability`, `continue`, `sweep`, `check-energy`, ...) accepts
//! `kind = "hyperbolic"` in problem files.
//!
//!   W(s, κ) = Σ_i B_i(s)/a² (cosh(a (κ_i − κ⁰_i(s))) − 1),
//!
//! the linear energy for small curvature changes, stiffening beyond 1/a.
//!
//! Run: `cargo run --release -p cosserat-cli --example own_energy -- solve
//! crates/cosserat/examples/hyperbolic_roll_up.toml`.

use std::process::ExitCode;
use std::sync::Arc;

use cosserat::model::{lift, AutoDiff, Density, EnergyCatalog, LinearElastic};
use num_dual::DualNum;

/// The hyperbolic material: the file's profiles and a (m).
#[derive(Debug)]
pub struct Hyperbolic {
    profiles: LinearElastic,
    a: f64,
}

impl Density for Hyperbolic {
    fn density<D: DualNum<Primitive = f64> + Copy>(&self, s: D, kappa: [D; 3]) -> D {
        let at = s.re();
        let (b, k0) = (
            self.profiles.stiffness_profiles(),
            self.profiles.intrinsic_curvature(),
        );
        (0..3)
            .map(|i| {
                let u = kappa[i] - lift(s, k0[i].value(at), k0[i].derivative(at));
                let bi = lift(s, b[i].value(at), b[i].derivative(at));
                bi * (((u * self.a).cosh() - 1.0) / (self.a * self.a))
            })
            .sum()
    }

    fn name(&self) -> &'static str {
        "hyperbolic"
    }

    /// Even in each κ_i − κ⁰_i: planar when κ⁰₁ = κ⁰₃ = 0.
    fn admits_planar_bending(&self) -> bool {
        let k0 = self.profiles.intrinsic_curvature();
        k0[0].is_zero() && k0[2].is_zero()
    }
}

/// The standard energies and `hyperbolic` (parameter `stiffening` = a > 0).
pub fn catalog() -> EnergyCatalog {
    let mut catalog = EnergyCatalog::standard();
    catalog.register("hyperbolic", |spec| {
        spec.only(&["stiffening"])?;
        let a = spec.parameter("stiffening")?;
        if a <= 0.0 {
            return Err(cosserat::model::EnergySpecError {
                field: "energy.parameters.stiffening".into(),
                message: format!("must be > 0, got {a}"),
            });
        }
        let profiles = spec.linear()?;
        Ok(Arc::new(AutoDiff::new(Hyperbolic { profiles, a })))
    });
    catalog
}

#[allow(dead_code)] // the tests include this file as a module
fn main() -> ExitCode {
    cosserat_cli::main_with_energies(catalog())
}
