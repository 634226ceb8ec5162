//! Every dataset of an HDF5 file as text, for comparing two files bit for
//! bit (floats by their bit patterns), and the few reads the tests of
//! result files repeat.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::Path;

use hdf5::types::{TypeDescriptor, VarLenUnicode};

/// Dataset path → its contents (floats as hex bit patterns).
pub fn datasets(path: &Path) -> BTreeMap<String, String> {
    let file = hdf5::File::open(path).unwrap();
    let mut out = BTreeMap::new();
    walk(&file, "", &mut out);
    out
}

fn walk(group: &hdf5::Group, prefix: &str, out: &mut BTreeMap<String, String>) {
    for name in group.member_names().unwrap() {
        let full = format!("{prefix}/{name}");
        if let Ok(g) = group.group(&name) {
            walk(&g, &full, out);
            continue;
        }
        let ds = group.dataset(&name).unwrap();
        let text = match ds.dtype().unwrap().to_descriptor().unwrap() {
            TypeDescriptor::Float(_) => ds
                .read_raw::<f64>()
                .unwrap()
                .iter()
                .map(|v| format!("{:016x}", v.to_bits()))
                .collect::<Vec<_>>()
                .join(" "),
            TypeDescriptor::Unsigned(_) => format!("{:?}", ds.read_raw::<u64>().unwrap()),
            TypeDescriptor::Integer(_) => format!("{:?}", ds.read_raw::<i64>().unwrap()),
            TypeDescriptor::VarLenUnicode => {
                format!("{:?}", ds.read_raw::<VarLenUnicode>().unwrap())
            }
            other => format!("{other:?}"),
        };
        out.insert(full, format!("{:?} {text}", ds.shape()));
    }
}

/// Asserts that two files hold the same datasets, bit for bit.
pub fn assert_same_datasets(a: &Path, b: &Path) {
    let (x, y) = (datasets(a), datasets(b));
    assert_eq!(
        x.keys().collect::<Vec<_>>(),
        y.keys().collect::<Vec<_>>(),
        "the same datasets"
    );
    for (k, v) in &x {
        assert!(
            v == &y[k],
            "dataset {k} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

/// The floats of dataset `name` of `group`.
pub fn read_f64(group: &hdf5::Group, name: &str) -> Vec<f64> {
    group.dataset(name).unwrap().read_raw::<f64>().unwrap()
}

/// The `stop_reason` attribute of a result file.
pub fn stop_reason(file: &hdf5::File) -> String {
    file.attr("stop_reason")
        .unwrap()
        .read_scalar::<VarLenUnicode>()
        .unwrap()
        .as_str()
        .to_string()
}
