//! `cosserat optimize`: the longest arm of a problem file's `[arm]` table,
//! with its reach map and chart (Fig. 5), the loading and control paths of
//! the design, and `--resume` of an interrupted search.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use crate::arm_chart::{draw_arm, ArmChart};
use cosserat::continuation::RunState;
use cosserat::input::Problem;
use cosserat::output::target::{replace_atomically, Claim};
use cosserat::output::{read_search, write_arm_study, ArmStudy};
use cosserat::study::arm::{
    ArmOptimum, ArmProblem, ArmScene, ArmWeight, ClosestStraight, ReachMap, SearchOptions,
    SearchProgress, StraightArm,
};

use crate::exit::{fail, BAD_INPUT, INTERRUPTED, NO_RESULT, OUTPUT};
use crate::signals;

/// How often a running search is saved (a kill loses at most this much).
const CHECKPOINT: std::time::Duration = std::time::Duration::from_secs(2);

/// A study of the best design so far, marked interrupted: what a killed or
/// interrupted run leaves for `--resume`.
fn interrupted_study<'a>(opt: &'a ArmOptimum, progress: &'a SearchProgress) -> ArmStudy<'a> {
    ArmStudy {
        optimum: opt,
        straight: None,
        map: None,
        closest: None,
        least_curvature: None,
        progress: Some(progress),
        stop_reason: RunState::Interrupted,
    }
}

/// What `cosserat optimize` was asked for.
pub struct OptimizeRun {
    /// The problem file.
    pub path: PathBuf,
    /// The HDF5 result.
    pub output: Option<PathBuf>,
    /// The loading-path diagram (κ⁰ fixed, load raised).
    pub loading_path: Option<PathBuf>,
    /// The control-path diagram (κ⁰ and load raised together).
    pub control_path: Option<PathBuf>,
    /// The shape-holding diagram (κ⁰ = φ' − λγm̄).
    pub holding_path: Option<PathBuf>,
    /// The chart of the study (Fig. 5).
    pub plot: Option<PathBuf>,
    /// `--set` overrides.
    pub set: Vec<String>,
    /// Overwrite outputs.
    pub force: bool,
    /// Go on with the interrupted search kept in `output`.
    pub resume: bool,
}

/// Optimizes the arm and writes the results.
pub fn run_optimize(run: &OptimizeRun) -> ExitCode {
    let path = &run.path;
    let problem = match crate::energies::read_problem(path, &run.set) {
        Ok(p) => p,
        Err(e) => return fail(BAD_INPUT, format!("{}: {e}", path.display())),
    };
    let _claims = match claim_outputs(run) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let (Some((arm, search, straight)), Some((scene, map_samples))) =
        (&problem.arm, &problem.arm_scene)
    else {
        return fail(
            BAD_INPUT,
            format!("{}: arm: the problem has no [arm] table", path.display()),
        );
    };
    if let Some(taper) = problem.arm_taper {
        return crate::taper_command::run_tapered(run, &problem, arm, search, taper);
    }
    if let Some(spatial) = &problem.arm_spatial {
        return crate::optimize_spatial::run_spatial(run, &problem, spatial, search, scene);
    }
    let progress = match start_from(run, &problem, arm, scene) {
        Ok(p) => p,
        Err(code) => return code,
    };
    report_problem(path, arm, scene);
    let t = Instant::now();
    let ((optimum, progress, was_interrupted), beside) =
        with_straight(arm, scene, *straight, || {
            run_search(run, &problem.text, arm, search, scene, progress)
        });
    let Some(opt) = optimum else {
        let limit = scene.max_curvature.map_or(String::new(), |k| {
            format!(" that the actuator limit arm.max_curvature = {k} can hold")
        });
        return fail(
            NO_RESULT,
            format!(
                "arm.bounds: no design with a finite critical load{limit} was found in the bounds"
            ),
        );
    };
    if was_interrupted {
        return keep_interrupted(run, &problem.text, &opt, &progress);
    }
    // The finished search is kept before the maps and paths that follow it
    // (they stop at once on a signal): `--resume` starts from the optimum.
    if let Some(out) = &run.output {
        if let Err(e) = write_arm_study(
            out,
            &problem.text,
            &interrupted_study(&opt, &progress),
            true,
        ) {
            return fail(OUTPUT, e);
        }
    }
    report_optimum(&opt, t.elapsed().as_secs_f64());
    // What follows the search stops at its next point on a signal; the
    // study then stays marked interrupted (its search complete), so that
    // `--resume` computes the rest.
    signals::set_mode(signals::Mode::NextPoint);
    let (straight, extras) = after_search(arm, search, scene, (*map_samples, beside), &opt);
    if signals::requested() {
        return keep_interrupted(run, &problem.text, &opt, &progress);
    }
    let paths = [
        (&run.loading_path, Route::LOADING),
        (&run.control_path, Route::CONTROL),
        (&run.holding_path, Route::HOLDING),
    ];
    for (out, kind) in paths {
        if let Some(out) = out {
            let code = write_path(&problem, arm, scene, &opt, out, kind);
            if code != ExitCode::SUCCESS {
                return code;
            }
        }
    }
    if signals::requested() {
        return keep_interrupted(run, &problem.text, &opt, &progress);
    }
    signals::set_mode(signals::Mode::Immediate);
    if let Err(code) = write_study(
        run,
        &problem.text,
        &opt,
        straight.as_ref(),
        &extras,
        &progress,
    ) {
        return code;
    }
    ExitCode::SUCCESS
}

