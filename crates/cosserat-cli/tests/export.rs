//! `cosserat export` and `cosserat solve -o NAME.vtp`: the files read back
//! by independent readers — VTK's Python package (`vtkXMLPolyDataReader`
//! for .vtp, the .pvd parsed as XML, `vtkXdmfReader` for .xmf, which
//! resolves the hyperslabs into the HDF5 file) — and compared with the
//! HDF5 datasets as h5py reads them (tests/export/read_back.py): positions
//! and fields equal to the stored values, directors orthonormal, s over
//! [0, L] with L from the problem file, one time step per stored point,
//! timesteps equal to the stored parameters along a monotone branch, an
//! arm study's designs equal to its stored centrelines.
//! Where ParaView's Python (`pvpython`, or `pvbatch`) is on PATH, ParaView
//! opens each file too and counts its time steps.
//!
//! The Python checks need `pip install vtk h5py`. Without them the checks
//! are skipped with a note, except under CI (`CI=true`), where their
//! absence fails the test.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;

use common::problems::shipped;
use common::run::{entries, run, scratch, stderr, BIN};

const READ_BACK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/export/read_back.py");
const PARAVIEW: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/export/paraview_steps.py"
);

/// Runs the binary in `dir`, asserting success.
fn ok(dir: &Path, args: &[&str]) -> String {
    let o = Command::new(BIN)
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Whether python3 with `vtk` and `h5py` is there; under CI it must be.
fn python_ready() -> bool {
    let ready = Command::new("python3")
        .args(["-c", "import vtk, h5py, numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ready {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "CI=true but python3 cannot import vtk and h5py: pip install vtk h5py"
        );
        eprintln!("note: python3 with vtk and h5py not found; the read-back checks are skipped");
    }
    ready
}

/// tests/export/read_back.py on `out` against `h5`.
fn read_back(dir: &Path, kind: &str, out: &str, h5: &str, length: f64, branch: Option<usize>) {
    let mut args = vec![
        READ_BACK.to_string(),
        kind.into(),
        out.into(),
        h5.into(),
        length.to_string(),
    ];
    args.extend(branch.map(|b| b.to_string()));
    let o = Command::new("python3")
        .args(&args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{args:?}: {}{}",
        String::from_utf8_lossy(&o.stdout),
        stderr(&o)
    );
}

/// ParaView's Python, if installed: `pvpython`, else `pvbatch`.
fn paraview() -> Option<&'static str> {
    ["pvpython", "pvbatch"].into_iter().find(|p| {
        Command::new("sh")
            .args(["-c", &format!("command -v {p}")])
            .output()
            .is_ok_and(|o| o.status.success())
    })
}

/// ParaView opens `file` and finds `steps` time steps (skipped with a
/// note when ParaView is not installed).
fn paraview_steps(dir: &Path, file: &str, steps: usize) {
    let Some(pv) = paraview() else {
        eprintln!("note: pvpython/pvbatch not on PATH; the ParaView check of {file} is skipped");
        return;
    };
    let o = Command::new(pv)
        .args([PARAVIEW, file, &steps.to_string()])
        .current_dir(dir)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && out.contains("paraview: ok"),
        "{pv} on {file}: {out}{}",
        stderr(&o)
    );
}

/// The diagram's stored branch lengths, from the export's own count line
/// cross-checked by the readers (each reader counts the HDF5 rows itself).
fn shapes_line(report: &str) -> usize {
    report
        .lines()
        .find_map(|l| l.strip_prefix("shapes"))
        .and_then(|n| n.trim().parse().ok())
        .expect("a shapes line")
}

