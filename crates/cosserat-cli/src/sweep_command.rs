//! `cosserat sweep` and `cosserat merge`: a problem's analysis on the grid
//! of its `[sweep]` table, checkpointed as it goes, and the join of shard
//! files.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use crate::sweep_figure as figure;
use cosserat::continuation::RunState;
use cosserat::input::Problem;
use cosserat::output::target::{replace_atomically, Claim};
use cosserat::output::{read_sweep, write_sweep, SweepHeader};
use cosserat::study::sweep::Sweep;
use cosserat::study::sweep::{run, ArmJob, Job, Record, Shard, SolveJob, SweepPlan};

use crate::exit::{fail, BAD_INPUT, INTERRUPTED, OUTPUT};
use crate::signals;

/// How often a running sweep saves its finished points.
const CHECKPOINT: Duration = Duration::from_secs(1);

/// The options of `cosserat sweep`.
pub struct SweepArgs {
    /// The problem file with a `[sweep]` table.
    pub path: PathBuf,
    /// The HDF5 results, also the checkpoint.
    pub output: PathBuf,
    /// `I/N`: compute shard I of N (every N-th line of the grid).
    pub shard: Option<String>,
    /// Worker threads (default: all cores).
    pub threads: Option<u16>,
    /// Go on with the run saved in `output`.
    pub resume: bool,
    /// Also draw the sweep to this .png or .svg.
    pub plot: Option<PathBuf>,
    /// `KEY=VALUE` overrides of the problem file.
    pub set: Vec<String>,
    /// Overwrite an existing output.
    pub force: bool,
}

/// A checked sweep, ready to run.
struct Setup {
    problem: Problem,
    sweep: Sweep,
    shard: Shard,
    done: Vec<Record>,
    job: Box<dyn Job>,
    threads: usize,
    _claims: Vec<Claim>,
}

/// Runs a sweep.
pub fn run_sweep(args: &SweepArgs) -> ExitCode {
    match prepare(args) {
        Ok(Some(setup)) => execute(args, &setup),
        Ok(None) => ExitCode::SUCCESS,
        Err(code) => code,
    }
}

/// Reads and checks everything before any work: the problem, the
/// `[sweep]` table, every grid point's problem, the shard, the output (or
/// the file to resume). Ok(None): nothing left to do.
fn prepare(args: &SweepArgs) -> Result<Option<Setup>, ExitCode> {
    let at = |e: &dyn std::fmt::Display| fail(BAD_INPUT, format!("{}: {e}", args.path.display()));
    let threads = threads(args.threads)?;
    let problem = crate::energies::read_problem(&args.path, &args.set).map_err(|e| at(&e))?;
    let mut sweep = problem
        .sweep
        .clone()
        .ok_or_else(|| at(&"sweep: the problem has no [sweep] table"))?;
    // Warm starts are for the arm's search; solves run point by point.
    sweep.warm_start &= problem.arm.is_some();
    let shard = match &args.shard {
        Some(s) => Shard::parse(s).map_err(|e| fail(BAD_INPUT, format!("--shard: {e}")))?,
        None => Shard::ALL,
    };
    check_points(&problem.text, &sweep, shard).map_err(|e| at(&e))?;
    if problem.arm_taper.is_some() {
        return Err(fail(
            BAD_INPUT,
            "arm.taper: a tapered arm runs with `cosserat optimize` only, not in a sweep",
        ));
    }
    let job: Box<dyn Job> = match &problem.arm {
        Some(_) => Box::new(ArmJob {
            families: sweep.families,
            warm_samples: sweep.warm_samples,
            warm_iterations: sweep.warm_iterations,
        }),
        None => Box::new(SolveJob),
    };
    let expected = header(&problem, &sweep, shard, job.kind(), RunState::InProgress);
    if args.plot.is_some() {
        figure::chartable(&expected.kind, &expected.keys).map_err(|e| at(&e))?;
    }
    let mut outputs: Vec<&Path> = vec![&args.output];
    outputs.extend(args.plot.as_deref());
    let claims =
        crate::solve_command::claim_outputs(&outputs, &[&args.path], args.force || args.resume)?;
    let done = if args.resume && args.output.exists() {
        let Some(done) = resumable(&args.output, &expected)? else {
            redraw(&args.output, args.plot.as_deref())?;
            return Ok(None);
        };
        done
    } else {
        vec![]
    };
    Ok(Some(Setup {
        problem,
        sweep,
        shard,
        done,
        job,
        threads,
        _claims: claims,
    }))
}