/// The search, stopped by Ctrl-C and saved every [`CHECKPOINT`] (so that a
/// kill loses little) as an interrupted study.
fn run_search(
    run: &OptimizeRun,
    text: &str,
    arm: &ArmProblem,
    search: &SearchOptions,
    scene: &ArmScene,
    progress: SearchProgress,
) -> (Option<ArmOptimum>, SearchProgress, bool) {
    let stop = signals::requested;
    // Stops at the next evaluation; what follows the search (maps, R0,
    // paths) stops at once, the search's last checkpoint kept.
    signals::set_mode(signals::Mode::NextPoint);
    let mut last_save = Instant::now();
    let meter = crate::progress::Meter::counted(
        search.samples + search.starts,
        progress.samples_done + progress.polishes_done,
    );
    let mut checkpoint = |p: &SearchProgress| {
        meter.set_position((p.samples_done + p.polishes_done) as u64);
        if last_save.elapsed() < CHECKPOINT {
            return;
        }
        if let (Some(out), Some(best)) = (&run.output, arm.best_so_far(scene, p)) {
            let _ = write_arm_study(out, text, &interrupted_study(&best, p), true);
        }
        last_save = Instant::now();
    };
    let outcome = arm.search(scene, search, progress, &stop, &mut checkpoint);
    meter.finish_and_clear();
    signals::set_mode(signals::Mode::Immediate);
    outcome
}

/// The search of `cosserat optimize` with neither checkpoints nor
/// progress (what `cosserat bench optimize` times with [`after_search`]).
pub fn search_only(
    arm: &ArmProblem,
    search: &SearchOptions,
    scene: &ArmScene,
) -> Option<ArmOptimum> {
    arm.search(
        scene,
        search,
        SearchProgress::default(),
        &|| false,
        &mut |_| {},
    )
    .0
}

/// The intrinsically straight arm's R0 as computed beside the search: None
/// where it is not asked for (`arm.straight = false`, or an arm with
/// weight), else the arm (None where no stable level equilibrium was
/// found) and the seconds it took.
pub type StraightRun = Option<(Option<StraightArm>, f64)>;

