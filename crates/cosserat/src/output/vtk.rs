//! A rod as VTK XML PolyData (`.vtp`) and a sequence of rods as a ParaView
//! data collection (`.pvd`), for ParaView, VisIt and VTK's own readers.
//!
//! The rod is one polyline through its sample points, with point data
//! (arc length, directors, curvature, moment, force: whatever the caller
//! has) and field data (scalars of the whole rod: a continuation point's
//! parameter, its Morse index). Values are written as ASCII Float64 with
//! Rust's shortest round-trip exponent form (`{:e}`), so a reader gets the
//! stored numbers bit for bit; non-finite values are refused when the
//! polyline is built, since VTK's ASCII parser cannot read them.
//!
//! Written by hand rather than through a crate: the format needed is two
//! small XML elements, and the crates that write VTK (vtkio) pull in a
//! parser and a model of every VTK data set for it. Nothing here touches
//! a file; the caller writes the text atomically ([`super::target`]).

use std::fmt::Write;

use nalgebra::Vector3;

use crate::equations::RodSample;

/// Why a polyline cannot be written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VtkError {
    /// A polyline needs at least one point.
    #[error("a rod polyline needs at least one point")]
    NoPoints,
    /// A field's length is not points × components.
    #[error("the field `{name}` has {len} values, not {points} points × {components}")]
    Length {
        /// The field's name.
        name: String,
        /// Its number of values.
        len: usize,
        /// The polyline's points.
        points: usize,
        /// Its components per point.
        components: usize,
    },
    /// Only scalars (1) and vectors (3) are written.
    #[error("the field `{name}` has {components} components; scalars (1) or vectors (3) only")]
    Components {
        /// The field's name.
        name: String,
        /// Its components per point.
        components: usize,
    },
    /// A value is NaN or infinite.
    #[error("`{name}` holds a non-finite value ({value}); VTK's ASCII reader cannot read it")]
    NotFinite {
        /// The field (or `points`).
        name: String,
        /// The value.
        value: f64,
    },
    /// A name that is empty or would break the XML.
    #[error("`{0}` is not a usable array name (letters, digits, `_`, `.`, `-` only)")]
    Name(String),
}

/// One array of point data: `components` values per point, point after
/// point.
#[derive(Debug, Clone, PartialEq)]
pub struct PointField {
    name: String,
    components: usize,
    values: Vec<f64>,
}

impl PointField {
    /// A scalar (`components` 1) or vector (3) field; every value finite.
    pub fn new(name: &str, components: usize, values: Vec<f64>) -> Result<Self, VtkError> {
        check_name(name)?;
        if components != 1 && components != 3 {
            return Err(VtkError::Components {
                name: name.into(),
                components,
            });
        }
        check_finite(name, &values)?;
        Ok(PointField {
            name: name.into(),
            components,
            values,
        })
    }

    /// The field's name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

/// A rod: its points in order, point data and field data.
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline {
    points: Vec<[f64; 3]>,
    fields: Vec<PointField>,
    tags: Vec<(String, f64)>,
}

impl Polyline {
    /// A polyline through `points` (at least one, finite) carrying
    /// `fields` (each one value or vector per point).
    pub fn new(points: Vec<[f64; 3]>, fields: Vec<PointField>) -> Result<Self, VtkError> {
        if points.is_empty() {
            return Err(VtkError::NoPoints);
        }
        check_finite("points", points.as_flattened())?;
        for f in &fields {
            if f.values.len() != points.len() * f.components {
                return Err(VtkError::Length {
                    name: f.name.clone(),
                    len: f.values.len(),
                    points: points.len(),
                    components: f.components,
                });
            }
        }
        Ok(Polyline {
            points,
            fields,
            tags: vec![],
        })
    }

    /// An equilibrium's samples: point data `s` (m), the directors `d1`,
    /// `d2`, `d3` (global components), `curvature_body` (1/m) and
    /// `moment_body` (N·m) in the directors' frame (κ·d_i, M·d_i: not
    /// global vectors, so their glyphs would mislead), `force` (N, global).
    pub fn from_samples(samples: &[RodSample]) -> Result<Self, VtkError> {
        let column = |f: &dyn Fn(&RodSample) -> Vector3<f64>| -> Vec<f64> {
            samples
                .iter()
                .flat_map(|p| f(p).as_slice().to_vec())
                .collect()
        };
        let fields = vec![
            PointField::new("s", 1, samples.iter().map(|p| p.s).collect())?,
            PointField::new("d1", 3, column(&|p| p.directors[0]))?,
            PointField::new("d2", 3, column(&|p| p.directors[1]))?,
            PointField::new("d3", 3, column(&|p| p.directors[2]))?,
            PointField::new("curvature_body", 3, column(&|p| p.curvature))?,
            PointField::new("moment_body", 3, column(&|p| p.moment))?,
            PointField::new("force", 3, column(&|p| p.force))?,
        ];
        let points = samples
            .iter()
            .map(|p| [p.position[0], p.position[1], p.position[2]])
            .collect();
        Polyline::new(points, fields)
    }