/// The worker threads asked for (0: one per core), at most four per core.
fn threads(asked: Option<u16>) -> Result<usize, ExitCode> {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    match asked.map(usize::from) {
        None => Ok(0),
        Some(n) if n <= 4 * cores => Ok(n),
        Some(n) => Err(fail(
            BAD_INPUT,
            format!(
                "--threads {n}: this machine has {cores} cores; more than {} threads only slow a sweep down",
                4 * cores
            ),
        )),
    }
}

/// Reads the problem at every point of this shard, so that a bad point is
/// refused before any point is computed.
fn check_points(text: &str, sweep: &Sweep, shard: Shard) -> Result<(), String> {
    let points = point_problems(text, sweep);
    let plan = SweepPlan {
        problem_at: &points,
        sweep,
        shard,
    };
    for i in plan.members() {
        plan.problem(i)
            .map_err(|e| format!("sweep point {i} ({}): {e}", sweep.overrides(i).join(", ")))?;
    }
    Ok(())
}

/// The problem at each grid point: the base problem's text read with the
/// point's `--set` overrides.
fn point_problems<'a>(
    text: &'a str,
    sweep: &'a Sweep,
) -> impl Fn(usize) -> Result<Problem, String> + Sync + 'a {
    move |i| {
        crate::energies::read_problem_text(text, &sweep.overrides(i)).map_err(|e| e.to_string())
    }
}

fn header(
    problem: &Problem,
    sweep: &Sweep,
    shard: Shard,
    kind: &str,
    reason: RunState,
) -> SweepHeader {
    let points = point_problems(&problem.text, sweep);
    let plan = SweepPlan {
        problem_at: &points,
        sweep,
        shard,
    };
    SweepHeader {
        problem: problem.text.clone(),
        kind: kind.to_string(),
        shard: shard.to_string(),
        stop_reason: reason,
        keys: sweep.axes.iter().map(|a| a.key.clone()).collect(),
        axes: sweep.axes.iter().map(|a| a.values.clone()).collect(),
        members: plan.members().len(),
    }
}

/// The finished points of a saved sweep of the same problem, grid and
/// shard; None when it is complete.
fn resumable(path: &Path, expected: &SweepHeader) -> Result<Option<Vec<Record>>, ExitCode> {
    let (saved, records) = read_sweep(path)
        .map_err(|e| fail(BAD_INPUT, format!("{}: cannot resume: {e}", path.display())))?;
    let same = saved.problem == expected.problem
        && saved.kind == expected.kind
        && saved.keys == expected.keys
        && saved.axes == expected.axes
        && saved.shard == expected.shard;
    if !same {
        return Err(fail(
            BAD_INPUT,
            format!(
                "{}: made from a different problem, grid or shard (or other --set values); \
                 cannot resume",
                path.display()
            ),
        ));
    }
    if !saved.stop_reason.resumable() {
        println!("nothing to resume: {} is complete", path.display());
        return Ok(None);
    }
    println!(
        "resume    {} finished points from {}",
        records.len(),
        path.display()
    );
    Ok(Some(records))
}

/// Prints what is about to run.
fn announce(args: &SweepArgs, setup: &Setup, members: usize) {
    println!("problem   {}", args.path.display());
    let axes: Vec<String> = setup
        .sweep
        .axes
        .iter()
        .map(|a| format!("{} × {}", a.key, a.values.len()))
        .collect();
    println!(
        "sweep     {} ({} points), shard {}: {members} points, {} done; job {}",
        axes.join(", "),
        setup.sweep.points(),
        setup.shard,
        setup.done.len(),
        setup.job.kind()
    );
}

