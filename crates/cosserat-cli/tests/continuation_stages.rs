//! Chained stages in one problem file (`[[continuation.stage]]`): the
//! joint diagram equals the stages run one by one as commands, stage 1
//! meets the clamped–clamped elastica's closed form, and what cannot be
//! chained is refused by name.

mod common;

use cosserat::output::store::Group;

use common::h5::read_f64;
use common::problems::shipped;
use common::run::{run, scratch, stderr};
use cosserat::references::clamped_elastica_load;

const CHAINED: &str = "compress_then_turn";

/// Branch `b`'s (m × n) dataset `name` as rows.
fn rows(file: &Group, b: usize, name: &str) -> Vec<Vec<f64>> {
    let ds = file.dataset(&format!("branches/{b}/{name}")).unwrap();
    let width = ds.shape()[1].max(1);
    let v = ds.floats().unwrap().to_vec();
    v.chunks(width).map(<[f64]>::to_vec).collect()
}

fn branch(file: &Group, b: usize) -> &Group {
    file.group(&format!("branches/{b}")).unwrap()
}

fn text_attr(g: &Group, name: &str) -> String {
    g.attrs.text(name).unwrap().to_owned()
}

/// The largest difference of two branches' parameters and unknowns, after
/// checking they have as many points.
fn largest_difference(a: &Group, ba: usize, b: &Group, bb: usize) -> f64 {
    let (pa, pb) = (
        read_f64(branch(a, ba), "parameter"),
        read_f64(branch(b, bb), "parameter"),
    );
    assert_eq!(pa.len(), pb.len(), "points of branch {ba} and {bb}");
    let (xa, xb) = (rows(a, ba, "unknowns"), rows(b, bb, "unknowns"));
    let mut worst: f64 = 0.0;
    for i in 0..pa.len() {
        worst = worst.max((pa[i] - pb[i]).abs());
        for (u, v) in xa[i].iter().zip(&xb[i]) {
            worst = worst.max((u - v).abs());
        }
    }
    worst
}

/// The shipped two-stage scene run as one command equals its stages run
/// as two (`continue`, then `continue --from … --point 0/last` in the
/// second key): stage 1 point for point (the same computation), stage 2
/// to the corrector's tolerance (the same first Newton solve, from the
/// same unknowns rescaled). Each branch carries its stage, key and held
/// keys.
#[test]
fn a_chained_run_equals_its_stages_run_one_by_one() {
    let dir = scratch("stages", "equal");
    let (chained, one, two) = (dir.join("chain.h5"), dir.join("one.h5"), dir.join("two.h5"));
    let problem = shipped(CHAINED);
    let o = run(&["continue", &problem, "-o", chained.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains(
            "stage 2   support.turn.angle from 0 in [0, 1.2], holding support.position[2] = -0.7"
        ),
        "{out}"
    );
    let alone = ["--set", "continuation.stage=[]"];
    let mut args = vec!["continue", &problem, "-o", one.to_str().unwrap()];
    args.extend(alone);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut args = vec![
        "continue",
        &problem,
        "-o",
        two.to_str().unwrap(),
        "--from",
        one.to_str().unwrap(),
        "--point",
        "0/last",
        "--set",
        "continuation.parameter=\"support.turn.angle\"",
        "--set",
        "continuation.start=0.0",
        "--set",
        "continuation.bounds=[0.0, 1.2]",
        "--set",
        "continuation.step=0.05",
        "--set",
        "continuation.max_step=0.1",
    ];
    args.extend(alone);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));

    let (c, a, b) = (
        common::h5::open(&chained),
        common::h5::open(&one),
        common::h5::open(&two),
    );
    assert_eq!(largest_difference(&c, 0, &a, 0), 0.0, "stage 1");
    let second = largest_difference(&c, 1, &b, 0);
    eprintln!("stage 2 against the second command: largest difference {second:.2e}");
    assert!(second < 1e-9, "stage 2 differs by {second}");
    assert!(
        c.group("branches/2").is_err(),
        "two branches, one per stage"
    );

    let (b0, b1) = (branch(&c, 0), branch(&c, 1));
    assert_eq!(text_attr(b0, "parameter_name"), "support.position[2]");
    assert_eq!(text_attr(b1, "parameter_name"), "support.turn.angle");
    let stage = |g: &Group| g.attrs.count("stage").unwrap();
    assert_eq!((stage(b0), stage(b1)), (1, 2));
    let held = b1.dataset("held_keys").unwrap();
    let keys = held.texts().unwrap().to_vec();
    assert_eq!(keys.len(), 1);
    assert_eq!(keys[0].as_str(), "support.position[2]");
    let last = *read_f64(b0, "parameter").last().unwrap();
    assert_eq!(read_f64(b1, "held_values"), [last]);
    assert!(read_f64(b0, "held_values").is_empty());
}

