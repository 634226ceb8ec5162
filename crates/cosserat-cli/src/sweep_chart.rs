//! Sweep charts (plotters; PNG or SVG by the file extension):
//!
//! - contour maps of a value over two axes, one panel per family that has
//!   values (the paper's Fig. 6 a, b), cells shaded by value with a shared
//!   colour bar, contour lines labelled, and the fitted curves
//!   B̄3 = Ω B̄1^(−ι) of eq. (61) dashed; a family without any value gets
//!   a note above the maps instead of an empty panel;
//! - reach envelopes in the (ẑ, −x̂) plane (the paper's Fig. 7: height
//!   above the clamp against horizontal reach, to scale), one curve per
//!   value of the other axis, with the classical limits of eqs. (2)–(4):
//!   Rb = π/2 (height), Rdef = 2 (horizontal), and the level reach
//!   μ ≈ 1.81 as a dot; the legend in its own panel.
//!
//! Legends sit above or beside the data, never over it
//! ([`crate::chart_style`]).

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart_style::{
    colour, colour_bar, draw_grid, equal_aspect, frame, legend, line, padded, render, tick,
    Failure, Figure, Glyph, LegendEntry, Stroke, AXIS_FONT, TEXT_FONT, TITLE_FONT,
};
use cosserat::study::sweep::contour::{GridField, PowerFit};

type Chart = Result<(), Failure>;

/// μ of eq. (4): the farthest level reach of the planar straight
/// cantilever (the paper quotes 1.81).
pub const MU: f64 = 1.81;

/// The colour of the eq. (61) fit (visible on both ends of the shades).
const FIT: RGBColor = RGBColor(200, 0, 0);

/// One contour panel of a map.
pub struct MapPanel<'a> {
    /// Title.
    pub title: String,
    /// The field.
    pub field: GridField<'a>,
    /// The fit drawn dashed, if any.
    pub fit: Option<&'a PowerFit>,
}

/// What a set of contour maps shows, in the problem's terms.
pub struct MapLabels {
    /// The horizontal axis (the first swept key).
    pub x: String,
    /// The vertical axis (the second swept key).
    pub y: String,
    /// The mapped value (the colour bar's title).
    pub value: String,
    /// The legend text of the fitted curves, if any.
    pub fit: Option<String>,
    /// Notes above the maps (families without a panel, and why).
    pub notes: Vec<String>,
}

/// Contour maps of several fields over the same axes, with one colour
/// scale and its bar.
pub fn contour_maps(out: &Path, labels: &MapLabels, panels: &[MapPanel]) -> Chart {
    let range = panels
        .iter()
        .filter_map(|p| p.field.range())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, r| {
            (a.0.min(r.0), a.1.max(r.1))
        });
    let range = if range.0 <= range.1 {
        range
    } else {
        (0.0, 1.0)
    };
    render(
        &Maps {
            labels,
            panels,
            range,
        },
        out,
    )
}

struct Maps<'a> {
    labels: &'a MapLabels,
    panels: &'a [MapPanel<'a>],
    range: (f64, f64),
}

/// Width of a map panel and of the colour bar (pixels).
const PANEL: u32 = 640;
const BAR: u32 = 120;
/// Height of the legend strip above the maps.
const STRIP: u32 = 70;