/// Runs the points, checkpointing every second; writes the final file.
fn execute(args: &SweepArgs, setup: &Setup) -> ExitCode {
    let points = point_problems(&setup.problem.text, &setup.sweep);
    let plan = SweepPlan {
        problem_at: &points,
        sweep: &setup.sweep,
        shard: setup.shard,
    };
    let members = plan.members().len();
    announce(args, setup, members);
    let before = setup.done.len();
    let bar = crate::progress::Meter::counted(members, before);
    let kind = setup.job.kind();
    let running = header(
        &setup.problem,
        &setup.sweep,
        setup.shard,
        kind,
        RunState::InProgress,
    );
    let last_save = Mutex::new(Instant::now());
    let on_point = |all: &[Record]| {
        bar.set_position(all.len() as u64);
        let mut last = last_save.lock().expect("no panic while saving");
        if last.elapsed() >= CHECKPOINT {
            let mut sorted = all.to_vec();
            sorted.sort_by_key(|r| r.index);
            if let Err(e) = write_sweep(&args.output, &running, &sorted, true) {
                bar.println(format!("warning: checkpoint not written: {e}"));
            }
            *last = Instant::now();
        }
    };
    let start = Instant::now();
    let threads = setup.threads;
    let done = setup.done.clone();
    signals::set_mode(signals::Mode::NextPoint);
    let records = match run(
        &plan,
        setup.job.as_ref(),
        threads,
        done,
        signals::flag(),
        &on_point,
    ) {
        Ok(r) => r,
        Err(e) => {
            return fail(
                BAD_INPUT,
                format!("--threads {threads}: no thread pool: {e}"),
            )
        }
    };
    bar.finish_and_clear();
    let elapsed = start.elapsed().as_secs_f64();
    let computed = records.len() - before;
    println!(
        "time      {elapsed:.1} s for {computed} points ({:.3} s per point, {} threads)",
        elapsed / computed.max(1) as f64,
        rayon_threads(threads)
    );
    let stopped = signals::requested() && records.len() < members;
    finish(args, running, &records, stopped)
}

/// Writes the final file (marked completed or interrupted), reports, and
/// draws the chart of a completed sweep.
fn finish(args: &SweepArgs, running: SweepHeader, records: &[Record], stopped: bool) -> ExitCode {
    let reason = if stopped {
        RunState::Interrupted
    } else {
        RunState::Completed
    };
    let header = SweepHeader {
        stop_reason: reason,
        ..running
    };
    if let Err(e) = write_sweep(&args.output, &header, records, true) {
        return fail(OUTPUT, e);
    }
    summarize(&header, records);
    println!("written   {}", args.output.display());
    if stopped {
        eprintln!(
            "interrupted: {} of {} points are in {}; rerun with --resume",
            records.len(),
            header.members,
            args.output.display()
        );
        return ExitCode::from(INTERRUPTED);
    }
    match &args.plot {
        Some(out) => plot(out, &header, records),
        None => ExitCode::SUCCESS,
    }
}

fn rayon_threads(asked: usize) -> usize {
    if asked > 0 {
        asked
    } else {
        std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
    }
}

/// Per family: points with an optimum and the range of R*; the eq. (61)
/// fit on two-axis arm sweeps; convergence counts of solve sweeps.
fn summarize(header: &SweepHeader, records: &[Record]) {
    let mut statuses: std::collections::BTreeMap<&str, std::collections::BTreeMap<&str, usize>> =
        std::collections::BTreeMap::new();
    for r in records {
        for (name, value) in &r.labels {
            *statuses
                .entry(name.as_str())
                .or_default()
                .entry(value.as_str())
                .or_default() += 1;
        }
    }
    for (name, counts) in &statuses {
        let text: Vec<String> = counts.iter().map(|(v, n)| format!("{n} {v}")).collect();
        println!("{name:<18}{}", text.join(", "));
    }
    for f in 0..2 {
        let reach: Vec<f64> = records
            .iter()
            .filter_map(|r| r.number(&format!("family_{f}/reach")))
            .filter(|v| v.is_finite())
            .collect();
        if let (Some(lo), Some(hi)) = (
            reach.iter().copied().reduce(f64::min),
            reach.iter().copied().reduce(f64::max),
        ) {
            println!("family {f}  R* from {lo:.4} to {hi:.4}");
        }
    }
    if let Some(fit) = figure::reach_fit(header, records, 0) {
        println!(
            "fit (61)  {} = Ω {}^(−ι) on {} contours of R*: common ι = {:.4} (rms of ln {}: {:.3})",
            header.keys[1],
            header.keys[0],
            fit.contours.len(),
            fit.iota,
            header.keys[1],
            fit.rms
        );
        for c in &fit.contours {
            println!(
                "          R* = {:.3}: Ω = {:.3} (common ι); this contour alone ι = {:.3} ({} points)",
                c.level, c.omega, c.iota, c.points
            );
        }
    }
}

