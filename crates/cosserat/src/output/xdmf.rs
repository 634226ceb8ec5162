//! Rods as an XDMF temporal collection (`.xmf`) whose heavy data stay in
//! the HDF5 result file: each grid's points and point data are references
//! `file.h5:/path` into it (one row of a stored array by a hyperslab), so
//! nothing is copied and ParaView animates a diagram over its points.
//! Small arrays a result file does not hold (the arc length of a diagram's
//! shape points) are written inline.
//!
//! The elements used (Domain, a Temporal collection of Uniform grids,
//! Time, Polyline topology, XYZ geometry, node-centred Scalar and Vector
//! attributes, HDF and XML data items, HyperSlab) are common to XDMF 2
//! and 3. VTK's `vtkXdmfReader` and ParaView's "XDMF Reader" (XDMF 2,
//! chosen by the extension `.xmf2`) read all of them; ParaView's Xdmf3
//! readers skip hyperslabs (they ask a referenced array for its type
//! before reading it), so a diagram needs the XDMF 2 reader. Written by hand: the text is a
//! few elements, and no Rust crate writes XDMF. Nothing here touches a
//! file; the caller writes the text atomically ([`super::target`]).

use std::fmt::Write;

/// Why a collection cannot be written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum XdmfError {
    /// A name XDMF cannot carry in `file:/dataset` or as an attribute.
    #[error(
        "`{0}` cannot be named in an XDMF file (it holds `:`, `\"`, `<`, `>`, `&` or a line break)"
    )]
    Name(String),
    /// A stored array's row is outside it, or its shape is not n×k.
    #[error("{0}")]
    Shape(String),
    /// A value is NaN or infinite.
    #[error("`{0}` holds a non-finite value")]
    NotFinite(String),
}

/// Where a grid's array comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// A dataset of an HDF5 file, whole or one row of its first axis.
    Stored(Stored),
    /// Numbers written into the XDMF file itself.
    Inline(Vec<f64>),
}

/// An array of an HDF5 file: the whole dataset (`dims`, n×k or n), or with
/// `row` its row `row` (the dataset m×n×k, the row n×k).
#[derive(Debug, Clone, PartialEq)]
pub struct Stored {
    file: String,
    dataset: String,
    dims: Vec<usize>,
    row: Option<usize>,
}

impl Stored {
    /// `file` (as the XDMF file's readers will find it: relative to its
    /// directory, or absolute), `dataset` its path inside, `dims` its shape;
    /// `row` picks one row of the first axis.
    pub fn new(
        file: &str,
        dataset: &str,
        dims: &[usize],
        row: Option<usize>,
    ) -> Result<Self, XdmfError> {
        for name in [file, dataset] {
            if name.is_empty() || name.contains([':', '"', '<', '>', '&', '\n', '\r']) {
                return Err(XdmfError::Name(name.into()));
            }
        }
        let rank_ok = match row {
            Some(r) => (2..=3).contains(&dims.len()) && r < dims[0],
            None => (1..=2).contains(&dims.len()),
        };
        if !rank_ok {
            return Err(XdmfError::Shape(format!(
                "{file}:{dataset} has shape {dims:?}; row {row:?} of it is not a rod array"
            )));
        }
        Ok(Stored {
            file: file.into(),
            dataset: dataset.into(),
            dims: dims.to_vec(),
            row,
        })
    }

    /// The points (first axis of what is selected).
    fn points(&self) -> usize {
        match self.row {
            Some(_) => self.dims[1],
            None => self.dims[0],
        }
    }

    /// The components per point of what is selected.
    fn components(&self) -> usize {
        let tail = if self.row.is_some() {
            &self.dims[2..]
        } else {
            &self.dims[1..]
        };
        tail.first().copied().unwrap_or(1)
    }
}

/// A node-centred array of a grid: a scalar (1 component) or vector (3).
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    name: String,
    values: Values,
}

impl Attribute {
    /// The array `name` with `values`.
    pub fn new(name: &str, values: Values) -> Result<Self, XdmfError> {
        if name.is_empty() || name.contains(['"', '<', '>', '&', '\n', '\r']) {
            return Err(XdmfError::Name(name.into()));
        }
        if let Values::Inline(v) = &values {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(XdmfError::NotFinite(name.into()));
            }
        }
        Ok(Attribute {
            name: name.into(),
            values,
        })
    }
}

/// One time step: a rod as one polyline through its points.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    name: String,
    time: f64,
    points: Stored,
    attributes: Vec<Attribute>,
}

impl Grid {
    /// The rod at `time` (finite) with its `points` (n×3) and `attributes`
    /// (each n values or n×3).
    pub fn new(
        name: &str,
        time: f64,
        points: Stored,
        attributes: Vec<Attribute>,
    ) -> Result<Self, XdmfError> {
        if name.contains(['"', '<', '>', '&', '\n', '\r']) {
            return Err(XdmfError::Name(name.into()));
        }
        if !time.is_finite() {
            return Err(XdmfError::NotFinite(format!("the time of {name}")));
        }
        let n = points.points();
        if points.components() != 3 || n == 0 {
            return Err(XdmfError::Shape(format!(
                "{}: the points of {name} are not n×3",
                points.dataset
            )));
        }
        for a in &attributes {
            let (len, k) = match &a.values {
                Values::Stored(s) => (s.points(), s.components()),
                Values::Inline(v) => (v.len(), 1),
            };
            if len != n || (k != 1 && k != 3) {
                return Err(XdmfError::Shape(format!(
                    "the attribute {} of {name} has {len}×{k} values for {n} points",
                    a.name
                )));
            }
        }
        Ok(Grid {
            name: name.into(),
            time,
            points,
            attributes,
        })
    }
}

