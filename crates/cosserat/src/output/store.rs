//! The one module that speaks HDF5: a result file as a tree of groups,
//! datasets and attributes in memory, written to disk in one go and read
//! back whole. Every other module of `output` (and the command's readers)
//! builds or reads this tree in domain terms; a change of HDF5 backend
//! touches this file only.
//!
//! The backend is hdf5-pure (pure Rust, no C library, no build step: the
//! README's fresh-machine promise). Whole-file reads suit result files
//! (megabytes at most), and a tree read in full makes every later access
//! an ordinary lookup that cannot fail halfway through a file. Reading is
//! the one place a file's bytes are parsed, so a parser panic on a damaged
//! file is contained here and becomes [`StoreError::Damaged`].
//!
//! Types (docs/hdf5-schema.md, "Types"): floats are f64, counts and indices
//! u64, signed i64 only where −1 means "none", and text (names, verdicts,
//! every enumeration) UTF-8 variable-length strings.

use std::collections::BTreeMap;
use std::path::Path;

use hdf5_pure::{AttrValue, Datatype, FileBuilder, GroupBuilder};

/// Why a result file could not be written or read back.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StoreError {
    /// The file could not be opened, parsed or written.
    #[error("{0}")]
    Unreadable(String),
    /// The HDF5 parser failed on the file's bytes (a damaged file).
    #[error("{0} is damaged: its HDF5 structure cannot be parsed")]
    Damaged(String),
    /// A group, dataset or attribute the reader needs is absent.
    #[error("it has no {0}")]
    Missing(String),
    /// Present but of another type or shape, or contradicting another.
    #[error("{0}")]
    Invalid(String),
}

impl From<&str> for StoreError {
    fn from(message: &str) -> Self {
        StoreError::Invalid(message.to_owned())
    }
}

impl From<String> for StoreError {
    fn from(message: String) -> Self {
        StoreError::Invalid(message)
    }
}

/// The result of a store operation.
pub type StoreResult<T> = Result<T, StoreError>;

/// The elements of a dataset.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// f64: every physical quantity.
    Floats(Vec<f64>),
    /// u64: counts and indices.
    Counts(Vec<u64>),
    /// i64: integers where −1 means "none".
    Signed(Vec<i64>),
    /// UTF-8 strings: names, verdicts, enumerations.
    Texts(Vec<String>),
    /// A type this crate never writes (in a file of another program).
    Other(String),
}

impl Values {
    fn len(&self) -> usize {
        match self {
            Values::Floats(v) => v.len(),
            Values::Counts(v) => v.len(),
            Values::Signed(v) => v.len(),
            Values::Texts(v) => v.len(),
            Values::Other(_) => 0,
        }
    }

    /// The type's name, as docs/hdf5-schema.md spells it.
    pub fn type_name(&self) -> &str {
        match self {
            Values::Floats(_) => "f64",
            Values::Counts(_) => "u64",
            Values::Signed(_) => "i64",
            Values::Texts(_) => "string",
            Values::Other(t) => t,
        }
    }
}

/// A scalar attribute.
#[derive(Debug, Clone, PartialEq)]
pub enum Attr {
    /// f64.
    Float(f64),
    /// u64.
    Count(u64),
    /// i64 (−1 for "none").
    Signed(i64),
    /// A UTF-8 string.
    Text(String),
    /// A type this crate never writes.
    Other(String),
}

impl Attr {
    /// The type's name, as docs/hdf5-schema.md spells it.
    pub fn type_name(&self) -> &str {
        match self {
            Attr::Float(_) => "f64",
            Attr::Count(_) => "u64",
            Attr::Signed(_) => "i64",
            Attr::Text(_) => "string",
            Attr::Other(t) => t,
        }
    }
}

/// The scalar attributes of a group or dataset, and their typed reads.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Attrs {
    path: String,
    map: BTreeMap<String, Attr>,
}

impl Attrs {
    fn get(&self, name: &str) -> StoreResult<&Attr> {
        self.map
            .get(name)
            .ok_or_else(|| StoreError::Missing(format!("attribute {}@{name}", shown(&self.path))))
    }

    fn wrong(&self, name: &str, want: &str, got: &Attr) -> StoreError {
        StoreError::Invalid(format!(
            "attribute {}@{name} is {}, not {want}",
            shown(&self.path),
            got.type_name()
        ))
    }

