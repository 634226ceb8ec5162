//! Numerical building blocks with nothing of rods in them: Gauss–Legendre
//! quadrature tables ([`quadrature`]), scalar root finding and
//! one-dimensional search ([`scalar`]), symmetric banded matrices with
//! their LDLᵀ factorization and inertia ([`banded`]), general banded LU
//! ([`band_lu`]) and the plain or bordered solves of the almost block
//! diagonal Jacobians of multiple shooting ([`staircase`]), the DOP853
//! integrator ([`integrator`]), the damped Newton method with its
//! convergence test ([`newton`]) and a dense LU for its small systems
//! ([`dense`]), and the eigensolvers of symmetric-definite banded pencils
//! (K, G): inertia counts, shift-invert Lanczos ([`eigen`]), and the pencil
//! restricted to the null space of a few constraints ([`constrained`]),
//! and their warm start from a nearby pencil's eigenvectors ([`subspace`]).
//! The stages above use them; nothing here imports a stage.
//! `stability::{banded, eigen, constrained}`, `bvp::integrator` and
//! `bvp::newton::Convergence` remain as re-exports.

pub mod band_lu;
pub mod banded;
pub mod constrained;
pub mod dense;
pub mod eigen;
pub mod integrator;
pub mod newton;
pub mod quadrature;
pub mod scalar;
pub mod staircase;
pub mod subspace;
