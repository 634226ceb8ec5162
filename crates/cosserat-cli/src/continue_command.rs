//! `cosserat continue` and `cosserat plot`: bifurcation diagrams from a
//! problem file's `[continuation]` table, saved as they grow.

use std::path::Path;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use crate::plot::{draw, problem_view, read_diagram};
use crate::progress::Meter;
use crate::stored_start::{solved_start, stored_start, Start, StoredStart};
use cosserat::continuation::{
    continuation, continuation_from, switch_from, ContinuationError, ContinuationOptions, Diagram,
    Family, Progress, RunState, SavedDiagram,
};
use cosserat::input::{Problem, MEASURES};
use cosserat::output::target::replace_atomically;
use cosserat::output::{read_saved, write_diagram, OutputError};

use crate::exit::{fail, BAD_INPUT, INTERRUPTED, NO_RESULT, OUTPUT};
use crate::signals;

/// How often a growing diagram is saved.
const CHECKPOINT: Duration = Duration::from_secs(2);

/// A string key of the `[continuation]` table of the effective problem
/// text (the parsed value, never a scan of the raw text).
pub(crate) fn section_key(text: &str, key: &str) -> Option<String> {
    let table: toml::Table = toml::from_str(text).ok()?;
    Some(table.get("continuation")?.get(key)?.as_str()?.to_string())
}

/// The problem's continued family and options, or exit 2 naming the
/// missing `[continuation]` table.
pub fn continued<'p>(
    problem: &'p Problem,
    path: &Path,
) -> Result<(&'p Family, &'p ContinuationOptions), ExitCode> {
    match &problem.continuation {
        Some((family, opts)) => Ok((family, opts)),
        None => Err(fail(
            BAD_INPUT,
            format!(
                "{}: continuation: the problem has no [continuation] table",
                path.display()
            ),
        )),
    }
}

/// What `cosserat continue` was asked.
pub struct ContinueArgs<'a> {
    /// The problem file.
    pub path: &'a Path,
    /// The diagram file to write.
    pub output: &'a Path,
    /// The chart to draw.
    pub plot: Option<&'a Path>,
    /// `--set` overrides.
    pub set: &'a [String],
    /// Replace an existing output.
    pub force: bool,
    /// Go on with the output's interrupted run.
    pub resume: bool,
    /// Start from a stored point: the diagram file and `B/I`, or a solve
    /// file (no point).
    pub from: Option<(&'a Path, Option<&'a str>)>,
    /// Follow the stored special point in two parameters.
    pub curve: bool,
}

/// The problem, and the stored start when `--from` is given (its
/// parameter value set before the user's `--set`).
fn read_problem(args: &ContinueArgs) -> Result<(Problem, Option<StoredStart>), ExitCode> {
    let read = |set: &[String]| {
        crate::energies::read_problem(args.path, set)
            .map_err(|e| fail(BAD_INPUT, format!("{}: {e}", args.path.display())))
    };
    let problem = read(args.set)?;
    if !problem.stage_keys.is_empty() {
        chain_alone(args)?;
    }
    let Some((file, spec)) = args.from else {
        return Ok((problem, None));
    };
    let Some((family, opts)) = &problem.continuation else {
        return Ok((problem, None));
    };
    let stored = match spec {
        Some(spec) => stored_start(file, spec, &family.key()),
        None => solved_start(file, &problem.text, family, opts.start),
    }
    .map_err(|e| fail(BAD_INPUT, e))?;
    let mut set = stored.sets.clone();
    set.extend_from_slice(args.set);
    let problem = read(&set)?;
    // The stored point in the scaling of the family that runs.
    let stored = match &problem.continuation {
        Some((family, _)) => stored.onto(family).map_err(|e| fail(BAD_INPUT, e))?,
        None => stored,
    };
    Ok((problem, Some(stored)))
}

