//! `cosserat bench solve|stability|continue|optimize PROBLEM`: the wall
//! time of exactly what the command computes (the functions the commands
//! call: [`crate::solve_command::compute_solve`],
//! [`crate::solve_command::compute_stability`], the continuation, the
//! search and what follows it in [`crate::optimize_command`]), with the
//! problem read once before and no result file written; one warm-up run,
//! then `--repeat` timed runs in this process. Printed with the work of a
//! run and the accuracy where a validation case gives a reference
//! ([`crate::bench_accuracy`]); `--csv FILE` writes the same as CSV
//! ([`crate::bench_record`]), claimed before the runs and written
//! atomically.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use cosserat::bvp::Discretization;
use cosserat::input::Problem;

use crate::bench_accuracy::{compare, method_name, Analysis};
use crate::bench_record::{Record, Times, Work};
use crate::exit::{fail, BAD_INPUT, NO_RESULT, OUTPUT};
use crate::solve_command::{compute_solve, compute_stability, StabilityFailure, StabilityOutcome};

/// The arguments every timed benchmark takes.
#[derive(Debug, Clone, clap::Args)]
pub struct TimedArgs {
    /// The problem file (TOML).
    pub problem: PathBuf,
    /// Override any key of the problem file, e.g. --set solver.method="collocation".
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Timed runs after the warm-up (default: solve 200, stability 20,
    /// continue 10, optimize 3).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeat: Option<u32>,
    /// Also write the measurement as CSV to this file.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Overwrite an existing CSV file.
    #[arg(long)]
    pub force: bool,
}

/// Which command is timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Timed {
    /// `cosserat solve`: the equilibrium and its stability verdict.
    Solve,
    /// `cosserat stability`: a critical load, or an equilibrium's decided stability.
    Stability,
    /// `cosserat continue`: the whole diagram.
    Continue,
    /// `cosserat optimize`: the search, R0 and the Fig. 5 map.
    Optimize,
}

impl Timed {
    /// The command's name.
    pub fn name(self) -> &'static str {
        match self {
            Timed::Solve => "solve",
            Timed::Stability => "stability",
            Timed::Continue => "continue",
            Timed::Optimize => "optimize",
        }
    }

    /// Timed runs when `--repeat` is not given: enough for a stable
    /// median within seconds to a minute on the shipped problems.
    pub fn default_repeat(self) -> usize {
        match self {
            Timed::Solve => 200,
            Timed::Stability => 20,
            Timed::Continue => 10,
            Timed::Optimize => 3,
        }
    }
}

/// Runs a timed benchmark; the exit code: 2 for a bad problem, `--set` or
/// CSV path (nothing computed or written), 3 when the command's
/// computation has no result, 1 when the CSV cannot be written.
pub fn run(which: Timed, args: &TimedArgs) -> ExitCode {
    let path = &args.problem;
    let problem = match crate::energies::read_problem(path, &args.set) {
        Ok(p) => p,
        Err(e) => return fail(BAD_INPUT, format!("{}: {e}", path.display())),
    };
    let _claim = match &args.csv {
        Some(csv) => match crate::solve_command::claim_outputs(&[csv], &[path], args.force) {
            Ok(c) => c,
            Err(code) => return code,
        },
        None => Vec::new(),
    };
    println!("problem   {}", path.display());
    let repeat = args.repeat.map_or(which.default_repeat(), |r| r as usize);
    let measured = match which {
        Timed::Solve => bench_solve(path, &problem, repeat),
        Timed::Stability => bench_stability(path, &problem, repeat),
        Timed::Continue => bench_continue(path, &problem, repeat),
        Timed::Optimize => bench_optimize(path, &problem, repeat),
    };
    let (times, work, accuracy) = match measured {
        Ok(m) => m,
        Err(code) => return code,
    };
    let record = Record {
        command: which.name(),
        problem: path.display().to_string(),
        set: args.set.clone(),
        times,
        work,
        accuracy,
    };
    print!("{}", record.summary());
    if let Some(csv) = &args.csv {
        let text = record.csv();
        if let Err(e) =
            cosserat::output::target::replace_atomically(csv, |tmp| std::fs::write(tmp, &text))
        {
            return fail(OUTPUT, e);
        }
        println!("written   {}", csv.display());
    }
    ExitCode::SUCCESS
}

/// Times, the work of the last run, the comparisons with references.
type Measured = Result<(Times, Work, Vec<crate::bench_accuracy::Accuracy>), ExitCode>;

/// One warm-up run of `compute`, then `repeat` timed runs; the times and
/// the last run's result, or the first failure.
fn time_runs<T>(
    repeat: usize,
    mut compute: impl FnMut() -> Result<T, ExitCode>,
) -> Result<(Times, T), ExitCode> {
    let mut last = compute()?;
    let mut runs = Vec::with_capacity(repeat);
    for _ in 0..repeat {
        let t = Instant::now();
        last = compute()?;
        runs.push(t.elapsed().as_secs_f64());
    }
    let times = Times::new(runs).ok_or_else(|| fail(NO_RESULT, "no timed run"))?;
    Ok((times, last))
}

