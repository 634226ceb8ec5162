//! What every chart of the command has in common, so that each one is fit
//! for a paper: one colour-blind-safe palette, axis ranges that are never
//! degenerate, tick labels with the digits the spacing needs, equal aspect
//! for pictures of rods, a boxed plotting area, legends drawn in their own
//! area (never over the data), colour bars wherever colour encodes a
//! value, labels of marked points nudged apart so that none overlaps
//! another, and the output format (PNG or SVG) chosen by the extension.
//!
//! The label placement is written here: plotters places no labels, and a
//! greedy search over candidate offsets is enough for the few special
//! points of a diagram (a force-directed or integer-programming placement
//! would be overkill).

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// What a chart's drawing fails with.
pub type Failure = Box<dyn std::error::Error>;

/// Okabe–Ito colours (distinguishable with the common colour-vision
/// deficiencies), black left for markers and frames.
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(120, 120, 120),
];

/// The colour of series `k`.
pub fn colour(k: usize) -> RGBColor {
    PALETTE[k % PALETTE.len()]
}

/// The grey of legend boxes (tests find legends by it).
pub const LEGEND_BORDER: RGBColor = RGBColor(128, 128, 128);

/// Font sizes (px).
pub const TITLE_FONT: u32 = 20;
/// Tick labels and legend text.
pub const TEXT_FONT: u32 = 15;
/// Axis titles.
pub const AXIS_FONT: u32 = 17;

/// A figure drawn on any plotters backend.
pub trait Figure {
    /// Pixels (width, height).
    fn size(&self) -> (u32, u32);
    /// Draws the whole figure on `root`.
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), Failure>
    where
        DB::ErrorType: 'static;
}

/// Renders `figure` to `out`: SVG for a `.svg` extension (any case), PNG
/// otherwise.
pub fn render(figure: &impl Figure, out: &Path) -> Result<(), Failure> {
    crate::plot::register_font();
    let svg = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    if svg {
        let root = SVGBackend::new(out, figure.size()).into_drawing_area();
        root.fill(&WHITE)?;
        figure.draw_on(&root)?;
        root.present()?;
    } else {
        let root = BitMapBackend::new(out, figure.size()).into_drawing_area();
        root.fill(&WHITE)?;
        figure.draw_on(&root)?;
        root.present()?;
    }
    Ok(())
}

/// The range of the finite `values`, padded by 5 % on each side; a
/// constant (or nearly constant) series gets ±max(10 % of its value, 1e-3
/// of 1) around it, an empty one [0, 1] — never a zero-width axis, whose
/// ticks all read the same number.
pub fn padded(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        return (0.0, 1.0);
    }
    let mid = 0.5 * (lo + hi);
    let scale = lo.abs().max(hi.abs());
    if hi - lo <= 1e-9 * scale.max(1.0) {
        let half = (0.1 * mid.abs()).max(1e-3);
        return (mid - half, mid + half);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// Widens the ranges `x` and `y` (each about its centre) so that a
/// plotting area of `pixels` (width, height) shows one data unit as the
/// same number of pixels on both axes: shapes keep their true form.
pub fn equal_aspect(x: (f64, f64), y: (f64, f64), pixels: (u32, u32)) -> ((f64, f64), (f64, f64)) {
    let (w, h) = (f64::from(pixels.0.max(1)), f64::from(pixels.1.max(1)));
    let per_pixel = ((x.1 - x.0) / w).max((y.1 - y.0) / h);
    let widen = |r: (f64, f64), px: f64| {
        let mid = 0.5 * (r.0 + r.1);
        let half = 0.5 * per_pixel * px;
        (mid - half, mid + half)
    };
    (widen(x, w), widen(y, h))
}

/// Length of a load arrow (pixels): a direction, not a magnitude.
pub const ARROW: f64 = 42.0;

/// A chart of rod shapes to scale on `area`: the ranges `zs` × `hs`
/// widened to equal aspect on its plotting pixels, and by room for the
/// load arrows at the tips when `arrows`. Built twice — first to learn the
/// plotting area's pixels, then with the final ranges (building draws
/// nothing). Returns the chart and its ranges.
pub fn shape_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    zs: (f64, f64),
    hs: (f64, f64),
    arrows: bool,
) -> Result<ShapeChart<'_, DB>, Failure>
where
    DB::ErrorType: 'static,
{
    let build = |zs: (f64, f64), hs: (f64, f64)| {
        ChartBuilder::on(area)
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(zs.0..zs.1, hs.0..hs.1)
    };
    let pixels = build(zs, hs)?.plotting_area().dim_in_pixel();
    let (zs, hs) = equal_aspect(zs, hs, pixels);
    let (zs, hs) = if arrows {
        let room = (ARROW + 12.0) * (zs.1 - zs.0) / f64::from(pixels.0.max(1));
        equal_aspect(
            (zs.0 - room, zs.1 + room),
            (hs.0 - room, hs.1 + room),
            pixels,
        )
    } else {
        (zs, hs)
    };
    Ok((build(zs, hs)?, zs, hs))
}

