//! A multiple branch point located again on another discretization of
//! the same family: the root in p of an entry of Govaerts' bordered G,
//!
//!   [F_x Ψ; Φᵀ 0] [V; G] = [0; I_m],
//!
//! along the branch through a given point, each trial point solved by
//! Newton at fixed p ([`Run::newton_at_fixed_p`]). A multiple branch
//! point is not a fold: the branch crosses it with p'(σ) ≠ 0, so p
//! parametrizes it locally and no arclength is needed. The borders Φ, Ψ
//! are the singular vectors of the m smallest singular values of F_x at
//! the given point (nearly singular there: it is the point located on the
//! coarser discretization), fixed for the whole location, as the run's own
//! bordered test fixes them for its bracket. The p-bracket is grown about
//! the point until an entry of G changes sign, then closed by Illinois to
//! the event tolerance.
//!
//! Newton at fixed p is near-singular close to the branch point along the
//! crossing directions only. A branch point that persists on every
//! discretization is one of symmetry (the straight rod's: every mesh keeps
//! it), and then the branch lies in the symmetric subspace, where F_x is
//! regular, and so do the carried point and its residual: Newton's
//! corrections have no part along the crossing modes, and the trials stay
//! on the branch.
//!
//! Used by `discretization.rs` on [`super::Family::refined`]. It locates
//! one root and nothing else — no events are detected and no error is
//! estimated here — so a location on the refined family never estimates
//! its own error again.

use nalgebra::DMatrix;

use super::events::sign_changing_entry;
use super::Run;
use crate::numerics::scalar::{End, Illinois};

/// The first half-width of the p-bracket, relative to max(|p|, 1): the
/// discretization errors measured lie between 1e-13 and 1e-3 relative, so
/// the bracket grows from here by [`GROWTH`] until it holds the root.
const FIRST_WIDTH: f64 = 1e-7;

/// The factor by which the p-bracket grows while no entry of G changes
/// sign.
const GROWTH: f64 = 10.0;

/// The most Illinois trials while closing the bracket (it converges
/// superlinearly; 80 is the run's own bound).
const MAX_TRIALS: usize = 80;

/// A point of the branch at fixed p and G there.
#[derive(Clone)]
struct Trial {
    p: f64,
    x: Vec<f64>,
    g: DMatrix<f64>,
}

/// The borders Φ (`right`) and Ψ (`left`) of the test.
struct Borders {
    right: DMatrix<f64>,
    left: DMatrix<f64>,
}

