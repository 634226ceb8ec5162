//! `cosserat continue` and `cosserat plot`: bifurcation diagrams from a
//! problem file's `[continuation]` table, saved as they grow.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use cosserat::continuation::{continuation, Diagram, Progress};
use cosserat::io::{check_target, read_saved, write_diagram, Problem, MEASURES};
use cosserat::plot::{draw, read_diagram};
use indicatif::{ProgressBar, ProgressStyle};

use crate::fail;

/// How often a growing diagram is saved.
const CHECKPOINT: Duration = Duration::from_secs(2);

/// Runs the continuation of a problem file.
pub fn run_continue(
    path: PathBuf,
    output: PathBuf,
    plot: Option<PathBuf>,
    set: &[String],
    force: bool,
    resume: bool,
) -> ExitCode {
    let problem = match Problem::from_path(&path, set) {
        Ok(p) => p,
        Err(e) => return fail(2, format!("{}: {e}", path.display())),
    };
    let Some((family, opts)) = &problem.continuation else {
        return fail(
            2,
            format!(
                "{}: continuation: the problem has no [continuation] table",
                path.display()
            ),
        );
    };
    let saved = if resume && output.exists() {
        match read_saved(&output) {
            Ok((text, _)) if text != problem.text => {
                return fail(
                    2,
                    format!(
                        "{}: made from a different problem (or other --set values); cannot resume",
                        output.display()
                    ),
                )
            }
            Ok((_, saved)) if saved.stop_reason == "completed" => {
                println!("nothing to resume: {} is complete", output.display());
                return ExitCode::SUCCESS;
            }
            Ok((_, saved)) => Some(saved),
            Err(e) => return fail(2, format!("{}: cannot resume: {e}", output.display())),
        }
    } else {
        if let Err(e) = check_target(&output, force) {
            return fail(2, e);
        }
        None
    };
    let parameter_name = problem
        .text
        .lines()
        .find(|l| l.trim_start().starts_with("parameter"))
        .map_or_else(
            || format!("{:?}", family.parameter()),
            |l| {
                l.split('=')
                    .nth(1)
                    .unwrap_or("")
                    .trim()
                    .trim_matches('"')
                    .to_string()
            },
        );
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
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let bar = if std::io::stderr().is_terminal() {
        let b = ProgressBar::new_spinner();
        b.set_style(
            ProgressStyle::with_template("{spinner} {msg} [{elapsed}]").expect("a valid template"),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let start = Instant::now();
    let mut last_save = Instant::now();
    let mut monitor = |progress: Progress, diagram: &Diagram| {
        bar.set_message(format!(
            "{} points, branch {}, parameter {:.6}",
            progress.points, progress.branch, progress.parameter
        ));
        bar.tick();
        if last_save.elapsed() >= CHECKPOINT {
            let _ = write_diagram(&output, &problem.text, &parameter_name, diagram, true);
            last_save = Instant::now();
        }
        !interrupted.load(Ordering::SeqCst)
    };
    if let Some(saved) = &saved {
        let points: usize = saved.branches.iter().map(|b| b.parameter.len()).sum();
        println!(
            "resume    {} branches, {points} points from {}",
            saved.branches.len(),
            output.display()
        );
    }
    let outcome = match &saved {
        Some(saved) => cosserat::continuation::resume(family, opts, saved, &mut monitor),
        None => continuation(family, opts, &mut monitor),
    };
    let diagram = match outcome {
        Ok(d) => d,
        Err(e) => return fail(2, e),
    };
    bar.finish_and_clear();
    let elapsed = start.elapsed();
    report(&diagram);
    println!("time      {:.1} ms", elapsed.as_secs_f64() * 1e3);
    if let Err(e) = write_diagram(&output, &problem.text, &parameter_name, &diagram, true) {
        return fail(1, e);
    }
    println!("written   {}", output.display());
    if let Some(png) = plot {
        // The validated `[continuation] measure` of the problem text.
        let table: Option<toml::Table> = toml::from_str(&problem.text).ok();
        let measure = table
            .as_ref()
            .and_then(|t| t.get("continuation")?.get("measure")?.as_str())
            .unwrap_or("tip_x");
        if let Err(e) = plot_file(&output, measure, &png) {
            return fail(1, e);
        }
    }
    if diagram.stop_reason == "interrupted" {
        eprintln!(
            "interrupted: every point computed so far is in {}",
            output.display()
        );
        return ExitCode::from(130);
    }
    ExitCode::SUCCESS
}

fn report(d: &Diagram) {
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
            "special {i}  {} on branch {} at parameter {:.12}, {} block{}, Morse index {}",
            s.kind.name(),
            s.branch,
            s.point.parameter,
            s.block.name(),
            if s.symmetry_breaking {
                ", symmetry-breaking"
            } else {
                ""
            },
            s.point.morse_index
        );
    }
}

/// Draws a diagram file.
pub fn plot_file(input: &Path, measure: &str, out: &Path) -> Result<(), String> {
    if !MEASURES.contains(&measure) {
        return Err(format!(
            "unknown measure `{measure}`; expected one of {MEASURES:?}"
        ));
    }
    let data = read_diagram(input).map_err(|e| format!("{}: {e}", input.display()))?;
    draw(&data, measure, out).map_err(|e| format!("{}: {e}", out.display()))?;
    println!("plotted   {}", out.display());
    Ok(())
}
