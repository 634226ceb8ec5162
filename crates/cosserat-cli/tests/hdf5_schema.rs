//! Self-describing result files (issue 19, item 4): every dataset of every
//! kind of file the commands write carries `units` and `description`
//! attributes from the schema table (none left "undescribed"), the root
//! its `schema_version`, and every dataset and attribute follows the type
//! policy of docs/hdf5-schema.md ("Types"): floats f64, counts and indices
//! u64, i64 only where −1 means "none", flags and enumerations as named
//! strings. The names below are this test's own reading of the policy,
//! not the writer's table.

mod common;

use std::path::Path;

use common::problems::shipped;
use common::run::{run, scratch, stderr};
use cosserat::output::store::{Attr, Group, Values};

/// Datasets holding counts or indices: u64 (i64 in sweep columns, where −1
/// marks a point without a value).
const COUNT_DATASETS: &[&str] = &[
    "morse_index",
    "index",
    "branch",
    "multiplicity",
    "shape",
    "cusps",
    "mesh_elements",
    "rejected_elements",
    "iterations",
    "elements",
    "evaluations",
    "limit_elements",
    "element_order",
];
/// Sweep count columns: i64, −1 where the point has no value.
const SIGNED_DATASETS: &[&str] = &["iterations", "elements", "evaluations", "element_order"];
/// Datasets holding flags, enumerations or names: strings.
const TEXT_DATASETS: &[&str] = &[
    "stable",
    "symmetry_breaking",
    "kind",
    "block",
    "location",
    "status",
    "start",
    "mesh",
    "limit",
    "keys",
    "warnings",
    "eigenvalue_names",
    "measure_names",
    "held_keys",
];
/// Count attributes: u64.
const COUNT_ATTRS: &[&str] = &[
    "segments",
    "iterations",
    "load_steps",
    "integration_steps",
    "morse_index",
    "stages",
    "stage",
    "points",
    "members",
    "samples",
    "samples_done",
    "polishes_done",
    "evaluations",
    "index",
    "elements",
    "element_order",
    "limit_order",
];
/// The one signed attribute: a branch's `parent`, −1 for a primary branch.
const SIGNED_ATTRS: &[&str] = &["parent"];
/// Float attributes (everything else is a string).
const FLOAT_ATTRS: &[&str] = &[
    "residual",
    "director_drift",
    "wall_time",
    "direction",
    "next_step",
];

/// The type the policy asks of an attribute.
fn attr_type(name: &str) -> &'static str {
    if COUNT_ATTRS.contains(&name) {
        "u64"
    } else if SIGNED_ATTRS.contains(&name) {
        "i64"
    } else if FLOAT_ATTRS.contains(&name) {
        "f64"
    } else {
        "string"
    }
}

/// The type the policy asks of dataset `name` (of a sweep file or not).
fn dataset_type(name: &str, sweep: bool) -> &'static str {
    if sweep && SIGNED_DATASETS.contains(&name) {
        "i64"
    } else if COUNT_DATASETS.contains(&name) {
        "u64"
    } else if TEXT_DATASETS.contains(&name) {
        "string"
    } else {
        "f64"
    }
}

fn check_attrs(owner: &str, attrs: &cosserat::output::store::Attrs, wrong: &mut Vec<String>) {
    for (name, a) in attrs.iter() {
        let want = attr_type(name);
        if a.type_name() != want {
            wrong.push(format!("{owner}@{name}: {} (want {want})", a.type_name()));
        }
        if let Attr::Text(t) = a {
            assert!(!t.is_empty() || name == "units", "{owner}@{name} is empty");
        }
    }
}

/// Checks every dataset below `group`: described, and typed by the policy.
fn walk(group: &Group, sweep: bool, found: &mut Vec<String>, count: &mut usize) {
    check_attrs(group.path(), &group.attrs, found);
    for (name, ds) in group.datasets() {
        *count += 1;
        let description = ds
            .attrs
            .text("description")
            .unwrap_or_else(|e| panic!("{}: {e}", ds.path()));
        ds.attrs
            .text("units")
            .unwrap_or_else(|e| panic!("{}: {e}", ds.path()));
        if description == cosserat::output::schema::UNDESCRIBED || description.is_empty() {
            found.push(format!("{}: undescribed", ds.path()));
        }
        let want = dataset_type(name, sweep);
        if ds.values().type_name() != want {
            found.push(format!(
                "{}: {} (want {want})",
                ds.path(),
                ds.values().type_name()
            ));
        }
        if let Values::Signed(v) = ds.values() {
            assert!(v.iter().all(|&x| x >= -1), "{}: {v:?}", ds.path());
        }
        check_attrs(ds.path(), &ds.attrs, found);
    }
    for (_, g) in group.groups() {
        walk(g, sweep, found, count);
    }
}

fn check(path: &Path) {
    let file = common::h5::open(path);
    assert_eq!(
        file.attrs.text("schema_version").unwrap(),
        cosserat::output::schema::SCHEMA_VERSION
    );
    let sweep = file.group("grid").is_ok();
    let (mut found, mut count) = (vec![], 0);
    walk(&file, sweep, &mut found, &mut count);
    assert!(count > 0, "{}: no datasets", path.display());
    assert!(found.is_empty(), "{}: {found:#?}", path.display());
}

#[test]
fn every_dataset_of_every_result_file_is_described() {
    let dir = scratch("hdf5_schema", "files");
    let out = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let runs: Vec<(String, Vec<String>)> = vec![
        (
            "solve.h5".into(),
            vec!["solve".into(), shipped("cantilever_tip_load")],
        ),
        (
            "stability.h5".into(),
            vec!["stability".into(), shipped("cantilever_tip_load")],
        ),
        (
            "shape.h5".into(),
            vec!["stability".into(), shipped("timoshenko_ltb")],
        ),
        (
            "diagram.h5".into(),
            vec!["continue".into(), shipped("euler_column")],
        ),
        (
            "stages.h5".into(),
            vec!["continue".into(), shipped("compress_then_turn")],
        ),
        (
            "curve.h5".into(),
            vec![
                "continue".into(),
                shipped("euler_column"),
                "--from".into(),
                out("diagram.h5"),
                "--point".into(),
                "special/0".into(),
                "--curve".into(),
                "--set".into(),
                "continuation.curve={parameter=\"rod.length\", start=1.0, bounds=[0.5, 2.0], step=0.1, max_step=0.3}".into(),
            ],
        ),
        (
            "arm.h5".into(),
            vec!["optimize".into(), shipped("longest_arm")],
        ),
        (
            "sweep.h5".into(),
            vec![
                "sweep".into(),
                shipped("cantilever_tip_load"),
                "--set".into(),
                "sweep.axes=[{key=\"loads.tip_force[0]\", values=[1.0, 2.0]}]".into(),
            ],
        ),
        (
            "arm_sweep.h5".into(),
            vec![
                "sweep".into(),
                shipped("longest_arm_fig7"),
                "--set".into(),
                "sweep.axes=[{key=\"arm.alpha\", values=[0.5]}]".into(),
            ],
        ),
        (
            "merged.h5".into(),
            vec!["merge".into(), out("sweep.h5")],
        ),
    ];
    for (name, mut args) in runs {
        args.extend(["-o".into(), out(&name)]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = run(&args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        check(&dir.join(&name));
    }
}
