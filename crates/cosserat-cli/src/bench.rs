//! `cosserat bench work-precision`: error against wall time for every
//! method and order on scenes with independent references.
//! `cosserat bench solve|stability|continue|optimize PROBLEM`: the wall
//! time of a command's computation beside its accuracy
//! ([`crate::bench_timed`]).
//!
//! Scenes: the planar cantilever under a tip force k = F L²/B = 3 and 10
//! (reference: the elliptic-integral closed form of Bisshopp & Drucker,
//! Q. Appl. Math. 3, 1945, evaluated with Carlson's R_F and R_D), and a
//! spatial scene solved with the 9-ODE model, the unloaded rod with constant
//! intrinsic curvature κ⁰ (reference: the helix
//! `r(L) = [L I + (1 − cos ωL)/ω² K + (ωL − sin ωL)/ω³ K²] e3`, `K = [κ⁰]×`,
//! ω = |κ⁰|). Sweeps: the integrator tolerance for single and multiple
//! shooting, the uniform mesh (no adaptation) for collocation of orders 4
//! and 6. Recorded per point: tip error (max-norm), wall time (median of
//! repeated solves in this process), Newton steps of the final solve, and
//! the mesh size (integration steps for shooting, intervals for
//! collocation). Output: `work_precision.csv`, `.png`, `.svg`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use clap::Subcommand;

use crate::bench_timed::{run as timed, Timed, TimedArgs};
use nalgebra::{Matrix3, Vector3};
use plotters::prelude::*;

use cosserat::bvp::integrator::Tolerances;
use cosserat::bvp::{solve, CollocationOptions, Discretization, Method, SolverOptions};
use cosserat::model::{Clamp, DeadLoads, LinearElastic, ModelChoice, ModelLevel, Rod};

/// The benchmarks of `cosserat bench`.
#[derive(Debug, Clone, Subcommand)]
pub enum BenchCommand {
    /// Error against wall time for every method and order (CSV, PNG, SVG).
    WorkPrecision {
        /// Directory for work_precision.csv, .png and .svg.
        #[arg(short, long, default_value = "work-precision")]
        output: PathBuf,
        /// Draw the chart of stored measurements (work_precision.csv files,
        /// or another tool's points in that format, such as
        /// scripts/scipy_work_precision.py's; repeat to draw several
        /// together) into the output directory instead of measuring again:
        /// the timings stay those of the machine that measured them.
        #[arg(long, value_name = "CSV")]
        redraw: Vec<PathBuf>,
    },
    /// Wall time of `cosserat solve`'s computation (the equilibrium and
    /// its stability verdict; no file written): median, min, max after
    /// one warm-up, the work of a run, the accuracy where a validation
    /// case gives a reference.
    Solve(TimedArgs),
    /// Wall time of `cosserat stability`'s computation (a critical load,
    /// or an equilibrium's decided stability), as `bench solve`.
    Stability(TimedArgs),
    /// Wall time of a problem's whole `[continuation]` diagram with its
    /// branches and special points, so that speed and result are read
    /// together.
    Continue(TimedArgs),
    /// Wall time of `cosserat optimize`'s computation (the search, R0 and
    /// the reach map; no paths, no file), as `bench solve`.
    Optimize(TimedArgs),
}

/// Runs a benchmark; the exit code of the command.
pub fn run(command: BenchCommand) -> ExitCode {
    match command {
        BenchCommand::WorkPrecision { output, redraw } if !redraw.is_empty() => {
            let mut points = Vec::new();
            for csv in &redraw {
                match read_points(csv) {
                    Ok(p) => points.extend(p),
                    Err(e) => {
                        return crate::exit::fail(
                            crate::exit::BAD_INPUT,
                            format!("{}: {e}", csv.display()),
                        )
                    }
                }
            }
            match draw_work_precision(&output, &points) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => crate::exit::fail(crate::exit::OUTPUT, e),
            }
        }
        BenchCommand::WorkPrecision { output, .. } => match work_precision(&output) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(3)
            }
        },
        BenchCommand::Solve(args) => timed(Timed::Solve, &args),
        BenchCommand::Stability(args) => timed(Timed::Stability, &args),
        BenchCommand::Continue(args) => timed(Timed::Continue, &args),
        BenchCommand::Optimize(args) => timed(Timed::Optimize, &args),
    }
}

