//! Bifurcation-diagram charts (plotters; PNG or SVG by the file extension).
//!
//! Left panel: the parameter against a measure of the solution, stable
//! stretches solid and unstable dashed, folds and branch points marked and
//! labelled (F1, BP1, ...). Right panel: rod shapes (height −x against the
//! horizontal z, the paper's axes) at the special points and branch ends.

use std::path::Path;

use cosserat::output::store::{Group, StoreError, StoreResult};
use plotters::prelude::*;

/// One branch as read from a diagram file.
#[derive(Debug, Clone, Default)]
pub struct BranchData {
    /// Parameter values.
    pub parameter: Vec<f64>,
    /// Tip positions.
    pub tip: Vec<[f64; 3]>,
    /// Tip angles (rad).
    pub tip_angle: Vec<f64>,
    /// Curvature norms.
    pub norm: Vec<f64>,
    /// Stable flags.
    pub stable: Vec<bool>,
    /// Shapes, 21 positions each.
    pub shapes: Vec<Vec<[f64; 3]>>,
    /// The named measures of each point (columns of
    /// [`DiagramData::measure_names`]).
    pub measures: Vec<Vec<f64>>,
}

/// A special point as read from a diagram file.
#[derive(Debug, Clone)]
pub struct SpecialData {
    /// "fold" or "branch_point".
    pub kind: String,
    /// The branch it lies on.
    pub branch: usize,
    /// The point index before it.
    pub index: usize,
    /// Its parameter.
    pub parameter: f64,
    /// Its tip.
    pub tip: [f64; 3],
    /// Its named measures.
    pub measures: Vec<f64>,
}

/// A diagram file's contents needed for charts.
#[derive(Debug, Clone, Default)]
pub struct DiagramData {
    /// The continued parameter's name (the stages' keys, in order, for a
    /// chained run: its stages share the horizontal axis).
    pub parameter_name: String,
    /// Branches.
    pub branches: Vec<BranchData>,
    /// Special points.
    pub specials: Vec<SpecialData>,
    /// The names of the per-point measures (none in files written before
    /// measures existed).
    pub measure_names: Vec<String>,
}

/// The rows of an m×k dataset, or m empty rows when the file has none
/// (written before measures existed).
fn measure_rows(g: &Group, k: usize, m: usize) -> StoreResult<Vec<Vec<f64>>> {
    let Ok(ds) = g.dataset("measures") else {
        return Ok(vec![vec![]; m]);
    };
    let v = ds.floats()?;
    if k == 0 {
        return Ok(vec![vec![]; m]);
    }
    if v.len() != m * k {
        return Err("the measures dataset does not have one row per point".into());
    }
    Ok(v.chunks_exact(k).map(<[f64]>::to_vec).collect())
}