    /// A string attribute.
    pub fn text(&self, name: &str) -> StoreResult<&str> {
        match self.get(name)? {
            Attr::Text(s) => Ok(s),
            other => Err(self.wrong(name, "a string", other)),
        }
    }

    /// A u64 attribute.
    pub fn count(&self, name: &str) -> StoreResult<u64> {
        match self.get(name)? {
            Attr::Count(v) => Ok(*v),
            other => Err(self.wrong(name, "u64", other)),
        }
    }

    /// An f64 attribute.
    pub fn float(&self, name: &str) -> StoreResult<f64> {
        match self.get(name)? {
            Attr::Float(v) => Ok(*v),
            other => Err(self.wrong(name, "f64", other)),
        }
    }

    /// An i64 attribute.
    pub fn signed(&self, name: &str) -> StoreResult<i64> {
        match self.get(name)? {
            Attr::Signed(v) => Ok(*v),
            other => Err(self.wrong(name, "i64", other)),
        }
    }

    /// Whether the attribute exists.
    pub fn has(&self, name: &str) -> bool {
        self.map.contains_key(name)
    }

    /// Every attribute, by name.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &Attr)> {
        self.map.iter().map(|(k, v)| (k.as_str(), v))
    }

    /// Sets (or replaces) an attribute.
    pub fn set(&mut self, name: &str, value: Attr) {
        self.map.insert(name.to_owned(), value);
    }

    /// Sets a string attribute.
    pub fn set_text(&mut self, name: &str, value: &str) {
        self.set(name, Attr::Text(value.to_owned()));
    }

    /// Sets a u64 attribute.
    pub fn set_count(&mut self, name: &str, value: u64) {
        self.set(name, Attr::Count(value));
    }

    /// Sets an f64 attribute.
    pub fn set_float(&mut self, name: &str, value: f64) {
        self.set(name, Attr::Float(value));
    }

    /// Sets an i64 attribute.
    pub fn set_signed(&mut self, name: &str, value: i64) {
        self.set(name, Attr::Signed(value));
    }
}

/// "/" for the root, else the path.
fn shown(path: &str) -> &str {
    if path.is_empty() {
        "/"
    } else {
        path
    }
}

/// A dataset: its shape (empty for a scalar), its elements in row-major
/// order, its attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset {
    shape: Vec<usize>,
    values: Values,
    /// The dataset's attributes (`units`, `description`).
    pub attrs: Attrs,
}

impl Dataset {
    /// A dataset of `values` in `shape` (`[]` for a scalar); the element
    /// count must match the shape.
    fn new(path: String, shape: &[usize], values: Values) -> StoreResult<Dataset> {
        let want: usize = shape.iter().product();
        if values.len() != want && !matches!(values, Values::Other(_)) {
            return Err(StoreError::Invalid(format!(
                "dataset {path}: {} elements for the shape {shape:?}",
                values.len()
            )));
        }
        Ok(Dataset {
            shape: shape.to_vec(),
            values,
            attrs: Attrs {
                path,
                map: BTreeMap::new(),
            },
        })
    }

    /// The full path of the dataset.
    pub fn path(&self) -> &str {
        &self.attrs.path
    }

    /// The dimensions (empty for a scalar).
    pub fn shape(&self) -> &[usize] {
        &self.shape
    }

    /// The elements.
    pub fn values(&self) -> &Values {
        &self.values
    }

    fn wrong(&self, want: &str) -> StoreError {
        StoreError::Invalid(format!(
            "dataset {} is {}, not {want}",
            self.path(),
            self.values.type_name()
        ))
    }

    /// The elements of an f64 dataset.
    pub fn floats(&self) -> StoreResult<&[f64]> {
        match &self.values {
            Values::Floats(v) => Ok(v),
            _ => Err(self.wrong("f64")),
        }
    }

    /// The elements of a u64 dataset.
    pub fn counts(&self) -> StoreResult<&[u64]> {
        match &self.values {
            Values::Counts(v) => Ok(v),
            _ => Err(self.wrong("u64")),
        }
    }

    /// The elements of an i64 dataset.
    pub fn signed(&self) -> StoreResult<&[i64]> {
        match &self.values {
            Values::Signed(v) => Ok(v),
            _ => Err(self.wrong("i64")),
        }
    }

