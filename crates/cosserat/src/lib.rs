//! cosserat: statics and stability of slender elastic rods.
//!
//! Data flows one way through the stages (docs/ARCHITECTURE.md):
//! problem file ([`io`]) → rod ([`model`]) → equations ([`equations`]) →
//! equilibrium ([`bvp`]) → output ([`io`]). A Rust user can skip the problem
//! file: build a [`model::Rod`] (with any [`model::StoredEnergy`]), pick a
//! [`model::ModelChoice`], and call [`bvp::solve`].

pub mod bvp;
pub mod continuation;
pub mod equations;
pub mod io;
pub mod model;
pub mod numerics;
pub mod optimize;
pub mod references;
pub mod stability;
pub mod sweep;

/// The code blocks of the repository's README, compiled and run as
/// doctests so that its library example cannot go stale.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeDoctests;
