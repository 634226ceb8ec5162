//! An independent reader (issue 19): h5py — the HDF5 C library under
//! Python, sharing no code with the pure-Rust writer — opens every kind of
//! file the commands write and checks values against what the command
//! printed and against closed forms: solve's tip position and tangent as
//! printed; stability's Morse index, verdict and lowest eigenvalues as
//! printed; the Euler column's branches as printed (point counts, end
//! values, special points), its trivial branch monotone in the load and
//! stable exactly below Euler's load π²B/(4L²) (load_scale π²/4 here);
//! the sweep's counts stored as integers and its tip at the problem's own
//! load equal to solve's; the arm's R*, meshes and R0 as printed. Every
//! dataset must carry `units` and `description`.
//!
//! Skipped (with a note) where `python3 -c "import h5py"` fails, except
//! under CI (`CI=true`), where a missing h5py fails the test: .ci/run
//! installs it.

mod common;

use std::process::Command;

use common::problems::shipped;
use common::run::{run, scratch, stderr};

/// The checks, in Python; argv[1] is a JSON list of (kind, path,
/// expectation).
const CHECKS: &str = r#"
import json, math, sys
import h5py, numpy as np

def text(values):
    return [v.decode() if isinstance(v, bytes) else str(v) for v in np.atleast_1d(values)]

def described(f, path):
    missing = []
    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            for key in ("units", "description"):
                if key not in obj.attrs:
                    missing.append(name + "@" + key)
    f.visititems(visit)
    assert not missing, (path, missing)
    assert f.attrs["schema_version"] == sys.argv[2], path

def close(a, b, tol, what):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape and np.all(np.abs(a - b) <= tol), (what, a.tolist(), b.tolist())

def solve(f, e):
    s = f["solution/s"][:]
    assert s[0] == 0.0 and np.all(np.diff(s) > 0), "s increases from 0"
    close(f["solution/position"][-1], e["tip"], 1e-12, "tip position")
    close(f["solution/d3"][-1], e["tangent"], 1e-12, "tip tangent")
    assert f["solution"].attrs["method"] == "shooting"

def stability(f, e):
    g = f["stability"]
    assert g["morse_index"].dtype.kind == "u" and g["morse_index"][()] == e["morse"]
    assert g.attrs["verdict"] == e["verdict"]
    for block, values in e["blocks"].items():
        got = g[block + "/eigenvalues"][:]
        close(got[: len(values)], values, 1e-6 * max(abs(v) for v in values), block)

def diagram(f, e):
    for i, (points, first, last) in enumerate(e["branches"]):
        b = f["branches/%d" % i]
        p = b["parameter"][:]
        assert len(p) == points, (i, len(p), points)
        close([p[0], p[-1]], [first, last], 5e-7, "branch %d ends" % i)
        stable = text(b["stable"][:])
        assert set(stable) <= {"stable", "unstable"}, stable
        assert b["morse_index"].dtype.kind == "u"
    p = f["branches/0/parameter"][:]
    assert np.all(np.diff(p) > 0), "the trivial branch is monotone in the load"
    stable = np.array(text(f["branches/0/stable"][:]))
    euler = math.pi ** 2 / 4
    assert np.all(stable[p < euler - 1e-3] == "stable"), "stable below Euler's load"
    assert np.all(stable[p > euler + 1e-3] == "unstable"), "unstable above Euler's load"
    sp = f["special_points"]
    assert text(sp["kind"][:]) == [k for k, _ in e["specials"]]
    close(sp["parameter"][:], [p for _, p in e["specials"]], 1e-11, "special points")
    assert set(text(sp["symmetry_breaking"][:])) <= {"breaking", "preserving"}

def sweep(f, e):
    for name in ("points/solve/iterations", "maps/solve/iterations"):
        assert f[name].dtype.kind == "i", (name, f[name].dtype)
    assert f["points/index"].dtype.kind == "u"
    assert np.all(f["points/solve/iterations"][:] >= 1)
    assert text(f["points/solve/status"][:]) == ["converged"] * len(f["points/index"])
    row = list(f["points/parameters"][:, 0]).index(e["load"])
    close(f["points/solve/tip_position"][row], e["tip"], 1e-9, "swept tip")

def arm(f, e):
    close(f["optimum/reach"][()], e["reach"], 5e-7, "R*")
    m = f["optimum/mesh_elements"]
    assert m.dtype.kind == "u" and m[:].tolist() == e["meshes"], m[:]
    close(f["straight/reach"][()], e["straight"], 5e-7, "R0")
    assert f["optimum"].attrs["mesh"] in ("resolved", "refined", "unresolved")

for kind, path, e in json.loads(sys.argv[1]):
    with h5py.File(path, "r") as f:
        described(f, path)
        globals()[kind](f, e)
print("checked", len(json.loads(sys.argv[1])), "files")
"#;

/// Whether h5py can be imported; under CI its absence is a failure.
fn h5py_available() -> bool {
    let ok = Command::new("python3")
        .args(["-c", "import h5py"])
        .output()
        .is_ok_and(|o| o.status.success());
    let ci = std::env::var("CI").is_ok_and(|v| v == "true");
    assert!(
        ok || !ci,
        "CI=true but h5py is missing: `python3 -m pip install h5py numpy` (.ci/run)"
    );
    ok
}

