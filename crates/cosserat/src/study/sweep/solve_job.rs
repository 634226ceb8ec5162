//! The equilibrium at one grid point of a problem without an `[arm]`
//! table: tip position, residual, Newton iterations, convergence — an
//! unconverged point is recorded as such, never as a result.

use super::{Job, Record};
use crate::bvp::solve;
use crate::study::Problem;

/// The solve job.
#[derive(Debug, Clone, Copy, Default)]
pub struct SolveJob;

impl Job for SolveJob {
    fn kind(&self) -> &'static str {
        "solve"
    }

    fn run(
        &self,
        index: usize,
        problem: &Problem,
        _previous: Option<&Record>,
        _stop: &dyn Fn() -> bool,
    ) -> Record {
        let mut record = Record::new(index);
        match solve(&problem.rod, &problem.model, &problem.options) {
            Ok(eq) if eq.residual <= problem.options.newton.tolerance => {
                let tip = eq.tip().position;
                record.set("solve/tip_position", vec![tip[0], tip[1], tip[2]]);
                record.set("solve/residual", vec![eq.residual]);
                record.set("solve/iterations", vec![eq.iterations as f64]);
                record.label("solve/status", "converged");
            }
            Ok(eq) => {
                record.set("solve/tip_position", vec![f64::NAN; 3]);
                record.set("solve/residual", vec![eq.residual]);
                record.set("solve/iterations", vec![eq.iterations as f64]);
                record.label("solve/status", "residual_above_tolerance");
            }
            Err(e) => {
                record.set("solve/tip_position", vec![f64::NAN; 3]);
                record.set("solve/residual", vec![f64::NAN]);
                record.set("solve/iterations", vec![f64::NAN]);
                record.label("solve/status", &format!("failed: {e}"));
            }
        }
        record
    }
}
