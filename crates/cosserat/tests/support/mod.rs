//! Helpers shared by the tests: the fuzz runner, column references that the
//! library has no use for, and the rods and problems several tests build.
//! The closed forms themselves live once, in `cosserat::references`.
#![allow(dead_code)]

pub mod columns;
pub mod fuzz;
pub mod methods;
pub mod parameter_derivative;
pub mod quadrature;
pub mod rods;