/// A shape chart and its ranges (z, height).
pub type ShapeChart<'a, DB> = (Chart2d<'a, DB>, (f64, f64), (f64, f64));

/// A tick label with the decimals its axis needs: `span` is the axis
/// length in data units (scientific notation beyond 1e5 or below 1e-4).
pub fn tick(v: f64, span: f64) -> String {
    // The 1-2-5 step plotters chooses for about ten ticks.
    let rough = (span.abs() / 10.0).max(f64::MIN_POSITIVE);
    let decade = 10f64.powf(rough.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|s| *s >= rough * (1.0 - 1e-9))
        .unwrap_or(10.0 * decade);
    if v.abs() >= 1e5 || step < 1e-4 {
        // Zero among scientific ticks is a plain 0.
        return if v.abs() < 1e-3 * step {
            "0".into()
        } else {
            format!("{v:.2e}")
        };
    }
    let decimals = (-step.log10() - 1e-9).ceil().clamp(0.0, 6.0) as usize;
    let s = format!("{v:.decimals$}");
    // "-0.00" is zero.
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

/// Draws a frame around a chart's plotting area (the box the data lives
/// in; tests find it as the black unfilled rectangle).
pub fn frame<DB: DrawingBackend, CT: plotters::coord::CoordTranslate>(
    plotting: &DrawingArea<DB, CT>,
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    let area = plotting.strip_coord_spec();
    let (w, h) = area.dim_in_pixel();
    area.draw(&Rectangle::new(
        [(0, 0), (w as i32 - 1, h as i32 - 1)],
        BLACK.stroke_width(1),
    ))?;
    Ok(())
}

/// A pixel box (x, y top-left; w, h size).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelBox {
    /// Left.
    pub x: i32,
    /// Top.
    pub y: i32,
    /// Width.
    pub w: i32,
    /// Height.
    pub h: i32,
}

impl PixelBox {
    /// Whether the two boxes share any pixel.
    pub fn overlaps(&self, o: &PixelBox) -> bool {
        self.x < o.x + o.w && o.x < self.x + self.w && self.y < o.y + o.h && o.y < self.y + self.h
    }

    /// Whether `o` lies inside this box.
    fn contains(&self, o: &PixelBox) -> bool {
        o.x >= self.x
            && o.y >= self.y
            && o.x + o.w <= self.x + self.w
            && o.y + o.h <= self.y + self.h
    }
}

/// Pixels kept between a label and anything else.
const GAP: i32 = 3;
/// Half the size of a point marker.
const MARKER: i32 = 7;

