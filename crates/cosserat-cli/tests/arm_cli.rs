//! The longest arm from the command line: `cosserat optimize` interrupted
//! (keeping its best design), resumed where it stopped, and the Fig. 5 file
//! and chart.
mod common;

use common::h5::stop_reason;
use common::problems::{load, shipped};
use common::run::{scratch, signal, stderr, BIN};

/// Ctrl-C during `cosserat optimize` keeps the best design found so far in
/// a valid file marked interrupted, and that design is what it claims.
#[test]
fn interrupted_optimization_keeps_its_best_design() {
    let dir = scratch("arm", "interrupted");
    let out = dir.join("arm.h5");
    let file = shipped("longest_arm");
    // `interrupt` also checks that the file is marked interrupted.
    let (code, _) = interrupt(&file, &out, &["--set", "arm.samples=20000"], "-INT", 1500);
    assert_eq!(code, Some(130));
    let (reach, c, _) = read_reach(&out);
    let (arm, _, _) = load("longest_arm").arm.unwrap();
    let again = arm.design(&c[1..]).unwrap();
    assert!(
        (again.reach - reach).abs() < 1e-12 && reach > 1.0,
        "{reach} vs {}",
        again.reach
    );
    std::fs::remove_dir_all(dir).unwrap();
}

fn optimize(args: &[&str]) -> std::process::Output {
    std::process::Command::new(BIN)
        .arg("optimize")
        .args(args)
        .output()
        .unwrap()
}

fn read_reach(path: &std::path::Path) -> (f64, Vec<f64>, u64) {
    let f = common::h5::open(path);
    let reach = f.dataset("optimum/reach").unwrap().float().unwrap();
    let c = common::h5::read_f64(&f, "optimum/shape_coefficients");
    let evaluations = f
        .group("optimum")
        .unwrap()
        .attrs
        .count("evaluations")
        .unwrap();
    (reach, c, evaluations)
}

/// Starts `optimize` on `file` with `set`, sends `signal` after `wait`
/// ms, and returns the exit code and the samples the file kept.
fn interrupt(
    file: &str,
    out: &std::path::Path,
    set: &[&str],
    sig: &str,
    wait: u64,
) -> (Option<i32>, u64) {
    let mut child = std::process::Command::new(BIN)
        .args(["optimize", file, "-o", out.to_str().unwrap()])
        .args(set)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(wait));
    signal(&child, sig);
    let code = child.wait().unwrap().code();
    let f = common::h5::open(out);
    assert_eq!(stop_reason(&f), "interrupted");
    let kept = f
        .group("search")
        .unwrap()
        .attrs
        .count("samples_done")
        .unwrap();
    (code, kept)
}

/// `optimize --resume` (issue 9): a run interrupted by SIGINT, or killed
/// (SIGKILL, no handler: the checkpoint saved every 2 s), keeps its search
/// progress; resuming goes on from there (not from the start) and ends on
/// exactly the optimum of an uninterrupted run, with the same number of
/// design evaluations — nothing lost, nothing done twice. A file of another
/// problem is refused; a completed one has nothing to resume.
#[test]
fn interrupted_optimization_resumes_where_it_stopped() {
    let dir = scratch("arm", "resume");
    let file = shipped("longest_arm");
    // Long enough that the kill at 3 s (after the first 2 s checkpoint)
    // lands mid-search: the parallel sampling finishes 6000 samples in
    // under 3 s on 2 cores (also in CI's build, whose dev profile
    // optimizes).
    let samples = 24000;
    let samples_key = format!("arm.samples={samples}");
    let set = ["--set", samples_key.as_str(), "--set", "arm.straight=false"];
    let reference = dir.join("reference.h5");
    let whole = optimize(&[
        &file,
        "-o",
        reference.to_str().unwrap(),
        set[0],
        set[1],
        set[2],
        set[3],
    ]);
    assert_eq!(whole.status.code(), Some(0));
    let expected = read_reach(&reference);
    for (signal, wait, code) in [("-INT", 1000, Some(130)), ("-KILL", 3000, None)] {
        let out = dir.join(format!("arm{signal}.h5"));
        let (got, kept) = interrupt(&file, &out, &set, signal, wait);
        assert_eq!(got, code, "{signal}");
        assert!(
            (1..samples).contains(&kept),
            "{signal}: samples done {kept}"
        );
        let other = optimize(&[&file, "-o", out.to_str().unwrap(), "--resume"]);
        assert_eq!(
            other.status.code(),
            Some(2),
            "another problem (other --set) resumed"
        );
        let resume = [
            &file,
            "-o",
            out.to_str().unwrap(),
            "--resume",
            set[0],
            set[1],
            set[2],
            set[3],
        ];
        let resumed = optimize(&resume);
        let text = String::from_utf8_lossy(&resumed.stdout);
        assert_eq!(resumed.status.code(), Some(0), "{text}");
        assert!(text.contains(&format!("after {kept} samples")), "{text}");
        let got = read_reach(&out);
        assert_eq!(
            got, expected,
            "{signal}: resumed {got:?} vs uninterrupted {expected:?}"
        );
        let again = optimize(&resume);
        assert!(String::from_utf8_lossy(&again.stdout).contains("nothing to resume"));
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// `cosserat optimize problems/longest_arm_fig5.toml -o … --plot …`: the
/// Fig. 5 file and chart. Checked from the file alone: 'Q' is the map
/// sample of least Σb² (recomputed from /map/curvature_coefficients) with
/// that sample's reach; the least-Σb² polish is no worse than Q; R* is at
/// least every sample's reach (the map is the search's own first samples).
#[test]
fn fig5_file_and_chart() {
    let dir = scratch("arm", "fig5");
    let (out, png) = (dir.join("fig5.h5"), dir.join("fig5.png"));
    let file = shipped("longest_arm_fig5");
    let o = optimize(&[
        &file,
        "-o",
        out.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
        "--set",
        "arm.map_samples=300",
        "--set",
        "arm.straight=false",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
    let f = common::h5::open(&out);
    let read = |name: &str| common::h5::read_f64(&f, name);
    let reach = read("map/reach");
    let b = read("map/curvature_coefficients");
    assert_eq!(b.len(), 4 * reach.len());
    let norms: Vec<f64> = b.chunks(4).map(|r| r.iter().map(|v| v * v).sum()).collect();
    let least = (0..norms.len())
        .min_by(|&i, &j| norms[i].total_cmp(&norms[j]))
        .unwrap();
    let q = f.group("closest_straight").unwrap();
    let index = q.attrs.count("index").unwrap() as usize;
    assert_eq!(index, least);
    let q_reach = read("closest_straight/reach")[0];
    assert!((q_reach - reach[least]).abs() < 1e-12);
    let q_norm = read("closest_straight/curvature_norm")[0];
    assert!((q_norm - norms[least]).abs() < 1e-9 * norms[least]);
    assert!(read("least_curvature/curvature_norm")[0] <= q_norm);
    let best = read("optimum/reach")[0];
    assert!(
        reach.iter().all(|r| *r <= best),
        "a sample beats R* = {best}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}
