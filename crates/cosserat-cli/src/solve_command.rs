//! `cosserat solve` and `cosserat stability`: one equilibrium (or a fixed
//! loaded shape) and its stability verdict.

use std::path::Path;
use std::process::ExitCode;

use cosserat::bvp::{solve, Equilibrium};
use cosserat::input::Problem;
use cosserat::output::target::{claim, Claim};
use cosserat::output::{write_equilibrium, write_stability, StabilityResult};
use cosserat::stability::{critical_load, CriticalLoad, Stability};

use crate::exit::{fail, BAD_INPUT, NO_RESULT, OUTPUT};
use crate::signals;

/// Reads the problem and claims the output before any work.
fn prepare(
    path: &Path,
    output: Option<&Path>,
    set: &[String],
    force: bool,
) -> Result<(Problem, Option<Claim>), ExitCode> {
    let problem = crate::energies::read_problem(path, set)
        .map_err(|e| fail(BAD_INPUT, format!("{}: {e}", path.display())))?;
    let claimed = output
        .map(|out| claim(out, &[path], force).map(hold))
        .transpose()
        .map_err(|e| fail(BAD_INPUT, e))?;
    println!("problem   {}", path.display());
    Ok((problem, claimed))
}

/// A failed solve: options the solver cannot run are bad input (2), a
/// solver that found no equilibrium is no result (3); each with what to
/// try next.
pub fn solve_failed(e: &cosserat::bvp::SolveError) -> ExitCode {
    use cosserat::bvp::SolveError as E;
    let (code, hint) = match e {
        E::Options(_) | E::Model(_) => (BAD_INPUT, "correct the problem file"),
        E::NoConvergence { .. } | E::RampStalled { .. } => (
            NO_RESULT,
            "try solver.strategy = \"ramp\", --method multiple-shooting or collocation, \
             or a guess solver.initial_curvature",
        ),
        E::Sampling(_) => (
            NO_RESULT,
            "raise solver.max_steps or loosen solver.integration_tolerance",
        ),
        E::Collocation { .. } => (
            NO_RESULT,
            "raise solver.max_intervals or loosen solver.collocation_tolerance",
        ),
        E::ShearStrain { .. } => (
            NO_RESULT,
            "the energy cannot carry the force there (W_νν not positive definite, or no ν with \
             W_ν = N): check its shear and extension terms, or lower the loads",
        ),
    };
    fail(code, format!("{e}\n  what to do: {hint}"))
}

/// Registers a claim's scratch files for removal on an immediate stop.
pub fn hold(claim: Claim) -> Claim {
    for f in claim.scratch_files() {
        signals::litter(f);
    }
    claim
}

/// Claims every output of a command (none named twice, none an input).
pub fn claim_outputs(
    outputs: &[&Path],
    inputs: &[&Path],
    replace: bool,
) -> Result<Vec<Claim>, ExitCode> {
    cosserat::output::target::claim_all(outputs, inputs, replace)
        .map(|claims| claims.into_iter().map(hold).collect())
        .map_err(|e| fail(BAD_INPUT, e))
}

/// `cosserat stability`: the stability of the problem's equilibrium
/// (spectra, Morse index) or the critical load of its `[shape]`, printed
/// and written to `output`; returns the exit code.
pub fn run_stability(path: &Path, output: Option<&Path>, set: &[String], force: bool) -> ExitCode {
    let (problem, _claim) = match prepare(path, output, set, force) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let opts = &problem.stability;
    println!(
        "mesh      {} elements of order {}",
        opts.elements(),
        opts.order()
    );
    if problem.shape.is_none() {
        println!(
            "model     {} ({})",
            problem.model.level.name(),
            problem.model.reason
        );
    }
    let result = match compute_stability(&problem) {
        Ok(StabilityOutcome::FixedShape(c)) => {
            report_critical(&c);
            StabilityResult::FixedShape(c)
        }
        Ok(StabilityOutcome::Decided(eq, decision, st)) => {
            report_decision(&st, &decision);
            StabilityResult::Equilibrium(eq, st)
        }
        Err(StabilityFailure::Solve(e)) => return solve_failed(&e),
        Err(StabilityFailure::NoResult(e)) => return fail(NO_RESULT, e),
    };
    if let Some(out) = output {
        if let Err(e) = write_stability(out, &problem.text, &result, true) {
            return fail(OUTPUT, e);
        }
        println!("written   {}", out.display());
    }
    ExitCode::SUCCESS
}

