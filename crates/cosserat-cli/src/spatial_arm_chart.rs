//! The chart of a spatial arm (`[arm] spatial = true`; plotters, PNG or SVG
//! by the extension): the optimum's loaded (solid) and unloaded (dashed)
//! centrelines as two projections to scale, a) the side view (height −x̂
//! against ẑ, the planar arm's view) and b) the top view (ŷ against ẑ),
//! in units of √(B₂/F); and, given directions studied, c) the reach against
//! the direction α for planar and spatial optima.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::chart_style::{
    colour, draw_grid, frame, line, padded, shape_chart, Failure, Figure, Stroke,
};
use cosserat::study::arm::SpatialOptimum;

/// (α in degrees, planar R*, spatial R*) of a direction study.
pub type DirectionReach = (f64, f64, f64);

/// What the chart shows.
#[derive(Debug, Clone, Copy)]
pub struct SpatialChart<'a> {
    /// The optimum.
    pub optimum: &'a SpatialOptimum,
    /// Reach against α (empty: no panel c).
    pub directions: &'a [DirectionReach],
}

type Area<'b, DB> = DrawingArea<DB, Shift>;

impl Figure for SpatialChart<'_> {
    fn size(&self) -> (u32, u32) {
        if self.directions.is_empty() {
            (1400, 650)
        } else {
            (2000, 650)
        }
    }

    fn draw_on<DB: DrawingBackend>(&self, root: &Area<DB>) -> Result<(), Failure>
    where
        DB::ErrorType: 'static,
    {
        let panels = if self.directions.is_empty() { 2 } else { 3 };
        let areas = root.split_evenly((1, panels));
        let o = self.optimum;
        let side = |p: &[f64; 3]| (p[2], -p[0]);
        let top = |p: &[f64; 3]| (p[2], p[1]);
        let views = [
            (
                "a) side view (loaded solid, unloaded dashed)",
                "height −x̂ √(B₂/F)",
            ),
            ("b) top view", "ŷ √(B₂/F)"),
        ];
        projection(&areas[0], views[0], &side, o)?;
        projection(&areas[1], views[1], &top, o)?;
        if panels == 3 {
            self.directions_panel(&areas[2])?;
        }
        Ok(())
    }
}

impl SpatialChart<'_> {
    fn directions_panel<DB: DrawingBackend>(&self, area: &Area<DB>) -> Result<(), Failure>
    where
        DB::ErrorType: 'static,
    {
        let area = area.titled(
            "c) R* against α: planar (●, solid) and spatial (✕, dashed)",
            ("sans-serif", crate::chart_style::TITLE_FONT),
        )?;
        let d = self.directions;
        let xs = padded(d.iter().map(|p| p.0));
        let ys = padded(d.iter().flat_map(|p| [p.1, p.2]).chain([0.0]));
        let mut chart = ChartBuilder::on(&area)
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(xs.0..xs.1, ys.0..ys.1)?;
        draw_grid(
            &mut chart,
            "direction α (degrees)".to_string(),
            "R* √(B₂/F)".to_string(),
            (xs.1 - xs.0, ys.1 - ys.0),
        )?;
        let planar: Vec<(f64, f64)> = d.iter().map(|p| (p.0, p.1)).collect();
        let spatial: Vec<(f64, f64)> = d.iter().map(|p| (p.0, p.2)).collect();
        line(&mut chart, planar.clone(), colour(0), Stroke::Solid, 2)?;
        line(&mut chart, spatial.clone(), colour(1), Stroke::Dashed, 2)?;
        chart.draw_series(
            planar
                .iter()
                .map(|p| Circle::new(*p, 6, colour(0).filled())),
        )?;
        chart.draw_series(
            spatial
                .iter()
                .map(|p| Cross::new(*p, 7, colour(1).stroke_width(3))),
        )?;
        frame(chart.plotting_area())
    }
}

/// One projection of the loaded and unloaded centrelines, to scale.
fn projection<DB: DrawingBackend>(
    area: &Area<DB>,
    (title, ylabel): (&str, &str),
    view: &dyn Fn(&[f64; 3]) -> (f64, f64),
    o: &SpatialOptimum,
) -> Result<(), Failure>
where
    DB::ErrorType: 'static,
{
    let area = area.titled(title, ("sans-serif", crate::chart_style::TITLE_FONT))?;
    let all: Vec<(f64, f64)> = o
        .loaded_shape
        .iter()
        .chain(&o.unloaded_shape)
        .map(view)
        .chain(std::iter::once((0.0, 0.0)))
        .collect();
    let zs = padded(all.iter().map(|p| p.0));
    let hs = padded(all.iter().map(|p| p.1));
    let (mut chart, zs, hs) = shape_chart(&area, zs, hs, false)?;
    draw_grid(
        &mut chart,
        "ẑ √(B₂/F)".to_string(),
        ylabel.to_string(),
        (zs.1 - zs.0, hs.1 - hs.0),
    )?;
    let loaded: Vec<(f64, f64)> = o.loaded_shape.iter().map(view).collect();
    let unloaded: Vec<(f64, f64)> = o.unloaded_shape.iter().map(view).collect();
    line(&mut chart, loaded, colour(0), Stroke::Solid, 3)?;
    line(&mut chart, unloaded, colour(0), Stroke::Dashed, 2)?;
    chart.draw_series(std::iter::once(Circle::new((0.0, 0.0), 5, BLACK.filled())))?;
    frame(chart.plotting_area())
}