impl Figure for Maps<'_> {
    fn size(&self) -> (u32, u32) {
        let notes = 22 * self.labels.notes.len() as u32;
        (PANEL * self.panels.len().max(1) as u32 + BAR, 680 + notes)
    }

    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Chart
    where
        DB::ErrorType: 'static,
    {
        let strip = STRIP + 22 * self.labels.notes.len() as u32;
        let (top, body) = root.split_vertically(strip);
        let mut entries = vec![LegendEntry::new(
            Glyph::Line(BLACK, Stroke::Solid),
            format!("contours of {} (labelled)", self.labels.value),
        )];
        if let Some(fit) = &self.labels.fit {
            entries.push(LegendEntry::new(
                Glyph::Line(FIT, Stroke::Dashed),
                fit.clone(),
            ));
        }
        let notes_at = legend(&top.margin(6, 0, 60, 0), &entries, 1)?;
        let font = ("sans-serif", TEXT_FONT).into_font();
        for (k, note) in self.labels.notes.iter().enumerate() {
            top.draw(&Text::new(
                note.as_str(),
                (
                    notes_at.x + 60,
                    notes_at.y + notes_at.h + 14 + 22 * k as i32,
                ),
                font.clone(),
            ))?;
        }
        let (maps, bar) = body.split_horizontally(PANEL * self.panels.len().max(1) as u32);
        for (area, panel) in maps
            .split_evenly((1, self.panels.len().max(1)))
            .iter()
            .zip(self.panels)
        {
            map_panel(area, self.labels, panel, self.range)?;
        }
        colour_bar(&bar, self.range, &shade, &self.labels.value, 53)
    }
}

/// A blue-to-yellow shade of t ∈ [0, 1].
pub fn shade(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let mix = |a: f64, b: f64| (a + (b - a) * t) as u8;
    RGBColor(mix(40.0, 250.0), mix(60.0, 230.0), mix(160.0, 90.0))
}

fn map_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    labels: &MapLabels,
    panel: &MapPanel,
    (lo, hi): (f64, f64),
) -> Chart
where
    DB::ErrorType: 'static,
{
    let f = &panel.field;
    // An axis of one value gets a padded range, never a zero-width one.
    let range = |v: &[f64]| {
        let (a, b) = (v[0], v[v.len() - 1]);
        if b > a {
            (a, b)
        } else {
            padded(v.iter().copied())
        }
    };
    let ((x0, x1), (y0, y1)) = (range(f.x), range(f.y));
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", TITLE_FONT))
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(65)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let (xspan, yspan) = (x1 - x0, y1 - y0);
    chart
        .configure_mesh()
        .x_desc(labels.x.as_str())
        .y_desc(labels.y.as_str())
        .x_label_formatter(&|v| tick(*v, xspan))
        .y_label_formatter(&|v| tick(*v, yspan))
        .label_style(("sans-serif", TEXT_FONT))
        .axis_desc_style(("sans-serif", AXIS_FONT))
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
                ("sans-serif", 14),
            )))?;
        }
    }
    if let Some(fit) = panel.fit {
        for omega in fit.contours.iter().map(|c| c.omega) {
            let pts: Vec<(f64, f64)> = (0..=200)
                .map(|k| x0 + (x1 - x0) * f64::from(k) / 200.0)
                .map(|x| (x, omega * x.powf(-fit.iota)))
                .filter(|(_, y)| (y0..=y1).contains(y))
                .collect();
            line(&mut chart, pts, FIT, Stroke::Dashed, 2)?;
        }
    }
    frame(chart.plotting_area())?;
    Ok(())
}

/// One curve of an envelope chart: a label and tip points (ẑ, height).
pub type Envelope = (String, Vec<(f64, f64)>);

/// What an envelope chart's axes show, in the problem's terms.
pub struct EnvelopeLabels {
    /// The horizontal axis (reach).
    pub reach: String,
    /// The vertical axis (height).
    pub height: String,
}

/// Reach envelopes, one panel per entry of `panels` (title, curves), to
/// scale and on one frame, with the legend beside them.
pub fn envelopes(out: &Path, labels: &EnvelopeLabels, panels: &[(String, Vec<Envelope>)]) -> Chart {
    render(&Envelopes { labels, panels }, out)
}

struct Envelopes<'a> {
    labels: &'a EnvelopeLabels,
    panels: &'a [(String, Vec<Envelope>)],
}

/// Width of the envelopes' legend panel.
const LEGEND: u32 = 260;

