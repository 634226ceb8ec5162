//! The chart of a longest-arm study (the paper's Fig. 5; plotters, PNG or
//! SVG by the file extension).
//!
//! a) R̂ of the sampled designs over (c2, c3), the loaded-shape
//!    coefficients; b) the same designs over (b1, b2), the Taylor
//!    coefficients of κ̄⁰2 (59), where the origin is the straight rod;
//!    'P' marks the optimum R*, 'Q' the sample closest to a straight rod
//!    (least Σb²). c) the optimum's loaded (solid) and unloaded (dashed)
//!    shapes; d) Q's shapes and the loaded shape of the true straight
//!    optimum R̂0. Shapes are in the reach's units, height −x against z,
//!    to scale, the load drawn at the tip (or the weight at mid-length).
//!    The reach of the dots is read on a colour bar beside each map; the
//!    shapes' legend sits above them.

use std::fmt::Write as _;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart_style::{
    self, colour, colour_bar, draw_grid, draw_tags, frame, legend, line, padded, render,
    shape_chart, Failure, Figure, Glyph, LegendEntry, PixelBox, Stroke, Tag, ARROW, TITLE_FONT,
};
use cosserat::study::arm::ArmWeight;

use cosserat::study::arm::{ArmOptimum, ClosestStraight, ReachMap, StraightArm};

/// What the chart shows.
#[derive(Debug, Clone, Copy)]
pub struct ArmChart<'a> {
    /// The optimum 'P'.
    pub optimum: &'a ArmOptimum,
    /// The sampled designs.
    pub map: Option<&'a ReachMap>,
    /// 'Q'.
    pub closest: Option<&'a ClosestStraight>,
    /// The true straight optimum.
    pub straight: Option<&'a StraightArm>,
}

type Area<'b, DB> = DrawingArea<DB, Shift>;

/// Draws the chart to `out` (.png or .svg), atomically: to a temporary
/// file beside it (same extension, so the format is kept), then renamed.
pub fn draw_arm(chart: &ArmChart, out: &Path) -> Result<(), Failure> {
    let extension = out
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    let stem = out
        .file_stem()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = out.with_file_name(format!(".{stem}.{}.tmp.{extension}", std::process::id()));
    let drawn = render(chart, &tmp);
    let renamed = drawn.and_then(|()| std::fs::rename(&tmp, out).map_err(Failure::from));
    if renamed.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    renamed
}

/// The unit of the reach (docs/problem-files.md, `[arm]`).
fn reach_unit(o: &ArmOptimum) -> &'static str {
    match o.scene.weight {
        ArmWeight::Alone => "(q/B₂)^(1/3)",
        ArmWeight::Weightless | ArmWeight::WithTipLoad(_) => "√(F/B₂)",
    }
}

