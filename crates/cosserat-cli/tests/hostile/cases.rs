//! The cases: the commands, what a case prepares in its directory, the
//! known-bad regressions, hostile output paths, and the case of an id.

use std::fmt::Write as _;

use super::*;

/// The commands and what they read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Verb {
    Solve,
    Stability,
    Continue,
    Optimize,
    Sweep,
    Plot,
    Merge,
    CheckEnergy,
    Export,
}

impl Verb {
    pub(crate) const ALL: [Verb; 9] = [
        Verb::Solve,
        Verb::Stability,
        Verb::Continue,
        Verb::Optimize,
        Verb::Sweep,
        Verb::Plot,
        Verb::Merge,
        Verb::CheckEnergy,
        Verb::Export,
    ];
    pub(crate) fn name(self) -> &'static str {
        match self {
            Verb::Solve => "solve",
            Verb::Stability => "stability",
            Verb::Continue => "continue",
            Verb::Optimize => "optimize",
            Verb::Sweep => "sweep",
            Verb::Plot => "plot",
            Verb::Merge => "merge",
            Verb::CheckEnergy => "check-energy",
            Verb::Export => "export",
        }
    }
    /// The table a problem needs for this command.
    pub(crate) fn table(self) -> Option<&'static str> {
        match self {
            Verb::Continue => Some("[continuation]"),
            Verb::Optimize => Some("[arm]"),
            Verb::Sweep => Some("[sweep]"),
            _ => None,
        }
    }
}

/// What a case puts in its directory before the run.
#[derive(Debug, Clone)]
pub(crate) enum Prepared {
    File(String, Vec<u8>),
    Directory(String),
    Symlink(String, String),
    Fifo(String),
}

/// One run of the binary.
#[derive(Debug, Clone)]
pub(crate) struct Case {
    pub(crate) id: usize,
    pub(crate) what: String,
    pub(crate) prepared: Vec<Prepared>,
    pub(crate) args: Vec<String>,
    /// Names (relative to the case directory) the run may create or
    /// replace.
    pub(crate) outputs: Vec<String>,
}

/// Known-bad cases from the issue that the harness always includes.
pub(crate) fn regressions() -> Vec<(Verb, &'static str, Vec<&'static str>)> {
    vec![
        (
            Verb::Continue,
            "euler_column.toml",
            vec!["--set", "continuation.eigenvalues=100"],
        ),
        (
            Verb::Continue,
            "euler_column.toml",
            vec!["--set", "rod.length=1e-320"],
        ),
        (
            Verb::Solve,
            "cantilever_tip_load.toml",
            vec!["--set", "rod.length=1e-320"],
        ),
        (
            Verb::Stability,
            "cantilever_tip_load.toml",
            vec!["--set", "rod.length=1e-320"],
        ),
        (
            Verb::Solve,
            "cantilever_tip_load.toml",
            vec!["--set", "solver.output_points=1000000000000"],
        ),
        (
            Verb::Solve,
            "cantilever_tip_load.toml",
            vec![
                "--set",
                "solver.segments=1000000",
                "--set",
                "solver.method=\"multiple-shooting\"",
            ],
        ),
        (
            Verb::Continue,
            "euler_column.toml",
            vec![
                "--set",
                "continuation.intervals=10000",
                "--set",
                "solver.method=\"collocation\"",
            ],
        ),
        (
            Verb::Solve,
            "cantilever_tip_load.toml",
            vec!["--set", "solver.tolerance=1"],
        ),
        (
            Verb::Solve,
            "cantilever_tip_load.toml",
            vec!["--set", "loads.tip_force=[1,0,0,0]"],
        ),
        (
            Verb::Optimize,
            "longest_arm.toml",
            vec!["--set", "arm.alpha=-90"],
        ),
        (
            Verb::Solve,
            "cantilever_tip_load.toml",
            vec!["--set", "energy.stiffness=[10,1,1e10]"],
        ),
        (
            Verb::Stability,
            "euler_column.toml",
            vec!["--set", "stability.elements=100000000"],
        ),
        (
            Verb::Continue,
            "euler_column.toml",
            vec!["--set", "continuation.max_points=1000000000"],
        ),
        // Found by the long form: a start solve of minutes ignored SIGTERM
        // (it now stops at once until the first point exists) ...
        (
            Verb::Continue,
            "guided_column.toml",
            vec!["--set", "loads.tip_force=[1e6, 0.0, -1.0]"],
        ),
        // ... and a stop inside a Nelder–Mead polish panicked in argmin.
        (
            Verb::Optimize,
            "longest_arm_fig7.toml",
            vec!["--set", "energy.stiffness[1]=1000000"],
        ),
    ]
}

