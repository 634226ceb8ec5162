//! Problem files in: TOML text and `--set key=value` overrides → a checked
//! [`Problem`]. The only code that reads problem files; no stage imports
//! it. Every table rejects unknown keys, syntax errors carry line and
//! column, and every physical check names the offending key
//! (docs/problem-files.md is the reference of every key). Before anything
//! is allocated, [`memory`] checks that the sizes a problem asks for fit
//! the memory budget.

mod arm_section;
mod continuation_section;
pub mod memory;
mod mesh;
mod problem;
mod strict;
mod support_section;
mod sweep_section;
mod turn_section;

pub use arm_section::ArmSection;
pub use continuation_section::{ContinuationSection, CurveSection, LinkSection, MEASURES};
pub use problem::{Problem, ProblemError, ProblemFile, ProfileSpec, MAX_PROBLEM_BYTES};
pub use support_section::SupportSection;
pub use sweep_section::{AxisSpec, SweepSection};
pub use turn_section::{TurnSection, MAX_TURN_ANGLE};