fn stored_item(out: &mut String, s: &Stored) {
    let dims = |d: &[usize]| d.iter().map(usize::to_string).collect::<Vec<_>>().join(" ");
    let whole = format!(
        r#"<DataItem Dimensions="{}" NumberType="Float" Precision="8" Format="HDF">{}:{}</DataItem>"#,
        dims(&s.dims),
        s.file,
        s.dataset
    );
    match s.row {
        None => {
            out.push_str(&whole);
            out.push('\n');
        }
        Some(r) => {
            let rank = s.dims.len();
            let mut start = vec![0; rank];
            start[0] = r;
            let mut count = s.dims.clone();
            count[0] = 1;
            let _ = writeln!(
                out,
                r#"<DataItem ItemType="HyperSlab" Dimensions="{}" Type="HyperSlab">"#,
                dims(&s.dims[1..])
            );
            let _ = writeln!(
                out,
                r#"<DataItem Dimensions="3 {rank}" NumberType="Int" Format="XML">{} {} {}</DataItem>"#,
                dims(&start),
                dims(&vec![1; rank]),
                dims(&count)
            );
            out.push_str(&whole);
            out.push_str("\n</DataItem>\n");
        }
    }
}

fn values_item(out: &mut String, v: &Values) {
    match v {
        Values::Stored(s) => stored_item(out, s),
        Values::Inline(x) => {
            let text: Vec<String> = x.iter().map(|v| format!("{v:e}")).collect();
            let _ = writeln!(
                out,
                r#"<DataItem Dimensions="{}" NumberType="Float" Precision="8" Format="XML">{}</DataItem>"#,
                x.len(),
                text.join(" ")
            );
        }
    }
}

fn grid(out: &mut String, g: &Grid) {
    let n = g.points.points();
    let _ = writeln!(out, r#"<Grid Name="{}" GridType="Uniform">"#, g.name);
    let _ = writeln!(out, r#"<Time Value="{:e}"/>"#, g.time);
    let _ = writeln!(
        out,
        r#"<Topology TopologyType="Polyline" NumberOfElements="1" NodesPerElement="{n}">"#
    );
    let ids: Vec<String> = (0..n).map(|i| i.to_string()).collect();
    let _ = writeln!(
        out,
        r#"<DataItem Dimensions="1 {n}" NumberType="Int" Format="XML">{}</DataItem>"#,
        ids.join(" ")
    );
    out.push_str("</Topology>\n<Geometry GeometryType=\"XYZ\">\n");
    stored_item(out, &g.points);
    out.push_str("</Geometry>\n");
    for a in &g.attributes {
        let kind = match &a.values {
            Values::Stored(s) if s.components() == 3 => "Vector",
            _ => "Scalar",
        };
        let _ = writeln!(
            out,
            r#"<Attribute Name="{}" AttributeType="{kind}" Center="Node">"#,
            a.name
        );
        values_item(out, &a.values);
        out.push_str("</Attribute>\n");
    }
    out.push_str("</Grid>\n");
}

/// The `.xmf` text of `grids` as one temporal collection, in the order
/// given (the caller keeps the times increasing); `note` (what the time
/// means) is written as an `Information` element.
pub fn temporal_collection(grids: &[Grid], note: &str) -> Result<String, XdmfError> {
    if note.contains(['"', '<', '>', '&']) {
        return Err(XdmfError::Name(note.into()));
    }
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n");
    out.push_str(r#"<Grid Name="rod" GridType="Collection" CollectionType="Temporal">"#);
    out.push('\n');
    let _ = writeln!(out, r#"<Information Name="time" Value="{note}"/>"#);
    for g in grids {
        grid(&mut out, g);
    }
    out.push_str("</Grid>\n</Domain>\n</Xdmf>\n");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_outside_the_dataset_is_refused() {
        assert!(Stored::new("a.h5", "/b/shapes", &[4, 21, 3], Some(4)).is_err());
        assert!(Stored::new("a.h5", "/b/shapes", &[4, 21, 3], Some(3)).is_ok());
    }

    #[test]
    fn a_colon_in_the_file_name_is_refused() {
        assert!(Stored::new("a:b.h5", "/solution/s", &[4], None).is_err());
    }

    #[test]
    fn an_attribute_of_the_wrong_length_is_refused() {
        let p = Stored::new("a.h5", "/solution/position", &[5, 3], None).unwrap();
        let s = Attribute::new("s", Values::Inline(vec![0.0; 4])).unwrap();
        assert!(Grid::new("g", 0.0, p, vec![s]).is_err());
    }
}