/// Boxes for labels of sizes `sizes` at the points `anchors` (pixels):
/// each label in turn takes the first candidate position — beside its
/// point on one of eight sides, at growing distances — whose box, widened
/// by a small gap, overlaps neither an earlier label nor any point's
/// marker or `obstacles` and lies within `bounds` (if no candidate fits inside, the
/// nearest free one outside). The boxes returned are pairwise disjoint.
pub fn place_labels(
    anchors: &[(i32, i32)],
    sizes: &[(u32, u32)],
    bounds: PixelBox,
    obstacles: &[PixelBox],
) -> Vec<PixelBox> {
    let mut markers: Vec<PixelBox> = anchors
        .iter()
        .map(|&(x, y)| PixelBox {
            x: x - MARKER,
            y: y - MARKER,
            w: 2 * MARKER,
            h: 2 * MARKER,
        })
        .collect();
    markers.extend_from_slice(obstacles);
    let mut placed: Vec<PixelBox> = Vec::with_capacity(anchors.len());
    for (&(x, y), &(w, h)) in anchors.iter().zip(sizes) {
        let (w, h) = (w as i32, h as i32);
        let free = |b: &PixelBox| {
            let wide = PixelBox {
                x: b.x - GAP,
                y: b.y - GAP,
                w: b.w + 2 * GAP,
                h: b.h + 2 * GAP,
            };
            !placed.iter().chain(&markers).any(|o| wide.overlaps(o))
        };
        let candidates = (0..60).flat_map(|ring| {
            let d = MARKER + GAP + 10 * ring;
            [
                (d, -h - d),
                (d, d),
                (-w - d, -h - d),
                (-w - d, d),
                (-w / 2, -h - d),
                (-w / 2, d),
                (d, -h / 2),
                (-w - d, -h / 2),
            ]
            .map(|(dx, dy)| PixelBox {
                x: x + dx,
                y: y + dy,
                w,
                h,
            })
        });
        let mut outside = None;
        let mut chosen = None;
        for b in candidates {
            if !free(&b) {
                continue;
            }
            if bounds.contains(&b) {
                chosen = Some(b);
                break;
            }
            outside.get_or_insert(b);
        }
        // 480 candidates always hold a free one for a handful of labels;
        // the last resort stacks below everything placed.
        let b = chosen.or(outside).unwrap_or_else(|| {
            let bottom = placed
                .iter()
                .chain(&markers)
                .map(|b| b.y + b.h)
                .max()
                .unwrap_or(y);
            PixelBox {
                x,
                y: bottom + 2 * GAP,
                w,
                h,
            }
        });
        placed.push(b);
    }
    placed
}

/// A chart of two f64 axes.
pub type Chart2d<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A tag to draw: its text, where (data coordinates), and the marker
/// drawn there (none on the shapes, tagged at their tips).
pub struct Tag {
    /// The text.
    pub text: String,
    /// Where.
    pub at: (f64, f64),
    /// The marker, if any.
    pub glyph: Option<Glyph>,
}

/// The grid every Cartesian chart draws: axis descriptions, tick labels
/// with the digits their spacing needs (`spans`: the axes' lengths, see
/// [`tick`]), faint major lines and no minor ones.
pub fn draw_grid<DB: DrawingBackend>(
    chart: &mut Chart2d<DB>,
    x_desc: impl Into<String>,
    y_desc: impl Into<String>,
    spans: (f64, f64),
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|v| tick(*v, spans.0))
        .y_label_formatter(&|v| tick(*v, spans.1))
        .label_style(("sans-serif", TEXT_FONT))
        .axis_desc_style(("sans-serif", AXIS_FONT))
        .light_line_style(WHITE)
        .bold_line_style(BLACK.mix(0.12))
        .draw()?;
    Ok(())
}

