//! Independent references for the tests: closed forms evaluated here, never
//! the solver's own output.
#![allow(dead_code)]

pub mod bessel;
pub mod columns;
pub mod elliptic;
pub mod fuzz;
pub mod references;