/// A hostile output path for a case, with what it needs prepared; None
/// for an ordinary `out.h5`.
pub(crate) fn hostile_output(rng: &mut Rng, ext: &str) -> (String, Vec<Prepared>, bool) {
    // (path, prepared, whether the run may write it)
    match rng.below(11) {
        0 => ("missing/dir/out.h5".into(), vec![], false),
        1 => ("/dev/null".into(), vec![], false),
        2 => (
            "adir".into(),
            vec![Prepared::Directory("adir".into())],
            false,
        ),
        3 => (
            "link.h5".into(),
            vec![
                Prepared::File("target.h5".into(), b"keep".to_vec()),
                Prepared::Symlink("link.h5".into(), "target.h5".into()),
            ],
            false,
        ),
        4 => (
            "fifo.h5".into(),
            vec![Prepared::Fifo("fifo.h5".into())],
            false,
        ),
        5 => (format!("with space and ünïcode.{ext}"), vec![], true),
        6 => (format!("new\nline.{ext}"), vec![], true),
        7 => (format!("{}.{ext}", "x".repeat(4000)), vec![], false),
        8 => (String::new(), vec![], false),
        9 => (
            format!("exists.{ext}"),
            vec![Prepared::File(
                format!("exists.{ext}"),
                b"precious".to_vec(),
            )],
            true,
        ),
        _ => (format!("out.{ext}"), vec![], true),
    }
}

/// With probability `p` a hostile output path (see [`hostile_output`]),
/// else the ordinary, writable `ordinary`.
pub(crate) fn output(
    rng: &mut Rng,
    p: f64,
    ext: &str,
    ordinary: &str,
) -> (String, Vec<Prepared>, bool) {
    if rng.chance(p) {
        hostile_output(rng, ext)
    } else {
        (ordinary.to_string(), vec![], true)
    }
}

/// The files the setup made once: a diagram and two sweep shards.
pub(crate) struct Fixtures {
    pub(crate) diagram: Vec<u8>,
    pub(crate) shards: [Vec<u8>; 2],
}

