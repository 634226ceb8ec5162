//! Bifurcation-diagram charts (plotters; PNG or SVG by the file extension).
//!
//! Left panel: the parameter against a measure of the solution, stable
//! stretches solid and unstable dashed, folds and branch points marked and
//! labelled (F1, BP1, ...). Right panel: rod shapes (height −x against the
//! horizontal z, the paper's axes) at the special points and branch ends.

use std::path::Path;

use cosserat::output::store::{Group, StoreError, StoreResult};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::axis_label::{measure_label, parameter_label, Scale};
use crate::chart_style::{
    self, colour, draw_grid, draw_tags, frame, legend, line, padded, render, shape_chart, Failure,
    Figure, Glyph, LegendEntry, PixelBox, Stroke, Tag, ARROW, TITLE_FONT,
};

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

// ---------------------------------------------------------------------
// Drawing (everything below works on the data read above).
// ---------------------------------------------------------------------

/// How the tip force of a diagram's problem changes with the parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
enum LoadRule {
    /// The problem's own tip force at every point.
    Fixed([f64; 3]),
    /// The problem's tip force times the parameter (`load_scale`,
    /// `control_scale`).
    Scaled([f64; 3]),
    /// The problem's tip force with component `i` the parameter.
    Component([f64; 3], usize),
    /// Not known (a chained run that changes a load): no arrow is drawn.
    Unknown,
}

impl LoadRule {
    /// The tip force at parameter `p`.
    fn at(self, p: f64) -> Option<[f64; 3]> {
        match self {
            LoadRule::Fixed(f) => Some(f),
            LoadRule::Scaled(f) => Some(f.map(|v| v * p)),
            LoadRule::Component(mut f, i) => {
                f[i] = p;
                Some(f)
            }
            LoadRule::Unknown => None,
        }
    }
}

/// What a diagram's chart needs to know of its problem: how to read its
/// numbers (axis labels) and the tip load to draw on the shapes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProblemView {
    scale: Scale,
    load: LoadRule,
}

impl ProblemView {
    /// A problem not known: documented units, no load arrows.
    pub fn unknown() -> ProblemView {
        ProblemView {
            scale: Scale::Dimensional,
            load: LoadRule::Unknown,
        }
    }

    /// The view of the effective problem text `text` of a diagram whose
    /// parameter name is `parameter_name` (a key, or a chained run's
    /// `stage 1: KEY | …`).
    pub fn of_problem(text: &str, parameter_name: &str) -> ProblemView {
        let keys: Vec<&str> = parameter_name
            .split(" | ")
            .map(|p| p.split_once(": ").map_or(p, |(_, k)| k))
            .collect();
        let scale = Scale::of_problem(text, &keys);
        let force = toml::from_str::<toml::Table>(text).ok().and_then(|t| {
            let f = t.get("loads")?.get("tip_force")?.as_array()?;
            let v: Vec<f64> = f
                .iter()
                .map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                .collect::<Option<_>>()?;
            <[f64; 3]>::try_from(v).ok()
        });
        let force = force.unwrap_or([0.0; 3]);
        let load = match keys.as_slice() {
            ["load_scale" | "control_scale"] => LoadRule::Scaled(force),
            [key] => match key.strip_prefix("loads.tip_force[") {
                Some("0]") => LoadRule::Component(force, 0),
                Some("1]") => LoadRule::Component(force, 1),
                Some("2]") => LoadRule::Component(force, 2),
                Some(_) => LoadRule::Unknown,
                None => LoadRule::Fixed(force),
            },
            _ if keys
                .iter()
                .any(|k| k.starts_with("loads.") || k.ends_with("_scale")) =>
            {
                LoadRule::Unknown
            }
            _ => LoadRule::Fixed(force),
        };
        ProblemView { scale, load }
    }
}

/// The problem view of a diagram file, from the problem text the file
/// keeps. (Reads the file through the library's `read_saved`, not with
/// HDF5 calls of its own; a file it cannot read gives
/// [`ProblemView::unknown`].)
pub fn problem_view(path: &Path, data: &DiagramData) -> ProblemView {
    match cosserat::output::read_saved(path) {
        Ok((text, _)) => ProblemView::of_problem(&text, &data.parameter_name),
        Err(_) => ProblemView::unknown(),
    }
}

