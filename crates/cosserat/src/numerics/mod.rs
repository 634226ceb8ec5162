//! Numerical building blocks with nothing of rods in them: Gauss–Legendre
//! quadrature tables ([`quadrature`]), scalar root finding and
//! one-dimensional search ([`scalar`]), symmetric banded matrices with
//! their LDLᵀ factorization and inertia ([`banded`]), the DOP853
//! integrator ([`integrator`]), and the damped Newton method with its
//! convergence test ([`newton`]). The stages above use them; nothing here
//! imports a stage. `stability::banded`, `bvp::integrator` and
//! `bvp::newton::Convergence` remain as re-exports.

pub mod banded;
pub mod dense;
pub mod integrator;
pub mod newton;
pub mod quadrature;
pub mod scalar;
