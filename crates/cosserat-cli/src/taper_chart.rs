//! The chart of a tapered-arm study (`[arm] taper`; plotters, PNG or SVG by
//! the file extension): a) the optimal section A(s̄) against the prismatic
//! A ≡ 1 (same volume) and the lower bound; b) the design's loaded (solid)
//! and unloaded (dashed) shapes to scale in the reach's units √(B2/F),
//! height −x against z, the loaded shape drawn with a width that follows
//! the section.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart_style::{
    colour, draw_grid, frame, line, padded, render, shape_chart, Failure, Figure, Stroke,
    TITLE_FONT,
};
use cosserat::study::arm::TaperedOptimum;

/// The figure of one tapered optimum.
pub struct TaperChart<'a> {
    /// The optimum.
    pub optimum: &'a TaperedOptimum,
}

/// Draws the chart to `out` (SVG for `.svg`, else PNG).
pub fn draw_taper(chart: &TaperChart, out: &Path) -> Result<(), Failure> {
    render(chart, out)
}

impl Figure for TaperChart<'_> {
    fn size(&self) -> (u32, u32) {
        (1500, 650)
    }

    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), Failure>
    where
        DB::ErrorType: 'static,
    {
        let (left, right) = root.split_horizontally(600);
        section_panel(&left, self.optimum)?;
        shape_panel(&right, self.optimum)
    }
}

/// a) A(s̄), the prismatic section and A_min.
fn section_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    o: &TaperedOptimum,
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    let (title, plot) = area.split_vertically(40);
    title.draw_text(
        "a) section A(s̄), unit volume",
        &("sans-serif", TITLE_FONT).into_font().into(),
        (20, 10),
    )?;
    let top = o.section.values().iter().fold(1.0f64, |a, v| a.max(*v));
    let mut chart = ChartBuilder::on(&plot)
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, 0.0..(1.1 * top))?;
    draw_grid(
        &mut chart,
        "arc length s̄ = s/L",
        "section A / prismatic section",
        (1.0, 1.1 * top),
    )?;
    let n = o.section_at_points.len().max(2) - 1;
    let profile: Vec<(f64, f64)> = o
        .section_at_points
        .iter()
        .enumerate()
        .map(|(i, a)| (i as f64 / n as f64, *a))
        .collect();
    line(&mut chart, profile, colour(0), Stroke::Solid, 3)?;
    line(
        &mut chart,
        vec![(0.0, 1.0), (1.0, 1.0)],
        colour(1),
        Stroke::Dashed,
        2,
    )?;
    let min = o.min_section;
    line(
        &mut chart,
        vec![(0.0, min), (1.0, min)],
        colour(2),
        Stroke::Dotted,
        2,
    )?;
    for (s, a) in o.section.knots().iter().zip(o.section.values()) {
        chart.draw_series(std::iter::once(Circle::new(
            (*s, *a),
            4,
            colour(0).filled(),
        )))?;
    }
    frame(chart.plotting_area())
}

/// b) The loaded and unloaded shapes to scale.
fn shape_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    o: &TaperedOptimum,
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    let (title, plot) = area.split_vertically(40);
    title.draw_text(
        &format!(
            "b) loaded (solid, width ∝ A) and unloaded (dashed) shapes: R* = {:.4} (prismatic {:.4})",
            o.design.reach, o.prismatic.reach
        ),
        &("sans-serif", TITLE_FONT).into_font().into(),
        (20, 10),
    )?;
    let all = || o.loaded_shape.iter().chain(&o.unloaded_shape);
    let zs = padded(all().map(|r| r[2]));
    let hs = padded(all().map(|r| -r[0]));
    let (mut chart, zs, hs) = shape_chart(&plot, zs, hs, false)?;
    draw_grid(
        &mut chart,
        "z / √(B₂/F)",
        "height −x / √(B₂/F)",
        (zs.1 - zs.0, hs.1 - hs.0),
    )?;
    let unloaded: Vec<(f64, f64)> = o.unloaded_shape.iter().map(|r| (r[2], -r[0])).collect();
    line(&mut chart, unloaded, colour(1), Stroke::Dashed, 2)?;
    for (w, a) in o.loaded_shape.windows(2).zip(&o.section_at_points) {
        let width = (2.0 + 6.0 * a).round() as u32;
        let pts = w.iter().map(|r| (r[2], -r[0])).collect();
        line(&mut chart, pts, colour(0), Stroke::Solid, width)?;
    }
    frame(chart.plotting_area())
}