    /// The elements of a string dataset.
    pub fn texts(&self) -> StoreResult<&[String]> {
        match &self.values {
            Values::Texts(v) => Ok(v),
            _ => Err(self.wrong("strings")),
        }
    }

    /// The one element of a scalar (or one-element) f64 dataset.
    pub fn float(&self) -> StoreResult<f64> {
        match self.floats()? {
            [v] => Ok(*v),
            v => Err(StoreError::Invalid(format!(
                "dataset {} has {} elements, not one",
                self.path(),
                v.len()
            ))),
        }
    }

    /// The one element of a scalar (or one-element) u64 dataset.
    pub fn count(&self) -> StoreResult<u64> {
        match self.counts()? {
            [v] => Ok(*v),
            v => Err(StoreError::Invalid(format!(
                "dataset {} has {} elements, not one",
                self.path(),
                v.len()
            ))),
        }
    }

    /// The rows of an f64 dataset of rank 2 or more (each row the
    /// elements under one first index); a 1-D dataset is one column.
    pub fn float_rows(&self) -> StoreResult<Vec<Vec<f64>>> {
        let v = self.floats()?;
        let rows = self.shape.first().copied().unwrap_or(1);
        let width = self.shape.iter().skip(1).product::<usize>();
        if rows == 0 {
            return Ok(vec![]);
        }
        if width == 0 {
            return Ok(vec![vec![]; rows]);
        }
        Ok(v.chunks(width).map(<[f64]>::to_vec).collect())
    }
}

/// A group: attributes, subgroups and datasets by name. The root group
/// stands for the file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Group {
    /// The group's attributes.
    pub attrs: Attrs,
    groups: BTreeMap<String, Group>,
    datasets: BTreeMap<String, Dataset>,
}

impl Group {
    /// An empty root group (a new file).
    pub fn root() -> Group {
        Group::default()
    }

    /// The full path of the group ("" for the root).
    pub fn path(&self) -> &str {
        &self.attrs.path
    }

    fn child_path(&self, name: &str) -> String {
        format!("{}/{name}", self.path())
    }

    /// The subgroup `name` (a path `a/b` for nested groups), created with
    /// its parents when absent.
    pub fn create_group(&mut self, name: &str) -> &mut Group {
        let mut g = self;
        for part in name.split('/').filter(|p| !p.is_empty()) {
            let path = g.child_path(part);
            g = g.groups.entry(part.to_owned()).or_insert_with(|| Group {
                attrs: Attrs {
                    path,
                    map: BTreeMap::new(),
                },
                ..Group::default()
            });
        }
        g
    }

    /// Puts a dataset at `name` (a path: missing groups are created),
    /// replacing one of that name.
    pub fn put(&mut self, name: &str, shape: &[usize], values: Values) -> StoreResult<()> {
        let (parent, last) = match name.rsplit_once('/') {
            Some((p, l)) => (self.create_group(p), l),
            None => (self, name),
        };
        let ds = Dataset::new(parent.child_path(last), shape, values)?;
        parent.datasets.insert(last.to_owned(), ds);
        Ok(())
    }

    /// Puts an f64 dataset of `shape`.
    pub fn floats(&mut self, name: &str, shape: &[usize], data: &[f64]) -> StoreResult<()> {
        self.put(name, shape, Values::Floats(data.to_vec()))
    }

    /// Puts a scalar f64 dataset.
    pub fn float(&mut self, name: &str, value: f64) -> StoreResult<()> {
        self.put(name, &[], Values::Floats(vec![value]))
    }

    /// Puts a 1-D u64 dataset.
    pub fn counts(&mut self, name: &str, data: &[u64]) -> StoreResult<()> {
        self.put(name, &[data.len()], Values::Counts(data.to_vec()))
    }

    /// Puts a scalar u64 dataset.
    pub fn count(&mut self, name: &str, value: u64) -> StoreResult<()> {
        self.put(name, &[], Values::Counts(vec![value]))
    }

    /// Puts a 1-D string dataset.
    pub fn texts<S: AsRef<str>>(&mut self, name: &str, data: &[S]) -> StoreResult<()> {
        let v: Vec<String> = data.iter().map(|s| s.as_ref().to_owned()).collect();
        self.put(name, &[v.len()], Values::Texts(v))
    }

