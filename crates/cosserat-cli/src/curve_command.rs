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
    for cusp in &followed.cusps {
        let [p1, p2] = cusp.point.parameters;
        println!(
            "cusp      at ({p1:.12}, {p2:.12}), after point {}",
            cusp.after
        );
    }
    println!("time      {:.1} ms", clock.elapsed().as_secs_f64() * 1e3);
    if let Err(e) = write_curve(output, &problem.text, point.kind, &followed, true) {
        return fail(OUTPUT, e);
    }
    println!("written   {}", output.display());
    ExitCode::SUCCESS
}