/// Rows of three; a length that is not a multiple of three is an error.
fn rows3(v: &[f64]) -> StoreResult<Vec<[f64; 3]>> {
    if !v.len().is_multiple_of(3) {
        return Err("a dataset of 3-vectors has a length that is not a multiple of 3".into());
    }
    Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

/// Reads a diagram written by `cosserat continue`.
pub fn read_diagram(path: &Path) -> StoreResult<DiagramData> {
    let f = cosserat::output::seal::open(path)?;
    let parameter_name = f.attrs.text("parameter_name")?.to_owned();
    let root = f.group("branches")?;
    let measure_names: Vec<String> = match root.dataset("measure_names") {
        Ok(ds) => ds.texts()?.to_vec(),
        Err(_) => vec![],
    };
    let k = measure_names.len();
    let mut branches = vec![];
    let mut keys: Vec<String> = vec![];
    for i in 0.. {
        let Ok(g) = root.group(&i.to_string()) else {
            break;
        };
        // A chained run's stages continue different keys on one axis.
        if let Ok(key) = g.attrs.text("parameter_name") {
            if !keys.iter().any(|k| k == key) {
                keys.push(key.to_owned());
            }
        }
        let read =
            |name: &str| -> StoreResult<Vec<f64>> { Ok(g.dataset(name)?.floats()?.to_vec()) };
        let shapes_ds = g.dataset("shapes")?;
        let per = shapes_ds.shape().get(1).copied().unwrap_or(0);
        let shapes = shapes_ds.floats()?;
        let parameter = read("parameter")?;
        let measures = measure_rows(g, k, parameter.len())?;
        branches.push(BranchData {
            measures,
            parameter,
            tip: rows3(&read("tip_position")?)?,
            tip_angle: read("tip_angle")?,
            norm: read("norm")?,
            stable: cosserat::output::read_stable(g.dataset("stable")?)?,
            shapes: shapes
                .chunks((per * 3).max(1))
                .map(rows3)
                .collect::<StoreResult<_>>()?,
        });
    }
    let sp = f.group("special_points")?;
    let kinds = sp.dataset("kind")?.texts()?;
    let branch = sp.dataset("branch")?.counts()?;
    let index = sp.dataset("index")?.counts()?;
    let parameter = sp.dataset("parameter")?.floats()?;
    let parameter_name = if keys.len() > 1 {
        keys.iter()
            .enumerate()
            .map(|(i, k)| format!("stage {}: {k}", i + 1))
            .collect::<Vec<_>>()
            .join(" | ")
    } else {
        parameter_name
    };
    let tip = rows3(sp.dataset("tip_position")?.floats()?)?;
    let n = kinds.len();
    let special_measures = measure_rows(sp, k, n)?;
    if [branch.len(), index.len(), parameter.len(), tip.len()] != [n; 4] {
        return Err("the special-point datasets have different lengths".into());
    }
    let specials = (0..n)
        .map(|i| SpecialData {
            kind: kinds[i].clone(),
            branch: branch[i] as usize,
            index: index[i] as usize,
            parameter: parameter[i],
            tip: tip[i],
            measures: special_measures[i].clone(),
        })
        .collect();
    let data = DiagramData {
        parameter_name,
        branches,
        specials,
        measure_names,
    };
    data.check().map_err(StoreError::Invalid)?;
    Ok(data)
}

impl DiagramData {
    /// A diagram file is input like any other: every branch's columns of
    /// one length, special points on existing points, numbers finite.
    fn check(&self) -> Result<(), String> {
        for (i, b) in self.branches.iter().enumerate() {
            let m = b.parameter.len();
            let lengths = [
                b.tip.len(),
                b.tip_angle.len(),
                b.norm.len(),
                b.stable.len(),
                b.shapes.len(),
            ];
            if lengths.iter().any(|&l| l != m) {
                return Err(format!("branch {i}: datasets of different lengths"));
            }
            let finite = b
                .parameter
                .iter()
                .chain(b.tip.iter().flatten())
                .all(|v| v.is_finite());
            if !finite {
                return Err(format!("branch {i}: a parameter or tip that is not finite"));
            }
        }
        for (i, s) in self.specials.iter().enumerate() {
            let exists = self
                .branches
                .get(s.branch)
                .is_some_and(|b| s.index < b.parameter.len());
            if !exists {
                return Err(format!(
                    "special point {i}: its branch point does not exist"
                ));
            }
            if !(s.parameter.is_finite() && s.tip.iter().all(|v| v.is_finite())) {
                return Err(format!("special point {i}: not finite"));
            }
        }
        Ok(())
    }
}

/// The value of `measure` at a tip.
pub fn measure_value(measure: &str, tip: &[f64; 3], angle: f64, norm: f64) -> f64 {
    match measure {
        "tip_y" => tip[1],
        "tip_z" => tip[2],
        "norm" => norm,
        "tip_angle" => angle.to_degrees(),
        _ => tip[0],
    }
}

/// Registers the shipped DejaVu Sans (no system font libraries needed).
pub fn register_font() {
    static FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
}

/// Draws the diagram to `out` (.png or .svg).
pub fn draw(
    data: &DiagramData,
    measure: &str,
    out: &Path,
) -> Result<(), Box<dyn std::error::Error>> {
    register_font();
    let svg = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    if svg {
        panels(
            &SVGBackend::new(out, (1400, 600)).into_drawing_area(),
            data,
            measure,
        )
    } else {
        panels(
            &BitMapBackend::new(out, (1400, 600)).into_drawing_area(),
            data,
            measure,
        )
    }
}

const COLORS: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        return (0.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

fn label(s: &SpecialData, counts: &mut [usize; 2]) -> String {
    let (tag, slot) = if s.kind == "fold" {
        ("F", 0)
    } else {
        ("BP", 1)
    };
    counts[slot] += 1;
    format!("{tag}{}", counts[slot])
}

fn panels<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    data: &DiagramData,
    measure: &str,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(820);
    diagram_panel(&left, data, measure)?;
    shapes_panel(&right, data)?;
    root.present()?;
    Ok(())
}

fn diagram_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    data: &DiagramData,
    measure: &str,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let named = data.measure_names.iter().position(|n| n == measure);
    let value = |b: &BranchData, i: usize| match named {
        Some(k) => b.measures[i][k],
        None => measure_value(measure, &b.tip[i], b.tip_angle[i], b.norm[i]),
    };
    let xs = bounds(
        data.branches
            .iter()
            .flat_map(|b| b.parameter.iter().copied()),
    );
    let ys = bounds(
        data.branches
            .iter()
            .flat_map(|b| (0..b.parameter.len()).map(move |i| value(b, i))),
    );
    let mut chart = ChartBuilder::on(area)
        .caption(
            "bifurcation diagram (solid: stable, dashed: unstable)",
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(65)
        .build_cartesian_2d(xs.0..xs.1, ys.0..ys.1)?;
    chart
        .configure_mesh()
        .x_desc(data.parameter_name.as_str())
        .y_desc(measure)
        .label_style(("sans-serif", 15))
        .draw()?;
    for (bi, b) in data.branches.iter().enumerate() {
        let color = COLORS[bi % COLORS.len()];
        let mut start = 0;
        while start + 1 < b.parameter.len() {
            let stable = b.stable[start + 1];
            let mut end = start + 1;
            while end + 1 < b.parameter.len() && b.stable[end + 1] == stable {
                end += 1;
            }
            let pts: Vec<(f64, f64)> = (start..=end)
                .map(|i| (b.parameter[i], value(b, i)))
                .collect();
            let style = color.stroke_width(2);
            if stable {
                chart.draw_series(LineSeries::new(pts, style))?;
            } else {
                chart.draw_series(DashedLineSeries::new(pts, 8, 6, style))?;
            }
            start = end;
        }
    }
    let mut counts = [0, 0];
    for s in &data.specials {
        let b = &data.branches[s.branch];
        let i = s.index.min(b.parameter.len().saturating_sub(1));
        let y = match named {
            Some(k) => s.measures[k],
            None => measure_value(
                measure,
                &s.tip,
                b.tip_angle.get(i).copied().unwrap_or(0.0),
                b.norm.get(i).copied().unwrap_or(0.0),
            ),
        };
        let name = label(s, &mut counts);
        let marker = (s.parameter, y);
        let element = EmptyElement::at(marker)
            + Circle::new((0, 0), 6, BLACK.filled())
            + Text::new(name, (8, -22), ("sans-serif", 16));
        chart.draw_series(std::iter::once(element))?;
    }
    Ok(())
}

fn shapes_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    data: &DiagramData,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    // The shapes at the special points' neighbours and the branch ends.
    let mut picks: Vec<(usize, usize)> =
        data.specials.iter().map(|s| (s.branch, s.index)).collect();
    for (bi, b) in data.branches.iter().enumerate() {
        if !b.shapes.is_empty() {
            picks.push((bi, b.shapes.len() - 1));
        }
    }
    let shapes: Vec<(usize, &Vec<[f64; 3]>)> = picks
        .iter()
        .filter_map(|&(b, i)| {
            data.branches
                .get(b)
                .and_then(|br| br.shapes.get(i))
                .map(|s| (b, s))
        })
        .collect();
    let zs = bounds(shapes.iter().flat_map(|(_, s)| s.iter().map(|r| r[2])));
    let hs = bounds(shapes.iter().flat_map(|(_, s)| s.iter().map(|r| -r[0])));
    let mut chart = ChartBuilder::on(area)
        .caption("rod shapes (height −x against z)", ("sans-serif", 20))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(55)
        .build_cartesian_2d(zs.0..zs.1, hs.0..hs.1)?;
    chart
        .configure_mesh()
        .x_desc("z")
        .y_desc("−x")
        .label_style(("sans-serif", 15))
        .draw()?;
    for (b, s) in shapes {
        let color = COLORS[b % COLORS.len()];
        chart.draw_series(LineSeries::new(
            s.iter().map(|r| (r[2], -r[0])),
            color.stroke_width(2),
        ))?;
    }
    Ok(())
}