/// What `cosserat stability` computes: the critical load of a `[shape]`,
/// or the equilibrium with its verdict decided on meshes that resolve the
/// shape and agree ([`cosserat::stability::decide`]), never read off one
/// mesh.
pub enum StabilityOutcome {
    /// The critical load of the fixed loaded shape.
    FixedShape(CriticalLoad),
    /// The equilibrium, the decision, and the analysis on its finest mesh.
    Decided(Box<Equilibrium>, cosserat::stability::Decision, Stability),
}

/// Why `cosserat stability` has no result.
pub enum StabilityFailure {
    /// The equilibrium was not found (exit code by [`SolveError`](cosserat::bvp::SolveError)'s kind).
    Solve(cosserat::bvp::SolveError),
    /// The analysis failed or the verdict is undecided (exit 3).
    NoResult(String),
}

/// The computation of `cosserat stability`, without printing or writing
/// (also what `cosserat bench stability` times).
pub fn compute_stability(problem: &Problem) -> Result<StabilityOutcome, StabilityFailure> {
    let opts = &problem.stability;
    if let Some(shape) = &problem.shape {
        return critical_load(&problem.rod, shape, opts)
            .map(StabilityOutcome::FixedShape)
            .map_err(|e| StabilityFailure::NoResult(e.to_string()));
    }
    let eq =
        solve(&problem.rod, &problem.model, &problem.options).map_err(StabilityFailure::Solve)?;
    let decision = cosserat::stability::decide(&problem.rod, &eq, &problem.options, opts)
        .map_err(|e| StabilityFailure::NoResult(e.to_string()))?;
    let Some(st) = decision.stability.clone() else {
        let reason = match &decision.verdict {
            cosserat::stability::Verdict::Undecided { reason } => reason.clone(),
            _ => "no mesh was analysed".into(),
        };
        return Err(StabilityFailure::NoResult(format!(
            "stability undecided: {reason}"
        )));
    };
    Ok(StabilityOutcome::Decided(Box::new(eq), decision, st))
}

/// The spectrum on the finest mesh used and the decided verdict.
fn report_decision(st: &Stability, decision: &cosserat::stability::Decision) {
    use cosserat::stability::Verdict;
    println!(
        "decided   on {} elements, eigenvalue error ≤ {:.1e}",
        decision.elements, decision.eigenvalue_error
    );
    for b in &st.blocks {
        let values: Vec<String> = b.eigenvalues.iter().map(|v| format!("{v:+.6e}")).collect();
        println!(
            "{:<13} lowest eigenvalues [{}], Morse index {}",
            b.block.name(),
            values.join(", "),
            b.morse_index
        );
    }
    println!("morse     {}", st.morse_index);
    match &decision.verdict {
        Verdict::Stable => println!("verdict   stable"),
        Verdict::Unstable { .. } => println!("verdict   unstable"),
        Verdict::Undecided { reason } => println!("verdict   undecided: {reason}"),
    }
}

fn report_critical(c: &CriticalLoad) {
    for (block, factor, _) in &c.blocks {
        match factor {
            Some(f) => println!("{:<13} critical load factor {f:.10e}", block.name()),
            None => println!("{:<13} no positive critical load", block.name()),
        }
    }
    match (c.load_factor, c.gamma) {
        (Some(f), Some(g)) => {
            println!("critical  load factor {f:.10e}");
            println!("          γ_crit = F L²/B2 = {g:.10e}");
        }
        _ => println!("critical  none: the shape is stable under any positive load"),
    }
}

/// `cosserat solve`: the problem's equilibrium, printed and written to
/// `output`; returns the exit code.
pub fn run_solve(path: &Path, output: Option<&Path>, set: &[String], force: bool) -> ExitCode {
    let (problem, _claim) = match prepare(path, output, set, force) {
        Ok(p) => p,
        Err(code) => return code,
    };
    if problem.shape.is_some() {
        return fail(
            BAD_INPUT,
            "a fixed-shape scene ([shape]) has no fixed intrinsic curvature to solve for; \
             use `cosserat stability`",
        );
    }
    println!(
        "model     {} ({})",
        problem.model.level.name(),
        problem.model.reason
    );
    println!("energy    {}", problem.rod.energy().name());
    let Solved { eq, decision } = match compute_solve(&problem) {
        Ok(s) => s,
        Err(e) => return solve_failed(&e),
    };
    report(&eq);
    verdict(decision);
    let tolerance = problem.options.newton.tolerance;
    if eq.residual.is_nan() || eq.residual > tolerance {
        // Belt and braces: solve() returns only converged results, but a
        // result whose residual exceeds the tolerance is never written.
        return fail(
            NO_RESULT,
            format!(
                "residual {:.3e} exceeds the tolerance {tolerance:.1e}",
                eq.residual
            ),
        );
    }
    if let Some(out) = output {
        let written = if is_vtp(out) {
            write_polyline(out, &eq)
        } else {
            write_equilibrium(out, &eq, &problem.text, true).map_err(|e| e.to_string())
        };
        if let Err(e) = written {
            return fail(OUTPUT, e);
        }
        println!("written   {}", out.display());
    }
    ExitCode::SUCCESS
}