/// The chart of a completed sweep file asked for by `--resume --plot`:
/// nothing is left to compute, but the chart is drawn from the file.
fn redraw(path: &Path, chart: Option<&Path>) -> Result<(), ExitCode> {
    let Some(out) = chart else {
        return Ok(());
    };
    let (header, records) = read_sweep(path)
        .map_err(|e| fail(BAD_INPUT, format!("{}: cannot read: {e}", path.display())))?;
    let code = plot(out, &header, &records);
    if code == ExitCode::SUCCESS {
        Ok(())
    } else {
        Err(code)
    }
}

fn plot(out: &Path, header: &SweepHeader, records: &[Record]) -> ExitCode {
    match replace_atomically(out, |tmp| figure::draw(tmp, header, records)) {
        Ok(()) => {
            println!("plotted   {}", out.display());
            ExitCode::SUCCESS
        }
        Err(e) => fail(OUTPUT, e),
    }
}

/// Joins shard files of one sweep; refuses files of different problems or
/// grids and overlapping points (exit 2, nothing written).
pub fn run_merge(inputs: &[PathBuf], output: &Path, chart: Option<&Path>, force: bool) -> ExitCode {
    let mut outputs: Vec<&Path> = vec![output];
    outputs.extend(chart);
    let sources: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    let _claims = match crate::solve_command::claim_outputs(&outputs, &sources, force) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let mut merged: Option<SweepHeader> = None;
    let mut records: Vec<Record> = vec![];
    let mut complete = true;
    for path in inputs {
        let (h, r) = match read_sweep(path) {
            Ok(x) => x,
            Err(e) => {
                return fail(
                    BAD_INPUT,
                    format!("{}: not a sweep file: {e}", path.display()),
                )
            }
        };
        if let Some(m) = &merged {
            if let Some(what) = mismatch(m, &h) {
                return fail(
                    BAD_INPUT,
                    format!(
                        "{}: {what} differs from {}",
                        path.display(),
                        inputs[0].display()
                    ),
                );
            }
        }
        complete &= h.stop_reason == RunState::Completed;
        let seen: std::collections::BTreeSet<usize> = records.iter().map(|r| r.index).collect();
        if let Some(dup) = r.iter().find(|x| seen.contains(&x.index)) {
            return fail(
                BAD_INPUT,
                format!(
                    "{}: point {} is also in an earlier file (overlapping shards)",
                    path.display(),
                    dup.index
                ),
            );
        }
        records.extend(r);
        merged.get_or_insert(h);
    }
    let Some(mut header) = merged else {
        return fail(BAD_INPUT, "merge: no input files");
    };
    if chart.is_some() {
        if let Err(e) = figure::chartable(&header.kind, &header.keys) {
            return fail(BAD_INPUT, e);
        }
    }
    records.sort_by_key(|r| r.index);
    header.shard = "merged".into();
    header.members = header.points();
    header.stop_reason = if complete && records.len() == header.points() {
        RunState::Completed
    } else {
        RunState::Partial
    };
    if let Err(e) = write_sweep(output, &header, &records, true) {
        return fail(OUTPUT, e);
    }
    println!(
        "merged    {} files, {} of {} points ({}) into {}",
        inputs.len(),
        records.len(),
        header.points(),
        header.stop_reason,
        output.display()
    );
    summarize(&header, &records);
    match chart {
        Some(out) => plot(out, &header, &records),
        None => ExitCode::SUCCESS,
    }
}

/// What makes two sweep files not parts of one sweep.
fn mismatch(a: &SweepHeader, b: &SweepHeader) -> Option<&'static str> {
    if a.problem != b.problem {
        Some("the problem")
    } else if a.kind != b.kind {
        Some("the job kind")
    } else if a.keys != b.keys || a.axes != b.axes {
        Some("the grid")
    } else if a.shard.split('/').nth(1) != b.shard.split('/').nth(1) {
        Some("the shard count")
    } else {
        None
    }
}