/// Draws the diagram to `out` (.png or .svg): the parameter against
/// `measure` (stable solid, unstable dashed, special points marked by
/// kind), a legend beside it, and the rod shapes at the special points and
/// branch ends, to scale, with the tip load.
pub fn draw(
    data: &DiagramData,
    view: &ProblemView,
    measure: &str,
    out: &Path,
) -> Result<(), Box<dyn std::error::Error>> {
    render(
        &DiagramChart {
            data,
            view,
            measure,
        },
        out,
    )
}

/// A diagram file's chart.
struct DiagramChart<'a> {
    data: &'a DiagramData,
    view: &'a ProblemView,
    measure: &'a str,
}

/// The kind of a special point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SpecialKind {
    Fold,
    BranchPoint,
    /// A kind this chart does not know (shown by its own name).
    Other,
}

impl SpecialKind {
    fn of(kind: &str) -> SpecialKind {
        match kind {
            "fold" => SpecialKind::Fold,
            "branch_point" => SpecialKind::BranchPoint,
            _ => SpecialKind::Other,
        }
    }

    fn tag(self) -> &'static str {
        match self {
            SpecialKind::Fold => "F",
            SpecialKind::BranchPoint => "BP",
            SpecialKind::Other => "S",
        }
    }

    fn glyph(self) -> Glyph {
        match self {
            SpecialKind::Fold => Glyph::Dot(BLACK),
            SpecialKind::BranchPoint => Glyph::Square(BLACK),
            SpecialKind::Other => Glyph::Ring(BLACK),
        }
    }
}

/// A marked point of the diagram: a special point or a branch end, with
/// its tag ("F1", "BP2", "E3") and where its shape is.
struct Mark {
    tag: String,
    glyph: Glyph,
    parameter: f64,
    value: f64,
    branch: usize,
    index: usize,
}

/// How many branches the legend lists by colour.
const LEGEND_BRANCHES: usize = 8;

impl DiagramChart<'_> {
    /// The measure of branch `b`'s point `i`.
    fn value(&self, b: &BranchData, i: usize) -> f64 {
        match self
            .data
            .measure_names
            .iter()
            .position(|n| n == self.measure)
        {
            Some(k) => b.measures[i][k],
            None => measure_value(self.measure, &b.tip[i], b.tip_angle[i], b.norm[i]),
        }
    }

    /// The special points (numbered per kind) and the branch ends.
    fn marks(&self) -> Vec<Mark> {
        let mut counts = [0usize; 3];
        let named = self
            .data
            .measure_names
            .iter()
            .position(|n| n == self.measure);
        let mut marks: Vec<Mark> = self
            .data
            .specials
            .iter()
            .map(|s| {
                let kind = SpecialKind::of(&s.kind);
                counts[kind as usize] += 1;
                let b = &self.data.branches[s.branch];
                let i = s.index.min(b.parameter.len().saturating_sub(1));
                let value = match named {
                    Some(k) => s.measures[k],
                    None => measure_value(
                        self.measure,
                        &s.tip,
                        b.tip_angle.get(i).copied().unwrap_or(0.0),
                        b.norm.get(i).copied().unwrap_or(0.0),
                    ),
                };
                Mark {
                    tag: format!("{}{}", kind.tag(), counts[kind as usize]),
                    glyph: kind.glyph(),
                    parameter: s.parameter,
                    value,
                    branch: s.branch,
                    index: s.index,
                }
            })
            .collect();
        for (bi, b) in self.data.branches.iter().enumerate() {
            if let Some(last) = b.parameter.len().checked_sub(1) {
                marks.push(Mark {
                    tag: format!("E{}", bi + 1),
                    glyph: Glyph::Ring(colour(bi)),
                    parameter: b.parameter[last],
                    value: self.value(b, last),
                    branch: bi,
                    index: last,
                });
            }
        }
        marks
    }

    fn legend_entries(&self, marks: &[Mark], arrow: bool) -> Vec<LegendEntry> {
        let flags = || {
            self.data
                .branches
                .iter()
                .flat_map(|b| b.stable.iter().skip(1))
        };
        let mut entries = vec![];
        if flags().any(|s| *s) {
            entries.push(LegendEntry::new(
                Glyph::Line(BLACK, Stroke::Solid),
                "stable",
            ));
        }
        if flags().any(|s| !*s) {
            entries.push(LegendEntry::new(
                Glyph::Line(BLACK, Stroke::Dashed),
                "unstable",
            ));
        }
        for (kind, text) in [
            (SpecialKind::Fold, "fold F"),
            (SpecialKind::BranchPoint, "branch point BP"),
            (SpecialKind::Other, "special point S"),
        ] {
            if marks
                .iter()
                .any(|m| m.tag.starts_with(kind.tag()) && m.glyph == kind.glyph())
            {
                entries.push(LegendEntry::new(kind.glyph(), text));
            }
        }
        entries.push(LegendEntry::new(Glyph::Ring(BLACK), "branch end E"));
        let n = self.data.branches.len();
        for bi in 0..n.min(LEGEND_BRANCHES) {
            entries.push(LegendEntry::new(
                Glyph::Line(colour(bi), Stroke::Solid),
                format!("branch {}", bi + 1),
            ));
        }
        if n > LEGEND_BRANCHES {
            entries.push(LegendEntry::new(
                Glyph::Line(colour(LEGEND_BRANCHES), Stroke::Dotted),
                format!("… {n} branches in all"),
            ));
        }
        if arrow {
            entries.push(LegendEntry::new(Glyph::Arrow(LOAD), "tip force F"));
        }
        entries
    }
}

