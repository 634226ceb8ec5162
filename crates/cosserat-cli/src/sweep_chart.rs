//! Sweep charts (plotters; PNG or SVG by the file extension):
//!
//! - contour maps of a value over two axes, one panel per family (the
//!   paper's Fig. 6 a, b), cells shaded by value, contour lines labelled,
//!   and the fitted curves B̄3 = Ω B̄1^(−ι) of eq. (61) dashed;
//! - reach envelopes in the (ẑ, −x̂) plane (the paper's Fig. 7: height
//!   above the clamp against horizontal reach), one curve per value of the
//!   other axis, with the classical limits of eqs. (2)–(4): Rb = π/2
//!   (height), Rdef = 2 (horizontal), and the level reach μ ≈ 1.81 as a dot.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use cosserat::study::sweep::contour::{GridField, PowerFit};

type Chart = Result<(), Box<dyn std::error::Error>>;

const COLORS: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

/// μ of eq. (4): the farthest level reach of the planar straight
/// cantilever (the paper quotes 1.81).
pub const MU: f64 = 1.81;

/// Draws `panels` side by side on a PNG or SVG backend chosen by `out`'s
/// extension.
fn draw_panels(
    out: &Path,
    count: usize,
    panel: &dyn Fn(&DrawingArea<SVGBackend, Shift>, usize) -> Chart,
    bitmap: &dyn Fn(&DrawingArea<BitMapBackend, Shift>, usize) -> Chart,
) -> Chart {
    crate::plot::register_font();
    let size = (620 * count as u32, 600);
    if out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"))
    {
        let root = SVGBackend::new(out, size).into_drawing_area();
        root.fill(&WHITE)?;
        for (k, area) in root.split_evenly((1, count)).iter().enumerate() {
            panel(area, k)?;
        }
        root.present()?;
    } else {
        let root = BitMapBackend::new(out, size).into_drawing_area();
        root.fill(&WHITE)?;
        for (k, area) in root.split_evenly((1, count)).iter().enumerate() {
            bitmap(area, k)?;
        }
        root.present()?;
    }
    Ok(())
}

/// One contour panel of a map.
pub struct MapPanel<'a> {
    /// Title.
    pub title: String,
    /// The field.
    pub field: GridField<'a>,
    /// The fit drawn dashed, if any.
    pub fit: Option<&'a PowerFit>,
}

/// Contour maps of several fields over the same axes (`x_name`,
/// `y_name`), with a shared colour scale.
pub fn contour_maps(out: &Path, x_name: &str, y_name: &str, panels: &[MapPanel]) -> Chart {
    let range = panels
        .iter()
        .filter_map(|p| p.field.range())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, r| {
            (a.0.min(r.0), a.1.max(r.1))
        });
    let svg = |a: &DrawingArea<SVGBackend, Shift>, k: usize| {
        map_panel(a, x_name, y_name, &panels[k], range)
    };
    let png = |a: &DrawingArea<BitMapBackend, Shift>, k: usize| {
        map_panel(a, x_name, y_name, &panels[k], range)
    };
    draw_panels(out, panels.len(), &svg, &png)
}

/// A blue-to-yellow shade of t ∈ [0, 1].
fn shade(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let mix = |a: f64, b: f64| (a + (b - a) * t) as u8;
    RGBColor(mix(40.0, 250.0), mix(60.0, 230.0), mix(160.0, 90.0))
}