fn bench_solve(path: &Path, problem: &Problem, repeat: usize) -> Measured {
    if problem.shape.is_some() {
        return Err(fail(
            BAD_INPUT,
            "a fixed-shape scene ([shape]) has no equilibrium to solve for; \
             use `cosserat bench stability`",
        ));
    }
    let (times, solved) = time_runs(repeat, || {
        compute_solve(problem).map_err(|e| crate::solve_command::solve_failed(&e))
    })?;
    let eq = &solved.eq;
    let work = Work {
        newton_iterations: Some(eq.iterations),
        integration_steps: Some(match &eq.discretization {
            Discretization::Collocation(sol) => sol.intervals(),
            Discretization::Shooting => eq.integration.accepted,
        }),
        elements: solved.decision.as_ref().ok().map(|d| d.elements),
        evaluations: None,
    };
    let values = |scale| crate::validate::tip_quantities(eq, problem, scale);
    let accuracy = compare(
        path,
        problem,
        Analysis::Solve,
        &method_name(eq.method),
        &values,
    );
    Ok((times, work, accuracy))
}

fn bench_stability(path: &Path, problem: &Problem, repeat: usize) -> Measured {
    let (times, outcome) = time_runs(repeat, || {
        compute_stability(problem).map_err(|e| match e {
            StabilityFailure::Solve(e) => crate::solve_command::solve_failed(&e),
            StabilityFailure::NoResult(e) => fail(NO_RESULT, e),
        })
    })?;
    Ok(match outcome {
        StabilityOutcome::FixedShape(c) => {
            let work = Work {
                elements: Some(problem.stability.elements()),
                ..Work::default()
            };
            let values = |_| {
                BTreeMap::from([
                    ("critical_load".to_string(), c.gamma),
                    ("chi".to_string(), c.gamma.map(f64::sqrt)),
                ])
            };
            let accuracy = compare(path, problem, Analysis::CriticalLoad, "fe", &values);
            (times, work, accuracy)
        }
        StabilityOutcome::Decided(eq, decision, _) => {
            let work = Work {
                newton_iterations: Some(eq.iterations),
                elements: Some(decision.elements),
                ..Work::default()
            };
            // No validation case decides an equilibrium's stability.
            (times, work, Vec::new())
        }
    })
}

fn bench_continue(path: &Path, problem: &Problem, repeat: usize) -> Measured {
    use cosserat::continuation::continuation;
    let (family, opts) = crate::continue_command::continued(problem, path)?;
    let (times, diagram) = time_runs(repeat, || {
        continuation(family, opts, &mut |_, _| true).map_err(|e| fail(NO_RESULT, e))
    })?;
    if let Ok(method) = family.derivative_method(opts.start) {
        println!(
            "F_p       {}",
            crate::continue_command::derivative_line(method)
        );
    }
    print!("{}", crate::bench::diagram_summary(&diagram));
    let work = Work {
        elements: Some(opts.stability.elements()),
        evaluations: Some(diagram.branches.iter().map(|b| b.points.len()).sum()),
        ..Work::default()
    };
    // No validation case holds a diagram's quantities: accuracy none.
    Ok((times, work, Vec::new()))
}

fn bench_optimize(path: &Path, problem: &Problem, repeat: usize) -> Measured {
    use crate::optimize_command::{after_search, search_only, with_straight};
    if problem.arm_taper.is_some() {
        return Err(fail(
            BAD_INPUT,
            format!(
                "{}: arm.taper: the bench times the prismatic search only",
                path.display()
            ),
        ));
    }
    if problem.arm_spatial.is_some() {
        // The planar search would be timed silently in its place.
        return Err(fail(
            BAD_INPUT,
            format!(
                "{}: arm.spatial: bench optimize times planar arms only",
                path.display()
            ),
        ));
    }
    let (Some((arm, search, straight)), Some((scene, samples))) =
        (&problem.arm, &problem.arm_scene)
    else {
        return Err(fail(
            BAD_INPUT,
            format!("{}: arm: the problem has no [arm] table", path.display()),
        ));
    };
    let (times, (opt, straight)) = time_runs(repeat, || {
        let (opt, beside) =
            with_straight(arm, scene, *straight, || search_only(arm, search, scene));
        let opt = opt.ok_or_else(|| {
            fail(
                NO_RESULT,
                "arm.bounds: no design with a finite critical load was found in the bounds",
            )
        })?;
        let (straight, _map) = after_search(arm, search, scene, (*samples, beside), &opt);
        Ok((opt, straight))
    })?;
    let work = Work {
        elements: Some(arm.stability.elements()),
        evaluations: Some(opt.evaluations),
        ..Work::default()
    };
    let values = |_| {
        BTreeMap::from([
            ("reach".to_string(), Some(opt.design.reach)),
            (
                "straight_reach".to_string(),
                straight.as_ref().map(|s| s.reach),
            ),
        ])
    };
    let accuracy = compare(path, problem, Analysis::Optimize, "fe", &values);
    Ok((times, work, accuracy))
}