/// Branches and special points of a diagram, one line each.
pub fn diagram_summary(d: &cosserat::continuation::Diagram) -> String {
    let mut out = String::new();
    for w in &d.warnings {
        let _ = writeln!(out, "warning   {w}");
    }
    for (i, b) in d.branches.iter().enumerate() {
        let (first, last) = (b.points.first(), b.points.last());
        let _ = writeln!(
            out,
            "branch {i}  {} points, parameter {:.12} → {:.12}; {}",
            b.points.len(),
            first.map_or(f64::NAN, |p| p.parameter),
            last.map_or(f64::NAN, |p| p.parameter),
            b.stop_reason
        );
    }
    for (i, s) in d.special_points.iter().enumerate() {
        let _ = writeln!(
            out,
            "special {i}  {} on branch {} at parameter {:.12}, {} block, Morse index {}",
            s.kind.name(),
            s.branch,
            s.point.parameter,
            s.block.name(),
            s.point.morse_index
        );
    }
    out
}

/// One point of a work-precision curve.
#[derive(Debug, Clone)]
pub struct Point {
    /// The scene solved (a name of [`scenes`]).
    pub scene: &'static str,
    /// "shooting", "multiple-shooting (8)", "collocation m=2", …
    pub method: String,
    /// The swept parameter: integrator tolerance or intervals.
    pub parameter: f64,
    /// Max-norm error of the tip position against the scene's reference.
    pub error: f64,
    /// Median wall time of one solve, s.
    pub time: f64,
    /// Newton iterations of the solve.
    pub newton_steps: usize,
    /// Collocation intervals, or accepted integrator steps for shooting.
    pub mesh: usize,
}

/// A scene with its reference tip position.
pub struct Scene {
    /// Its name in the chart and the CSV.
    pub name: &'static str,
    /// The rod and its loads.
    pub rod: Rod,
    /// The model level it is solved at.
    pub level: ModelLevel,
    /// The reference tip position r(L), from a closed form.
    pub tip: Vector3<f64>,
}

/// The three scenes of the chart.
pub fn scenes() -> Vec<Scene> {
    let cantilever = |k: f64| {
        let rod = Rod::new(
            1.0,
            Arc::new(
                LinearElastic::uniform([10.0, 1.0, 10.0], [0.0; 3])
                    .expect("a fixed scene is a valid energy"),
            ),
            Clamp::paper(),
            DeadLoads {
                tip_force: Vector3::new(k, 0.0, 0.0),
                ..Default::default()
            },
            None,
        )
        .expect("a fixed scene is a valid rod");
        let (x, z) = cantilever_tip(k);
        (rod, Vector3::new(x, 0.0, z))
    };
    let (k3, tip3) = cantilever(3.0);
    let (k10, tip10) = cantilever(10.0);
    let kappa0 = Vector3::new(1.3, -0.7, 2.1);
    let helix = Rod::new(
        3.0,
        Arc::new(
            LinearElastic::uniform([1.0, 2.0, 0.8], kappa0.into())
                .expect("a fixed scene is a valid energy"),
        ),
        Clamp::paper(),
        DeadLoads::default(),
        None,
    )
    .expect("a fixed scene is a valid rod");
    vec![
        Scene {
            name: "planar cantilever k = 3",
            rod: k3,
            level: ModelLevel::Planar,
            tip: tip3,
        },
        Scene {
            name: "planar cantilever k = 10",
            rod: k10,
            level: ModelLevel::Planar,
            tip: tip10,
        },
        Scene {
            name: "spatial helix (9-ODE)",
            rod: helix,
            level: ModelLevel::Kirchhoff,
            tip: helix_tip(kappa0, 3.0),
        },
    ]
}

