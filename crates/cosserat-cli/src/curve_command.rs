//! `cosserat continue PROBLEM --from DIAGRAM --point special/K --curve`: a
//! stored fold or branch point followed in the second parameter of
//! `[continuation.curve]` (two-parameter continuation), written as an HDF5
//! curve file.

use std::process::ExitCode;
use std::time::Instant;

use cosserat::continuation::follow_singular;
use cosserat::input::Problem;
use cosserat::output::write_curve;

use crate::exit::{fail, BAD_INPUT, NO_RESULT, OUTPUT};
use crate::stored_start::{Start, StoredStart};

/// The line stating the curve's largest estimated discretization errors:
/// of p₁ at fixed p₂ and of p₂ at fixed p₁, each over the points where it
/// is finite, and how many points have no estimate.
fn largest_errors(curve: &cosserat::continuation::SingularCurve) -> String {
    let estimated: Vec<[f64; 2]> = curve
        .points
        .iter()
        .filter_map(|p| p.parameter_error)
        .collect();
    let largest = |k: usize| {
        estimated
            .iter()
            .map(|e| e[k])
            .filter(|e| e.is_finite())
            .fold(None, |m: Option<f64>, e| Some(m.map_or(e, |m| m.max(e))))
            .map_or_else(|| "none finite".to_string(), |e| format!("±{e:.1e}"))
    };
    let missing = curve.points.len() - estimated.len();
    format!(
        "error     largest estimated discretization error of {} at fixed {}: {}; of {} at fixed \
         {}: {}{}",
        curve.keys[0],
        curve.keys[1],
        largest(0),
        curve.keys[1],
        curve.keys[0],
        largest(1),
        if missing == 0 {
            String::new()
        } else {
            format!(" ({missing} points without an estimate: see the warnings)")
        }
    )
}

/// Follows the stored special point of `stored` in the problem's curve
/// parameters and writes the curve to `output` (already claimed).
pub fn run_curve(
    problem: &Problem,
    stored: Option<&StoredStart>,
    output: &std::path::Path,
) -> ExitCode {
    let Some((family, _)) = &problem.continuation else {
        return fail(
            BAD_INPUT,
            "--curve: the problem has no [continuation] table",
        );
    };
    let Some(curve) = &problem.curve else {
        return fail(
            BAD_INPUT,
            "--curve: the problem has no [continuation.curve] table naming the second parameter",
        );
    };
    let Some(StoredStart {
        start: Start::Switch { saved, special },
        summary,
        ..
    }) = stored
    else {
        return fail(
            BAD_INPUT,
            "--curve follows a stored special point: give --from DIAGRAM --point special/K",
        );
    };
    let point = &saved.specials[*special];
    println!("from      {summary}");
    println!(
        "curve     {} from {} in [{}, {}]",
        curve.pair.keys()[1],
        curve.start,
        curve.options.bounds[1].0,
        curve.options.bounds[1].1
    );
    let clock = Instant::now();
    let followed = follow_singular(
        family,
        &curve.pair,
        point.kind,
        &point.unknowns,
        [point.parameter, curve.start],
        &curve.options,
    );
    let followed = match followed {
        Ok(c) => c,
        Err(e) => return fail(NO_RESULT, e),
    };
    let (first, last) = (followed.points.first(), followed.points.last());
    println!(
        "points    {}, from ({:.10}, {:.10}) to ({:.10}, {:.10}); ends: {}",
        followed.points.len(),
        first.map_or(f64::NAN, |p| p.parameters[0]),
        first.map_or(f64::NAN, |p| p.parameters[1]),
        last.map_or(f64::NAN, |p| p.parameters[0]),
        last.map_or(f64::NAN, |p| p.parameters[1]),
        followed.ends.join("; ")
    );
    println!("{}", largest_errors(&followed));
    for cusp in &followed.cusps {
        let [p1, p2] = cusp.point.parameters;
        println!(
            "cusp      at ({p1:.12}, {p2:.12}), after point {}{}",
            cusp.after,
            cusp.parameter_error.map_or_else(
                || " (its error unknown: see the warnings)".to_string(),
                |[e1, e2]| format!(" (error ±{e1:.1e}, ±{e2:.1e})")
            )
        );
    }
    for w in &followed.warnings {
        eprintln!("warning: {w}");
    }
    println!("time      {:.1} ms", clock.elapsed().as_secs_f64() * 1e3);
    if let Err(e) = write_curve(output, &problem.text, point.kind, &followed, true) {
        return fail(OUTPUT, e);
    }
    println!("written   {}", output.display());
    ExitCode::SUCCESS
}