impl Figure for Envelopes<'_> {
    fn size(&self) -> (u32, u32) {
        (600 * self.panels.len().max(1) as u32 + LEGEND, 720)
    }

    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Chart
    where
        DB::ErrorType: 'static,
    {
        let points = || {
            self.panels
                .iter()
                .flat_map(|p| p.1.iter().flat_map(|c| c.1.iter()))
        };
        let z_max = points().fold(2.2f64, |m, (z, _)| m.max(z.abs())) * 1.05;
        let low = points().fold(0.0f64, |m, (_, h)| m.min(*h)) * 1.05 - 0.1;
        let high = points().fold(2.5f64, |m, (_, h)| m.max(*h)) * 1.05;
        let (plots, side) = root.split_horizontally(600 * self.panels.len().max(1) as u32);
        let areas = plots.split_evenly((1, self.panels.len().max(1)));
        let inner = areas
            .iter()
            .zip(self.panels)
            .map(|(a, p)| a.titled(&p.0, ("sans-serif", TITLE_FONT)))
            .collect::<Result<Vec<_>, _>>()?;
        let Some(first) = inner.first() else {
            return Ok(());
        };
        // One frame for all panels, to scale (building draws nothing).
        let pixels = build(first, (0.0, z_max), (low, high))?
            .plotting_area()
            .dim_in_pixel();
        let (z, h) = equal_aspect((-0.1, z_max), (low, high), pixels);
        // Widened to the right only: the clamp stays at the left edge.
        let frame_ranges = ((-0.1, z.1 - z.0 - 0.1), h);
        for (area, panel) in inner.iter().zip(self.panels) {
            self.envelope_panel(area, &panel.1, frame_ranges)?;
        }
        let curves = self.panels.iter().map(|p| p.1.len()).max().unwrap_or(0);
        let grey = RGBColor(110, 110, 110);
        let mut entries = vec![
            LegendEntry::new(Glyph::Line(grey, Stroke::Dashed), "Rb = π/2, eq. (2)"),
            LegendEntry::new(Glyph::Line(grey, Stroke::Dotted), "Rdef = 2, eq. (3)"),
            LegendEntry::new(Glyph::Dot(RED), "μ ≈ 1.81, eq. (4)"),
        ];
        let names = self.panels.iter().find(|p| p.1.len() == curves);
        for (k, (label, _)) in names.map_or(&[][..], |p| p.1.as_slice()).iter().enumerate() {
            entries.push(LegendEntry::new(
                Glyph::Line(colour(k), Stroke::Solid),
                label.clone(),
            ));
        }
        legend(&side.margin(60, 0, 6, 6), &entries, 1)?;
        Ok(())
    }
}

fn build<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    z: (f64, f64),
    h: (f64, f64),
) -> Result<ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, Failure>
where
    DB::ErrorType: 'static,
{
    Ok(ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(65)
        .build_cartesian_2d(z.0..z.1, h.0..h.1)?)
}

impl Envelopes<'_> {
    fn envelope_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        curves: &[Envelope],
        (z, h): ((f64, f64), (f64, f64)),
    ) -> Chart
    where
        DB::ErrorType: 'static,
    {
        let mut chart = build(area, z, h)?;
        draw_grid(
            &mut chart,
            self.labels.reach.as_str(),
            self.labels.height.as_str(),
            (z.1 - z.0, h.1 - h.0),
        )?;
        let grey = RGBColor(110, 110, 110);
        let rb = std::f64::consts::FRAC_PI_2;
        line(
            &mut chart,
            vec![(z.0, rb), (z.1, rb)],
            grey,
            Stroke::Dashed,
            1,
        )?;
        line(
            &mut chart,
            vec![(2.0, h.0), (2.0, h.1)],
            grey,
            Stroke::Dotted,
            1,
        )?;
        chart.draw_series(std::iter::once(Circle::new((MU, 0.0), 5, RED.filled())))?;
        for (k, (_, points)) in curves.iter().enumerate() {
            line(&mut chart, points.clone(), colour(k), Stroke::Solid, 2)?;
            chart.draw_series(
                points
                    .iter()
                    .map(|p| Circle::new(*p, 3, colour(k).filled())),
            )?;
        }
        frame(chart.plotting_area())?;
        Ok(())
    }
}