/// `search()` and the straight arm's R0 (where `straight` asks for it and
/// the arm is weightless) at the same time on rayon's threads: R0 does
/// not depend on the search, and the search leaves a thread idle at its
/// stages' ends. Both stop at once on a signal.
pub fn with_straight<T: Send>(
    arm: &ArmProblem,
    scene: &ArmScene,
    straight: bool,
    search: impl FnOnce() -> T + Send,
) -> (T, StraightRun) {
    let wanted = straight && scene.weight == ArmWeight::Weightless;
    rayon::join(search, || {
        wanted.then(|| {
            let t = Instant::now();
            let s = arm.straight_until(&signals::requested);
            (s, t.elapsed().as_secs_f64())
        })
    })
}

/// What `cosserat optimize` computes after its search: the report of the
/// intrinsically straight arm's R0 computed beside it ([`with_straight`])
/// and the Fig. 5 data set of `samples` map points.
pub fn after_search(
    arm: &ArmProblem,
    search: &SearchOptions,
    scene: &ArmScene,
    (samples, straight): (usize, StraightRun),
    opt: &ArmOptimum,
) -> (Option<StraightArm>, MapExtras) {
    let straight = straight.and_then(|(s, seconds)| report_straight(s, seconds, opt));
    (straight, map_extras(arm, search, scene, samples, opt))
}

/// The Fig. 5 data set: the map, its 'Q', the least-Σb² design.
#[derive(Default)]
pub struct MapExtras {
    map: Option<ReachMap>,
    closest: Option<ClosestStraight>,
    least: Option<ClosestStraight>,
}

fn map_extras(
    arm: &ArmProblem,
    search: &SearchOptions,
    scene: &ArmScene,
    samples: usize,
    opt: &ArmOptimum,
) -> MapExtras {
    if samples == 0 {
        return MapExtras::default();
    }
    let map = arm.reach_map(scene, samples, &signals::requested);
    let closest = map.closest_straight(arm, scene);
    if let Some(q) = &closest {
        println!(
            "map       {} designs; Q (least Σb² = {:.3e}): R̂ = {:.6}; R*/R̂(Q) = {:.3}",
            map.reach.len(),
            q.curvature_norm,
            q.optimum.design.reach,
            opt.design.reach / q.optimum.design.reach
        );
    }
    let (least, _) = arm.least_curvature(
        scene,
        &map,
        search.starts,
        search.iterations,
        &signals::requested,
    );
    if let Some(l) = &least {
        println!(
            "least Σb² {:.3e} (the paper's R0 by Nelder–Mead from Q): R̂ = {:.6}; R*/R̂ = {:.3}",
            l.curvature_norm,
            l.optimum.design.reach,
            opt.design.reach / l.optimum.design.reach
        );
    }
    MapExtras {
        map: Some(map),
        closest,
        least,
    }
}

/// Writes the completed study (HDF5) and its chart, as asked.
fn write_study(
    run: &OptimizeRun,
    text: &str,
    opt: &ArmOptimum,
    straight: Option<&StraightArm>,
    extras: &MapExtras,
    progress: &SearchProgress,
) -> Result<(), ExitCode> {
    if let Some(out) = &run.output {
        let study = ArmStudy {
            optimum: opt,
            straight,
            map: extras.map.as_ref(),
            closest: extras.closest.as_ref(),
            least_curvature: extras.least.as_ref(),
            progress: Some(progress),
            stop_reason: RunState::Completed,
        };
        write_arm_study(out, text, &study, true).map_err(|e| fail(OUTPUT, e))?;
        println!("written   {}", out.display());
    }
    if let Some(out) = &run.plot {
        let chart = ArmChart {
            optimum: opt,
            map: extras.map.as_ref(),
            closest: extras.closest.as_ref(),
            straight,
        };
        replace_atomically(out, |tmp| draw_arm(&chart, tmp)).map_err(|e| fail(OUTPUT, e))?;
        println!("plotted   {}", out.display());
    }
    Ok(())
}

