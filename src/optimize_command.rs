//! `cosserat optimize`: the longest arm of a problem file's `[arm]` table.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use cosserat::io::{check_target, write_arm, Problem};

use crate::fail;

/// Optimizes the arm and writes the result.
pub fn run_optimize(
    path: PathBuf,
    output: Option<PathBuf>,
    loading_path: Option<PathBuf>,
    set: &[String],
    force: bool,
) -> ExitCode {
    let problem = match Problem::from_path(&path, set) {
        Ok(p) => p,
        Err(e) => return fail(2, format!("{}: {e}", path.display())),
    };
    let Some((arm, search, straight)) = &problem.arm else {
        return fail(
            2,
            format!("{}: arm: the problem has no [arm] table", path.display()),
        );
    };
    for out in output.iter().chain(&loading_path) {
        if let Err(e) = check_target(out, force) {
            return fail(2, e);
        }
    }
    println!("problem   {}", path.display());
    println!(
        "arm       B̄1 = {:.4}, B̄3 = {:.4}, α = {:.2}°, M = {}, {} elements of order {}",
        arm.b1,
        arm.b3,
        arm.alpha.to_degrees(),
        arm.coefficients(),
        arm.stability.elements,
        arm.stability.order
    );
    let interrupted = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        let _ = ctrlc::set_handler(move || flag.store(true, std::sync::atomic::Ordering::SeqCst));
    }
    let t = Instant::now();
    let stop = || interrupted.load(std::sync::atomic::Ordering::SeqCst);
    let Some((opt, was_interrupted)) = arm.optimize_until(search, &stop) else {
        return fail(
            2,
            "no design with a finite critical load was found in the bounds",
        );
    };
    if was_interrupted {
        println!(
            "interrupted: R* = {:.6} is the best design found so far",
            opt.design.reach
        );
        if let Some(out) = &output {
            if let Err(e) = write_arm(out, &problem.text, &opt, None, "interrupted", force) {
                return fail(1, e);
            }
            eprintln!(
                "interrupted: the best design so far is in {}",
                out.display()
            );
        }
        return ExitCode::from(130);
    }
    let time = t.elapsed().as_secs_f64();
    let fmt = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:+.6}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    println!(
        "optimum   R* = {:.6} (√(B2/F)), γ_crit = {:.6}",
        opt.design.reach, opt.design.gamma
    );
    println!(
        "          shape c = [{}]",
        fmt(&opt.design.shape_coefficients)
    );
    println!(
        "          κ⁰ fit b = [{}]",
        fmt(&opt.curvature_coefficients)
    );
    println!("          {} evaluations, {:.2} s", opt.evaluations, time);
    let straight_arm = if *straight {
        let t = Instant::now();
        let s = arm.straight();
        match &s {
            Some(s) => println!(
                "straight  R0 = {:.6}, γ_crit = {:.6}, clamp angle {:.3}° ({:.2} s); R*/R0 = {:.3}",
                s.reach,
                s.gamma,
                s.clamp_angle.to_degrees(),
                t.elapsed().as_secs_f64(),
                opt.design.reach / s.reach
            ),
            None => println!("straight  no stable level equilibrium found"),
        }
        s
    } else {
        None
    };
    if let Some(out) = output {
        if let Err(e) = write_arm(
            &out,
            &problem.text,
            &opt,
            straight_arm.as_ref(),
            "completed",
            force,
        ) {
            return fail(1, e);
        }
        println!("written   {}", out.display());
    }
    if let Some(out) = loading_path {
        return write_loading_path(&problem, arm, &opt, &out, force);
    }
    ExitCode::SUCCESS
}

/// Continues the designed arm in its load from unloaded to the design load
/// and writes the diagram (and a chart next to it).
fn write_loading_path(
    problem: &Problem,
    arm: &cosserat::optimize::ArmProblem,
    opt: &cosserat::optimize::ArmOptimum,
    out: &std::path::Path,
    force: bool,
) -> ExitCode {
    let t = Instant::now();
    let diagram = match cosserat::optimize::loading_path(arm, &opt.design, 2001) {
        Ok(d) => d,
        Err(e) => return fail(2, format!("loading path: {e}")),
    };
    let Some(last) = diagram.branches.first().and_then(|b| b.points.last()) else {
        return fail(2, "loading path: no point");
    };
    let designed = opt
        .loaded_shape
        .last()
        .map(|r| r.map(|v| v / opt.design.gamma.sqrt()));
    let miss = designed.map_or(f64::NAN, |d| {
        ((last.tip.position[0] - d[0]).powi(2) + (last.tip.position[2] - d[2]).powi(2)).sqrt()
    });
    println!(
        "loading   λ = {:.4}: tip ({:+.4}, {:+.4}), {} from the design tip, Morse index {} ({:.1} s)",
        last.parameter,
        last.tip.position[0],
        last.tip.position[2],
        format_args!("{miss:.2e}"),
        last.morse_index,
        t.elapsed().as_secs_f64()
    );
    for s in &diagram.special_points {
        println!(
            "          {} at λ = {:.6} ({} block)",
            s.kind.name(),
            s.point.parameter,
            s.block.name()
        );
    }
    if let Err(e) = cosserat::io::write_diagram(
        out,
        &problem.text,
        "load factor λ (× γ_crit)",
        &diagram,
        force,
    ) {
        return fail(1, e);
    }
    let chart = out.with_extension("png");
    if let Err(e) = crate::continue_command::plot_file(out, "tip_z", &chart) {
        return fail(1, e);
    }
    println!("written   {}", out.display());
    ExitCode::SUCCESS
}
