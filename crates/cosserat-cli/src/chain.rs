//! `cosserat continue` on a problem with `[[continuation.stage]]`: the
//! stages run one after the other into one diagram. Stage n + 1 starts
//! from the last point of stage n's first branch, stage n's key held at
//! the value it ended at ([`cosserat::input::Problem::stage`]), its first
//! point found by Newton from those unknowns
//! ([`cosserat::continuation::continuation_from`]), travelling towards
//! increasing values of its own key — as `continue --from DIAGRAM --point
//! B/last` with the stage's key would.

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use cosserat::continuation::{Diagram, Family, Point, RunState, Stage, StartPoint};
use cosserat::input::Problem;
use cosserat::output::write_stages;

use crate::continue_command::{plot_file, report, section_key, Run};
use crate::exit::{fail, BAD_INPUT, INTERRUPTED, NO_RESULT, OUTPUT};
use crate::stored_start::Start;

/// The chained stages of `problem` (its `[continuation]` the first),
/// written to `output` as they grow, charted to `plot`.
pub fn run_chain(problem: &Problem, path: &Path, output: &Path, plot: Option<&Path>) -> ExitCode {
    let Some((family, opts)) = &problem.continuation else {
        return fail(
            BAD_INPUT,
            "continuation: the problem has no [continuation] table",
        );
    };
    println!("problem   {}", path.display());
    println!(
        "model     {} ({})",
        problem.model.level.name(),
        problem.model.reason
    );
    let stages = 1 + problem.stage_keys.len();
    let started = Instant::now();
    let mut chain = Chain {
        text: &problem.text,
        output,
        tags: vec![],
        joint: None,
    };
    let key = family.key();
    println!(
        "stage 1   {key} from {} in [{}, {}]",
        opts.start, opts.bounds.0, opts.bounds.1
    );
    let mut before = match chain.stage(family, opts, &key, vec![], None) {
        Ok(last) => last,
        Err(code) => return code,
    };
    let mut held: Vec<(String, f64)> = vec![];
    let mut stage_problems = vec![];
    for number in 2..=stages {
        let Some((last, previous_key)) = before.take() else {
            let key = &problem.stage_keys[number - 2];
            let none = "the stage before ended without a point to start from";
            return chain.failed(number, key, &none);
        };
        held.push((previous_key, last.parameter));
        let stage = match problem.stage_in(number, &held, crate::energies::catalog()) {
            Ok(p) => p,
            Err(e) => return chain.failed(number, &problem.stage_keys[number - 2], &e),
        };
        stage_problems.push(stage);
        let stage = stage_problems.last().expect("just pushed");
        let (next, next_opts) = stage.continuation.as_ref().expect("a stage is continued");
        let previous = stage_family(problem, &stage_problems, number - 1);
        let key = next.key();
        let start = match carried(previous, next, &last) {
            Ok(x) => StartPoint::new(x, None),
            Err(e) => return chain.failed(number, &key, &e),
        };
        println!(
            "stage {number}   {key} from {} in [{}, {}], holding {}",
            next_opts.start,
            next_opts.bounds.0,
            next_opts.bounds.1,
            held.iter()
                .map(|(k, v)| format!("{k} = {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        before = match chain.stage(next, next_opts, &key, held.clone(), Some(start)) {
            Ok(last) => last,
            Err(code) => return code,
        };
    }
    let joint = chain.joint.take().expect("stage 1 ran");
    report(&joint);
    println!("time      {:.1} ms", started.elapsed().as_secs_f64() * 1e3);
    if let Err(e) = write_stages(output, &problem.text, &chain.tags, &joint, true) {
        return fail(OUTPUT, e);
    }
    println!("written   {}", output.display());
    if let Some(png) = plot {
        let measure = section_key(&problem.text, "measure").unwrap_or_else(|| "tip_x".into());
        if let Err(e) = plot_file(output, &measure, png) {
            return fail(OUTPUT, e);
        }
    }
    ExitCode::SUCCESS
}

/// The family of stage `number` (1 for the problem's own).
fn stage_family<'p>(problem: &'p Problem, stages: &'p [Problem], number: usize) -> &'p Family {
    let p = if number == 1 {
        problem
    } else {
        &stages[number - 2]
    };
    &p.continuation.as_ref().expect("a stage is continued").0
}

/// The unknowns of `last` (a point of `before`) as the unknowns of `next`:
/// the same shooting unknowns, rescaled by the new family's weights.
fn carried(before: &Family, next: &Family, last: &Point) -> Result<Vec<f64>, String> {
    if before.size() != next.size() {
        return Err(format!(
            "the stage before ended with {} unknowns, this stage's discretization has {}",
            before.size(),
            next.size()
        ));
    }
    Ok(next.scaled(&before.unscaled(&last.unknowns)))
}

/// The joint diagram of the stages run so far and where it is written.
struct Chain<'a> {
    text: &'a str,
    output: &'a Path,
    tags: Vec<Stage>,
    joint: Option<Diagram>,
}

impl Chain<'_> {
    /// Runs one stage (from `start`, or the problem's own solve) and
    /// appends its diagram: the last point of its first branch and its key
    /// for the next stage, none when it was interrupted (written, exit
    /// 130) — or the exit code of a failure.
    fn stage(
        &mut self,
        family: &Family,
        opts: &cosserat::continuation::ContinuationOptions,
        key: &str,
        held: Vec<(String, f64)>,
        start: Option<StartPoint>,
    ) -> Result<Option<(Point, String)>, ExitCode> {
        let number = self.tags.len() + 1;
        let first_branch = self.joint.as_ref().map_or(0, |d| d.branches.len());
        let tag = if number == 1 {
            Stage::first(key)
        } else {
            Stage::later(key, held, first_branch)
        };
        let mut tags = self.tags.clone();
        tags.push(tag);
        let run = Run {
            family,
            opts,
            output: self.output,
            text: self.text,
            parameter_name: key,
        };
        let save = |d: &Diagram| {
            let joint = self.joined(d.clone(), number).map_err(|e| {
                cosserat::output::OutputError::Unusable(format!("stage {number}: {e}"))
            })?;
            write_stages(self.output, self.text, &tags, &joint, true)
        };
        let start = start.map(Start::Point);
        let bar = crate::progress::Meter::spinner();
        let diagram = match run.follow_saving(&bar, None, start.as_ref(), &save) {
            Ok(d) => d,
            Err(e) => return Err(self.failed(number, key, &e)),
        };
        let last = diagram
            .branches
            .first()
            .and_then(|b| b.points.last())
            .cloned();
        let interrupted = diagram.stop_reason == RunState::Interrupted;
        let joint = self
            .joined(diagram, number)
            .map_err(|e| fail(NO_RESULT, e))?;
        self.joint = Some(joint);
        self.tags = tags;
        if interrupted {
            let joint = self.joint.as_ref().expect("just set");
            if let Err(e) = write_stages(self.output, self.text, &self.tags, joint, true) {
                return Err(fail(OUTPUT, e));
            }
            eprintln!(
                "interrupted in stage {number}: every point computed so far is in {}; a chained \
                 run is not resumed, run it again",
                self.output.display()
            );
            return Err(ExitCode::from(INTERRUPTED));
        }
        Ok(last.map(|p| (p, key.to_string())))
    }

    /// Stage `number` did not run: the earlier stages' diagram is written
    /// (when there are any) and the failure named by the stage.
    fn failed(&self, number: usize, key: &str, e: &dyn std::fmt::Display) -> ExitCode {
        let kept = match &self.joint {
            Some(joint) => match write_stages(self.output, self.text, &self.tags, joint, true) {
                Ok(()) => format!(
                    "; stages 1 to {} are in {}",
                    number - 1,
                    self.output.display()
                ),
                Err(w) => format!("; the earlier stages were not written: {w}"),
            },
            None => String::new(),
        };
        fail(NO_RESULT, format!("stage {number} ({key}): {e}{kept}"))
    }

    /// The stages so far with `diagram` (stage `number`) appended.
    fn joined(&self, diagram: Diagram, number: usize) -> Result<Diagram, String> {
        let Some(joint) = &self.joint else {
            return Ok(diagram);
        };
        let mut joint = joint.clone();
        joint.append(diagram, number)?;
        Ok(joint)
    }
}