fn map_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    x_name: &str,
    y_name: &str,
    panel: &MapPanel,
    (lo, hi): (f64, f64),
) -> Chart
where
    DB::ErrorType: 'static,
{
    let f = &panel.field;
    let (x0, x1) = (f.x[0], f.x[f.x.len() - 1]);
    let (y0, y1) = (f.y[0], f.y[f.y.len() - 1]);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(x0..x1.max(x0 + 1e-9), y0..y1.max(y0 + 1e-9))?;
    chart
        .configure_mesh()
        .x_desc(x_name)
        .y_desc(y_name)
        .disable_mesh()
        .draw()?;
    // Cells: each grid value shades the rectangle around its node.
    let mid = |v: &[f64], i: usize, up: bool| {
        let j = if up {
            (i + 1).min(v.len() - 1)
        } else {
            i.saturating_sub(1)
        };
        0.5 * (v[i] + v[j])
    };
    let cells = (0..f.x.len()).flat_map(|i| (0..f.y.len()).map(move |j| (i, j)));
    chart.draw_series(cells.filter_map(|(i, j)| {
        let v = f.z[i * f.y.len() + j];
        v.is_finite().then(|| {
            Rectangle::new(
                [
                    (mid(f.x, i, false), mid(f.y, j, false)),
                    (mid(f.x, i, true), mid(f.y, j, true)),
                ],
                shade((v - lo) / (hi - lo).max(1e-12)).filled(),
            )
        })
    }))?;
    for level in f.levels(8) {
        let segments = f.contour(level);
        chart.draw_series(
            segments
                .iter()
                .map(|s| PathElement::new(s.to_vec(), BLACK.stroke_width(1))),
        )?;
        if let Some(s) = segments.get(segments.len() / 2) {
            chart.draw_series(std::iter::once(Text::new(
                format!("{level:.2}"),
                s[0],
                ("sans-serif", 13),
            )))?;
        }
    }
    if let Some(fit) = panel.fit {
        for omega in fit.contours.iter().map(|c| c.omega) {
            let pts: Vec<(f64, f64)> = (0..=100)
                .map(|k| x0 + (x1 - x0) * f64::from(k) / 100.0)
                .map(|x| (x, omega * x.powf(-fit.iota)))
                .filter(|(_, y)| (y0..=y1).contains(y))
                .collect();
            chart.draw_series(DashedLineSeries::new(pts, 6, 5, WHITE.stroke_width(2)))?;
        }
    }
    Ok(())
}

/// One curve of an envelope chart: a label and tip points (ẑ, height).
pub type Envelope = (String, Vec<(f64, f64)>);

/// Reach envelopes, one panel per entry of `panels` (title, curves).
pub fn envelopes(out: &Path, panels: &[(String, Vec<Envelope>)]) -> Chart {
    let points = || {
        panels
            .iter()
            .flat_map(|p| p.1.iter().flat_map(|c| c.1.iter()))
    };
    let z_max = points().fold(2.2f64, |m, (z, _)| m.max(z.abs())) * 1.05;
    let low = points().fold(0.0f64, |m, (_, h)| m.min(*h)) * 1.05;
    let high = points().fold(2.5f64, |m, (_, h)| m.max(*h)) * 1.05;
    let frame = (z_max, low, high);
    let svg = |a: &DrawingArea<SVGBackend, Shift>, k: usize| envelope_panel(a, &panels[k], frame);
    let png =
        |a: &DrawingArea<BitMapBackend, Shift>, k: usize| envelope_panel(a, &panels[k], frame);
    draw_panels(out, panels.len(), &svg, &png)
}

fn envelope_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (title, curves): &(String, Vec<Envelope>),
    (extent, low, high): (f64, f64, f64),
) -> Chart
where
    DB::ErrorType: 'static,
{
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..extent, low..high)?;
    chart
        .configure_mesh()
        .x_desc("ẑ = z √(F/B2)")
        .y_desc("−x̂ (height above the clamp)")
        .draw()?;
    let grey = RGBColor(120, 120, 120);
    let rb = std::f64::consts::FRAC_PI_2;
    chart
        .draw_series(DashedLineSeries::new(
            vec![(0.0, rb), (extent, rb)],
            6,
            5,
            grey.stroke_width(1),
        ))?
        .label("Rb = π/2 (2)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], grey));
    chart
        .draw_series(DashedLineSeries::new(
            vec![(2.0, low), (2.0, high)],
            2,
            4,
            grey.stroke_width(1),
        ))?
        .label("Rdef = 2 (3)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], grey));
    chart
        .draw_series(std::iter::once(Circle::new((MU, 0.0), 5, RED.filled())))?
        .label("μ ≈ 1.81 (4)")
        .legend(|(x, y)| Circle::new((x + 8, y), 4, RED.filled()));
    for (k, (label, points)) in curves.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        chart
            .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))?
            .label(label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
        chart.draw_series(points.iter().map(|p| Circle::new(*p, 3, color.filled())))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()?;
    Ok(())
}
