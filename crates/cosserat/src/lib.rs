//! cosserat: statics and stability of slender elastic rods.
//!
//! A rod is a curve r(s), 0 ≤ s ≤ L, carrying an orthonormal director
//! frame (d1, d2, d3) with d_i' = k × d_i, k = κ_i d_i. A hyperelastic
//! material has a stored energy W(s, κ) (with the strain ν = Rᵀr' at the
//! Cosserat level), the moment M = ∂W/∂κ, and equilibria satisfy the
//! balance laws n' + f = 0, m' + r' × n = 0 under dead loads, a clamp at
//! s = 0 and a tip condition at s = L (Antman, *Nonlinear Problems of
//! Elasticity*, 2nd ed., Ch. 4 and 8). The crate computes those
//! equilibria, decides their stability from the second variation δ²V,
//! continues them in a parameter (pseudo-arclength, Keller 1977), and
//! optimizes the longest soft robotic arm of Sipos & Várkonyi (2019).
//!
//! # Stages
//!
//! Data flows one way; a lower stage never imports a higher one
//! (docs/ARCHITECTURE.md has the full table and the tests of each stage).
//!
//! | stage | module | takes | gives |
//! |---|---|---|---|
//! | numerics | [`numerics`] | numbers | the damped Newton method (a system's residual and linear solve) with its convergence test, Gauss–Legendre tables, scalar root finding and maximization, the banded LDLᵀ with inertia, the eigensolvers of banded pencils (inertia counts, shift-invert Lanczos, constrained pencils), the DOP853 integrator — nothing of rods |
//! | model | [`model`] | lengths, stiffnesses, loads | [`model::Rod`]: length, `Arc<dyn` [`model::StoredEnergy`]`>`, clamp, [`model::DeadLoads`], an optional [`model::TipSupport`]; n(s) = P + R + ∫_s^L f is known up to the tip reaction R |
//! | equations | [`equations`] | a rod and its [`model::ModelLevel`] | a [`equations::RodEquations`]: the first-order ODEs (planar 4, Kirchhoff 9, Cosserat 9 with ν = e3 + S⁻¹N), their linearization, clamp and tip residuals |
//! | equilibrium | [`bvp`] | the equations | [`bvp::solve`] by shooting, multiple shooting or Gauss–Legendre collocation with damped Newton → [`bvp::Equilibrium`]: samples (s, r, d1, d2, d3, κ, M, n), unknowns, Jacobian |
//! | stability | [`stability`] | an equilibrium | [`stability::analyze`]: per quadrature point the [`stability::FormCoefficients`] (A = H, B, C) of δ²V, finite elements, banded K and G, their inertia and lowest eigenpairs (numerics) → [`stability::Stability`] (spectra, Morse index); [`stability::critical_load`] of a fixed shape |
//! | continuation | [`continuation`] | a [`continuation::Family`] F(x, p) = 0 | [`continuation::continuation`]: predictor–corrector, eigenvalue tracking, folds and branch points → [`continuation::Diagram`] |
//! | study | [`study`] | a [`study::Problem`] | [`study::arm`]: fixed-shape critical loads over the shape coefficients, Sobol' + Nelder–Mead → [`study::arm::ArmOptimum`]; [`study::sweep`]: a job at every point of a grid in parallel → one [`study::sweep::Record`] per point |
//!
//! Beside the stages, and imported by none of them:
//!
//! | module | takes | gives |
//! |---|---|---|
//! | [`input`] | TOML text, `--set` overrides | a checked [`study::Problem`] (the only code that reads problem files) |
//! | [`output`] | results | HDF5 files (feature `hdf5`: `output::write_equilibrium`, `write_stability`, `write_diagram`, `write_arm_study`, `write_sweep`), written atomically to outputs claimed by [`output::target`] and sealed by [`output::seal`] |
//!
//! [`references`] holds the closed forms (elliptic
//! integrals, Bessel zeros) that validation and tests compare against. The
//! `cosserat` command, its charts, the bench and the validation runner live
//! in the separate crate `cosserat-cli`.
//!
//! # From Rust
//!
//! A program can skip the problem file: build a [`model::Rod`] (with any
//! [`model::StoredEnergy`]), pick a [`model::ModelChoice`], and call
//! [`bvp::solve`]; the README's example does so and runs as a doctest.

#![warn(missing_docs)]

pub mod bvp;
pub mod continuation;
pub mod equations;
pub mod input;
pub mod model;
pub mod numerics;
pub mod output;
pub mod references;
pub mod stability;
pub mod study;

/// The code blocks of the repository's README, compiled and run as
/// doctests so that its library example cannot go stale.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeDoctests;
