//! `cosserat optimize` of a spatial arm (`[arm] spatial = true`, issue 20):
//! the planar optimum first (the reference, and a seed of the spatial
//! search, so the spatial optimum is never reported below it), then the
//! spatial search, its mesh check, its loading path by continuation from
//! the unloaded arm, and, with `arm.directions`, the planar and spatial
//! optima in each direction (the chart's reach against α).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use crate::exit::{fail, BAD_INPUT, INTERRUPTED, NO_RESULT, OUTPUT};
use crate::optimize_command::OptimizeRun;
use crate::signals;
use crate::spatial_arm_chart::{DirectionReach, SpatialChart};
use cosserat::continuation::RunState;
use cosserat::input::Problem;
use cosserat::output::target::replace_atomically;
use cosserat::study::arm::{
    ArmOptimum, ArmScene, DirectionComparison, PathVerdict, Resolution, SearchOptions, SpatialArm,
    SpatialOptimum,
};

/// Runs the spatial study of `problem` as `run` asks.
pub fn run_spatial(
    run: &OptimizeRun,
    problem: &Problem,
    arm: &SpatialArm,
    search: &SearchOptions,
    scene: &ArmScene,
) -> ExitCode {
    if let Some(flag) = planar_only_flag(run) {
        return fail(
            BAD_INPUT,
            format!("{flag}: not available for spatial arms (arm.spatial = true)"),
        );
    }
    let t = Instant::now();
    signals::set_mode(signals::Mode::NextPoint);
    let stop = &signals::requested;
    let (planar, spatial) = optimum_pair(arm, search, scene, stop);
    if signals::requested() {
        return fail(INTERRUPTED, "interrupted: nothing written");
    }
    let Some(opt) = spatial else {
        return fail(
            NO_RESULT,
            "arm.bounds: no spatial design with a finite critical load was found in the bounds",
        );
    };
    report(planar.as_ref(), &opt, t.elapsed().as_secs_f64());
    let (diagram, verdict) = arm.loading_path(scene, &opt, stop);
    println!("loading   {}", describe(&verdict));
    let mut compared = vec![];
    for alpha in &arm.directions {
        let Some(c) = compare(&arm.towards(*alpha), search, scene, stop) else {
            return fail(INTERRUPTED, "interrupted: nothing written");
        };
        compared.push(c);
    }
    let directions: Vec<DirectionReach> = compared
        .iter()
        .map(|c| (c.alpha.to_degrees(), c.planar.0, c.spatial.0))
        .collect();
    signals::set_mode(signals::Mode::Immediate);
    if let Some(out) = &run.loading_path {
        if let Some(d) = &diagram {
            let axis = "load factor λ (× design load; κ⁰ fixed)";
            if let Err(e) = cosserat::output::write_diagram(out, &problem.text, axis, d, true) {
                return fail(OUTPUT, e);
            }
            println!("written   {}", out.display());
        }
    }
    if let Some(out) = &run.output {
        let study = cosserat::output::SpatialStudy {
            optimum: &opt,
            verdict: Some(&verdict),
            directions: &compared,
        };
        let written = cosserat::output::write_spatial_arm(
            out,
            &problem.text,
            &study,
            RunState::Completed,
            true,
        );
        if let Err(e) = written {
            return fail(OUTPUT, e);
        }
        println!("written   {}", out.display());
    }
    if let Some(out) = &run.plot {
        let chart = SpatialChart {
            optimum: &opt,
            directions: &directions,
        };
        let drawn = replace_atomically(out, |tmp| crate::chart_style::render(&chart, tmp));
        if let Err(e) = drawn {
            return fail(OUTPUT, e);
        }
        println!("plotted   {}", out.display());
    }
    ExitCode::SUCCESS
}