impl Figure for ArmChart<'_> {
    fn size(&self) -> (u32, u32) {
        (1500, 1200)
    }

    fn draw_on<DB: DrawingBackend>(&self, root: &Area<DB>) -> Result<(), Failure>
    where
        DB::ErrorType: 'static,
    {
        let areas = root.split_evenly((2, 2));
        let p = self.optimum;
        let q = self.closest.map(|q| &q.optimum);
        let unit = reach_unit(p);
        let coefficient = |i: usize| move |o: &ArmOptimum| o.design.shape_coefficients[i];
        let curvature = |i: usize| move |o: &ArmOptimum| o.curvature_coefficients[i];
        if p.design.shape_coefficients.len() >= 3 {
            let map = self.map.map(|m| (&m.shape_coefficients, &m.reach));
            let marks = (coefficient(1), coefficient(2));
            scatter(
                &areas[0],
                "a) reach of the sampled designs over the loaded shape",
                ("loaded-shape coefficient c₂", "loaded-shape coefficient c₃"),
                unit,
                map,
                (1, 2),
                (p, q),
                &marks,
            )?;
        }
        if p.curvature_coefficients.len() >= 2 {
            let map = self.map.map(|m| (&m.curvature_coefficients, &m.reach));
            let marks = (curvature(0), curvature(1));
            scatter(
                &areas[1],
                "b) the same designs over the intrinsic curvature",
                ("κ⁰₂ Taylor coefficient b₁", "κ⁰₂ Taylor coefficient b₂"),
                unit,
                map,
                (0, 1),
                (p, q),
                &marks,
            )?;
        }
        let title = format!("c) P, the optimum: R* = {:.4} {unit}", p.design.reach);
        let shapes = vec![
            Shape::new(&p.loaded_shape, 0, Stroke::Solid, "P loaded"),
            Shape::new(&p.unloaded_shape, 0, Stroke::Dashed, "P unloaded"),
        ];
        shapes_panel(&areas[2], &title, &shapes, p)?;
        let mut shapes = vec![];
        let mut title = String::from("d)");
        if let Some(q) = q {
            write!(title, " Q: R = {:.4}", q.design.reach)
                .expect("writing to a String cannot fail");
            shapes.push(Shape::new(&q.loaded_shape, 1, Stroke::Solid, "Q loaded"));
            shapes.push(Shape::new(
                &q.unloaded_shape,
                1,
                Stroke::Dashed,
                "Q unloaded",
            ));
        }
        if let Some(s) = self.straight {
            let sep = if q.is_some() { ";" } else { "" };
            write!(title, "{sep} straight optimum R0 = {:.4}", s.reach)
                .expect("writing to a String cannot fail");
            shapes.push(Shape::new(
                &s.loaded_shape,
                2,
                Stroke::Solid,
                "R0 loaded (κ⁰ = 0)",
            ));
        }
        if !shapes.is_empty() {
            shapes_panel(&areas[3], &title, &shapes, p)?;
        }
        Ok(())
    }
}

/// Low reach dark blue, high reach yellow.
fn heat(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let mix = |a: f64, b: f64| (a + (b - a) * t) as u8;
    RGBColor(mix(40.0, 250.0), mix(30.0, 210.0), mix(120.0, 30.0))
}

/// The sampled designs as dots coloured by R̂ (highest drawn last, a
/// colour bar beside), with P and Q marked and tagged apart.
#[allow(clippy::too_many_arguments)]
fn scatter<DB: DrawingBackend>(
    area: &Area<DB>,
    title: &str,
    axes: (&str, &str),
    unit: &str,
    map: Option<(&Vec<Vec<f64>>, &Vec<f64>)>,
    columns: (usize, usize),
    (p, q): (&ArmOptimum, Option<&ArmOptimum>),
    mark: &(impl Fn(&ArmOptimum) -> f64, impl Fn(&ArmOptimum) -> f64),
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    let mut dots: Vec<(f64, f64, f64)> = map
        .map(|(rows, reach)| {
            rows.iter()
                .zip(reach)
                .map(|(r, v)| (r[columns.0], r[columns.1], *v))
                .filter(|d| d.2.is_finite())
                .collect()
        })
        .unwrap_or_default();
    dots.sort_by(|a, b| a.2.total_cmp(&b.2));
    let marks: Vec<(&str, f64, f64)> = std::iter::once(("P", mark.0(p), mark.1(p)))
        .chain(q.map(|q| ("Q", mark.0(q), mark.1(q))))
        .collect();
    let xs = padded(dots.iter().map(|d| d.0).chain(marks.iter().map(|m| m.1)));
    let ys = padded(dots.iter().map(|d| d.1).chain(marks.iter().map(|m| m.2)));
    let (plot, bar) = area.split_horizontally(area.dim_in_pixel().0 - 110);
    let mut chart = ChartBuilder::on(&plot)
        .caption(title, ("sans-serif", TITLE_FONT))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(xs.0..xs.1, ys.0..ys.1)?;
    draw_grid(&mut chart, axes.0, axes.1, (xs.1 - xs.0, ys.1 - ys.0))?;
    let range = padded(dots.iter().map(|d| d.2));
    let range = if dots.len() > 1 {
        (dots[0].2, dots[dots.len() - 1].2)
    } else {
        range
    };
    let width = (range.1 - range.0).max(1e-12);
    chart.draw_series(
        dots.iter()
            .map(|d| Circle::new((d.0, d.1), 3, heat((d.2 - range.0) / width).filled())),
    )?;
    frame(chart.plotting_area())?;
    let tags: Vec<Tag> = marks
        .iter()
        .map(|(name, x, y)| Tag {
            text: (*name).to_string(),
            at: (*x, *y),
            glyph: Some(Glyph::Ring(BLACK)),
        })
        .collect();
    draw_tags(&mut chart, &tags, &[])?;
    if !dots.is_empty() {
        colour_bar(&bar, range, &heat, &format!("R {unit}"), 75)?;
    }
    Ok(())
}

