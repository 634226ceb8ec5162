//! `cosserat optimize` of a tapered arm (`[arm] taper`): the shape and the
//! section optimized together (`study::arm::TaperedArm`), the loading path
//! of the design and its verdict, the HDF5 study and the chart. The search
//! is short (seconds) and not resumable: an interrupt writes nothing.

use std::process::ExitCode;
use std::time::Instant;

use cosserat::input::Problem;
use cosserat::output::target::replace_atomically;
use cosserat::output::{write_tapered_arm, TaperedStudy};
use cosserat::study::arm::taper::Taper;
use cosserat::study::arm::{ArmProblem, SearchOptions, TaperedArm, TaperedOptimum};

use crate::exit::{fail, BAD_INPUT, INTERRUPTED, NO_RESULT, OUTPUT};
use crate::optimize_command::OptimizeRun;
use crate::signals;
use crate::taper_chart::{draw_taper, TaperChart};

/// Runs the tapered search and writes what `run` asks for.
pub fn run_tapered(
    run: &OptimizeRun,
    problem: &Problem,
    arm: &ArmProblem,
    search: &SearchOptions,
    taper: Taper,
) -> ExitCode {
    if run.resume {
        return fail(
            BAD_INPUT,
            "--resume: a tapered search is not resumable (it is short; run it again)",
        );
    }
    if run.control_path.is_some() || run.holding_path.is_some() {
        return fail(
            BAD_INPUT,
            "--control-path/--holding-path: a tapered arm has the loading path only",
        );
    }
    println!("problem   {}", run.path.display());
    println!(
        "arm       B̄1 = {:.4}, B̄3 = {:.4}, α = {:.2}°, M = {}, {} elements of order {}; \
         tapered: {} knots, A ≥ {}",
        arm.b1,
        arm.b3,
        arm.alpha.to_degrees(),
        arm.coefficients(),
        arm.stability.elements(),
        arm.stability.order(),
        taper.knots(),
        taper.min_section()
    );
    let tapered = TaperedArm::new(arm.clone(), taper);
    let t = Instant::now();
    signals::set_mode(signals::Mode::NextPoint);
    let found = tapered.optimize(search, &signals::requested);
    if signals::requested() {
        return interrupted();
    }
    let opt = match found {
        Ok(Some(o)) => o,
        Ok(None) => {
            return fail(
                NO_RESULT,
                "arm.bounds: no design with a finite critical load was found in the bounds",
            )
        }
        Err(e) => return fail(NO_RESULT, format!("arm.taper: {e}")),
    };
    report(&opt, t.elapsed().as_secs_f64());
    let t = Instant::now();
    let path = tapered.loading_path(&opt, &signals::requested);
    if signals::requested() {
        return interrupted();
    }
    signals::set_mode(signals::Mode::Immediate);
    let verdict = match &path {
        Ok((_, v)) => {
            println!(
                "loading   {} {} ({:.1} s)",
                v.name(),
                if v.value().is_nan() {
                    String::new()
                } else {
                    format!("at {:.4}", v.value())
                },
                t.elapsed().as_secs_f64()
            );
            Some(*v)
        }
        Err(e) => {
            eprintln!("warning: loading path: {e}; its verdict is undecided");
            Some(cosserat::study::arm::LoadingVerdict::Undecided(0.0))
        }
    };
    if let (Some(out), Ok((diagram, _))) = (&run.loading_path, &path) {
        let axis = "load factor λ (× design load; κ⁰ fixed)";
        if let Err(e) = cosserat::output::write_diagram(out, &problem.text, axis, diagram, true) {
            return fail(OUTPUT, e);
        }
        println!("written   {}", out.display());
    }
    if let Some(out) = &run.output {
        let study = TaperedStudy {
            optimum: &opt,
            loading: verdict,
        };
        if let Err(e) = write_tapered_arm(out, &problem.text, &study, true) {
            return fail(OUTPUT, e);
        }
        println!("written   {}", out.display());
    }
    if let Some(out) = &run.plot {
        let chart = TaperChart { optimum: &opt };
        if let Err(e) = replace_atomically(out, |tmp| draw_taper(&chart, tmp)) {
            return fail(OUTPUT, e);
        }
        println!("plotted   {}", out.display());
    }
    ExitCode::SUCCESS
}

fn interrupted() -> ExitCode {
    eprintln!("interrupted: a tapered search is not resumable; nothing written");
    ExitCode::from(INTERRUPTED)
}

fn report(o: &TaperedOptimum, time: f64) {
    let fmt = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:+.4}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    println!(
        "prismatic R* = {:.6}, γ_crit = {:.6} (the start of the tapered search)",
        o.prismatic.reach, o.prismatic.gamma
    );
    let m = &o.mesh;
    println!(
        "tapered   R* = {:.6}, γ_crit = {:.6} (designed rod: {:.6}), {} block; gain {:.4}",
        o.design.reach,
        o.design.gamma,
        o.critical_load,
        o.block.name(),
        o.design.reach / o.prismatic.reach
    );
    println!(
        "          joint ascent {} after {} iterations, projected gradient {:.1e} (tolerance {:.0e} R*)",
        o.ascent.end.name(),
        o.ascent.iterations,
        o.ascent.projected_gradient,
        cosserat::study::arm::taper::ASCENT_TOLERANCE
    );
    println!(
        "          re-polished on {}/{}/{} elements: R* = {:.8}, {:.8}, {:.8}; order {}, error {:.1e}",
        m.elements[0],
        m.elements[1],
        m.elements[2],
        m.reach[0],
        m.reach[1],
        m.reach[2],
        m.order().map_or("undecided".into(), |p| format!("{p:.2}")),
        o.reach_error()
    );
    println!(
        "          shape c = [{}]",
        fmt(&o.design.shape_coefficients)
    );
    println!("          section A = [{}]", fmt(o.section.values()));
    let peak = o
        .intrinsic_curvature
        .iter()
        .fold(0.0f64, |a, k| a.max(k.abs()));
    println!(
        "          max |κ̄⁰| = {peak:.4} (per L); {} evaluations, {time:.2} s",
        o.evaluations
    );
}
