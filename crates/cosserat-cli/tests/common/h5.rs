//! Every dataset of an HDF5 file as text, for comparing two files bit for
//! bit (floats by their bit patterns), and the few reads the tests of
//! result files repeat. Files are read through the library's one HDF5
//! module (`cosserat::output::store`); h5py reads them independently in
//! tests/h5py_reader.rs.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::Path;

use cosserat::output::store::{self, Group, Values};

/// The whole file at `path` (its seal, if any, not checked).
pub fn open(path: &Path) -> Group {
    store::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Dataset path → its contents (floats as hex bit patterns).
pub fn datasets(path: &Path) -> BTreeMap<String, String> {
    let file = open(path);
    let mut out = BTreeMap::new();
    walk(&file, &mut out);
    out
}

fn walk(group: &Group, out: &mut BTreeMap<String, String>) {
    for (_, ds) in group.datasets() {
        let text = match ds.values() {
            Values::Floats(v) => v
                .iter()
                .map(|v| format!("{:016x}", v.to_bits()))
                .collect::<Vec<_>>()
                .join(" "),
            other => format!("{other:?}"),
        };
        out.insert(ds.path().to_owned(), format!("{:?} {text}", ds.shape()));
    }
    for (_, g) in group.groups() {
        walk(g, out);
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
pub fn read_f64(group: &Group, name: &str) -> Vec<f64> {
    group.dataset(name).unwrap().floats().unwrap().to_vec()
}

/// The `stop_reason` attribute of a result file.
pub fn stop_reason(file: &Group) -> String {
    file.attrs.text("stop_reason").unwrap().to_owned()
}

/// Rewrites the HDF5 file at `path` after `edit` changed its tree; the
/// result is unsealed (a file written by another program).
pub fn rewrite(path: &Path, edit: impl FnOnce(&mut Group)) {
    let mut file = open(path);
    edit(&mut file);
    store::write(path, &file).unwrap();
}
