//! Numerical building blocks with nothing of rods in them: Gauss–Legendre
//! quadrature tables ([`quadrature`]), scalar root finding and
//! one-dimensional search ([`scalar`]), symmetric banded matrices with
//! their LDLᵀ factorization and inertia ([`banded`]), and the DOP853
//! integrator ([`integrator`]). The stages above use them; nothing here
//! imports a stage. `stability::banded` and `bvp::integrator` remain as
//! re-exports of the last two.

pub mod banded;
pub mod integrator;
pub mod quadrature;
pub mod scalar;
