//! Numerical building blocks with nothing of rods in them: Gauss–Legendre
//! quadrature tables ([`quadrature`]) and scalar root finding and
//! one-dimensional search ([`scalar`]). The stages above use them; nothing
//! here imports a stage.

pub mod quadrature;
pub mod scalar;
