//! cosserat: statics and stability of slender elastic rods.
//!
//! Data flows one way through the stages (docs/ARCHITECTURE.md):
//! problem file ([`io`]) → rod ([`model`]) → equations ([`equations`]) →
//! equilibrium ([`bvp`]) → output ([`io`]). A Rust user can skip the problem
//! file: build a [`model::Rod`] (with any [`model::StoredEnergy`]), pick a
//! [`model::ModelChoice`], and call [`bvp::solve`].

pub mod arm_chart;
pub mod bench;
pub mod bvp;
pub mod cli;
pub mod continuation;
pub mod equations;
pub mod io;
pub mod model;
pub mod optimize;
pub mod plot;
pub mod stability;
pub mod sweep;
pub mod validate;
