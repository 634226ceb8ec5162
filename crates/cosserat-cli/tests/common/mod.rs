//! Helpers shared by the CLI's tests: running the built binary (`run`),
//! the shipped problems and small problem texts (`problems`), and reading
//! result files (`h5`).
#![allow(dead_code)]

pub mod h5;
pub mod problems;
pub mod run;