    /// Removes the dataset or group `name` (a path); true if it existed.
    pub fn remove(&mut self, name: &str) -> bool {
        let (parent, last) = match name.rsplit_once('/') {
            Some((p, l)) => match self.find_group_mut(p) {
                Some(g) => (g, l),
                None => return false,
            },
            None => (self, name),
        };
        parent.datasets.remove(last).is_some() || parent.groups.remove(last).is_some()
    }

    fn find_group_mut(&mut self, path: &str) -> Option<&mut Group> {
        let mut g = self;
        for part in path.split('/').filter(|p| !p.is_empty()) {
            g = g.groups.get_mut(part)?;
        }
        Some(g)
    }

    fn find_group(&self, path: &str) -> Option<&Group> {
        let mut g = self;
        for part in path.split('/').filter(|p| !p.is_empty()) {
            g = g.groups.get(part)?;
        }
        Some(g)
    }

    /// The subgroup at `path` (relative, `a/b` for nested groups).
    pub fn group(&self, path: &str) -> StoreResult<&Group> {
        self.find_group(path)
            .ok_or_else(|| StoreError::Missing(format!("group {}", self.child_path(path))))
    }

    /// The dataset at `path` (relative, `a/b/name`).
    pub fn dataset(&self, path: &str) -> StoreResult<&Dataset> {
        let (parent, last) = match path.rsplit_once('/') {
            Some((p, l)) => (self.find_group(p), l),
            None => (Some(self), path),
        };
        parent
            .and_then(|g| g.datasets.get(last))
            .ok_or_else(|| StoreError::Missing(format!("dataset {}", self.child_path(path))))
    }

    /// The dataset at `path`, mutable (to describe it).
    pub fn dataset_mut(&mut self, path: &str) -> Option<&mut Dataset> {
        let (parent, last) = match path.rsplit_once('/') {
            Some((p, l)) => (self.find_group_mut(p), l),
            None => (Some(self), path),
        };
        parent.and_then(|g| g.datasets.get_mut(last))
    }

    /// The subgroups, by name.
    pub fn groups(&self) -> impl Iterator<Item = (&str, &Group)> {
        self.groups.iter().map(|(k, v)| (k.as_str(), v))
    }

    /// The datasets, by name.
    pub fn datasets(&self) -> impl Iterator<Item = (&str, &Dataset)> {
        self.datasets.iter().map(|(k, v)| (k.as_str(), v))
    }

    /// Runs `f` on every dataset of this group and its subgroups, with the
    /// name of the group holding it ("" for the root).
    pub fn each_dataset_mut(&mut self, parent: &str, f: &mut impl FnMut(&str, &str, &mut Dataset)) {
        for (name, ds) in &mut self.datasets {
            f(parent, name, ds);
        }
        for (name, g) in &mut self.groups {
            g.each_dataset_mut(name, f);
        }
    }
}

/// Writes the tree under `root` to `path` as an HDF5 file (unsealed: the
/// caller seals and renames it into place).
pub fn write(path: &Path, root: &Group) -> StoreResult<()> {
    let mut file = FileBuilder::new();
    for (name, value) in root.attrs.iter() {
        file.set_attr(name, attr_value(value)?);
    }
    for (name, ds) in root.datasets() {
        fill_dataset(file.create_dataset(name), ds)?;
    }
    for (name, g) in root.groups() {
        let mut builder = file.create_group(name);
        fill_group(&mut builder, g)?;
        file.add_group(builder.finish());
    }
    file.write(path)
        .map_err(|e| StoreError::Unreadable(format!("writing {}: {e}", path.display())))
}

fn fill_group(builder: &mut GroupBuilder, g: &Group) -> StoreResult<()> {
    for (name, value) in g.attrs.iter() {
        builder.set_attr(name, attr_value(value)?);
    }
    for (name, ds) in g.datasets() {
        fill_dataset(builder.create_dataset(name), ds)?;
    }
    for (name, sub) in g.groups() {
        let mut child = builder.create_group(name);
        fill_group(&mut child, sub)?;
        builder.add_group(child.finish());
    }
    Ok(())
}

