//! Studies built on the stages below: the longest soft robotic arm
//! ([`arm`]), and sweeps of any problem over a grid of its keys
//! ([`sweep`]). [`Problem`] gathers what a problem file asks for.

pub mod arm;
mod problem;
pub mod sweep;

pub use problem::{Curve, Problem};