/// Claims every file the run will write (the study, the paths and the
/// charts beside them, the figure) before any work.
fn claim_outputs(run: &OptimizeRun) -> Result<Vec<Claim>, ExitCode> {
    let charts: Vec<PathBuf> = [&run.loading_path, &run.control_path, &run.holding_path]
        .into_iter()
        .flatten()
        .map(|p| p.with_extension("png"))
        .collect();
    let outputs: Vec<&Path> = run
        .output
        .iter()
        .chain(&run.loading_path)
        .chain(&run.control_path)
        .chain(&run.holding_path)
        .chain(&run.plot)
        .chain(&charts)
        .map(PathBuf::as_path)
        .collect();
    crate::solve_command::claim_outputs(&outputs, &[&run.path], run.force || run.resume)
}

/// The search progress to start from: fresh, or what an interrupted run
/// kept in the output file (`--resume`).
fn start_from(
    run: &OptimizeRun,
    problem: &Problem,
    arm: &ArmProblem,
    scene: &ArmScene,
) -> Result<SearchProgress, ExitCode> {
    let resumable = run.resume && run.output.as_ref().is_some_and(|o| o.exists());
    if run.resume && run.output.is_none() {
        return Err(fail(
            BAD_INPUT,
            "--resume needs the output file (-o) of the run",
        ));
    }
    let Some(out) = run.output.as_ref().filter(|_| resumable) else {
        return Ok(SearchProgress::default());
    };
    let saved = read_search(out)
        .map_err(|e| fail(BAD_INPUT, format!("{}: cannot resume: {e}", out.display())))?;
    if saved.problem != problem.text {
        return Err(fail(
            BAD_INPUT,
            format!(
                "{}: made from a different problem (or other --set values); cannot resume",
                out.display()
            ),
        ));
    }
    if !saved.stop_reason.resumable() {
        println!("nothing to resume: {} is complete", out.display());
        return Err(ExitCode::SUCCESS);
    }
    let mut progress = saved.progress;
    progress.best = saved.best.get(1..).and_then(|c| arm.design_in(scene, c));
    println!(
        "resume    after {} samples and {} polishes ({} evaluations) from {}",
        progress.samples_done,
        progress.polishes_done,
        progress.evaluations,
        out.display()
    );
    Ok(progress)
}

fn report_problem(path: &Path, arm: &ArmProblem, scene: &ArmScene) {
    println!("problem   {}", path.display());
    println!(
        "arm       B̄1 = {:.4}, B̄3 = {:.4}, α = {:.2}°, M = {}, {} elements of order {}",
        arm.b1,
        arm.b3,
        arm.alpha.to_degrees(),
        arm.coefficients(),
        arm.stability.elements(),
        arm.stability.order()
    );
    match scene.weight {
        ArmWeight::Weightless => {}
        ArmWeight::WithTipLoad(w) => println!("weight    qL/F = {w} with the tip load"),
        ArmWeight::Alone => println!("weight    alone (lengths in (B2/q)^(1/3))"),
    }
    if let Some(k) = scene.max_curvature {
        println!("actuator  |κ⁰| ≤ {k} (units of the inverse reach)");
    }
}

/// Ctrl-C: the best design so far and the search progress, marked
/// interrupted, so that `--resume` goes on from there.
fn keep_interrupted(
    run: &OptimizeRun,
    text: &str,
    opt: &ArmOptimum,
    progress: &SearchProgress,
) -> ExitCode {
    println!(
        "interrupted: R* = {:.6} is the best design found so far",
        opt.design.reach
    );
    if let Some(out) = &run.output {
        if let Err(e) = write_arm_study(out, text, &interrupted_study(opt, progress), true) {
            return fail(OUTPUT, e);
        }
        eprintln!(
            "interrupted: the best design so far is in {}; go on with --resume",
            out.display()
        );
    }
    ExitCode::from(INTERRUPTED)
}

