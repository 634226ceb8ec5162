//! Which chart a sweep file makes, and the eq. (61) fit of its reach map.
//!
//! An arm sweep with `arm.alpha` among its axes is a reach envelope (the
//! paper's Fig. 7: panel a with optimized curvature, family 0; panel b the
//! straight arm's R0); an arm sweep over two other axes is a pair of
//! contour maps of R* (Fig. 6: families 0 and 1), with eq. (61) fitted to
//! family 0.

use std::path::Path;

use crate::axis_label::{key_label, Scale};
use crate::sweep_chart::{contour_maps, envelopes, Envelope, EnvelopeLabels, MapLabels, MapPanel};
use cosserat::output::SweepHeader;
use cosserat::study::sweep::contour::{fit_power_law, GridField, PowerFit};
use cosserat::study::sweep::Record;

/// The key of the reach direction (degrees).
const ALPHA: &str = "arm.alpha";

/// A one-value column on the whole grid (NaN where missing).
pub fn grid_values(header: &SweepHeader, records: &[Record], column: &str) -> Vec<f64> {
    let mut z = vec![f64::NAN; header.points()];
    for r in records {
        if let Some(v) = r.number(column) {
            z[r.index] = v;
        }
    }
    z
}

/// R* of family `f` on the whole grid, NaN where the family has no
/// optimum of its own (not found, or merged into family 0).
pub fn family_map(header: &SweepHeader, records: &[Record], f: usize) -> Vec<f64> {
    let status = format!("family_{f}/status");
    let own: Vec<Record> = records
        .iter()
        .filter(|r| r.labels.get(&status).is_some_and(|s| s == "optimum"))
        .cloned()
        .collect();
    grid_values(header, &own, &format!("family_{f}/reach"))
}

/// The fit of B̄3 = Ω B̄1^(−ι) to 8 contours of `family`'s R* on a sweep
/// over two axes (None otherwise).
pub fn reach_fit(header: &SweepHeader, records: &[Record], family: usize) -> Option<PowerFit> {
    let [x, y] = &header.axes[..] else {
        return None;
    };
    // Only stiffness-like axes: positive values, not the direction α.
    if header.keys.iter().any(|k| k == ALPHA) || x.iter().chain(y).any(|v| *v <= 0.0) {
        return None;
    }
    let z = family_map(header, records, family);
    let field = GridField { x, y, z: &z };
    fit_power_law(&field, &field.levels(8))
}

/// Whether a sweep of this header has a chart; Err names why not (checked
/// before any work, so that `--plot` on a sweep without one is bad input).
pub fn chartable(kind: &str, keys: &[String]) -> Result<(), String> {
    if kind != "arm" {
        return Err("--plot: charts are drawn for arm sweeps (an [arm] table)".into());
    }
    if keys.iter().any(|k| k == ALPHA) || keys.len() == 2 {
        Ok(())
    } else {
        Err(format!(
            "--plot: charts need two axes or `{ALPHA}` among the axes, got {keys:?}"
        ))
    }
}

/// Draws the sweep's chart; Err names why there is none.
pub fn draw(out: &Path, header: &SweepHeader, records: &[Record]) -> Result<(), String> {
    chartable(&header.kind, &header.keys)?;
    let result = if let Some(a) = header.keys.iter().position(|k| k == ALPHA) {
        envelope_chart(out, header, records, a)
    } else {
        map_chart(out, header, records)
    };
    result.map_err(|e| format!("{}: {e}", out.display()))
}

/// The scale of a sweep's problem and the unit its reaches are given in
/// (docs/problem-files.md, `[arm]`): √(B₂/F) with a tip load, (B₂/q)^(1/3)
/// with the arm's weight alone.
fn reach_unit(header: &SweepHeader) -> (Scale, &'static str) {
    let keys: Vec<&str> = header.keys.iter().map(String::as_str).collect();
    let scale = Scale::of_problem(&header.problem, &keys);
    let weight_alone = toml::from_str::<toml::Table>(&header.problem)
        .ok()
        .and_then(|t| {
            let f = t.get("loads")?.get("tip_force")?.as_array()?.clone();
            Some(
                f.iter()
                    .all(|v| v.as_float().or(v.as_integer().map(|i| i as f64)) == Some(0.0)),
            )
        })
        .unwrap_or(false);
    let unit = if weight_alone {
        "(q/B₂)^(1/3)"
    } else {
        "√(F/B₂)"
    };
    (scale, unit)
}

