//! The chart of a longest-arm study (the paper's Fig. 5; plotters, PNG or
//! SVG by the file extension).
//!
//! a) R̂ of the sampled designs over (c2, c3), the loaded-shape
//!    coefficients; b) the same designs over (b1, b2), the Taylor
//!    coefficients of κ̄⁰2 (59), where the origin is the straight rod;
//!    'P' marks the optimum R*, 'Q' the sample closest to a straight rod
//!    (least Σb²). c) the optimum's loaded (solid) and unloaded (dashed)
//!    shapes; d) Q's shapes and the loaded shape of the true straight
//!    optimum R̂0. Shapes are in the reach's units, height −x against z.

use std::fmt::Write as _;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

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
type Failure = Box<dyn std::error::Error>;

/// Draws the chart to `out` (.png or .svg), atomically: to a temporary
/// file beside it (same extension, so the format is kept), then renamed.
pub fn draw_arm(chart: &ArmChart, out: &Path) -> Result<(), Failure> {
    crate::plot::register_font();
    let size = (1400, 1100);
    let extension = out
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    let stem = out
        .file_stem()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = out.with_file_name(format!(".{stem}.{}.tmp.{extension}", std::process::id()));
    let drawn = if extension == "svg" {
        panels(&SVGBackend::new(&tmp, size).into_drawing_area(), chart)
    } else {
        panels(&BitMapBackend::new(&tmp, size).into_drawing_area(), chart)
    };
    let renamed = drawn.and_then(|()| std::fs::rename(&tmp, out).map_err(Failure::from));
    if renamed.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    renamed
}

fn panels<DB: DrawingBackend>(root: &Area<DB>, chart: &ArmChart) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let areas = root.split_evenly((2, 2));
    let p = chart.optimum;
    let q = chart.closest.map(|q| &q.optimum);
    let coefficient = |i: usize| move |o: &ArmOptimum| o.design.shape_coefficients[i];
    let curvature = |i: usize| move |o: &ArmOptimum| o.curvature_coefficients[i];
    if p.design.shape_coefficients.len() >= 3 {
        let map = chart.map.map(|m| (&m.shape_coefficients, &m.reach));
        let marks = (coefficient(1), coefficient(2));
        scatter(
            &areas[0],
            "a) reach R over the loaded shape",
            ("c2", "c3"),
            map,
            (1, 2),
            p,
            q,
            &marks,
        )?;
    }
    if p.curvature_coefficients.len() >= 2 {
        let map = chart.map.map(|m| (&m.curvature_coefficients, &m.reach));
        let marks = (curvature(0), curvature(1));
        scatter(
            &areas[1],
            "b) reach R over the intrinsic curvature",
            ("b1", "b2"),
            map,
            (0, 1),
            p,
            q,
            &marks,
        )?;
    }
    let title = format!(
        "c) P: R* = {:.4} (solid loaded, dashed unloaded)",
        p.design.reach
    );
    let mut shapes = vec![(&p.loaded_shape, 0, false), (&p.unloaded_shape, 0, true)];
    shapes_panel(&areas[2], &title, &shapes)?;
    shapes.clear();
    let mut title = String::from("d)");
    if let Some(q) = q {
        write!(title, " Q: R = {:.4}", q.design.reach).expect("writing to a String cannot fail");
        shapes.push((&q.loaded_shape, 1, false));
        shapes.push((&q.unloaded_shape, 1, true));
    }
    if let Some(s) = chart.straight {
        write!(title, "; true straight optimum R0 = {:.4} (green)", s.reach)
            .expect("writing to a String cannot fail");
        shapes.push((&s.loaded_shape, 2, false));
    }
    shapes_panel(&areas[3], &title, &shapes)?;
    root.present()?;
    Ok(())
}

const COLORS: [RGBColor; 3] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
];

/// Low reach dark blue, high reach yellow.
fn heat(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let mix = |a: f64, b: f64| (a + (b - a) * t) as u8;
    RGBColor(mix(40.0, 250.0), mix(30.0, 210.0), mix(120.0, 30.0))
}

fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        return (-1.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

/// The sampled designs as dots coloured by R̂ (highest drawn last), with
/// P and Q marked.
#[allow(clippy::too_many_arguments)]
fn scatter<DB: DrawingBackend>(
    area: &Area<DB>,
    title: &str,
    axes: (&str, &str),
    map: Option<(&Vec<Vec<f64>>, &Vec<f64>)>,
    columns: (usize, usize),
    p: &ArmOptimum,
    q: Option<&ArmOptimum>,
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
                .collect()
        })
        .unwrap_or_default();
    dots.sort_by(|a, b| a.2.total_cmp(&b.2));
    let marks: Vec<(&str, f64, f64)> = std::iter::once(("P", mark.0(p), mark.1(p)))
        .chain(q.map(|q| ("Q", mark.0(q), mark.1(q))))
        .collect();
    let xs = span(dots.iter().map(|d| d.0).chain(marks.iter().map(|m| m.1)));
    let ys = span(dots.iter().map(|d| d.1).chain(marks.iter().map(|m| m.2)));
    let (lo, hi) = dots
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), d| (a.min(d.2), b.max(d.2)));
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("{title} ({lo:.2} dark … {hi:.2} light)"),
            ("sans-serif", 18),
        )
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(xs.0..xs.1, ys.0..ys.1)?;
    chart
        .configure_mesh()
        .x_desc(axes.0)
        .y_desc(axes.1)
        .label_style(("sans-serif", 14))
        .draw()?;
    let width = (hi - lo).max(1e-12);
    chart.draw_series(
        dots.iter()
            .map(|d| Circle::new((d.0, d.1), 3, heat((d.2 - lo) / width).filled())),
    )?;
    for (name, x, y) in marks {
        let element = EmptyElement::at((x, y))
            + Circle::new((0, 0), 7, BLACK.stroke_width(2))
            + Text::new(name, (9, -20), ("sans-serif", 18));
        chart.draw_series(std::iter::once(element))?;
    }
    Ok(())
}

/// Rod shapes, height −x against z.
fn shapes_panel<DB: DrawingBackend>(
    area: &Area<DB>,
    title: &str,
    shapes: &[(&Vec<[f64; 3]>, usize, bool)],
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    let zs = span(shapes.iter().flat_map(|s| s.0.iter().map(|r| r[2])));
    let hs = span(shapes.iter().flat_map(|s| s.0.iter().map(|r| -r[0])));
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(zs.0..zs.1, hs.0..hs.1)?;
    chart
        .configure_mesh()
        .x_desc("z")
        .y_desc("−x (height)")
        .label_style(("sans-serif", 14))
        .draw()?;
    for (shape, color, dashed) in shapes {
        let style = COLORS[*color % COLORS.len()].stroke_width(2);
        let pts: Vec<(f64, f64)> = shape.iter().map(|r| (r[2], -r[0])).collect();
        if *dashed {
            chart.draw_series(DashedLineSeries::new(pts, 8, 6, style))?;
        } else {
            chart.draw_series(LineSeries::new(pts, style))?;
        }
    }
    Ok(())
}
