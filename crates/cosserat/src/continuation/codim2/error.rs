//! The discretization error of a curve of singular points and of its
//! cusps.
//!
//! Every point of the curve solves the *discretized* augmented system to
//! the corrector's tolerance, so its parameters carry the discretization's
//! error, as a located fold or branch point does (`discretization.rs`):
//! O(h^{2m}) for Gauss collocation of m points on intervals h, the
//! integrator's global error on shooting. Each point is located again on
//! the family refined ([`Family::refined`]: twice the intervals, or the
//! integration tolerances up to 100 times tighter; gain G), by the same
//! augmented Newton, from the point carried onto it, with the parameter
//! the curve moves along most held fixed (the corrector's constraint row
//! set to that parameter's unit vector): the other parameter's shift δ,
//! Richardson-scaled, is its error at the fixed one,
//!
//!   e_other = |p_other − p_other,fine| · G/(G − 1),
//!
//! and the fixed parameter's error at the other held fixed is
//! e_other · |dp_fixed/dp_other| along the curve (the tangent's ratio;
//! infinite where the curve runs parallel to the fixed parameter's axis,
//! where that error has no meaning). A cusp is located again between the
//! refined curve's points around it, by the same bisection, and its two
//! parameters' shifts, Richardson-scaled, are its errors. A relocation that
//! fails leaves the error unknown (None) with a note saying why — never a
//! guessed bound.
//!
//! [`Family::refined`]: crate::continuation::Family::refined

use rayon::prelude::*;

use super::{curve_point, locate_cusp, projected, Augmented, CurveOptions, CurvePoint, Cusp};

/// The estimated errors of a curve's points and cusps, and why any is
/// unknown.
pub(super) struct CurveErrors {
    /// Per point: the errors of (p₁ at its p₂, p₂ at its p₁).
    pub points: Vec<Option<[f64; 2]>>,
    /// Per cusp: the errors of its (p₁, p₂).
    pub cusps: Vec<Option<[f64; 2]>>,
    /// Why an error is unknown, one note for each.
    pub notes: Vec<String>,
}

/// The errors of `points` and `cusps`, curves of `aug`'s family.
pub(super) fn estimate(
    aug: &Augmented,
    points: &[CurvePoint],
    cusps: &[Cusp],
    opts: &CurveOptions,
) -> CurveErrors {
    let (fine_family, gain) = match aug.family.refined() {
        Ok(refined) => refined,
        Err(why) => return unknown(points.len(), cusps.len(), &why),
    };
    let fine = Augmented {
        family: &fine_family,
        pair: std::sync::Arc::clone(&aug.pair),
        n: fine_family.size(),
        branch: aug.branch,
    };
    let scale = gain / (gain - 1.0);
    let relocated: Vec<Result<CurvePoint, String>> = points
        .par_iter()
        .map(|point| relocate(aug, &fine, point, opts))
        .collect();
    let mut notes = vec![];
    let point_errors = points
        .iter()
        .zip(&relocated)
        .enumerate()
        .map(|(i, (point, fine_point))| match fine_point {
            Ok(f) => Some(point_error(aug.n, point, f, scale)),
            Err(why) => {
                notes.push(format!("curve point {i}: {why}"));
                None
            }
        })
        .collect();
    let cusp_errors = cusps
        .iter()
        .map(
            |cusp| match cusp_error(&fine, &relocated, cusp, opts, scale) {
                Ok(e) => Some(e),
                Err(why) => {
                    let [p1, p2] = cusp.point.parameters;
                    notes.push(format!("the cusp at ({p1:.10}, {p2:.10}): {why}"));
                    None
                }
            },
        )
        .collect();
    CurveErrors {
        points: point_errors,
        cusps: cusp_errors,
        notes,
    }
}

/// No estimate anywhere, and why.
fn unknown(points: usize, cusps: usize, why: &str) -> CurveErrors {
    CurveErrors {
        points: vec![None; points],
        cusps: vec![None; cusps],
        notes: vec![format!(
            "the curve's discretization error is unknown: the family cannot be refined: {why}"
        )],
    }
}