/// A grid value as a short number (0.25, 16, 0.667).
fn short(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn map_chart(
    out: &Path,
    header: &SweepHeader,
    records: &[Record],
) -> Result<(), Box<dyn std::error::Error>> {
    let (scale, unit) = reach_unit(header);
    let with_values: Vec<usize> = (0..2)
        .filter(|f| {
            records
                .iter()
                .any(|r| r.number(&format!("family_{f}/reach")).is_some())
        })
        .collect();
    let maps: Vec<(usize, Vec<f64>)> = with_values
        .iter()
        .map(|f| (*f, family_map(header, records, *f)))
        .collect();
    // A family without a single optimum of its own gets a note, not an
    // empty panel.
    let (drawn, empty): (Vec<_>, Vec<_>) = maps
        .iter()
        .partition(|(_, z)| z.iter().any(|v| v.is_finite()));
    let drawn = if drawn.is_empty() {
        maps.iter().take(1).collect()
    } else {
        drawn
    };
    let fit = reach_fit(header, records, 0);
    let (x, y) = (
        key_label(&header.keys[0], scale),
        key_label(&header.keys[1], scale),
    );
    let panels: Vec<MapPanel> = drawn
        .iter()
        .map(|(f, z)| MapPanel {
            title: format!("R*, family {f}"),
            field: GridField {
                x: &header.axes[0],
                y: &header.axes[1],
                z,
            },
            fit: if *f == 0 { fit.as_ref() } else { None },
        })
        .collect();
    let labels = MapLabels {
        fit: fit.as_ref().map(|fit| {
            format!(
                "eq. (61) on family 0: {y} = Ω ({x})^(−ι), one ι = {:.3} for all contours",
                fit.iota
            )
        }),
        notes: empty
            .iter()
            .map(|(f, _)| format!("family {f}: no distinct optimum at any grid point (no panel)"))
            .collect(),
        value: format!("R* {unit}"),
        x,
        y,
    };
    contour_maps(out, &labels, &panels)
}

/// Tip points (ẑ, height) = R (cos α, sin α) along α, one curve per value
/// of the other axes.
fn curves(header: &SweepHeader, records: &[Record], a: usize, column: &str) -> Vec<Envelope> {
    let (scale, _) = reach_unit(header);
    let mut out: Vec<(Vec<usize>, Envelope)> = vec![];
    for r in records {
        let Some(reach) = r.number(column).filter(|v| v.is_finite()) else {
            continue;
        };
        let idx = multi_index(&header.axes, r.index);
        let alpha = header.axes[a][idx[a]].to_radians();
        let mut key = idx.clone();
        key[a] = 0;
        let point = (reach * alpha.cos(), reach * alpha.sin());
        if let Some((_, (_, pts))) = out.iter_mut().find(|(k, _)| *k == key) {
            pts.push(point);
        } else {
            let label = (0..idx.len())
                .filter(|&j| j != a)
                .map(|j| {
                    format!(
                        "{} = {}",
                        key_label(&header.keys[j], scale),
                        short(header.axes[j][idx[j]])
                    )
                })
                .collect::<Vec<_>>()
                .join(", ");
            out.push((key, (label, vec![point])));
        }
    }
    out.into_iter().map(|(_, e)| e).collect()
}

fn multi_index(axes: &[Vec<f64>], i: usize) -> Vec<usize> {
    let shape: Vec<usize> = axes.iter().map(Vec::len).collect();
    cosserat::study::sweep::grid_index(&shape, i)
}

fn envelope_chart(
    out: &Path,
    header: &SweepHeader,
    records: &[Record],
    a: usize,
) -> Result<(), Box<dyn std::error::Error>> {
    let (_, unit) = reach_unit(header);
    let labels = EnvelopeLabels {
        reach: format!("horizontal reach z {unit}"),
        height: format!("height above the clamp −x {unit}"),
    };
    envelopes(
        out,
        &labels,
        &[
            (
                "a) optimized intrinsic curvature: R*".to_string(),
                curves(header, records, a, "family_0/reach"),
            ),
            (
                "b) intrinsically straight: R0".to_string(),
                curves(header, records, a, "straight/reach"),
            ),
        ],
    )
}