/// A rod shape to draw.
struct Shape<'a> {
    points: &'a [[f64; 3]],
    colour: usize,
    stroke: Stroke,
    label: &'static str,
}

impl<'a> Shape<'a> {
    fn new(
        points: &'a [[f64; 3]],
        colour: usize,
        stroke: Stroke,
        label: &'static str,
    ) -> Shape<'a> {
        Shape {
            points,
            colour,
            stroke,
            label,
        }
    }

    fn loaded(&self) -> bool {
        self.label.contains("loaded") && !self.label.contains("unloaded")
    }
}

/// The colour of load arrows.
const LOAD: RGBColor = RGBColor(200, 0, 0);

/// Rod shapes, height −x against z, to scale, with the load on the loaded
/// shapes and the legend above.
fn shapes_panel<DB: DrawingBackend>(
    area: &Area<DB>,
    title: &str,
    shapes: &[Shape],
    p: &ArmOptimum,
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    let inner = area.titled(title, ("sans-serif", TITLE_FONT))?;
    let (top, plot) = inner.split_vertically(60);
    let loads = p.scene.loads();
    let (at_tip, force) = if loads.tip_force.norm() > 0.0 {
        (true, loads.tip_force)
    } else {
        (false, loads.distributed_force)
    };
    let mut entries: Vec<LegendEntry> = shapes
        .iter()
        .map(|s| LegendEntry::new(Glyph::Line(colour(s.colour), s.stroke), s.label))
        .collect();
    let (dz, dh) = (force[2], -force[0]);
    let size = dz.hypot(dh);
    if size > 0.0 {
        let text = if at_tip {
            "tip force F"
        } else {
            "weight q (at mid-length)"
        };
        entries.push(LegendEntry::new(Glyph::Arrow(LOAD), text));
    }
    legend(&top.margin(4, 0, 70, 0), &entries, 3)?;
    let zs = padded(shapes.iter().flat_map(|s| s.points.iter().map(|r| r[2])));
    let hs = padded(shapes.iter().flat_map(|s| s.points.iter().map(|r| -r[0])));
    let (mut chart, zs, hs) = shape_chart(&plot, zs, hs, true)?;
    draw_grid(
        &mut chart,
        format!("z {}", reach_unit(p)),
        format!("height −x {}", reach_unit(p)),
        (zs.1 - zs.0, hs.1 - hs.0),
    )?;
    for s in shapes {
        let pts: Vec<(f64, f64)> = s.points.iter().map(|r| (r[2], -r[0])).collect();
        line(&mut chart, pts, colour(s.colour), s.stroke, 2)?;
    }
    frame(chart.plotting_area())?;
    if size > 0.0 {
        let (bx, by) = plot.get_base_pixel();
        for s in shapes.iter().filter(|s| s.loaded() && !s.points.is_empty()) {
            let r = if at_tip {
                s.points[s.points.len() - 1]
            } else {
                s.points[s.points.len() / 2]
            };
            let from = chart.backend_coord(&(r[2], -r[0]));
            let d = ((dz / size * ARROW) as i32, (-dh / size * ARROW) as i32);
            let _: PixelBox = chart_style::arrow(&plot, (from.0 - bx, from.1 - by), d, LOAD)?;
        }
    }
    Ok(())
}