/// `-o NAME.vtp`: the equilibrium as VTK PolyData for ParaView, not HDF5.
fn is_vtp(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vtp"))
}

/// Writes the equilibrium as a VTK polyline with its fields, atomically.
fn write_polyline(path: &Path, eq: &Equilibrium) -> Result<(), String> {
    use cosserat::output::vtk::{polydata, Polyline};
    let rod = Polyline::from_samples(&eq.samples).map_err(|e| e.to_string())?;
    let text = polydata(&rod);
    cosserat::output::target::replace_atomically(path, |tmp| std::fs::write(tmp, &text))
}

/// What `cosserat solve` computes: the equilibrium and its stability
/// verdict ([`cosserat::stability::decide_verdict`]: the verdict alone, from
/// the coarsest meshes that settle it).
pub struct Solved {
    /// The equilibrium.
    pub eq: Equilibrium,
    /// Its stability decision, or why none was made.
    pub decision: Result<cosserat::stability::Decision, cosserat::stability::StabilityError>,
}

/// The computation of `cosserat solve`, without printing or writing (also
/// what `cosserat bench solve` times).
pub fn compute_solve(problem: &Problem) -> Result<Solved, cosserat::bvp::SolveError> {
    let eq = solve(&problem.rod, &problem.model, &problem.options)?;
    let decision = cosserat::stability::decide_verdict(
        &problem.rod,
        &eq,
        &problem.options,
        &problem.stability,
    );
    Ok(Solved { eq, decision })
}

/// Prints the stability verdict of a solved equilibrium (conservative
/// loads), decided on a mesh refined from the problem's `[stability]`
/// settings until the Morse index and the signs of the lowest eigenvalues
/// are certain: a converged but unstable equilibrium is one the loading
/// does not reach — say so rather than let it pass as the answer — and an
/// uncertain one is "undecided".
fn verdict(decision: Result<cosserat::stability::Decision, cosserat::stability::StabilityError>) {
    use cosserat::stability::Verdict;
    match decision {
        Ok(d) => match d.verdict {
            Verdict::Stable => println!(
                "stability stable (Morse index 0; {} elements, eigenvalue error ≤ {:.1e})",
                d.elements, d.eigenvalue_error
            ),
            Verdict::Unstable { morse_index } => {
                println!(
                    "stability UNSTABLE (Morse index {morse_index}; {} elements, eigenvalue error ≤ {:.1e})",
                    d.elements, d.eigenvalue_error
                );
                eprintln!(
                    "warning: this equilibrium is unstable (Morse index {morse_index}): loading the rod \
                     would not settle here; follow the load with `cosserat continue` or try \
                     --method multiple-shooting / collocation"
                );
            }
            Verdict::Undecided { reason } => {
                println!("stability undecided: {reason}");
                eprintln!(
                    "warning: the stability of this equilibrium is undecided ({reason}); \
                     raise stability.elements or run `cosserat stability` on it"
                );
            }
        },
        Err(e) => println!("stability not decided: {e}"),
    }
}

fn report(eq: &Equilibrium) {
    let tip = eq.tip();
    let v = |x: nalgebra::Vector3<f64>| format!("[{:+.12e}, {:+.12e}, {:+.12e}]", x[0], x[1], x[2]);
    println!("method    {}", eq.method.name());
    if eq.load_steps > 0 {
        println!("load ramp {} steps", eq.load_steps);
    }
    println!("newton    {} iterations", eq.iterations);
    println!("residual  {:.3e} (scaled max-norm)", eq.residual);
    println!("tip       position {}", v(tip.position));
    println!("          tangent  {}", v(tip.directors[2]));
    println!("drift     {:.1e} (max |d_i·d_j − δ_ij|)", eq.director_drift);
    println!(
        "work      {} steps, {} rejected, {} evaluations",
        eq.integration.accepted, eq.integration.rejected, eq.integration.evaluations
    );
    println!("time      {:.3} ms", eq.wall_time * 1e3);
}