/// Draws `tags` (markers, then their texts placed apart and clear of the
/// markers and `obstacles`, absolute pixels) on `chart`.
pub fn draw_tags<DB: DrawingBackend>(
    chart: &mut Chart2d<DB>,
    tags: &[Tag],
    obstacles: &[PixelBox],
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    for t in tags {
        match t.glyph {
            Some(Glyph::Dot(c)) => {
                chart.draw_series(std::iter::once(Circle::new(t.at, 6, c.filled())))?;
            }
            Some(Glyph::Square(c)) => {
                let square =
                    EmptyElement::at(t.at) + Rectangle::new([(-6, -6), (6, 6)], c.stroke_width(2));
                chart.draw_series(std::iter::once(square))?;
            }
            Some(Glyph::Ring(c) | Glyph::Line(c, _) | Glyph::Arrow(c)) => {
                chart.draw_series(std::iter::once(Circle::new(t.at, 6, c.stroke_width(2))))?;
            }
            None => {}
        }
    }
    let font: TextStyle = ("sans-serif", 16).into_font().into();
    let area = chart.plotting_area();
    let (x0, y0) = area.get_base_pixel();
    let (w, h) = area.dim_in_pixel();
    let anchors: Vec<(i32, i32)> = tags.iter().map(|t| chart.backend_coord(&t.at)).collect();
    let sizes = tags
        .iter()
        .map(|t| area.estimate_text_size(&t.text, &font))
        .collect::<Result<Vec<_>, _>>()?;
    let bounds = PixelBox {
        x: x0,
        y: y0,
        w: w as i32,
        h: h as i32,
    };
    let boxes = place_labels(&anchors, &sizes, bounds, obstacles);
    for ((t, anchor), b) in tags.iter().zip(&anchors).zip(&boxes) {
        let offset = (b.x - anchor.0, b.y - anchor.1);
        if offset.0.abs().max(offset.1.abs()) > 24 {
            let centre = (offset.0 + b.w / 2, offset.1 + b.h / 2);
            let leader =
                EmptyElement::at(t.at) + PathElement::new(vec![(0, 0), centre], BLACK.mix(0.4));
            chart.draw_series(std::iter::once(leader))?;
        }
        let text = EmptyElement::at(t.at) + Text::new(t.text.clone(), offset, font.clone());
        chart.draw_series(std::iter::once(text))?;
    }
    Ok(())
}

/// How a line is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stroke {
    /// Solid.
    Solid,
    /// Dashed.
    Dashed,
    /// Dotted.
    Dotted,
}

/// Draws `points` as a line of `stroke`.
pub fn line<DB: DrawingBackend>(
    chart: &mut Chart2d<DB>,
    points: Vec<(f64, f64)>,
    colour: RGBColor,
    stroke: Stroke,
    width: u32,
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    let style = colour.stroke_width(width);
    match stroke {
        Stroke::Solid => chart
            .draw_series(LineSeries::new(points, style))
            .map(|_| ())?,
        Stroke::Dashed => chart
            .draw_series(DashedLineSeries::new(points, 9, 6, style))
            .map(|_| ())?,
        Stroke::Dotted => chart
            .draw_series(DashedLineSeries::new(points, 2, 4, style))
            .map(|_| ())?,
    }
    Ok(())
}

/// The mark of a legend entry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Glyph {
    /// A line.
    Line(RGBColor, Stroke),
    /// A filled disc.
    Dot(RGBColor),
    /// A ring (open circle).
    Ring(RGBColor),
    /// An open square.
    Square(RGBColor),
    /// An arrow (a load).
    Arrow(RGBColor),
}

impl Glyph {
    /// Draws the glyph in the 24 × 14 box at (x, y) of `area`.
    fn draw<DB: DrawingBackend>(
        self,
        area: &DrawingArea<DB, Shift>,
        (x, y): (i32, i32),
    ) -> Result<(), Failure>
    where
        DB::ErrorType: 'static,
    {
        let mid = (x + 12, y + 7);
        match self {
            Glyph::Line(c, stroke) => {
                let style = c.stroke_width(3);
                let segments: Vec<(i32, i32)> = match stroke {
                    Stroke::Solid => vec![(0, 24)],
                    Stroke::Dashed => vec![(0, 9), (15, 24)],
                    Stroke::Dotted => vec![(0, 2), (7, 9), (14, 16), (21, 23)],
                };
                for (a, b) in segments {
                    area.draw(&PathElement::new(
                        vec![(x + a, mid.1), (x + b, mid.1)],
                        style,
                    ))?;
                }
            }
            Glyph::Dot(c) => area.draw(&Circle::new(mid, 5, c.filled()))?,
            Glyph::Ring(c) => area.draw(&Circle::new(mid, 6, c.stroke_width(2)))?,
            Glyph::Square(c) => area.draw(&Rectangle::new(
                [(mid.0 - 5, mid.1 - 5), (mid.0 + 5, mid.1 + 5)],
                c.stroke_width(2),
            ))?,
            Glyph::Arrow(c) => {
                arrow(area, (x, mid.1), (24, 0), c)?;
            }
        }
        Ok(())
    }
}