/// The sweeps: (label, options) for every method and setting.
fn sweeps() -> Vec<(String, f64, SolverOptions)> {
    let base = SolverOptions {
        output_points: 2,
        newton: cosserat::bvp::newton::NewtonOptions {
            tolerance: 1e-12,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut out = Vec::new();
    for (label, method) in [
        ("shooting".to_string(), Method::Shooting),
        (
            "multiple shooting (8)".to_string(),
            Method::MultipleShooting { segments: 8 },
        ),
    ] {
        for e in 3..=12 {
            let tol = 10f64.powi(-e);
            out.push((
                label.clone(),
                tol,
                SolverOptions {
                    method,
                    integration: Tolerances {
                        rtol: tol,
                        atol: tol,
                        ..Default::default()
                    },
                    ..base.clone()
                },
            ));
        }
    }
    for (stages, meshes) in [
        (2usize, &[4usize, 8, 16, 32, 64, 128, 256, 512][..]),
        (3, &[4, 8, 16, 32, 64, 128][..]),
    ] {
        for &n in meshes {
            out.push((
                format!("collocation order {}", 2 * stages),
                n as f64,
                SolverOptions {
                    method: Method::Collocation { stages },
                    collocation: CollocationOptions {
                        stages,
                        intervals: n,
                        adapt: false,
                        tolerance: f64::INFINITY,
                        max_intervals: n,
                    },
                    ..base.clone()
                },
            ));
        }
    }
    out
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Runs every sweep on every scene.
pub fn measure() -> Vec<Point> {
    let mut points = Vec::new();
    for scene in scenes() {
        let choice = ModelChoice::forced(&scene.rod, scene.level).expect("scene fits its level");
        for (method, parameter, opts) in sweeps() {
            let t = Instant::now();
            let Ok(eq) = solve(&scene.rod, &choice, &opts) else {
                eprintln!("{} / {method} / {parameter:e}: no solution", scene.name);
                continue;
            };
            let first = t.elapsed().as_secs_f64();
            let repeats = ((0.05 / first) as usize).clamp(2, 21) | 1;
            let times: Vec<f64> = (0..repeats)
                .map(|_| {
                    let t = Instant::now();
                    let _ = solve(&scene.rod, &choice, &opts);
                    t.elapsed().as_secs_f64()
                })
                .collect();
            let error = (eq.tip().position - scene.tip).amax();
            let (newton_steps, mesh) = match &eq.discretization {
                Discretization::Collocation(sol) => (sol.newton_steps, sol.intervals()),
                Discretization::Shooting => (eq.iterations, eq.integration.accepted),
            };
            let p = Point {
                scene: scene.name,
                method,
                parameter,
                error,
                time: median(times),
                newton_steps,
                mesh,
            };
            eprintln!(
                "{:<26} {:<22} {:>8.0e} error {:>8.1e} time {:>9.1} µs",
                p.scene,
                p.method,
                p.parameter,
                p.error,
                p.time * 1e6
            );
            points.push(p);
        }
    }
    points
}

fn work_precision(dir: &Path) -> Result<(), Box<dyn std::error::Error>> {
    std::fs::create_dir_all(dir)?;
    let points = measure();
    let mut csv = String::from("scene,method,parameter,tip_error,time_s,newton_steps,mesh_size\n");
    for p in &points {
        writeln!(
            csv,
            "{},{},{:e},{:e},{:e},{},{}",
            p.scene, p.method, p.parameter, p.error, p.time, p.newton_steps, p.mesh
        )
        .expect("writing to a String cannot fail");
    }
    cosserat::output::target::replace_atomically(&dir.join("work_precision.csv"), |tmp| {
        std::fs::write(tmp, &csv)
    })?;
    draw_work_precision(dir, &points)?;
    println!("written   {}", dir.join("work_precision.csv").display());
    Ok(())
}

/// Draws `points` to work_precision.png and .svg in `dir`.
fn draw_work_precision(dir: &Path, points: &[Point]) -> Result<(), Box<dyn std::error::Error>> {
    std::fs::create_dir_all(dir)?;
    let png = dir.join("work_precision.png");
    let svg = dir.join("work_precision.svg");
    let chart = WorkPrecision { points };
    crate::chart_style::render(&chart, &png)?;
    crate::chart_style::render(&chart, &svg)?;
    println!("written   {}, {}", png.display(), svg.display());
    Ok(())
}

/// The points of a work_precision.csv as `cosserat bench work-precision` writes it;
/// Err names the line and what is wrong.
pub fn read_points(csv: &Path) -> Result<Vec<Point>, String> {
    let text = std::fs::read_to_string(csv).map_err(|e| e.to_string())?;
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, "scene,method,parameter,tip_error,time_s,newton_steps,mesh_size")) => {}
        _ => return Err("line 1: not a work_precision.csv header".into()),
    }
    let names: Vec<&'static str> = scenes().iter().map(|s| s.name).collect();
    lines
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            let bad = |what: &str| format!("line {}: {what}", i + 1);
            let f: Vec<&str> = l.split(',').collect();
            let [scene, method, parameter, error, time, steps, mesh] = f[..] else {
                return Err(bad("not 7 fields"));
            };
            let number = |v: &str| {
                v.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| bad(&format!("`{v}` is not a finite number")))
            };
            let count = |v: &str| {
                v.parse::<usize>()
                    .map_err(|_| bad(&format!("`{v}` is not a count")))
            };
            Ok(Point {
                scene: names
                    .iter()
                    .find(|n| **n == scene)
                    .ok_or_else(|| bad(&format!("unknown scene `{scene}`")))?,
                method: method.to_string(),
                parameter: number(parameter)?,
                error: number(error)?,
                time: number(time)?,
                newton_steps: count(steps)?,
                mesh: count(mesh)?,
            })
        })
        .collect()
}