/// Runs the continuation of a problem file.
pub fn run_continue(args: &ContinueArgs) -> ExitCode {
    let (path, output, plot, force, resume) =
        (args.path, args.output, args.plot, args.force, args.resume);
    let (problem, stored) = match read_problem(args) {
        Ok(read) => read,
        Err(code) => return code,
    };
    let (family, opts) = match continued(&problem, path) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let mut outputs: Vec<&Path> = vec![output];
    outputs.extend(plot);
    let mut inputs = vec![path];
    inputs.extend(args.from.map(|(file, _)| file));
    let _claims = match crate::solve_command::claim_outputs(&outputs, &inputs, force || resume) {
        Ok(c) => c,
        Err(code) => return code,
    };
    if !problem.stage_keys.is_empty() {
        return crate::chain::run_chain(&problem, path, output, plot);
    }
    if args.curve {
        return crate::curve_command::run_curve(&problem, stored.as_ref(), output);
    }
    let saved = match saved_diagram(&problem.text, output, force, resume) {
        Ok(saved) => saved,
        Err(code) => return code,
    };
    let parameter_name = family.key();
    println!("problem   {}", path.display());
    println!(
        "model     {} ({})",
        problem.model.level.name(),
        problem.model.reason
    );
    println!(
        "continue  {parameter_name} from {} in [{}, {}]",
        opts.start, opts.bounds.0, opts.bounds.1
    );
    if let Some(stored) = &stored {
        println!("from      {}", stored.summary);
    }
    // A rod refused at the start is the run's error, reported below.
    if let Ok(method) = family.derivative_method(opts.start) {
        println!("F_p       {}", derivative_line(method));
    }
    let bar = Meter::spinner();
    let start = Instant::now();
    let run = Run {
        family,
        opts,
        output,
        text: &problem.text,
        parameter_name: &parameter_name,
    };
    let outcome = run.follow(&bar, saved.as_ref(), stored.as_ref().map(|s| &s.start));
    let diagram = match outcome {
        Ok(d) => d,
        Err(e) => return fail(NO_RESULT, e),
    };
    let elapsed = start.elapsed();
    report(&diagram);
    println!("time      {:.1} ms", elapsed.as_secs_f64() * 1e3);
    run.finish(&diagram, plot)
}

/// A chained run (`[[continuation.stage]]`) starts from the problem's own
/// solve and is not resumed: `--from`, `--curve` and `--resume` are
/// refused (exit 2) rather than applied to one stage of it.
fn chain_alone(args: &ContinueArgs) -> Result<(), ExitCode> {
    let refused = if args.from.is_some() {
        Some("--from")
    } else if args.resume {
        Some("--resume")
    } else if args.curve {
        Some("--curve")
    } else {
        None
    };
    match refused {
        Some(flag) => Err(fail(
            BAD_INPUT,
            format!(
                "{flag}: {} chains stages ([[continuation.stage]]), which run from the \
                 problem's own solve to the end; run the stages one by one (continue, then \
                 continue --from DIAGRAM --point 0/last) to restart or resume one",
                args.path.display()
            ),
        )),
        None => Ok(()),
    }
}

/// The diagram to resume from: none without `--resume` or when `output`
/// does not exist yet; the exit code when it cannot or need not be
/// resumed.
fn saved_diagram(
    text: &str,
    output: &Path,
    force: bool,
    resume: bool,
) -> Result<Option<SavedDiagram>, ExitCode> {
    if resume && output.exists() {
        match read_saved(output) {
            Ok((saved_text, _)) if saved_text != text => Err(fail(
                BAD_INPUT,
                format!(
                    "{}: made from a different problem (or other --set values); cannot resume",
                    output.display()
                ),
            )),
            Ok((_, saved)) if !saved.stop_reason.resumable() => {
                println!("nothing to resume: {} is complete", output.display());
                Err(ExitCode::SUCCESS)
            }
            Ok((_, saved)) => Ok(Some(saved)),
            Err(e) => Err(fail(
                BAD_INPUT,
                format!("{}: cannot resume: {e}", output.display()),
            )),
        }
    } else {
        if resume && !force {
            println!(
                "nothing to resume: {} does not exist; starting",
                output.display()
            );
        }
        Ok(None)
    }
}