    /// Adds a number of the whole rod (VTK field data), e.g. the
    /// continuation parameter of the point it shows.
    pub fn with_tag(mut self, name: &str, value: f64) -> Result<Self, VtkError> {
        check_name(name)?;
        check_finite(name, &[value])?;
        self.tags.push((name.into(), value));
        Ok(self)
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Always false: a polyline has at least one point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

fn check_name(name: &str) -> Result<(), VtkError> {
    let usable = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-'));
    if usable {
        Ok(())
    } else {
        Err(VtkError::Name(name.into()))
    }
}

fn check_finite(name: &str, values: &[f64]) -> Result<(), VtkError> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(VtkError::NotFinite {
            name: name.into(),
            value,
        }),
        None => Ok(()),
    }
}

/// Values separated by spaces, six to a line.
fn numbers(out: &mut String, values: &[f64]) {
    for (i, v) in values.iter().enumerate() {
        let sep = if i % 6 == 5 { "\n" } else { " " };
        let _ = write!(out, "{v:e}{sep}");
    }
    out.push('\n');
}

fn data_array(out: &mut String, name: &str, components: usize, values: &[f64]) {
    let _ = writeln!(
        out,
        r#"<DataArray type="Float64" Name="{name}" NumberOfComponents="{components}" format="ascii">"#
    );
    numbers(out, values);
    out.push_str("</DataArray>\n");
}

/// The `.vtp` text of `rod`: one piece, its points joined by one polyline
/// (a single point is a vertex).
pub fn polydata(rod: &Polyline) -> String {
    let n = rod.points.len();
    let mut out = String::new();
    out.push_str(concat!(
        "<?xml version=\"1.0\"?>\n",
        "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
        "<PolyData>\n"
    ));
    if !rod.tags.is_empty() {
        out.push_str("<FieldData>\n");
        for (name, value) in &rod.tags {
            let _ = writeln!(
                out,
                r#"<DataArray type="Float64" Name="{name}" NumberOfTuples="1" format="ascii">"#
            );
            numbers(&mut out, &[*value]);
            out.push_str("</DataArray>\n");
        }
        out.push_str("</FieldData>\n");
    }
    let (verts, lines) = if n == 1 { (1, 0) } else { (0, 1) };
    let _ = writeln!(
        out,
        r#"<Piece NumberOfPoints="{n}" NumberOfVerts="{verts}" NumberOfLines="{lines}" NumberOfStrips="0" NumberOfPolys="0">"#
    );
    out.push_str("<PointData>\n");
    for f in &rod.fields {
        data_array(&mut out, &f.name, f.components, &f.values);
    }
    out.push_str("</PointData>\n<Points>\n");
    data_array(&mut out, "Points", 3, rod.points.as_flattened());
    out.push_str("</Points>\n");
    let cells = if n == 1 { "Verts" } else { "Lines" };
    let _ = writeln!(out, "<{cells}>");
    out.push_str(r#"<DataArray type="Int64" Name="connectivity" format="ascii">"#);
    out.push('\n');
    let ids: Vec<String> = (0..n).map(|i| i.to_string()).collect();
    out.push_str(&ids.join(" "));
    out.push_str("\n</DataArray>\n");
    out.push_str(r#"<DataArray type="Int64" Name="offsets" format="ascii">"#);
    let _ = write!(out, "\n{n}\n</DataArray>\n</{cells}>\n");
    out.push_str("</Piece>\n</PolyData>\n</VTKFile>\n");
    out
}

/// One data set of a collection: the time it shows and its file, relative
/// to the collection file's directory.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    time: f64,
    file: String,
}

impl Step {
    /// A step at `time` (finite) in `file` (a path without `"`, `<`, `&`).
    pub fn new(time: f64, file: &str) -> Result<Self, VtkError> {
        check_finite("timestep", &[time])?;
        if file.is_empty() || file.contains(['"', '<', '>', '&', '\n']) {
            return Err(VtkError::Name(file.into()));
        }
        Ok(Step {
            time,
            file: file.into(),
        })
    }
}

/// The `.pvd` text of a time series: ParaView shows `steps` in the order
/// of their times (which the caller keeps increasing) and animates them.
/// `note` (what the time means) is written as an XML comment.
pub fn collection(steps: &[Step], note: &str) -> String {
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\"?>\n");
    let note = note.replace("--", "- -");
    let _ = writeln!(out, "<!-- {note} -->");
    out.push_str("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
    out.push_str("<Collection>\n");
    for s in steps {
        let _ = writeln!(
            out,
            r#"<DataSet timestep="{:e}" group="" part="0" file="{}"/>"#,
            s.time, s.file
        );
    }
    out.push_str("</Collection>\n</VTKFile>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_of_the_wrong_length_is_refused() {
        let f = PointField::new("s", 1, vec![0.0, 1.0, 2.0]).unwrap();
        let e = Polyline::new(vec![[0.0; 3], [1.0; 3]], vec![f]).unwrap_err();
        assert!(matches!(e, VtkError::Length { len: 3, .. }));
    }

    #[test]
    fn non_finite_values_and_xml_breaking_names_are_refused() {
        assert!(PointField::new("s", 1, vec![f64::NAN]).is_err());
        assert!(PointField::new("a\"b", 1, vec![0.0]).is_err());
        assert!(Polyline::new(vec![[f64::INFINITY, 0.0, 0.0]], vec![]).is_err());
        assert!(Step::new(0.0, "a\".vtp").is_err());
    }

    #[test]
    fn numbers_round_trip_through_the_text() {
        let x = [0.1, -1.0 / 3.0, 1e-300, 6.02e23];
        let mut out = String::new();
        numbers(&mut out, &x);
        let back: Vec<f64> = out.split_whitespace().map(|t| t.parse().unwrap()).collect();
        assert_eq!(back, x);
    }
}