fn report_optimum(opt: &ArmOptimum, time: f64) {
    let fmt = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:+.6}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    println!(
        "optimum   R* = {:.6}, load factor {:.6}, γ_crit = {:.6}",
        opt.design.reach, opt.design.gamma, opt.critical_load
    );
    println!(
        "          shape c = [{}]",
        fmt(&opt.design.shape_coefficients)
    );
    println!(
        "          κ⁰ fit b = [{}]",
        fmt(&opt.curvature_coefficients)
    );
    let peak = opt
        .intrinsic_curvature
        .iter()
        .fold(0.0f64, |a, k| a.max(k.abs()));
    println!(
        "          max |κ̄⁰| = {:.6} (per L), {:.6} in units of the inverse reach",
        peak,
        peak / opt.scene.length(opt.design.gamma)
    );
    println!("          {} evaluations, {:.2} s", opt.evaluations, time);
    report_mesh(opt);
}

/// `value ± bound` with the digits down to the bound's: every printed digit
/// is converged.
fn with_bound(value: f64, bound: f64) -> String {
    let digits = (-bound.max(f64::EPSILON * value.abs()).log10())
        .floor()
        .clamp(0.0, 15.0);
    format!("{value:.0$} ± {bound:.1e}", digits as usize)
}

/// The mesh-converged optimum (`ReachLimit`): its three order-2 meshes and
/// Richardson's limit with its bound, or why there is none.
fn report_limit(l: &cosserat::study::arm::ReachLimit) {
    let s = &l.study;
    let limit = match (l.converged(), s.order()) {
        (Some((limit, bound)), Some(p)) => format!(
            "R*(N → ∞) = {} (Richardson at the measured order {p:.2}; ± the finest mesh's \
             estimated error)",
            with_bound(limit, bound)
        ),
        _ => "R*(N → ∞) undecided (the differences do not converge geometrically)".into(),
    };
    println!(
        "limit     R* = {:.9} / {:.9} / {:.9} on {} / {} / {} elements of order {}: {limit}",
        s.reach[0], s.reach[1], s.reach[2], s.elements[0], s.elements[1], s.elements[2], l.order
    );
}

/// The discretization error of R* (`optimize::Resolution`), and a warning on
/// stderr when the search's mesh did not resolve its optimum.
fn report_mesh(opt: &ArmOptimum) {
    let Some(r) = &opt.resolution else {
        return;
    };
    let s = &r.study;
    let error = match (s.error(), s.order()) {
        (Some(e), Some(p)) => format!("error {e:+.2e} (Richardson, measured order {p:.2})"),
        _ => "error undecided (the differences do not converge geometrically)".into(),
    };
    println!(
        "mesh      R* = {:.6} / {:.6} / {:.6} on {} / {} / {} elements of order {}: {error}; {}",
        s.reach[0],
        s.reach[1],
        s.reach[2],
        s.elements[0],
        s.elements[1],
        s.elements[2],
        opt.mesh.order(),
        r.verdict.name()
    );
    if let Some(l) = &opt.limit {
        report_limit(l);
    } else if let Some((limit, bound)) = s.converged() {
        println!(
            "          R*(N → ∞) = {} (Richardson at the measured order; ± the finest mesh's \
             estimated error)",
            with_bound(limit, bound)
        );
    }
    if s.local_optima {
        println!(
            "          (on the finer meshes: the optima re-polished from the design there, so the \
             limit is the converged optimum's)"
        );
    }
    for (n, coarse, fine) in &r.rejected {
        eprintln!(
            "warning: R* = {coarse:.6} on {n} elements but {fine:.6} on {}: the mesh does not \
             resolve the optimum (tolerance {:.0e}); searched again, reported on {} elements \
             of order {}",
            4 * n,
            cosserat::study::arm::REACH_TOLERANCE,
            opt.mesh.elements(),
            opt.mesh.order()
        );
    }
    if r.verdict == cosserat::study::arm::Verdict::Unresolved {
        eprintln!(
            "warning: R* = {:.6} on {} elements is not resolved to {:.0e} ({:.6} on {}); \
             it carries the error above",
            s.reach[0],
            s.elements[0],
            cosserat::study::arm::REACH_TOLERANCE,
            s.reach[2],
            s.elements[2]
        );
    }
}