/// Draws an arrow from `from` by `(dx, dy)` pixels, head at the end;
/// returns the box it covers (pixels of `area`).
pub fn arrow<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    from: (i32, i32),
    (dx, dy): (i32, i32),
    c: RGBColor,
) -> Result<PixelBox, Failure>
where
    DB::ErrorType: 'static,
{
    let to = (from.0 + dx, from.1 + dy);
    area.draw(&PathElement::new(vec![from, to], c.stroke_width(2)))?;
    let len = f64::from(dx).hypot(f64::from(dy)).max(1.0);
    let (ux, uy) = (f64::from(dx) / len, f64::from(dy) / len);
    let (head, half) = (9.0, 4.5);
    let base = (f64::from(to.0) - head * ux, f64::from(to.1) - head * uy);
    let corner = |s: f64| {
        (
            (base.0 - s * half * uy) as i32,
            (base.1 + s * half * ux) as i32,
        )
    };
    area.draw(&Polygon::new(
        vec![to, corner(1.0), corner(-1.0)],
        c.filled(),
    ))?;
    let (x0, x1) = (from.0.min(to.0) - 5, from.0.max(to.0) + 5);
    let (y0, y1) = (from.1.min(to.1) - 5, from.1.max(to.1) + 5);
    Ok(PixelBox {
        x: x0,
        y: y0,
        w: x1 - x0,
        h: y1 - y0,
    })
}

/// One legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct LegendEntry {
    /// Its mark.
    pub glyph: Glyph,
    /// Its text.
    pub text: String,
}

impl LegendEntry {
    /// An entry.
    pub fn new(glyph: Glyph, text: impl Into<String>) -> LegendEntry {
        LegendEntry {
            glyph,
            text: text.into(),
        }
    }
}

/// Draws `entries` in a grey box at the top left of `area` (its own area,
/// beside or above the plot, never over the data), `columns` entries per
/// row; returns the box.
pub fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    columns: usize,
) -> Result<PixelBox, Failure>
where
    DB::ErrorType: 'static,
{
    let font: TextStyle = ("sans-serif", TEXT_FONT).into_font().into();
    let columns = columns.max(1);
    let widths = entries
        .iter()
        .map(|e| area.estimate_text_size(&e.text, &font).map(|s| s.0 as i32))
        .collect::<Result<Vec<_>, _>>()?;
    let cell = widths.iter().copied().max().unwrap_or(0) + 24 + 8 + 16;
    let rows = entries.len().div_ceil(columns) as i32;
    let (pad, row) = (8, 22);
    let used = columns.min(entries.len()).max(1) as i32;
    let (w, h) = area.dim_in_pixel();
    let b = PixelBox {
        x: 2,
        y: 2,
        w: (cell * used + 2 * pad - 16).min(w as i32 - 4),
        h: (row * rows + 2 * pad - 6).min(h as i32 - 4),
    };
    area.draw(&Rectangle::new(
        [(b.x, b.y), (b.x + b.w, b.y + b.h)],
        WHITE.filled(),
    ))?;
    area.draw(&Rectangle::new(
        [(b.x, b.y), (b.x + b.w, b.y + b.h)],
        LEGEND_BORDER.stroke_width(1),
    ))?;
    for (k, e) in entries.iter().enumerate() {
        let x = b.x + pad + cell * (k % columns) as i32;
        let y = b.y + pad + row * (k / columns) as i32;
        e.glyph.draw(area, (x, y))?;
        area.draw(&Text::new(e.text.as_str(), (x + 32, y), font.clone()))?;
    }
    Ok(b)
}