fn fill_dataset(builder: &mut hdf5_pure::DatasetBuilder, ds: &Dataset) -> StoreResult<()> {
    match &ds.values {
        Values::Floats(v) => builder.with_f64_data(v),
        Values::Counts(v) => builder.with_u64_data(v),
        Values::Signed(v) => builder.with_i64_data(v),
        Values::Texts(v) => {
            let refs: Vec<&str> = v.iter().map(String::as_str).collect();
            builder.with_vlen_strings(&refs)
        }
        Values::Other(t) => {
            return Err(StoreError::Invalid(format!(
                "dataset {}: cannot write the type {t}",
                ds.path()
            )))
        }
    };
    let shape: Vec<u64> = ds.shape.iter().map(|&n| n as u64).collect();
    builder.with_shape(&shape);
    for (name, value) in ds.attrs.iter() {
        builder.set_attr(name, attr_value(value)?);
    }
    Ok(())
}

fn attr_value(a: &Attr) -> StoreResult<AttrValue> {
    Ok(match a {
        Attr::Float(v) => AttrValue::F64(*v),
        Attr::Count(v) => AttrValue::U64(*v),
        Attr::Signed(v) => AttrValue::I64(*v),
        Attr::Text(s) => AttrValue::VarLenString(s.clone()),
        Attr::Other(t) => {
            return Err(StoreError::Invalid(format!(
                "cannot write an attribute of type {t}"
            )))
        }
    })
}

/// Reads the whole HDF5 file at `path` into a tree. A panic of the HDF5
/// parser on damaged bytes is caught here and named.
pub fn read(path: &Path) -> StoreResult<Group> {
    let shown = path.display().to_string();
    let parse = || -> StoreResult<Group> {
        let file = hdf5_pure::File::open(path).map_err(|e| match e {
            hdf5_pure::Error::Io(io) => {
                StoreError::Unreadable(format!("cannot read {shown}: {io}"))
            }
            other => {
                StoreError::Unreadable(format!("{shown} is not a readable HDF5 file: {other}"))
            }
        })?;
        read_group(&file.root(), "").map_err(|e| StoreError::Unreadable(format!("{shown}: {e}")))
    };
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse))
        .unwrap_or_else(|_| Err(StoreError::Damaged(shown.clone())))
}

fn read_group(g: &hdf5_pure::Group, path: &str) -> Result<Group, hdf5_pure::Error> {
    let mut out = Group {
        attrs: read_attrs(g.attrs()?, path.to_owned()),
        ..Group::default()
    };
    for name in g.datasets()? {
        let ds = g.dataset(&name)?;
        let child = format!("{path}/{name}");
        let shape: Vec<usize> = ds.shape()?.iter().map(|&n| n as usize).collect();
        let values = match ds.datatype()? {
            Datatype::FloatingPoint { .. } => Values::Floats(ds.read_f64()?),
            Datatype::FixedPoint { layout, .. } if layout.signed => Values::Signed(ds.read_i64()?),
            Datatype::FixedPoint { .. } => Values::Counts(ds.read_u64()?),
            Datatype::String { .. }
            | Datatype::VariableLength {
                is_string: true, ..
            } => Values::Texts(ds.read_string()?),
            other => Values::Other(format!("{other:?}")),
        };
        out.datasets.insert(
            name,
            Dataset {
                shape,
                values,
                attrs: read_attrs(ds.attrs()?, child),
            },
        );
    }
    for name in g.groups()? {
        let child = format!("{path}/{name}");
        let sub = read_group(&g.group(&name)?, &child)?;
        out.groups.insert(name, sub);
    }
    Ok(out)
}