/// One continuation run: what it follows and where its diagram goes.
pub(crate) struct Run<'a> {
    pub(crate) family: &'a Family,
    pub(crate) opts: &'a ContinuationOptions,
    pub(crate) output: &'a Path,
    pub(crate) text: &'a str,
    pub(crate) parameter_name: &'a str,
}

impl Run<'_> {
    /// Follows the branches (from `saved` when resuming), showing progress
    /// on `bar` and writing a checkpoint every [`CHECKPOINT`].
    fn follow(
        &self,
        bar: &Meter,
        saved: Option<&SavedDiagram>,
        start: Option<&Start>,
    ) -> Result<Diagram, ContinuationError> {
        let save = |diagram: &Diagram| {
            write_diagram(self.output, self.text, self.parameter_name, diagram, true)
        };
        self.follow_saving(bar, saved, start, &save)
    }

    /// [`Run::follow`] with the checkpoints written by `save`.
    pub(crate) fn follow_saving(
        &self,
        bar: &Meter,
        saved: Option<&SavedDiagram>,
        start: Option<&Start>,
        save: &dyn Fn(&Diagram) -> Result<(), OutputError>,
    ) -> Result<Diagram, ContinuationError> {
        let mut last_save = Instant::now();
        let mut checkpoint_error = None;
        let mut monitor = |progress: Progress, diagram: &Diagram| {
            // From the first point on there is work to keep: a signal stops at
            // the next point. Before it (the start solve, a resumed run's
            // replay) it stops at once, losing nothing.
            signals::set_mode(signals::Mode::NextPoint);
            bar.set_message(format!(
                "{} points, branch {}, parameter {:.6}",
                progress.points, progress.branch, progress.parameter
            ));
            bar.tick();
            if last_save.elapsed() >= CHECKPOINT {
                if let Err(e) = save(diagram) {
                    checkpoint_error.get_or_insert_with(|| e.to_string());
                }
                last_save = Instant::now();
            }
            !signals::requested()
        };
        if let Some(saved) = saved {
            let points: usize = saved.branches.iter().map(|b| b.parameter.len()).sum();
            println!(
                "resume    {} branches, {points} points from {}",
                saved.branches.len(),
                self.output.display()
            );
        }
        let outcome = match (saved, start) {
            (Some(saved), _) => {
                cosserat::continuation::resume(self.family, self.opts, saved, &mut monitor)
            }
            (None, Some(Start::Point(start))) => {
                continuation_from(self.family, self.opts, start, &mut monitor)
            }
            (None, Some(Start::Switch { saved, special })) => {
                switch_from(self.family, self.opts, saved, *special, &mut monitor)
            }
            (None, None) => continuation(self.family, self.opts, &mut monitor),
        };
        bar.finish_and_clear();
        signals::set_mode(signals::Mode::Immediate);
        if let Some(e) = checkpoint_error {
            eprintln!("warning: a checkpoint was not written: {e}");
        }
        outcome
    }

    /// Writes the finished (or interrupted) diagram and its chart.
    fn finish(&self, diagram: &Diagram, plot: Option<&Path>) -> ExitCode {
        if let Err(e) = write_diagram(self.output, self.text, self.parameter_name, diagram, true) {
            return fail(OUTPUT, e);
        }
        println!("written   {}", self.output.display());
        if diagram.stop_reason == RunState::Interrupted {
            eprintln!(
                "interrupted: every point computed so far is in {}; go on with --resume",
                self.output.display()
            );
            return ExitCode::from(INTERRUPTED);
        }
        if let Some(png) = plot {
            let measure = section_key(self.text, "measure").unwrap_or_else(|| "tip_x".into());
            if let Err(e) = plot_file(self.output, &measure, png) {
                return fail(OUTPUT, e);
            }
        }
        ExitCode::SUCCESS
    }
}

