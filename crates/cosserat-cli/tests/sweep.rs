//! `cosserat sweep` and `cosserat merge`: values against closed forms,
//! results independent of threads, shards and interruptions, and every
//! class of bad input (exit 2, the field named, nothing written).
mod common;
use common::problems::shipped;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use cosserat::input::Problem;
use cosserat::output::read_sweep;
use cosserat::study::sweep::contour::{fit_power_law, GridField};
use cosserat::study::sweep::Record;

use common::run::{interrupt_after, stderr, BIN};

/// A small arm (M = 3, a short search) over B̄1 × B̄3 with two families;
/// `count` values of B̄3 per line.
fn small_arm(count: usize) -> String {
    format!(
        r#"
[rod]
length = 1.0
[energy]
stiffness = [2.0, 1.0, 1.0]
[loads]
tip_force = [1.0, 0.0, 0.0]
[arm]
coefficients = 3
bounds = [[-4.0, 4.0], [-2.0, 2.0]]
samples = 30
starts = 1
iterations = 80
elements = 40
order = 1
straight = false
[sweep]
families = 2
warm_iterations = 80
axes = [
  {{ key = "energy.stiffness[0]", values = [1.0, 3.0] }},
  {{ key = "energy.stiffness[2]", linspace = [0.5, 2.0, {count}] }},
]
"#
    )
}

fn scratch(name: &str) -> PathBuf {
    common::run::scratch("sweep", name)
}

fn sweep(problem: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut c = Command::new(BIN);
    c.args([
        "sweep",
        problem.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ])
    .args(extra)
    .stdout(Stdio::piped())
    .stderr(Stdio::piped());
    c
}

fn run(c: &mut Command) -> Output {
    c.output().expect("the binary runs")
}

/// A record as bit patterns: index, numeric columns, labels.
type Bits = (usize, Vec<(String, Vec<u64>)>, Vec<(String, String)>);

/// Records as bit patterns, so that NaN = NaN and −0 ≠ 0.
fn bits(records: &[Record]) -> Vec<Bits> {
    records
        .iter()
        .map(|r| {
            (
                r.index,
                r.numbers
                    .iter()
                    .map(|(k, v)| (k.clone(), v.iter().map(|x| x.to_bits()).collect()))
                    .collect(),
                r.labels.clone().into_iter().collect(),
            )
        })
        .collect()
}

fn stop_reason(path: &Path) -> cosserat::continuation::RunState {
    read_sweep(path).unwrap().0.stop_reason
}