pub(crate) fn fixtures(dir: &Path) -> Fixtures {
    let run = |args: &[&str]| {
        let o = Command::new(BIN)
            .args(args)
            .current_dir(dir)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    let euler = common::problems::shipped("euler_column");
    run(&[
        "continue",
        &euler,
        "-o",
        "diagram.h5",
        "--set",
        "continuation.tip_angle_limit=40",
    ]);
    let cantilever = common::problems::shipped_text("cantilever_tip_load");
    let sweep = format!(
        "{cantilever}\n[sweep]\naxes = [{{ key = \"loads.tip_force[0]\", values = [0.5, 1] }}, {{ key = \"energy.stiffness[1]\", values = [1, 2] }}]\n"
    );
    std::fs::write(dir.join("sweep.toml"), sweep).unwrap();
    run(&["sweep", "sweep.toml", "-o", "s0.h5", "--shard", "0/2"]);
    run(&["sweep", "sweep.toml", "-o", "s1.h5", "--shard", "1/2"]);
    let read = |n: &str| std::fs::read(dir.join(n)).unwrap();
    Fixtures {
        diagram: read("diagram.h5"),
        shards: [read("s0.h5"), read("s1.h5")],
    }
}

/// Builds case `id` of the seed.
pub(crate) fn case(id: usize, seed: u64, seeds: &[(String, String)], fx: &Fixtures) -> Case {
    let mut rng = Rng(seed ^ (id as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
    let regressions = regressions();
    if id < regressions.len() {
        let (verb, file, set) = &regressions[id];
        let text = &seeds.iter().find(|(n, _)| n == file).unwrap().1;
        let mut args = vec![
            verb.name().to_string(),
            "p.toml".into(),
            "-o".into(),
            "out.h5".into(),
        ];
        args.extend(set.iter().map(std::string::ToString::to_string));
        return Case {
            id,
            what: format!("{} {file} {}", verb.name(), set.join(" ")),
            prepared: vec![Prepared::File("p.toml".into(), text.as_bytes().to_vec())],
            args,
            outputs: vec!["out.h5".into()],
        };
    }
    let verb = *rng.pick(&Verb::ALL);
    match verb {
        Verb::Plot => plot_case(id, &mut rng, fx),
        Verb::Merge => merge_case(id, &mut rng, fx),
        Verb::Export => export_case(id, &mut rng, fx),
        _ => problem_case(id, verb, &mut rng, seeds),
    }
}

pub(crate) fn problem_case(
    id: usize,
    verb: Verb,
    rng: &mut Rng,
    seeds: &[(String, String)],
) -> Case {
    // Mostly problems the command can run; sometimes any file.
    let fitting: Vec<&(String, String)> = seeds
        .iter()
        .filter(|(_, t)| verb.table().is_none_or(|h| t.contains(h)))
        .collect();
    let (name, text) = if rng.chance(0.85) && !fitting.is_empty() {
        *rng.pick(&fitting)
    } else {
        rng.pick(seeds)
    };
    let mut prepared = vec![];
    let mut what = format!("{} {name}", verb.name());
    let mut args = vec![verb.name().to_string()];
    // The problem path: usually a mutated file, sometimes a hostile path.
    match rng.below(20) {
        0 => {
            args.push("/dev/zero".into());
            what += " from /dev/zero";
        }
        1 => {
            prepared.push(Prepared::Fifo("p.toml".into()));
            args.push("p.toml".into());
            what += " from a FIFO";
        }
        2 => {
            prepared.push(Prepared::Directory("p.toml".into()));
            args.push("p.toml".into());
            what += " from a directory";
        }
        3 => {
            args.push("absent.toml".into());
            what += " from a missing file";
        }
        _ => {
            let (bytes, how) = if rng.chance(0.8) {
                mutate(rng, text)
            } else {
                (text.as_bytes().to_vec(), "as shipped".into())
            };
            write!(what, " ({how})").expect("writing to a String cannot fail");
            prepared.push(Prepared::File("p.toml".into(), bytes));
            args.push("p.toml".into());
        }
    }
    let mut outputs = vec![];
    let wants_output = verb != Verb::CheckEnergy
        && (matches!(verb, Verb::Continue | Verb::Sweep) || rng.chance(0.7));
    if wants_output {
        // `solve -o NAME.vtp` writes VTK PolyData instead of HDF5.
        let ext = if verb == Verb::Solve && rng.chance(0.3) {
            "vtp"
        } else {
            "h5"
        };
        let (out, more, writable) = output(rng, 0.3, ext, &format!("out.{ext}"));
        if rng.chance(0.1) {
            // The input itself as the output.
            args.extend(["-o".into(), "p.toml".into()]);
            what += " -o p.toml";
        } else {
            args.extend(["-o".into(), out.clone()]);
            write!(what, " -o {out:?}").expect("writing to a String cannot fail");
            if writable {
                outputs.push(out);
            }
        }
        prepared.extend(more);
    }
    if matches!(verb, Verb::Continue | Verb::Optimize | Verb::Sweep) && rng.chance(0.2) {
        args.extend(["--plot".into(), "fig.png".into()]);
        outputs.push("fig.png".into());
    }
    if rng.chance(0.3) {
        args.extend(overrides(rng, text));
        write!(what, " {}", args[args.len().saturating_sub(2)..].join(" "))
            .expect("writing to a String cannot fail");
    }
    if verb != Verb::CheckEnergy && rng.chance(0.3) {
        args.push("--force".into());
    }
    if matches!(verb, Verb::Continue | Verb::Optimize | Verb::Sweep) && rng.chance(0.15) {
        args.push("--resume".into());
    }
    if verb == Verb::Sweep && rng.chance(0.2) {
        let shard = rng.pick(&["0/2", "1/2", "2/2", "0/0", "x", "1/1000000"]);
        args.extend(["--shard".into(), shard.to_string()]);
    }
    Case {
        id,
        what,
        prepared,
        args,
        outputs,
    }
}

pub(crate) fn plot_case(id: usize, rng: &mut Rng, fx: &Fixtures) -> Case {
    let (bytes, how) = if rng.chance(0.5) {
        (fx.diagram.clone(), "intact".to_string())
    } else {
        damaged(rng, &fx.diagram)
    };
    let mut prepared = vec![Prepared::File("d.h5".into(), bytes)];
    let measure = rng.pick(&["tip_x", "tip_z", "norm", "tip_angle", "bogus", ""]);
    let (out, more, writable) = output(rng, 0.4, "png", "fig.png");
    prepared.extend(more);
    let mut args: Vec<String> = vec!["plot".into(), "d.h5".into(), "-o".into(), out.clone()];
    args.extend(["--measure".into(), measure.to_string()]);
    if rng.chance(0.3) {
        args.push("--force".into());
    }
    Case {
        id,
        what: format!("plot ({how}) -o {out:?} --measure {measure}"),
        prepared,
        args,
        outputs: if writable { vec![out] } else { vec![] },
    }
}

pub(crate) fn merge_case(id: usize, rng: &mut Rng, fx: &Fixtures) -> Case {
    let mut prepared = vec![];
    let mut args: Vec<String> = vec!["merge".into()];
    let mut what = "merge".to_string();
    let n = 1 + rng.below(3);
    for i in 0..n {
        let source = match rng.below(5) {
            0 => fx.diagram.clone(),
            1 | 2 => fx.shards[i % 2].clone(),
            3 => fx.shards[0].clone(),
            _ => damaged(rng, &fx.shards[i % 2]).0,
        };
        let name = format!("in{i}.h5");
        prepared.push(Prepared::File(name.clone(), source));
        args.push(name);
    }
    write!(what, " of {n} files").expect("writing to a String cannot fail");
    let (out, more, writable) = output(rng, 0.3, "h5", "all.h5");
    prepared.extend(more);
    args.extend(["-o".into(), out.clone()]);
    let mut outputs = if writable { vec![out] } else { vec![] };
    if rng.chance(0.2) {
        args.extend(["--plot".into(), "m.png".into()]);
        outputs.push("m.png".into());
    }
    if rng.chance(0.3) {
        args.push("--force".into());
    }
    Case {
        id,
        what,
        prepared,
        args,
        outputs,
    }
}

/// `export`: the diagram intact or damaged, or a sweep shard (no shape),
/// as VTK (a `.pvd` and its `.vtp` files, or a `.vtp` the diagram's many
/// shapes cannot go to) or XDMF, to hostile paths.
pub(crate) fn export_case(id: usize, rng: &mut Rng, fx: &Fixtures) -> Case {
    let (bytes, how) = match rng.below(4) {
        0 => (fx.shards[0].clone(), "a sweep shard".to_string()),
        1 => damaged(rng, &fx.diagram),
        _ => (fx.diagram.clone(), "intact".to_string()),
    };
    let mut prepared = vec![Prepared::File("d.h5".into(), bytes)];
    let (format, ext) = *rng.pick(&[("vtk", "pvd"), ("vtk", "vtp"), ("xdmf", "xmf2")]);
    let (out, more, writable) = output(rng, 0.4, ext, &format!("out.{ext}"));
    prepared.extend(more);
    let mut args: Vec<String> = ["export", "d.h5", "--format", format, "-o", &out]
        .map(String::from)
        .to_vec();
    if rng.chance(0.3) {
        args.extend(["--branch".into(), rng.pick(&["0", "1", "7"]).to_string()]);
    }
    if rng.chance(0.3) {
        args.push("--force".into());
    }
    let mut outputs = if writable { vec![out.clone()] } else { vec![] };
    if writable && ext == "pvd" {
        // The collection's shapes beside it: OUT_0000.vtp, ...
        let stem = out.strip_suffix(".pvd").unwrap_or(&out);
        outputs.extend((0..1000).map(|k| format!("{stem}_{k:04}.vtp")));
    }
    Case {
        id,
        what: format!("export ({how}) {}", args[2..].join(" ")),
        prepared,
        args,
        outputs,
    }
}