fn report_straight(s: Option<StraightArm>, seconds: f64, opt: &ArmOptimum) -> Option<StraightArm> {
    match &s {
        Some(s) => println!(
            "straight  R0 = {:.6}, γ_crit = {:.6}, clamp angle {:.3}° ({seconds:.2} s, beside \
             the search); R*/R0 = {:.3}",
            s.reach,
            s.gamma,
            s.clamp_angle.to_degrees(),
            opt.design.reach / s.reach
        ),
        None => println!("straight  no stable level equilibrium found"),
    }
    if let Some(s) = s
        .as_ref()
        .filter(|s| s.limit != cosserat::study::arm::StraightLimit::StabilityLoss)
    {
        eprintln!(
            "warning: R0 = {:.6} is a lower bound: the level family ended without losing \
             stability ({})",
            s.reach,
            s.limit.name()
        );
    }
    s
}

/// Which path to the design.
#[derive(Clone, Copy, PartialEq)]
struct Route {
    name: &'static str,
    axis: &'static str,
}

impl Route {
    const LOADING: Route = Route {
        name: "loading",
        axis: "load factor λ (× design load; κ⁰ fixed)",
    };
    const CONTROL: Route = Route {
        name: "control",
        axis: "control λ (κ⁰ = λ κ⁰_design, load × λ)",
    };
    const HOLDING: Route = Route {
        name: "holding",
        axis: "shape-holding λ (κ⁰ = φ' − λγm̄, load × λ)",
    };
}

/// Continues the designed arm along a path to its design and writes the
/// diagram (and a chart next to it).
fn write_path(
    problem: &Problem,
    arm: &ArmProblem,
    scene: &ArmScene,
    opt: &ArmOptimum,
    out: &Path,
    kind: Route,
) -> ExitCode {
    let t = Instant::now();
    let stop = &signals::requested;
    let diagram = match kind.name {
        "loading" => cosserat::study::arm::loading_path_until(arm, scene, &opt.design, 2001, stop),
        "control" => cosserat::study::arm::control_path_until(arm, scene, &opt.design, 2001, stop),
        _ => cosserat::study::arm::shape_holding_path_until(arm, scene, &opt.design, 2001, stop),
    };
    let diagram = match diagram {
        Ok(d) => d,
        Err(e) => return fail(NO_RESULT, format!("{} path: {e}", kind.name)),
    };
    let Some(last) = diagram.branches.first().and_then(|b| b.points.last()) else {
        return fail(NO_RESULT, format!("{} path: no point", kind.name));
    };
    let scale = opt.scene.length(opt.design.gamma);
    let designed = opt.loaded_shape.last().map(|r| r.map(|v| v / scale));
    let miss = designed.map_or(f64::NAN, |d| {
        ((last.tip.position[0] - d[0]).powi(2) + (last.tip.position[2] - d[2]).powi(2)).sqrt()
    });
    println!(
        "{:<9} λ = {:.4}: tip ({:+.4}, {:+.4}), {} from the design tip, Morse index {} ({:.1} s)",
        kind.name,
        last.parameter,
        last.tip.position[0],
        last.tip.position[2],
        format_args!("{miss:.2e}"),
        last.morse_index,
        t.elapsed().as_secs_f64()
    );
    for w in &diagram.warnings {
        eprintln!("warning: {} path: {w}", kind.name);
    }
    for s in &diagram.special_points {
        println!(
            "          {} at λ = {:.6} ({} block)",
            s.kind.name(),
            s.point.parameter,
            s.block.name()
        );
    }
    if let Err(e) = cosserat::output::write_diagram(out, &problem.text, kind.axis, &diagram, true) {
        return fail(OUTPUT, e);
    }
    let chart = out.with_extension("png");
    if let Err(e) = crate::continue_command::plot_file(out, "tip_z", &chart) {
        return fail(OUTPUT, e);
    }
    println!("written   {}", out.display());
    ExitCode::SUCCESS
}