/// `cosserat plot`: the chart of a diagram file, claimed like every output
/// (never the input, never a non-regular file, `--force` to replace).
pub fn run_plot(diagram: &Path, measure: &str, output: &Path, force: bool) -> ExitCode {
    let _claims = match crate::solve_command::claim_outputs(&[output], &[diagram], force) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let data = match read_diagram(diagram) {
        Ok(d) => d,
        Err(e) => {
            return fail(
                BAD_INPUT,
                format!("{}: not a diagram file: {e}", diagram.display()),
            )
        }
    };
    if let Err(e) = known_measure(&data, measure) {
        return fail(BAD_INPUT, format!("--measure: {e}"));
    }
    match replace_atomically(output, |tmp| {
        draw(&data, &problem_view(diagram, &data), measure, tmp)
    }) {
        Ok(()) => {
            println!("plotted   {}", output.display());
            ExitCode::SUCCESS
        }
        Err(e) => fail(OUTPUT, e),
    }
}

/// How ∂F/∂p is computed, as the run header says it: a central
/// difference is named with its cost in accuracy, never passed off as exact.
pub(crate) fn derivative_line(method: cosserat::continuation::DerivativeMethod) -> String {
    use cosserat::continuation::DerivativeMethod;
    match method {
        DerivativeMethod::Exact => method.to_string(),
        DerivativeMethod::CentralDifference => format!(
            "{method} (h = 1e-4 max(1, |p|): no exact derivative of this parameter on this rod; \
             tangents and located folds carry its ~1e-8 relative truncation error)"
        ),
    }
}

pub(crate) fn report(d: &Diagram) {
    for w in &d.warnings {
        eprintln!("warning: {w}");
    }
    for (i, b) in d.branches.iter().enumerate() {
        let (first, last) = (b.points.first(), b.points.last());
        println!(
            "branch {i}  {} points, parameter {:.6} → {:.6}{}; {}",
            b.points.len(),
            first.map_or(f64::NAN, |p| p.parameter),
            last.map_or(f64::NAN, |p| p.parameter),
            b.parent
                .map_or(String::new(), |p| format!(", from special point {p}")),
            b.stop_reason
        );
    }
    for (i, s) in d.special_points.iter().enumerate() {
        println!(
            "special {i}  {} on branch {} at parameter {:.12}, {} block{}, Morse index {}, \
             multiplicity {}, located {}{}",
            s.kind.name(),
            s.branch,
            s.point.parameter,
            s.block.name(),
            if s.symmetry_breaking {
                ", symmetry-breaking"
            } else {
                ""
            },
            s.point.morse_index,
            s.multiplicity,
            s.location.name(),
            s.parameter_error.map_or(String::new(), |e| format!(
                " (error of the parameter ±{e:.1e})"
            ))
        );
    }
}

/// A measure the chart can draw: a tip measure or one the diagram stored.
fn known_measure(data: &crate::plot::DiagramData, measure: &str) -> Result<(), String> {
    if MEASURES.contains(&measure) || data.measure_names.iter().any(|n| n == measure) {
        return Ok(());
    }
    Err(format!(
        "unknown measure `{measure}`; expected one of {} or a measure the diagram stored ({})",
        MEASURES.join(", "),
        if data.measure_names.is_empty() {
            "none".to_string()
        } else {
            data.measure_names.join(", ")
        }
    ))
}

/// Draws a diagram file (the output already claimed by the caller).
pub fn plot_file(input: &Path, measure: &str, out: &Path) -> Result<(), String> {
    let data = read_diagram(input).map_err(|e| format!("{}: {e}", input.display()))?;
    known_measure(&data, measure)?;
    replace_atomically(out, |tmp| {
        draw(&data, &problem_view(input, &data), measure, tmp)
    })?;
    println!("plotted   {}", out.display());
    Ok(())
}