/// The numbers in `text`, in order.
fn numbers_in(text: &str) -> Vec<f64> {
    text.split(|c: char| !(c.is_ascii_digit() || "+-.e".contains(c)))
        .filter_map(|w| w.parse::<f64>().ok())
        .collect()
}

/// The numbers after `label` on the line of stdout that starts with it.
fn numbers(stdout: &str, label: &str) -> Vec<f64> {
    let line = stdout
        .lines()
        .map(str::trim_start)
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no `{label}` line in\n{stdout}"));
    numbers_in(&line[label.len()..])
}

/// Runs the command, asserting success; its stdout.
fn stdout_of(args: &[&str]) -> String {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn h5py_reads_every_result_file_as_the_commands_report_it() {
    if !h5py_available() {
        eprintln!("h5py not installed: the independent-reader test is skipped");
        return;
    }
    let dir = scratch("h5py_reader", "files");
    let out = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let (solved, tip) = solve(&out("solve.h5"));
    let files = [
        solved,
        stability(&out("stability.h5")),
        diagram(&out("diagram.h5")),
        sweep(&out("sweep.h5"), &tip),
        arm(&out("arm.h5")),
    ];
    let o = Command::new("python3")
        .args([
            "-c",
            CHECKS,
            &format!("[{}]", files.join(", ")),
            cosserat::output::schema::SCHEMA_VERSION,
        ])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "h5py: {said}{}", stderr(&o));
    assert!(said.contains("checked 5 files"), "{said}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The cantilever solved: its entry, and the printed tip position.
fn solve(path: &str) -> (String, Vec<f64>) {
    let s = stdout_of(&["solve", &shipped("cantilever_tip_load"), "-o", path]);
    let (tip, tangent) = (numbers(&s, "tip"), numbers(&s, "tangent"));
    let e = format!("{{\"tip\": {tip:?}, \"tangent\": {tangent:?}}}");
    (entry("solve", path, &e), tip)
}

/// The cantilever's stability: Morse index, verdict and the printed lowest
/// eigenvalues of each block.
fn stability(path: &str) -> String {
    let s = stdout_of(&["stability", &shipped("cantilever_tip_load"), "-o", path]);
    let blocks = ["in_plane", "out_of_plane"].map(|b| {
        let v = numbers(&s, b);
        // The eigenvalues, less the trailing Morse index.
        format!("\"{b}\": {:?}", &v[..v.len() - 1])
    });
    let morse = numbers(&s, "morse")[0];
    let verdict = if s.contains("verdict   stable") {
        "stable"
    } else {
        "unstable"
    };
    let e = format!(
        "{{\"morse\": {morse}, \"verdict\": \"{verdict}\", \"blocks\": {{{}}}}}",
        blocks.join(", ")
    );
    entry("stability", path, &e)
}

/// The Euler column's diagram: each branch's points and end values, each
/// special point's kind and parameter, as printed.
fn diagram(path: &str) -> String {
    let s = stdout_of(&["continue", &shipped("euler_column"), "-o", path]);
    let branches: Vec<String> = s
        .lines()
        .filter(|l| l.starts_with("branch "))
        .map(|l| {
            let v = numbers(l, "branch");
            // branch i, points, parameter first → last.
            format!("[{}, {:?}, {:?}]", v[1], v[2], v[3])
        })
        .collect();
    let specials: Vec<String> = s
        .lines()
        .filter(|l| l.starts_with("special "))
        .map(|l| {
            let kind = l.split_whitespace().nth(2).unwrap();
            let at = numbers(&l[l.find("at parameter").unwrap()..], "at parameter")[0];
            format!("[\"{kind}\", {at:?}]")
        })
        .collect();
    assert!(!specials.is_empty(), "{s}");
    let e = format!(
        "{{\"branches\": [{}], \"specials\": [{}]}}",
        branches.join(", "),
        specials.join(", ")
    );
    entry("diagram", path, &e)
}

/// The cantilever swept over its tip force: at the shipped problem's own
/// force, 3.0, the swept point is solve's equilibrium (`tip`).
fn sweep(path: &str, tip: &[f64]) -> String {
    stdout_of(&[
        "sweep",
        &shipped("cantilever_tip_load"),
        "--set",
        "sweep.axes=[{key=\"loads.tip_force[0]\", values=[1.0, 3.0]}]",
        "-o",
        path,
    ]);
    entry(
        "sweep",
        path,
        &format!("{{\"load\": 3.0, \"tip\": {tip:?}}}"),
    )
}

/// The README's arm: R*, the meshes of its check and R0, as printed.
fn arm(path: &str) -> String {
    let s = stdout_of(&["optimize", &shipped("longest_arm"), "-o", path]);
    let reach = numbers(&s, "optimum   R* =")[0];
    let line = s.lines().find(|l| l.starts_with("mesh")).unwrap();
    let meshes: Vec<u64> = numbers_in(&line[line.find(" on ").unwrap()..])
        .iter()
        .take(3)
        .map(|m| *m as u64)
        .collect();
    let straight = numbers(&s, "straight  R0 =")[0];
    let e = format!("{{\"reach\": {reach:?}, \"meshes\": {meshes:?}, \"straight\": {straight:?}}}");
    entry("arm", path, &e)
}

/// One entry of the checks' list: `[kind, path, expectation]` (JSON; paths
/// of the scratch directory need no escaping).
fn entry(kind: &str, path: &str, expectation: &str) -> String {
    assert!(!path.contains(['"', '\\']), "{path}");
    format!("[\"{kind}\", \"{path}\", {expectation}]")
}