#[test]
fn an_equilibrium_exports_with_every_field() {
    let dir = scratch("export", "equilibrium");
    let problem = shipped("cantilever_tip_load");
    ok(&dir, &["solve", &problem, "-o", "c.h5"]);
    ok(&dir, &["solve", &problem, "-o", "direct.vtp"]);
    ok(&dir, &["export", "c.h5", "--format", "vtk", "-o", "c.vtp"]);
    ok(&dir, &["export", "c.h5", "--format", "xdmf"]);
    // A stability file holds the same equilibrium with its spectrum.
    ok(&dir, &["stability", &problem, "-o", "st.h5"]);
    ok(&dir, &["export", "st.h5", "--format", "vtk"]);
    // The cantilever's length from its problem file.
    let length = 1.0;
    assert!(std::fs::read_to_string(&problem)
        .unwrap()
        .contains("length = 1.0"));
    if python_ready() {
        read_back(&dir, "vtp", "c.vtp", "c.h5", length, None);
        read_back(&dir, "vtp", "direct.vtp", "c.h5", length, None);
        read_back(&dir, "xmf", "c.xmf2", "c.h5", length, None);
        read_back(&dir, "vtp", "st.vtp", "st.h5", length, None);
    }
    paraview_steps(&dir, "c.vtp", 0);
    paraview_steps(&dir, "c.xmf2", 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_diagram_exports_one_time_step_per_point() {
    let dir = scratch("export", "diagram");
    ok(
        &dir,
        &[
            "continue",
            &shipped("euler_column"),
            "-o",
            "d.h5",
            "--set",
            "continuation.bounds=[0.0,4.0]",
            "--set",
            "continuation.tip_angle_limit=60",
        ],
    );
    let all = shapes_line(&ok(&dir, &["export", "d.h5", "--format", "vtk"]));
    let one = ok(
        &dir,
        &[
            "export", "d.h5", "--format", "vtk", "--branch", "1", "-o", "b1.pvd",
        ],
    );
    assert!(
        one.contains("the continuation parameter load_scale"),
        "{one}"
    );
    let one = shapes_line(&one);
    ok(&dir, &["export", "d.h5", "--format", "xdmf"]);
    ok(
        &dir,
        &[
            "export", "d.h5", "--format", "xdmf", "--branch", "1", "-o", "b1.xmf2",
        ],
    );
    if python_ready() {
        read_back(&dir, "pvd", "d.pvd", "d.h5", 1.0, None);
        read_back(&dir, "pvd", "b1.pvd", "d.h5", 1.0, Some(1));
        read_back(&dir, "xmf", "d.xmf2", "d.h5", 1.0, None);
        read_back(&dir, "xmf", "b1.xmf2", "d.h5", 1.0, Some(1));
    }
    paraview_steps(&dir, "d.pvd", all);
    paraview_steps(&dir, "b1.pvd", one);
    paraview_steps(&dir, "d.xmf2", all);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A continuation in the rod's length: s spans each point's own length
/// (the parameter), read back from the HDF5 file by the reader.
#[test]
fn a_length_continuation_has_each_points_own_arc_length() {
    let dir = scratch("export", "length");
    ok(
        &dir,
        &[
            "continue",
            &shipped("euler_column"),
            "-o",
            "l.h5",
            "--set",
            "continuation.parameter=\"rod.length\"",
            "--set",
            "continuation.start=1.0",
            "--set",
            "continuation.bounds=[0.5,1.4]",
        ],
    );
    let out = ok(
        &dir,
        &[
            "export", "l.h5", "--format", "vtk", "--branch", "0", "-o", "l.pvd",
        ],
    );
    assert!(
        out.contains("the continuation parameter rod.length"),
        "{out}"
    );
    if python_ready() {
        // Length 0: the reader takes each point's length from its
        // stored parameter.
        read_back(&dir, "pvd", "l.pvd", "l.h5", 0.0, Some(0));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_arm_study_exports_its_designs() {
    let dir = scratch("export", "arm");
    ok(
        &dir,
        &[
            "optimize",
            &shipped("longest_arm"),
            "-o",
            "a.h5",
            "--set",
            "arm.samples=20",
            "--set",
            "arm.starts=1",
            "--set",
            "arm.iterations=20",
            "--set",
            "arm.straight=false",
        ],
    );
    let out = ok(&dir, &["export", "a.h5", "--format", "vtk"]);
    assert!(out.contains("optimum loaded, optimum unloaded"), "{out}");
    ok(&dir, &["export", "a.h5", "--format", "xdmf"]);
    if python_ready() {
        read_back(&dir, "pvd", "a.pvd", "a.h5", 0.0, None);
    }
    paraview_steps(&dir, "a.pvd", 2);
    paraview_steps(&dir, "a.xmf2", 2);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Files without a shape, missing or foreign files, impossible outputs:
/// exit 2 with a named error, nothing written, nothing replaced.
#[test]
fn bad_inputs_and_outputs_are_named_errors_that_write_nothing() {
    let dir = scratch("export", "errors");
    ok(
        &dir,
        &["stability", &shipped("euler_column"), "-o", "fixed.h5"],
    );
    ok(
        &dir,
        &[
            "continue",
            &shipped("euler_column"),
            "-o",
            "d.h5",
            "--set",
            "continuation.tip_angle_limit=40",
        ],
    );
    std::fs::write(dir.join("junk.h5"), b"not hdf5").unwrap();
    std::fs::copy(dir.join("d.h5"), dir.join("dd.xmf2")).unwrap();
    std::fs::write(dir.join("d.pvd"), b"precious").unwrap();
    let d = |a: &str| dir.join(a).display().to_string();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec![d("fixed.h5"), "--format".into(), "vtk".into()],
            "holds no rod shape",
        ),
        (
            vec![d("missing.h5"), "--format".into(), "vtk".into()],
            "missing.h5",
        ),
        (
            vec![d("junk.h5"), "--format".into(), "xdmf".into()],
            "junk.h5",
        ),
        (
            vec![
                d("d.h5"),
                "--format".into(),
                "vtk".into(),
                "--branch".into(),
                "9".into(),
            ],
            "--branch 9",
        ),
        (
            vec![
                d("d.h5"),
                "--format".into(),
                "vtk".into(),
                "-o".into(),
                d("x.vtp"),
            ],
            "-o NAME.pvd",
        ),
        (
            vec![
                d("d.h5"),
                "--format".into(),
                "xdmf".into(),
                "-o".into(),
                d("x.txt"),
            ],
            ".xmf2",
        ),
        (vec![d("d.h5"), "--format".into(), "vtk".into()], "--force"),
        (
            vec![
                d("dd.xmf2"),
                "--format".into(),
                "xdmf".into(),
                "-o".into(),
                d("dd.xmf2"),
            ],
            "input",
        ),
    ];
    let before = entries(&dir);
    for (args, named) in cases {
        let mut all = vec!["export".to_string()];
        all.extend(args);
        let refs: Vec<&str> = all.iter().map(String::as_str).collect();
        let o = run(&refs);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(named), "{all:?}: {}", stderr(&o));
        assert_eq!(entries(&dir).len(), before.len(), "{all:?} left a file");
    }
    assert_eq!(std::fs::read(dir.join("d.pvd")).unwrap(), b"precious");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Replacing with --force rewrites the collection and its shapes.
#[test]
fn force_replaces_an_earlier_export() {
    let dir = scratch("export", "force");
    ok(
        &dir,
        &[
            "continue",
            &shipped("euler_column"),
            "-o",
            "d.h5",
            "--set",
            "continuation.tip_angle_limit=40",
        ],
    );
    ok(&dir, &["export", "d.h5", "--format", "vtk"]);
    let first: PathBuf = dir.join("d_0000.vtp");
    std::fs::write(&first, b"stale").unwrap();
    ok(&dir, &["export", "d.h5", "--format", "vtk", "--force"]);
    assert!(std::fs::read_to_string(&first)
        .unwrap()
        .contains("PolyData"));
    let leftovers: Vec<_> = entries(&dir)
        .into_iter()
        .filter(|n| n.to_string_lossy().starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