/// Stage 1 of the shipped scene is the clamped–clamped elastica: the
/// support's force P L²/B = 16 K(k)² at the shortening δ/L =
/// 2(1 − E/K) (B2 = L = 1; Love, Treatise §263) at every point; and
/// stage 2 holds the end distance where stage 1 ended.
#[test]
fn the_first_stage_follows_the_clamped_elastica() {
    let dir = scratch("stages", "elastica");
    let out = dir.join("chain.h5");
    let o = run(&["continue", &shipped(CHAINED), "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let f = common::h5::open(&out);
    let names: Vec<String> = f
        .dataset("branches/measure_names")
        .unwrap()
        .texts()
        .unwrap()
        .to_vec()
        .iter()
        .map(|s| s.as_str().to_string())
        .collect();
    assert_eq!(names[0], "force[2]@1");
    let z = read_f64(branch(&f, 0), "parameter");
    let measures = rows(&f, 0, "measures");
    assert!(z.len() > 20);
    for (z, m) in z.iter().zip(&measures) {
        let delta = 1.0 + z;
        let exact = clamped_elastica_load(delta);
        assert!(
            (m[0] - exact).abs() <= 1e-8 * exact,
            "δ = {delta}: {} vs {exact}",
            m[0]
        );
    }
    // The held end: every tip of stage 2 at z = −0.7, x = 0.
    for tip in rows(&f, 1, "tip_position") {
        assert!(
            (tip[2] + 0.7).abs() < 1e-9 && tip[0].abs() < 1e-9,
            "{tip:?}"
        );
    }
}

/// A problem text: the shipped scene with its stage replaced by `stage`.
fn with_stage(stage: &str) -> String {
    let text = std::fs::read_to_string(shipped(CHAINED)).unwrap();
    let head = text.split("[[continuation.stage]]").next().unwrap();
    format!("{head}[[continuation.stage]]\n{stage}\n")
}

/// What cannot be chained is refused by name with exit code 2 before
/// anything runs (a stage repeating its predecessor's key, a stage key
/// that is not a number of the file, an unknown key in a stage, a stage
/// after a scaling, `--from` and `--resume` on a chained problem); a
/// stage that does not start is named by its number (exit 3).
#[test]
fn what_cannot_be_chained_is_refused_by_stage() {
    let dir = scratch("stages", "refused");
    let out = dir.join("out.h5");
    let cases = [
        (
            "parameter = \"support.position[2]\"\nstart = -0.7\nbounds = [-0.9, -0.6]",
            "stage 2 continues support.position[2] again",
        ),
        (
            "parameter = \"support.color\"\nstart = 0.0\nbounds = [0.0, 1.0]",
            "continuation.stage[0]: stage 2:",
        ),
        (
            "parameter = \"support.turn.angle\"\nstart = 0.0\nbounds = [0.0, 1.0]\nmeasures = []",
            "measures",
        ),
        (
            "parameter = \"support.turn.angle\"\nstart = 2.0\nbounds = [0.0, 1.0]",
            "continuation.stage[0]: stage 2: continuation.start",
        ),
    ];
    for (stage, says) in cases {
        let path = dir.join("problem.toml");
        std::fs::write(&path, with_stage(stage)).unwrap();
        let o = run(&[
            "continue",
            path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{stage}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{stage}: {}", stderr(&o));
        assert!(!out.exists(), "nothing written");
    }
    // A stage after load_scale would have to hold a scaling.
    let euler = std::fs::read_to_string(shipped("euler_column")).unwrap();
    let path = dir.join("scaled.toml");
    std::fs::write(
        &path,
        format!(
            "{euler}\n[[continuation.stage]]\nparameter = \"loads.tip_force[0]\"\nstart = 0.0\n\
             bounds = [0.0, 1.0]\n"
        ),
    )
    .unwrap();
    let o = run(&[
        "continue",
        path.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("would hold load_scale"),
        "{}",
        stderr(&o)
    );

    // Flags that would apply to one stage of the chain.
    let problem = shipped(CHAINED);
    for extra in [
        &["--resume"][..],
        &["--from", "/dev/null", "--point", "0/0"][..],
    ] {
        let mut args = vec!["continue", &problem, "-o", out.to_str().unwrap()];
        args.extend(extra);
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("chains stages"), "{}", stderr(&o));
    }

    // A stage whose first point has no equilibrium: the rod shortened to
    // less than the distance its ends are held at.
    let path = dir.join("short.toml");
    std::fs::write(
        &path,
        with_stage("parameter = \"rod.length\"\nstart = 0.5\nbounds = [0.4, 1.0]"),
    )
    .unwrap();
    let o = run(&[
        "continue",
        path.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("stage 2 (rod.length): no equilibrium at the start value"),
        "{}",
        stderr(&o)
    );
    // Stage 1 is kept.
    let f = common::h5::open(&out);
    assert!(f.group("branches/0").is_ok() && f.group("branches/1").is_err());
}

/// `--from` a point of stage 2 holds stage 2's held key: restarted in
/// its own key from its tenth point, the branch goes on to the end stage
/// 2 reached (the same last point to the corrector's tolerance).
#[test]
fn a_later_stage_restarts_with_its_held_keys() {
    let dir = scratch("stages", "restart");
    let (chained, again) = (dir.join("chain.h5"), dir.join("again.h5"));
    let problem = shipped(CHAINED);
    let o = run(&["continue", &problem, "-o", chained.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The file's own start (stage 1's, −0.95) is outside stage 2's bounds:
    // the point's value, which --from would set, is given for the check.
    let c = common::h5::open(&chained);
    let start = format!(
        "continuation.start={}",
        read_f64(branch(&c, 1), "parameter")[10]
    );
    let o = run(&[
        "continue",
        &problem,
        "-o",
        again.to_str().unwrap(),
        "--set",
        &start,
        "--from",
        chained.to_str().unwrap(),
        "--point",
        "1/10",
        "--set",
        "continuation.stage=[]",
        "--set",
        "continuation.parameter=\"support.turn.angle\"",
        "--set",
        "continuation.bounds=[0.0, 1.2]",
        "--set",
        "continuation.step=0.05",
        "--set",
        "continuation.max_step=0.1",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let a = common::h5::open(&again);
    let ends = |f: &Group, b: usize| {
        let g = branch(f, b);
        (
            *read_f64(g, "parameter").last().unwrap(),
            rows(f, b, "unknowns").pop().unwrap(),
        )
    };
    let ((p, x), (q, y)) = (ends(&c, 1), ends(&a, 0));
    assert_eq!((p, q), (1.2, 1.2));
    let worst = x
        .iter()
        .zip(&y)
        .fold(0f64, |w, (u, v)| w.max((u - v).abs()));
    assert!(worst < 1e-9, "the ends differ by {worst}");
    // The restart held the end distance stage 2 held.
    for tip in rows(&a, 0, "tip_position") {
        assert!((tip[2] + 0.7).abs() < 1e-9, "{tip:?}");
    }
}