/// The index (0 or 1) of the parameter the curve moves along most at
/// `point`: held fixed when the point is located again.
fn held(n: usize, point: &CurvePoint) -> usize {
    usize::from(point.tangent[n + 1].abs() >= point.tangent[n].abs())
}

/// (e₁, e₂) of `point` from its relocation `fine` on the refined family:
/// the free parameter's shift, Richardson-scaled, and the held one's
/// through the curve's slope.
fn point_error(n: usize, point: &CurvePoint, fine: &CurvePoint, scale: f64) -> [f64; 2] {
    let fixed = held(n, point);
    let free = 1 - fixed;
    let shift = (point.parameters[free] - fine.parameters[free]).abs() * scale;
    let slope = (point.tangent[n + fixed] / point.tangent[n + free]).abs();
    let mut e = [0.0; 2];
    e[free] = shift;
    e[fixed] = shift * slope;
    e
}

/// `point` located again on the refined system `fine` at the same value
/// of its held parameter, with its tangent there (oriented as the
/// point's own).
fn relocate(
    aug: &Augmented,
    fine: &Augmented,
    point: &CurvePoint,
    opts: &CurveOptions,
) -> Result<CurvePoint, String> {
    let (n, nf) = (aug.n, fine.n);
    let [p1, p2] = point.parameters;
    let fixed = held(n, point);
    let x = fine
        .slice(p2)
        .carried(&aug.slice(p2), &point.unknowns, p1)
        .map_err(|e| format!("the point cannot be carried onto the refined family: {e}"))?;
    let mut z0 = x.clone();
    z0.extend_from_slice(&point.parameters);
    z0.resize(fine.unknowns(), 0.0);
    let refined = |e: super::PointError| format!("on the refined discretization {e}");
    let (_, fx) = fine.evaluate(&z0).map_err(refined)?;
    let (b, c) = Augmented::null_vectors(&fx, p1).map_err(refined)?;
    let mut hold = vec![0.0; fine.unknowns()];
    hold[nf + fixed] = 1.0;
    let (z, mut at, _) = fine
        .correct(&z0, &hold, (&b, &c), &x, opts.tolerance)
        .map_err(refined)?
        .ok_or("on the refined discretization the augmented Newton did not converge")?;
    let mut t = fine
        .tangent(&mut at, &hold)
        .ok_or("on the refined discretization the curve has no tangent")?;
    if t[nf + fixed] * point.tangent[n + fixed] < 0.0 {
        for v in &mut t {
            *v = -*v;
        }
    }
    curve_point(fine, &z, t, &b, &c).map_err(refined)
}

/// The errors of `cusp`'s two parameters: the cusp located again between
/// the relocated points around it.
fn cusp_error(
    fine: &Augmented,
    relocated: &[Result<CurvePoint, String>],
    cusp: &Cusp,
    opts: &CurveOptions,
    scale: f64,
) -> Result<[f64; 2], String> {
    let around = |i: usize| -> Result<&CurvePoint, String> {
        relocated
            .get(i)
            .ok_or_else(|| "it has no point after it".to_string())?
            .as_ref()
            .map_err(|why| format!("a point around it was not located again ({why})"))
    };
    let (a, b) = (around(cusp.after)?, around(cusp.after + 1)?);
    if projected(a, fine.n).dot(&projected(b, fine.n)) >= 0.0 {
        return Err(
            "the refined curve does not turn back between the points around it, so the cusp \
             moved by more than their spacing"
                .into(),
        );
    }
    let located =
        locate_cusp(fine, a, b, opts).map_err(|e| format!("on the refined discretization {e}"))?;
    let [p1, p2] = cusp.point.parameters;
    let [f1, f2] = located.parameters;
    Ok([(p1 - f1).abs() * scale, (p2 - f2).abs() * scale])
}