const FLOOR: f64 = 1e-16;

/// The work-precision chart: one panel per scene, error against time on
/// log axes, one colour per method; the legend in a strip above the
/// panels (never over the data).
struct WorkPrecision<'a> {
    points: &'a [Point],
}

impl crate::chart_style::Figure for WorkPrecision<'_> {
    fn size(&self) -> (u32, u32) {
        (1800, 680)
    }

    fn draw_on<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>
    where
        DB::ErrorType: 'static,
    {
        use crate::chart_style::{colour, frame, legend, Glyph, LegendEntry, Stroke};
        let points = self.points;
        let names: Vec<&str> = scenes().iter().map(|s| s.name).collect();
        let mut order: Vec<String> = Vec::new();
        for p in points {
            if !order.contains(&p.method) {
                order.push(p.method.clone());
            }
        }
        let (top, body) = root.split_vertically(56);
        let entries: Vec<LegendEntry> = order
            .iter()
            .enumerate()
            .map(|(i, m)| LegendEntry::new(Glyph::Line(colour(i), stroke_of(m)), m.clone()))
            .collect();
        legend(&top.margin(10, 0, 90, 0), &entries, entries.len())?;
        let panels = body.split_evenly((1, names.len()));
        for (panel, name) in panels.iter().zip(&names) {
            let mine: Vec<&Point> = points.iter().filter(|p| p.scene == *name).collect();
            let (tmin, tmax) = mine.iter().fold((f64::MAX, f64::MIN), |(a, b), p| {
                (a.min(p.time), b.max(p.time))
            });
            let (tmin, tmax) = if tmin <= tmax {
                (tmin, tmax)
            } else {
                (1e-6, 1.0)
            };
            let mut c = ChartBuilder::on(panel)
                .caption(*name, ("sans-serif", 24))
                .margin(12)
                .x_label_area_size(50)
                .y_label_area_size(80)
                .build_cartesian_2d(
                    (tmin / 1.5..tmax * 1.5).log_scale(),
                    (FLOOR..1.0).log_scale(),
                )?;
            c.configure_mesh()
                .x_desc("wall time per equilibrium (s)")
                .y_desc("tip error, max-norm of Δr(L)")
                .x_label_formatter(&|v| format!("{v:.0e}"))
                .y_label_formatter(&|v| format!("{v:.0e}"))
                .label_style(("sans-serif", 16))
                .axis_desc_style(("sans-serif", 18))
                .light_line_style(WHITE)
                .bold_line_style(BLACK.mix(0.12))
                .draw()?;
            for (i, m) in order.iter().enumerate() {
                let color = colour(i);
                let series: Vec<(f64, f64)> = mine
                    .iter()
                    .filter(|p| &p.method == m)
                    .map(|p| (p.time, p.error.clamp(FLOOR, 1.0)))
                    .collect();
                let style = color.stroke_width(2);
                if stroke_of(m) == Stroke::Dashed {
                    c.draw_series(DashedLineSeries::new(series.clone(), 9, 6, style))?;
                } else {
                    c.draw_series(LineSeries::new(series.clone(), style))?;
                }
                c.draw_series(
                    series
                        .iter()
                        .map(|&(x, y)| Circle::new((x, y), 4, color.filled())),
                )?;
            }
            frame(c.plotting_area())?;
        }
        Ok(())
    }
}

/// Another tool's curve (a method named for its tool, e.g. "scipy
/// solve_bvp" from scripts/scipy_work_precision.py) dashed, this
/// project's methods solid.
fn stroke_of(method: &str) -> crate::chart_style::Stroke {
    if method.starts_with("scipy") {
        crate::chart_style::Stroke::Dashed
    } else {
        crate::chart_style::Stroke::Solid
    }
}

/// Tip (x, z) of the unit cantilever under a tip force perpendicular to the
/// clamp (Bisshopp & Drucker 1945), from the validation references.
pub fn cantilever_tip(k: f64) -> (f64, f64) {
    let (x, z, _) = cosserat::references::cantilever_tip(k);
    (x, z)
}

/// Tip of the unloaded rod with constant intrinsic curvature κ⁰ clamped
/// with d1 = e1, d3 = e3 at the origin.
pub fn helix_tip(kappa0: Vector3<f64>, s: f64) -> Vector3<f64> {
    let w = kappa0.norm();
    let k = kappa0.cross_matrix();
    let m = Matrix3::identity() * s
        + k * ((1.0 - (w * s).cos()) / (w * w))
        + k * k * ((w * s - (w * s).sin()) / (w * w * w));
    m * Vector3::z()
}