impl Run<'_> {
    /// The parameter of the branch point of multiplicity `m` nearest
    /// (x0, p0) on this run's family: x0 lies near the branch (the point
    /// located on another discretization, carried onto this one), and the
    /// root is looked for within `reach` of p0 (the coarse step's length
    /// in p). Err says why it was not found: no borders, no sign change
    /// of G within reach, or Newton at fixed p failing before the bracket
    /// closed to the event tolerance (the width it reached is named).
    pub(super) fn bordered_root_in_p(
        &self,
        x0: &[f64],
        p0: f64,
        m: usize,
        reach: f64,
    ) -> Result<f64, String> {
        let (_, right, left) = self.borders_at(x0, p0, m).ok_or_else(|| {
            format!("the {m} smallest singular vectors of F_x could not be computed")
        })?;
        let borders = Borders { right, left };
        let (lo, hi, entry) = self.sign_change(x0, p0, &borders, reach)?;
        self.closed_bracket(lo, hi, entry, &borders)
    }

    /// The branch at p and G there: Newton at fixed p from `guess`, G
    /// from the bordered system. None where either fails.
    fn trial(&self, guess: Vec<f64>, p: f64, borders: &Borders) -> Option<Trial> {
        let x = self.newton_at_fixed_p(guess, p).ok()?;
        let g = self.bordered(&x, p, &borders.right, &borders.left)?;
        Some(Trial { p, x, g })
    }

    /// The p-bracket [p0 − w, p0 + w] grown by [`GROWTH`] from
    /// w = [`FIRST_WIDTH`] · max(|p0|, 1) until an entry of G changes sign
    /// across it ([`sign_changing_entry`]), and that entry. Each end is
    /// solved from the nearest point solved on its side before (x0 at
    /// first).
    fn sign_change(
        &self,
        x0: &[f64],
        p0: f64,
        borders: &Borders,
        reach: f64,
    ) -> Result<(Trial, Trial, (usize, usize)), String> {
        let mut width = FIRST_WIDTH * p0.abs().max(1.0);
        let (mut below, mut above) = (x0.to_vec(), x0.to_vec());
        while width <= reach {
            let lo = self.trial(below, p0 - width, borders);
            let hi = self.trial(above, p0 + width, borders);
            let (Some(lo), Some(hi)) = (lo, hi) else {
                return Err(format!(
                    "Newton at fixed p failed at parameter {p0:.12} ± {width:.1e}"
                ));
            };
            if let Some(entry) = sign_changing_entry(&lo.g, &hi.g) {
                return Ok((lo, hi, entry));
            }
            (below, above) = (lo.x, hi.x);
            width *= GROWTH;
        }
        Err(format!(
            "no entry of Govaerts' G changes sign within ±{reach:.1e} of parameter {p0:.12}"
        ))
    }

    /// Illinois on the entry of G from the bracket [lo, hi] until its
    /// width is within the event tolerance, each trial solved from the
    /// chord between the ends (an O(Δp²) guess); where Newton fails at
    /// a trial, up to three points halfway towards the nearer end are
    /// tried instead. The root is the false position of the final
    /// bracket's actual values (inside it, and closer to the root than
    /// either end).
    fn closed_bracket(
        &self,
        mut lo: Trial,
        mut hi: Trial,
        entry: (usize, usize),
        borders: &Borders,
    ) -> Result<f64, String> {
        let mut bracket = Illinois::new(lo.p, hi.p, lo.g[entry], hi.g[entry])
            .ok_or("the bracket holds no sign change")?;
        for _ in 0..MAX_TRIALS {
            let tol = self.opts.event_tolerance * lo.p.abs().max(1.0);
            if hi.p - lo.p <= tol {
                let (f_lo, f_hi) = (lo.g[entry], hi.g[entry]);
                return Ok((lo.p * f_hi - hi.p * f_lo) / (f_hi - f_lo));
            }
            let here = self
                .trial_near(&lo, &hi, bracket.next_point(), borders)
                .ok_or_else(|| {
                    format!(
                        "Newton at fixed p failed inside the bracket {:.12} … {:.12} (width \
                     {:.1e}, the event tolerance {tol:.1e})",
                        lo.p,
                        hi.p,
                        hi.p - lo.p
                    )
                })?;
            let value = here.g[entry];
            if value == 0.0 {
                return Ok(here.p);
            }
            match bracket.update(here.p, value) {
                End::Lower => lo = here,
                End::Upper => hi = here,
            }
        }
        Err(format!(
            "the bracket {:.12} … {:.12} did not close in {MAX_TRIALS} trials",
            lo.p, hi.p
        ))
    }

    /// The trial at q inside (lo, hi), or — where Newton fails there — at
    /// up to three points each halfway from the last try towards the
    /// nearer end; each from the chord between the ends' solutions.
    fn trial_near(&self, lo: &Trial, hi: &Trial, q: f64, borders: &Borders) -> Option<Trial> {
        let mut q = q;
        for _ in 0..4 {
            let t = (q - lo.p) / (hi.p - lo.p);
            let guess =
                lo.x.iter()
                    .zip(&hi.x)
                    .map(|(a, b)| a + t * (b - a))
                    .collect();
            if let Some(here) = self.trial(guess, q, borders) {
                return Some(here);
            }
            let nearer = if q - lo.p < hi.p - q { lo.p } else { hi.p };
            q = 0.5 * (q + nearer);
        }
        None
    }
}