/// The colour of load arrows.
const LOAD: RGBColor = RGBColor(200, 0, 0);

impl Figure for DiagramChart<'_> {
    fn size(&self) -> (u32, u32) {
        (1560, 640)
    }

    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), Failure>
    where
        DB::ErrorType: 'static,
    {
        let (left, rest) = root.split_horizontally(800);
        let (middle, right) = rest.split_horizontally(230);
        let marks = self.marks();
        self.diagram_panel(&left, &marks)?;
        let arrow = self.shapes_panel(&right, &marks)?;
        let entries = self.legend_entries(&marks, arrow);
        legend(&middle.margin(60, 0, 4, 4), &entries, 1)?;
        Ok(())
    }
}

impl DiagramChart<'_> {
    fn diagram_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        marks: &[Mark],
    ) -> Result<(), Failure>
    where
        DB::ErrorType: 'static,
    {
        let data = self.data;
        let scale = self.view.scale;
        let xs = padded(
            data.branches
                .iter()
                .flat_map(|b| b.parameter.iter().copied()),
        );
        let ys = padded(
            data.branches
                .iter()
                .flat_map(|b| (0..b.parameter.len()).map(move |i| self.value(b, i)))
                .chain(marks.iter().map(|m| m.value)),
        );
        let mut chart = ChartBuilder::on(area)
            .caption("bifurcation diagram", ("sans-serif", TITLE_FONT))
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(xs.0..xs.1, ys.0..ys.1)?;
        draw_grid(
            &mut chart,
            parameter_label(&data.parameter_name, scale),
            measure_label(self.measure, scale),
            (xs.1 - xs.0, ys.1 - ys.0),
        )?;
        for (bi, b) in data.branches.iter().enumerate() {
            let mut start = 0;
            while start + 1 < b.parameter.len() {
                let stable = b.stable[start + 1];
                let mut end = start + 1;
                while end + 1 < b.parameter.len() && b.stable[end + 1] == stable {
                    end += 1;
                }
                let pts: Vec<(f64, f64)> = (start..=end)
                    .map(|i| (b.parameter[i], self.value(b, i)))
                    .collect();
                let stroke = if stable {
                    Stroke::Solid
                } else {
                    Stroke::Dashed
                };
                line(&mut chart, pts, colour(bi), stroke, 2)?;
                start = end;
            }
        }
        frame(chart.plotting_area())?;
        let tags: Vec<Tag> = marks
            .iter()
            .map(|m| Tag {
                text: m.tag.clone(),
                at: (m.parameter, m.value),
                glyph: Some(m.glyph),
            })
            .collect();
        draw_tags(&mut chart, &tags, &[])
    }

    /// The shapes at the marks, to scale, tagged at their tips, with the
    /// tip load as an arrow; whether an arrow was drawn.
    fn shapes_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        marks: &[Mark],
    ) -> Result<bool, Failure>
    where
        DB::ErrorType: 'static,
    {
        let data = self.data;
        let shown: Vec<(&Mark, &Vec<[f64; 3]>)> = marks
            .iter()
            .filter_map(|m| {
                let b = data.branches.get(m.branch)?;
                Some((m, b.shapes.get(m.index)?))
            })
            .filter(|(_, s)| !s.is_empty())
            .collect();
        let zs = padded(shown.iter().flat_map(|(_, s)| s.iter().map(|r| r[2])));
        let hs = padded(shown.iter().flat_map(|(_, s)| s.iter().map(|r| -r[0])));
        let (x_unit, h_unit) = match self.view.scale {
            Scale::Nondimensional => ("z/L", "height −x/L"),
            Scale::Dimensional => ("z (m)", "height −x (m)"),
        };
        let inner = area
            .margin(12, 0, 0, 0)
            .titled("rod shapes (to scale)", ("sans-serif", TITLE_FONT))?;
        // Room for the load arrows at the tips where the load is known.
        let arrows = self.view.load != LoadRule::Unknown;
        let (mut chart, zs, hs) = shape_chart(&inner, zs, hs, arrows)?;
        draw_grid(&mut chart, x_unit, h_unit, (zs.1 - zs.0, hs.1 - hs.0))?;
        for (m, s) in &shown {
            let pts = s.iter().map(|r| (r[2], -r[0])).collect();
            line(&mut chart, pts, colour(m.branch), Stroke::Solid, 2)?;
        }
        frame(chart.plotting_area())?;
        let (bx, by) = area.get_base_pixel();
        let mut arrows = vec![];
        for (m, s) in &shown {
            let Some(f) = self.view.load.at(m.parameter) else {
                continue;
            };
            // In the picture's plane: z to the right, height (−x) up.
            let (dz, dh) = (f[2], -f[0]);
            let size = dz.hypot(dh);
            if size <= 1e-9 * f.iter().fold(0.0f64, |a, v| a.max(v.abs())) || size == 0.0 {
                continue;
            }
            let tip = s[s.len() - 1];
            let from = chart.backend_coord(&(tip[2], -tip[0]));
            let d = ((dz / size * ARROW) as i32, (-dh / size * ARROW) as i32);
            let b = chart_style::arrow(area, (from.0 - bx, from.1 - by), d, LOAD)?;
            arrows.push(PixelBox {
                x: b.x + bx,
                y: b.y + by,
                ..b
            });
        }
        draw_tags(&mut chart, &shape_tags(&shown), &arrows)?;
        Ok(!arrows.is_empty())
    }
}

/// One tag per distinct shape at its tip: marks whose shapes coincide
/// (the two sides of one branch point, a trivial branch's end) share it.
fn shape_tags(shown: &[(&Mark, &Vec<[f64; 3]>)]) -> Vec<Tag> {
    let mut groups: Vec<(Vec<&str>, &Vec<[f64; 3]>)> = vec![];
    for (m, s) in shown {
        let same = |g: &&mut (Vec<&str>, &Vec<[f64; 3]>)| {
            g.1.len() == s.len()
                && g.1
                    .iter()
                    .zip(s.iter())
                    .all(|(a, b)| (0..3).all(|k| (a[k] - b[k]).abs() <= 1e-9))
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.0.push(&m.tag),
            None => groups.push((vec![&m.tag], s)),
        }
    }
    groups
        .into_iter()
        .map(|(tags, s)| {
            let t = s[s.len() - 1];
            Tag {
                text: tags.join(", "),
                at: (t[2], -t[0]),
                glyph: None,
            }
        })
        .collect()
}