/// Draws a vertical colour bar for values `range` in `area` (its own area
/// beside the map): the shades of `shade` (t ∈ [0, 1] from low to high),
/// ticks, and `title` along it.
pub fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (lo, hi): (f64, f64),
    shade: &dyn Fn(f64) -> RGBColor,
    title: &str,
    top: u32,
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    let (lo, hi) = if hi > lo {
        (lo, hi)
    } else {
        padded([lo, hi].into_iter())
    };
    let mut chart = ChartBuilder::on(area)
        .margin_top(top)
        .margin_bottom(15)
        .margin_left(8)
        .margin_right(8)
        .y_label_area_size(0)
        .right_y_label_area_size(58)
        .build_cartesian_2d(0.0..1.0, lo..hi)?;
    let span = hi - lo;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(6)
        .y_label_formatter(&|v| tick(*v, span))
        .label_style(("sans-serif", TEXT_FONT))
        .draw()?;
    let steps: i32 = 96;
    chart.draw_series((0..steps).map(|k| {
        let n = f64::from(steps);
        let a = lo + span * f64::from(k) / n;
        let b = lo + span * f64::from(k + 1) / n;
        let t = (f64::from(k) + 0.5) / n;
        Rectangle::new([(0.0, a), (1.0, b)], shade(t).filled())
    }))?;
    frame(chart.plotting_area())?;
    let (w, _) = area.dim_in_pixel();
    let font: TextStyle = ("sans-serif", TEXT_FONT).into_font().into();
    let text_w = area.estimate_text_size(title, &font)?.0 as i32;
    area.draw(&Text::new(
        title,
        (
            (w as i32 - text_w).max(0) / 2,
            top.saturating_sub(24) as i32,
        ),
        font,
    ))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds() -> PixelBox {
        PixelBox {
            x: 0,
            y: 0,
            w: 800,
            h: 600,
        }
    }

    #[test]
    fn labels_of_close_points_do_not_overlap() {
        // Five points within a few pixels, two of them identical (the
        // branch points of a pitchfork found from both sides).
        let anchors = [(400, 300), (400, 300), (404, 302), (398, 297), (410, 300)];
        let sizes = [(30, 16), (30, 16), (44, 16), (20, 16), (30, 16)];
        let boxes = place_labels(&anchors, &sizes, bounds(), &[]);
        for (i, a) in boxes.iter().enumerate() {
            assert!(bounds().contains(a), "{a:?}");
            for b in &boxes[i + 1..] {
                assert!(!a.overlaps(b), "{a:?} and {b:?}");
            }
            // No label covers a marker.
            for &(x, y) in &anchors {
                let m = PixelBox {
                    x: x - MARKER,
                    y: y - MARKER,
                    w: 2 * MARKER,
                    h: 2 * MARKER,
                };
                assert!(!a.overlaps(&m));
            }
        }
    }

    #[test]
    fn a_label_in_a_corner_stays_inside() {
        let boxes = place_labels(&[(795, 5)], &[(40, 16)], bounds(), &[]);
        assert!(bounds().contains(&boxes[0]), "{:?}", boxes[0]);
    }

    #[test]
    fn constant_series_get_a_padded_range() {
        let (lo, hi) = padded([2.0, 2.0].into_iter());
        assert!(lo < 2.0 && hi > 2.0 && hi - lo >= 0.2 - 1e-12);
        let (lo, hi) = padded([0.0, 1e-12].into_iter());
        assert!(hi - lo >= 2e-3 - 1e-15);
        assert_eq!(padded(std::iter::empty()), (0.0, 1.0));
        assert_eq!(padded([0.0, 1.0, f64::NAN].into_iter()), (-0.05, 1.05));
    }

    #[test]
    fn equal_aspect_has_one_scale() {
        let (x, y) = equal_aspect((0.0, 1.0), (-0.2, 0.2), (500, 400));
        let sx = 500.0 / (x.1 - x.0);
        let sy = 400.0 / (y.1 - y.0);
        assert!((sx / sy - 1.0).abs() < 1e-12);
        // Both ranges still contain the data.
        assert!(x.0 <= 0.0 && x.1 >= 1.0 && y.0 <= -0.2 && y.1 >= 0.2);
    }

    #[test]
    fn ticks_have_the_digits_of_their_spacing() {
        assert_eq!(tick(0.2, 1.0), "0.2");
        assert_eq!(tick(0.3, 0.9), "0.3");
        assert_eq!(tick(0.05, 0.5), "0.05");
        assert_eq!(tick(2.0, 10.0), "2");
        assert_eq!(tick(-0.0, 1.0), "0.0");
        assert_eq!(tick(0.0012, 0.005), "0.0012");
        assert_eq!(tick(3e-6, 1e-5), "3.00e-6");
        assert_eq!(tick(0.0, 1e-5), "0");
    }
}