/// With M = 1 the loaded shape is the straight horizontal rod, whose
/// critical load is Timoshenko's: γ = 2 j₋₁/₄,₁ √(B̄1 B̄3), so
/// R* = √γ at every grid point (closed form, Bessel zero).
#[test]
fn straight_arm_grid_matches_timoshenko() {
    let dir = scratch("timoshenko");
    let problem = dir.join("p.toml");
    let text = small_arm(3)
        .replace("coefficients = 3", "coefficients = 1")
        .replace("bounds = [[-4.0, 4.0], [-2.0, 2.0]]", "bounds = []")
        .replace("order = 1", "order = 2")
        .replace("elements = 40", "elements = 100")
        .replace("families = 2", "families = 1");
    std::fs::write(&problem, text).unwrap();
    let out = dir.join("s.h5");
    let o = run(&mut sweep(&problem, &out, &[]));
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, records) = read_sweep(&out).unwrap();
    assert_eq!(header.stop_reason, "completed");
    assert_eq!(records.len(), 6);
    let j = cosserat::references::bessel_first_zero(-0.25, 1.0, 3.0);
    for r in &records {
        let (b1, b3) = (header.axes[0][r.index / 3], header.axes[1][r.index % 3]);
        let exact = (2.0 * j * (b1 * b3).sqrt()).sqrt();
        let reach = r.number("family_0/reach").unwrap();
        assert!(
            (reach - exact).abs() < 1e-6 * exact,
            "({b1}, {b3}): {reach} vs {exact}"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// The contour fit of eq. (61) on the closed form R = (B̄1 B̄3)^(1/4),
/// whose contours are exactly B̄3 = Ω B̄1^(−1): ι converges to 1 as the
/// grid is refined (a convergence study of the interpolation error).
#[test]
fn power_law_fit_converges_to_the_exact_exponent() {
    let error = |n: usize| {
        let axis: Vec<f64> = (0..n)
            .map(|i| 0.25 + 6.75 * i as f64 / (n - 1) as f64)
            .collect();
        let y: Vec<f64> = (0..n)
            .map(|i| 1.0 / 6.0 + 4.5 * i as f64 / (n - 1) as f64)
            .collect();
        let z: Vec<f64> = axis
            .iter()
            .flat_map(|a| y.iter().map(move |b| (a * b).powf(0.25)))
            .collect();
        let field = GridField {
            x: &axis,
            y: &y,
            z: &z,
        };
        let fit = fit_power_law(&field, &field.levels(8)).unwrap();
        (fit.iota - 1.0).abs()
    };
    let (coarse, fine) = (error(7), error(28));
    assert!(fine < coarse / 2.0, "7×7: {coarse}, 28×28: {fine}");
    assert!(fine < 0.01, "28×28: |ι − 1| = {fine}");
}

/// The same numbers on 1 and 2 threads, and from two shards merged.
#[test]
fn threads_and_shards_give_identical_results() {
    let dir = scratch("threads");
    let problem = dir.join("p.toml");
    std::fs::write(&problem, small_arm(4)).unwrap();
    let (one, two) = (dir.join("one.h5"), dir.join("two.h5"));
    for (out, t) in [(&one, "1"), (&two, "2")] {
        let o = run(&mut sweep(&problem, out, &["--threads", t]));
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let (a, b) = (read_sweep(&one).unwrap().1, read_sweep(&two).unwrap().1);
    assert_eq!(a.len(), 8);
    assert!(a.iter().all(|r| r.labels["family_0/status"] == "optimum"));
    assert_eq!(bits(&a), bits(&b));
    let shards: Vec<PathBuf> = (0..2).map(|i| dir.join(format!("shard{i}.h5"))).collect();
    for (i, out) in shards.iter().enumerate() {
        let o = run(&mut sweep(&problem, out, &["--shard", &format!("{i}/2")]));
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(read_sweep(out).unwrap().1.len(), 4, "one line per shard");
    }
    let merged = dir.join("merged.h5");
    let o = run(Command::new(BIN).args([
        "merge",
        shards[0].to_str().unwrap(),
        shards[1].to_str().unwrap(),
        "-o",
        merged.to_str().unwrap(),
    ]));
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, m) = read_sweep(&merged).unwrap();
    assert_eq!(h.stop_reason, "completed");
    assert_eq!(bits(&m), bits(&a));
    std::fs::remove_dir_all(dir).unwrap();
}

/// Merging refuses overlapping shards and files of another problem.
#[test]
fn merge_refuses_overlaps_and_mismatches() {
    let dir = scratch("merge");
    let problem = dir.join("p.toml");
    std::fs::write(&problem, small_arm(2)).unwrap();
    let a = dir.join("a.h5");
    let o = run(&mut sweep(&problem, &a, &["--shard", "0/2"]));
    assert!(o.status.success(), "{}", stderr(&o));
    let other = dir.join("other.h5");
    let o = run(&mut sweep(
        &problem,
        &other,
        &["--shard", "1/2", "--set", "arm.samples=31"],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let out = dir.join("all.h5");
    for (inputs, expect) in [
        ([&a, &a], "overlapping"),
        ([&a, &other], "the problem differs"),
    ] {
        let o = run(Command::new(BIN)
            .arg("merge")
            .args(inputs.iter().map(|p| p.to_str().unwrap()))
            .args(["-o", out.to_str().unwrap(), "--force"]));
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(expect), "{}", stderr(&o));
        assert!(!out.exists(), "nothing written");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A killed sweep (SIGKILL: no handler runs) leaves a valid checkpoint;
/// `--resume` finishes it with the numbers of an uninterrupted run.
#[test]
fn killed_sweep_resumes_to_the_same_results() {
    let dir = scratch("kill");
    let problem = dir.join("p.toml");
    std::fs::write(&problem, small_arm(30)).unwrap();
    let (partial, full) = (dir.join("partial.h5"), dir.join("full.h5"));
    let mut child = sweep(&problem, &partial, &["--threads", "1"])
        .spawn()
        .unwrap();
    // Kill as soon as a checkpoint holds a point (a fixed sleep raced the
    // sweep on a lightly loaded machine), well before the 60th.
    let saved_some = || read_sweep(&partial).is_ok_and(|(_, s)| !s.is_empty());
    for _ in 0..600 {
        if saved_some() || child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    let _ = child.wait();
    let (h, saved) = read_sweep(&partial).expect("the checkpoint is a valid sweep file");
    assert_eq!(h.stop_reason, "in progress");
    assert!(
        !saved.is_empty() && saved.len() < 60,
        "{} points saved",
        saved.len()
    );
    let o = run(&mut sweep(
        &problem,
        &partial,
        &["--resume", "--threads", "2"],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("resume"));
    let o = run(&mut sweep(&problem, &full, &[]));
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stop_reason(&partial), "completed");
    let (a, b) = (
        read_sweep(&partial).unwrap().1,
        read_sweep(&full).unwrap().1,
    );
    assert_eq!(a.len(), 60);
    assert_eq!(bits(&a), bits(&b));
    std::fs::remove_dir_all(dir).unwrap();
}

/// Ctrl-C keeps every finished point in a valid file marked interrupted
/// and exits with 130; no temporary file is left behind.
#[test]
fn interrupted_sweep_keeps_its_points() {
    let dir = scratch("int");
    let problem = dir.join("p.toml");
    std::fs::write(&problem, small_arm(30)).unwrap();
    let out = dir.join("s.h5");
    let mut child = sweep(&problem, &out, &["--threads", "1"]).spawn().unwrap();
    // Interrupt once the checkpoint holds a point (a fixed 1.5 s raced the
    // whole sweep once its points got faster), well before the 60th.
    for _ in 0..600 {
        let saved = read_sweep(&out).is_ok_and(|(_, s)| !s.is_empty());
        if saved || child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let status = interrupt_after(&mut child, 0);
    assert_eq!(status.code(), Some(130));
    let (h, records) = read_sweep(&out).unwrap();
    assert_eq!(h.stop_reason, "interrupted");
    assert!(!records.is_empty() && records.len() < 60);
    let left = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(left, 2, "the problem and the result only");
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--set energy.stiffness[0]=…` sets one element; an index past the end
/// is an error naming the array.
#[test]
fn indexed_overrides_set_one_element() {
    let text = small_arm(2);
    let p = Problem::from_str_with(&text, &["energy.stiffness[2]=5".into()]).unwrap();
    let (arm, _, _) = p.arm.unwrap();
    assert_eq!((arm.b1, arm.b3), (2.0, 5.0));
    let e = Problem::from_str_with(&text, &["energy.stiffness[3]=5".into()]).unwrap_err();
    assert!(e.to_string().contains("`stiffness` has 3 elements"), "{e}");
}

/// Bad input: exit 2, a message naming the field, no output file.
#[test]
fn bad_sweeps_are_rejected_before_any_work() {
    let dir = scratch("bad");
    let base = small_arm(2);
    let cases: [(&str, String, &[&str]); 6] = [
        (
            "no table",
            base.split("[sweep]").next().unwrap().to_string(),
            &[],
        ),
        (
            "linspace",
            base.replace("linspace = [0.5, 2.0, 2]", "linspace = [0.5, 2.0, 0]"),
            &[],
        ),
        (
            "two ways",
            base.replace(
                "values = [1.0, 3.0]",
                "values = [1.0], linspace = [1.0, 2.0, 2]",
            ),
            &[],
        ),
        (
            "bad key",
            base.replace("energy.stiffness[0]", "energy.stifness[0]"),
            &[],
        ),
        (
            "bad value",
            base.replace("values = [1.0, 3.0]", "values = [1.0, -3.0]"),
            &[],
        ),
        ("shard", base.clone(), &["--shard", "2/2"]),
    ];
    let expect = [
        "sweep: the problem has no [sweep] table",
        "sweep.axes[1].linspace",
        "sweep.axes[0]",
        "energy.stifness",
        "energy.stiffness[0]",
        "--shard 2/2",
    ];
    for ((name, text, extra), want) in cases.iter().zip(expect) {
        let problem = dir.join("p.toml");
        std::fs::write(&problem, text).unwrap();
        let out = dir.join("out.h5");
        let o = run(&mut sweep(&problem, &out, extra));
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(want),
            "{name}: `{want}` not in {}",
            stderr(&o)
        );
        assert!(!out.exists(), "{name}: output written");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// The shipped Fig. 6 problem on a 3 × 3 grid (the CI-sized run): every
/// point has an optimum, and R* grows with B̄1 and with B̄3 (paper Sec. 4.2:
/// "the outreach is an increasing function of B̄1 and B̄3").
#[test]
fn fig6_problem_on_a_small_grid() {
    let dir = scratch("fig6");
    let problem = shipped("longest_arm_fig6");
    let out = dir.join("fig6.h5");
    let chart = dir.join("fig6.svg");
    let axes = "sweep.axes=[{key=\"energy.stiffness[0]\",linspace=[0.25,7,3]},\
                {key=\"energy.stiffness[2]\",linspace=[0.1666666666666667,4.666666666666667,3]}]";
    let o = run(&mut sweep(
        Path::new(&problem),
        &out,
        &["--set", axes, "--plot", chart.to_str().unwrap()],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(chart.exists());
    // A completed file resumed with --plot computes nothing and draws the
    // chart from the file.
    std::fs::remove_file(&chart).unwrap();
    let o = run(&mut sweep(
        Path::new(&problem),
        &out,
        &["--set", axes, "--resume", "--plot", chart.to_str().unwrap()],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("nothing to resume"));
    assert!(chart.exists(), "the chart of the completed sweep is drawn");
    let (header, records) = read_sweep(&out).unwrap();
    assert_eq!(header.points(), 9);
    let reach: Vec<f64> = records
        .iter()
        .map(|r| r.number("family_0/reach").unwrap())
        .collect();
    for i in 0..3 {
        for j in 0..2 {
            assert!(
                reach[i * 3 + j + 1] > reach[i * 3 + j],
                "B̄3 row {i}: {reach:?}"
            );
            assert!(
                reach[(j + 1) * 3 + i] > reach[j * 3 + i],
                "B̄1 column {i}: {reach:?}"
            );
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// The shipped Fig. 7 problem straight up (α = 90°): the optimized arm
/// reaches Euler's column height Rb = π/2 (paper eq. (2) and Sec. 4.3: in
/// the plane, intrinsic curvature cannot raise it), and intrinsic curvature
/// lets the level arm (α = 0) reach farther than the straight one.
#[test]
fn fig7_problem_reaches_euler_height_upwards() {
    let dir = scratch("fig7");
    let problem = shipped("longest_arm_fig7");
    let out = dir.join("fig7.h5");
    let axes = "sweep.axes=[{key=\"energy.stiffness[0]\",values=[1.0]},\
                {key=\"arm.alpha\",values=[90,0]}]";
    let o = run(&mut sweep(Path::new(&problem), &out, &["--set", axes]));
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, records) = read_sweep(&out).unwrap();
    let up = records[0].number("family_0/reach").unwrap();
    let rb = std::f64::consts::FRAC_PI_2;
    assert!((up - rb).abs() < 1e-3 * rb, "R*(90°) = {up}");
    let level = records[1].number("family_0/reach").unwrap();
    let straight = records[1].number("straight/reach").unwrap();
    assert!(level > straight, "R* = {level}, R0 = {straight}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// A solve sweep over the tip load of the shipped cantilever: every tip
/// on the Bisshopp–Drucker elastica (elliptic integrals).
#[test]
fn solve_sweep_follows_the_elastica() {
    let dir = scratch("solve");
    let problem = dir.join("p.toml");
    let base = include_str!("../../../problems/cantilever_tip_load.toml");
    let text = format!(
        "{base}\n[sweep]\naxes = [{{ key = \"loads.tip_force[0]\", values = [0.5, 1, 2, 3] }}]\n"
    );
    std::fs::write(&problem, text).unwrap();
    let out = dir.join("s.h5");
    let o = run(&mut sweep(&problem, &out, &[]));
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, records) = read_sweep(&out).unwrap();
    assert_eq!(header.kind, "solve");
    for r in &records {
        let k = header.axes[0][r.index];
        let exact = cosserat::references::CantileverTip::at(k);
        let tip = &r.numbers["solve/tip_position"];
        assert_eq!(r.labels["solve/status"], "converged");
        assert!(
            (tip[0] - exact.x).abs() < 1e-8 && (tip[2] - exact.z).abs() < 1e-8,
            "k = {k}: {tip:?} vs ({}, {})",
            exact.x,
            exact.z
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}
