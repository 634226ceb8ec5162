//! Self-describing result files (issue 19, item 4): every dataset of every
//! kind of file the commands write carries `units` and `description`
//! attributes from the schema table (none left "undescribed"), and the root
//! its `schema_version`. docs/hdf5-schema.md lists the paths.

mod common;

use std::path::Path;

use common::problems::shipped;
use common::run::{run, scratch, stderr};
use hdf5::types::VarLenUnicode;

fn text_attr(loc: &hdf5::Location, name: &str) -> String {
    let v: VarLenUnicode = loc
        .attr(name)
        .unwrap_or_else(|e| panic!("{}: no attribute {name}: {e}", loc.name()))
        .read_scalar()
        .unwrap();
    v.as_str().to_owned()
}

fn undescribed(group: &hdf5::Group, found: &mut Vec<String>, count: &mut usize) {
    for name in group.member_names().unwrap() {
        if let Ok(sub) = group.group(&name) {
            undescribed(&sub, found, count);
            continue;
        }
        let ds = group.dataset(&name).unwrap();
        let _units = text_attr(&ds, "units");
        let description = text_attr(&ds, "description");
        *count += 1;
        if description == cosserat::output::schema::UNDESCRIBED || description.is_empty() {
            found.push(ds.name());
        }
    }
}

fn check(path: &Path) {
    let file = hdf5::File::open(path).unwrap();
    assert_eq!(
        text_attr(&file, "schema_version"),
        cosserat::output::schema::SCHEMA_VERSION
    );
    let (mut found, mut count) = (vec![], 0);
    undescribed(&file, &mut found, &mut count);
    assert!(count > 0, "{}: no datasets", path.display());
    assert!(
        found.is_empty(),
        "{}: undescribed {found:?}",
        path.display()
    );
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
    ];
    for (name, mut args) in runs {
        args.extend(["-o".into(), out(&name)]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = run(&args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        check(&dir.join(&name));
    }
}