fn read_attrs(map: std::collections::HashMap<String, AttrValue>, path: String) -> Attrs {
    let map = map
        .into_iter()
        .map(|(k, v)| {
            let a = match &v {
                AttrValue::F64(x) => Attr::Float(*x),
                AttrValue::F32(x) => Attr::Float(f64::from(*x)),
                AttrValue::U64(_) | AttrValue::U32(_) | AttrValue::U16(_) | AttrValue::U8(_) => v
                    .as_u64()
                    .map_or_else(|| Attr::Other("u64".into()), Attr::Count),
                AttrValue::I64(_) | AttrValue::I32(_) | AttrValue::I16(_) | AttrValue::I8(_) => v
                    .as_i64()
                    .map_or_else(|| Attr::Other("i64".into()), Attr::Signed),
                _ => match v.as_str() {
                    Some(s) => Attr::Text(s.to_owned()),
                    None => Attr::Other(v.type_name().to_owned()),
                },
            };
            (k, a)
        })
        .collect();
    Attrs { path, map }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("cosserat-store-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    /// Every type the crate writes comes back as written, scalars and
    /// empty datasets included, on the root, groups and datasets.
    #[test]
    fn a_tree_reads_back_as_written() {
        let mut root = Group::root();
        root.attrs.set_text("problem", "[rod]\nlength = 1.0 # κ");
        root.attrs.set_count("stages", 3);
        root.texts::<&str>("warnings", &[]).unwrap();
        let g = root.create_group("branches/0");
        g.attrs.set_signed("parent", -1);
        g.attrs.set_float("direction", -1.0);
        g.floats("tip", &[2, 3], &[1.0, 2.0, 3.0, 4.0, 5.0, f64::NAN])
            .unwrap();
        g.floats("empty", &[0, 3], &[]).unwrap();
        g.float("load", f64::INFINITY).unwrap();
        g.counts("morse_index", &[0, 1, u64::MAX]).unwrap();
        g.count("n", 7).unwrap();
        g.texts("stable", &["stable", "unstable"]).unwrap();
        root.put("points/a/b", &[1], Values::Signed(vec![-1]))
            .unwrap();
        root.dataset_mut("branches/0/tip")
            .unwrap()
            .attrs
            .set_text("units", "m");
        let path = scratch("tree.h5");
        write(&path, &root).unwrap();
        let back = read(&path).unwrap();
        let tip = back.dataset("branches/0/tip").unwrap();
        assert_eq!(tip.shape(), [2, 3]);
        assert_eq!(tip.floats().unwrap()[..5], [1.0, 2.0, 3.0, 4.0, 5.0]);
        assert!(tip.floats().unwrap()[5].is_nan());
        assert_eq!(tip.attrs.text("units").unwrap(), "m");
        let g = back.group("branches/0").unwrap();
        assert_eq!(g.attrs.signed("parent").unwrap(), -1);
        assert_eq!(g.attrs.float("direction").unwrap(), -1.0);
        assert_eq!(g.dataset("empty").unwrap().shape(), [0, 3]);
        assert_eq!(g.dataset("load").unwrap().shape(), [0usize; 0]);
        assert_eq!(g.dataset("load").unwrap().float().unwrap(), f64::INFINITY);
        assert_eq!(
            g.dataset("morse_index").unwrap().counts().unwrap(),
            [0, 1, u64::MAX]
        );
        assert_eq!(g.dataset("n").unwrap().count().unwrap(), 7);
        assert_eq!(
            g.dataset("stable").unwrap().texts().unwrap(),
            ["stable", "unstable"]
        );
        assert_eq!(
            back.attrs.text("problem").unwrap(),
            "[rod]\nlength = 1.0 # κ"
        );
        assert_eq!(back.attrs.count("stages").unwrap(), 3);
        assert!(back
            .dataset("warnings")
            .unwrap()
            .texts()
            .unwrap()
            .is_empty());
        assert_eq!(back.dataset("points/a/b").unwrap().signed().unwrap(), [-1]);
        // Typed reads name what they found.
        let e = g
            .dataset("stable")
            .unwrap()
            .floats()
            .unwrap_err()
            .to_string();
        assert!(e.contains("/branches/0/stable is string, not f64"), "{e}");
        let e = back.group("nope").unwrap_err().to_string();
        assert_eq!(e, "it has no group /nope");
        std::fs::remove_file(&path).unwrap();
    }

    /// Truncated and bit-flipped copies of a file give errors, never a
    /// panic out of `read`.
    #[test]
    fn damaged_files_are_errors() {
        let mut root = Group::root();
        root.attrs.set_text("problem", "x");
        let g = root.create_group("a");
        g.floats("x", &[4, 3], &[0.5; 12]).unwrap();
        g.texts("names", &["p", "q"]).unwrap();
        let path = scratch("damaged.h5");
        write(&path, &root).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let copy = scratch("damaged-copy.h5");
        for n in (0..bytes.len()).step_by(97) {
            std::fs::write(&copy, &bytes[..n]).unwrap();
            assert!(read(&copy).is_err(), "truncated at {n}");
        }
        for k in (0..bytes.len()).step_by(13) {
            let mut b = bytes.clone();
            b[k] ^= 0x5a;
            std::fs::write(&copy, &b).unwrap();
            let _ = read(&copy);
        }
        std::fs::remove_file(&path).unwrap();
        std::fs::remove_file(&copy).unwrap();
    }
}