/// The planar and spatial optima in the direction of `arm`, with their
/// Richardson errors and the spatial optimum's loading path; None when
/// interrupted.
fn compare(
    arm: &SpatialArm,
    search: &SearchOptions,
    scene: &ArmScene,
    stop: &dyn Fn() -> bool,
) -> Option<DirectionComparison> {
    let (p, s) = optimum_pair(arm, search, scene, stop);
    if signals::requested() {
        return None;
    }
    let error = |r: &Resolution| r.study.error().unwrap_or(f64::NAN);
    let planar = p.as_ref().map_or((f64::NAN, f64::NAN), |p| {
        (
            p.design.reach,
            p.resolution.as_ref().map_or(f64::NAN, error),
        )
    });
    let (spatial, verdict) = match &s {
        Some(s) => (
            (s.design.reach, error(&s.resolution)),
            arm.loading_path(scene, s, stop).1,
        ),
        None => (
            (f64::NAN, f64::NAN),
            PathVerdict::Undecided("no spatial optimum".into()),
        ),
    };
    if signals::requested() {
        return None;
    }
    let extrapolated = |(r, e): (f64, f64)| r - e;
    println!(
        "direction α = {:>6.1}°: planar R* = {:.6} (error {:+.1e}), spatial R* = {:.6} ({}); \
         gain {:+.3} % (extrapolated {:+.3} %); loading {}",
        arm.planar.alpha.to_degrees(),
        planar.0,
        planar.1,
        spatial.0,
        s.as_ref()
            .map_or(String::new(), |s| mesh_error(&s.resolution)),
        100.0 * (spatial.0 / planar.0 - 1.0),
        100.0 * (extrapolated(spatial) / extrapolated(planar) - 1.0),
        describe(&verdict)
    );
    Some(DirectionComparison {
        alpha: arm.planar.alpha,
        planar,
        spatial,
        verdict,
    })
}

/// The flags of planar studies only.
fn planar_only_flag(run: &OptimizeRun) -> Option<&'static str> {
    let given = |p: &Option<PathBuf>| p.is_some();
    if run.resume {
        Some("--resume")
    } else if given(&run.control_path) {
        Some("--control-path")
    } else if given(&run.holding_path) {
        Some("--holding-path")
    } else {
        None
    }
}

/// The planar optimum of the arm's direction, then the spatial one seeded
/// with it.
fn optimum_pair(
    arm: &SpatialArm,
    search: &SearchOptions,
    scene: &ArmScene,
    stop: &dyn Fn() -> bool,
) -> (Option<ArmOptimum>, Option<SpatialOptimum>) {
    let (planar, _, _) = arm.planar.search(
        scene,
        search,
        cosserat::study::arm::SearchProgress::default(),
        stop,
        &mut |_| {},
    );
    let seeds: Vec<Vec<f64>> = planar
        .iter()
        .map(|p| arm.embedded(&p.design.shape_coefficients[1..]))
        .collect();
    (planar, arm.optimize_seeded(scene, search, &seeds, stop))
}

fn mesh_error(r: &Resolution) -> String {
    let s = &r.study;
    match (s.error(), s.order()) {
        (Some(e), Some(p)) => format!(
            "{} on {}/{}/{} elements, error {e:+.1e}, order {p:.2}",
            r.verdict.name(),
            s.elements[0],
            s.elements[1],
            s.elements[2]
        ),
        _ => format!(
            "{} on {}/{}/{} elements: {:.6} / {:.6} / {:.6}, order undecided",
            r.verdict.name(),
            s.elements[0],
            s.elements[1],
            s.elements[2],
            s.reach[0],
            s.reach[1],
            s.reach[2]
        ),
    }
}

fn report(planar: Option<&ArmOptimum>, opt: &SpatialOptimum, time: f64) {
    let fmt = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:+.5}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(p) = planar {
        println!(
            "planar    R* = {:.6}, γ_crit = {:.6}",
            p.design.reach, p.design.gamma
        );
    }
    let d = &opt.design;
    println!(
        "spatial   R* = {:.6}, γ_crit = {:.6}, roll {:.3}°",
        d.reach,
        d.gamma,
        d.roll.to_degrees()
    );
    let names = ["κ̄1", "κ̄2", "κ̄3"];
    for (name, c) in names.iter().zip(&d.curvature_coefficients) {
        println!("          {name} = [{}]", fmt(c));
    }
    println!("mesh      {}", mesh_error(&opt.resolution));
    if let Some(p) = planar {
        println!(
            "gain      R*spatial / R*planar − 1 = {:+.4} %",
            100.0 * (d.reach / p.design.reach - 1.0)
        );
    }
    println!("          {} evaluations, {time:.2} s", opt.evaluations);
}

fn describe(v: &PathVerdict) -> String {
    match v {
        PathVerdict::Reaches { miss } => {
            format!("path from the unloaded arm reaches the design (tip {miss:.2e} L from it)")
        }
        PathVerdict::Misses { parameter, reason } => {
            format!("path misses the design: at λ = {parameter:.4}, {reason}")
        }
        PathVerdict::Undecided(why) => format!("path undecided: {why}"),
    }
}
