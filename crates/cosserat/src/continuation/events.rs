//! Folds and branch points between two points of a branch: detection,
//! location by regula falsi (Illinois) in the arclength, classification,
//! and branch switching.

use nalgebra::{DMatrix, DVector};

use super::{Point, Run, SpecialKind, SpecialPoint};
use crate::model::ModelLevel;
use crate::numerics::scalar::{End, Illinois};
use crate::stability::Block;

/// A test function along the step from a point: f(σ) and the point there.
type Located = (f64, Vec<f64>, f64, Vec<f64>);

impl Run<'_> {
    /// The special points between consecutive points `a` and `b`, and a
    /// note for every event detected there that could not be located (it
    /// is reported, never dropped).
    pub(super) fn events(
        &mut self,
        a: &Point,
        b: &Point,
        sign: f64,
        branch: usize,
        index: usize,
    ) -> (Vec<SpecialPoint>, Vec<String>) {
        let n = a.unknowns.len();
        let fold = a.tangent[n] * b.tangent[n] < 0.0;
        let spectra_a = self.block_morse(a);
        let spectra_b = self.block_morse(b);
        let blocks: Vec<Block> = self.tracker.blocks().to_vec();
        let changed: Vec<(Block, usize)> = blocks
            .iter()
            .zip(spectra_a.iter().zip(&spectra_b))
            .filter(|(_, (x, y))| x != y)
            .map(|(blk, (x, y))| (*blk, x.abs_diff(*y)))
            .collect();
        let wanted: Vec<(SpecialKind, Block, usize)> = if fold {
            let block = changed.first().map_or(blocks[0], |c| c.0);
            vec![(SpecialKind::Fold, block, 1)]
        } else {
            changed
                .into_iter()
                .map(|(block, jump)| (SpecialKind::BranchPoint, block, jump))
                .collect()
        };
        let (mut found, mut missed) = (vec![], vec![]);
        for (kind, block, jump) in wanted {
            match self.locate(a, b, sign, branch, index, kind, block, jump) {
                Some(sp) => found.push(sp),
                None => missed.push(format!(
                    "branch {branch}: a {} ({} block, Morse index {} → {}) between points {index} \
                     and {} at parameter {:.10} … {:.10} could not be located",
                    kind.name(),
                    block.name(),
                    a.morse_index,
                    b.morse_index,
                    index + 1,
                    a.parameter,
                    b.parameter
                )),
            }
        }
        (found, missed)
    }

    fn block_morse(&mut self, p: &Point) -> Vec<usize> {
        // The per-block Morse indices are recomputed from the stored
        // eigenvalues: tracked values below zero, plus any beyond the
        // computed ones is impossible (they are the lowest).
        let k = self.opts.stability.eigenvalues();
        p.eigenvalues
            .chunks(k)
            .map(|c| c.iter().filter(|v| **v < 0.0).count())
            .collect()
    }

    /// Whether the model's BVP Jacobian sees the block's mode.
    fn representable(&self, block: Block) -> bool {
        matches!(
            (self.family.level(), block),
            (ModelLevel::Kirchhoff | ModelLevel::Cosserat, _)
                | (ModelLevel::Planar, Block::InPlane)
        )
    }

    /// The test function at arclength σ from `a`: the p-component of the
    /// tangent (folds), det F_x (simple branch points the model sees), or
    /// the block eigenvalue nearest zero.
    fn test_at(
        &self,
        a: &Point,
        sign: f64,
        sigma: f64,
        kind: SpecialKind,
        block: Block,
        use_det: bool,
    ) -> Option<Located> {
        let (x, p, tangent, _) = self.step(a, sign, sigma).ok()??;
        let n = x.len();
        let value = match kind {
            SpecialKind::Fold => tangent[n],
            SpecialKind::BranchPoint if use_det => self.det(&x, p)?,
            SpecialKind::BranchPoint => {
                self.tracker.nearest_zero(self.family, &x, p, block).ok()?.0
            }
        };
        Some((value, x, p, tangent))
    }

    fn det(&self, x: &[f64], p: f64) -> Option<f64> {
        let n = x.len();
        let (mut r, mut j) = (DVector::zeros(n), DMatrix::zeros(n, n));
        self.family.residual(x, p, &mut r, &mut j).ok()?;
        Some(j.determinant())
    }

    /// Locates the event between `a` and `b` by the Illinois method on the
    /// arclength σ ∈ (0, σ_b), σ_b = τ_aᵀ(z_b − z_a).
    #[allow(clippy::too_many_arguments)]
    fn locate(
        &mut self,
        a: &Point,
        b: &Point,
        sign: f64,
        branch: usize,
        index: usize,
        kind: SpecialKind,
        block: Block,
        jump: usize,
    ) -> Option<SpecialPoint> {
        let n = a.unknowns.len();
        let t: Vec<f64> = a.tangent.iter().map(|v| v * sign).collect();
        let mut za = a.unknowns.clone();
        za.push(a.parameter);
        let mut zb = b.unknowns.clone();
        zb.push(b.parameter);
        let span: f64 = t
            .iter()
            .zip(zb.iter().zip(&za))
            .map(|(t, (y, x))| t * (y - x))
            .sum();
        let use_det = jump == 1 && self.representable(block);
        let f_lo = self.test_at(a, sign, 1e-12 * span, kind, block, use_det)?.0;
        let f_hi = self.test_at(a, sign, span, kind, block, use_det)?.0;
        let mut bracket = Illinois::new(0.0, span, f_lo, f_hi)?;
        let mut best = self.test_at(a, sign, 0.5 * span, kind, block, use_det)?;
        let (mut p_lo, mut p_hi) = (a.parameter, b.parameter);
        for _ in 0..80 {
            let sigma = bracket.next_point();
            best = self.test_at(a, sign, sigma, kind, block, use_det)?;
            match bracket.update(sigma, best.0) {
                End::Lower => p_lo = best.2,
                End::Upper => p_hi = best.2,
            }
            let tol = self.opts.event_tolerance * best.2.abs().max(1.0);
            if (p_hi - p_lo).abs() <= tol && bracket.width() <= 1e3 * tol
                || best.0 == 0.0
                || bracket.width() <= 1e-15 * span
            {
                break;
            }
        }
        let (_, x, p, tangent) = best;
        let stored: Vec<f64> = tangent.iter().map(|v| v * sign).collect();
        let (eigenvalue, null_mode) = self.tracker.nearest_zero(self.family, &x, p, block).ok()?;
        // |det F_x| relative to its size at the two neighbours; NaN (not a
        // default) where a determinant cannot be evaluated.
        let det_here = self.det(&x, p).unwrap_or(f64::NAN);
        let det_scale = self
            .det(&a.unknowns, a.parameter)
            .unwrap_or(f64::NAN)
            .abs()
            .max(self.det(&b.unknowns, b.parameter).unwrap_or(f64::NAN).abs());
        let mut tracker = self.tracker.clone();
        tracker.reset();
        let spectrum = tracker.measure(self.family, &x, p).ok()?;
        let point = self.point_from(x, p, stored, spectrum).ok()?;
        let _ = n;
        Some(SpecialPoint {
            kind,
            branch,
            index,
            symmetry_breaking: symmetry_breaking(block, &point, &null_mode),
            point,
            block,
            null_mode,
            children: vec![],
            singularity: ((det_here / det_scale).abs(), eigenvalue),
        })
    }

    /// New branches from a simple branch point the model represents: the
    /// null vector of [F_x F_p] orthogonal to the tangent, both ways.
    /// `neighbour` is a regular point of the same branch: its Jacobian sets
    /// the scale against which the null space of [F_x F_p] is judged.
    pub(super) fn switch(&mut self, sp: &SpecialPoint, neighbour: &Point) -> Vec<(Point, f64)> {
        if sp.kind != SpecialKind::BranchPoint || !self.representable(sp.block) {
            return vec![];
        }
        let x = &sp.point.unknowns;
        let p = sp.point.parameter;
        let n = x.len();
        let (mut r, mut fx) = (DVector::zeros(n), DMatrix::zeros(n, n));
        if self.family.residual(x, p, &mut r, &mut fx).is_err() {
            return vec![];
        }
        let Ok(fp) = self.family.parameter_derivative(x, p) else {
            return vec![];
        };
        let mut e = DMatrix::zeros(n, n + 1);
        e.view_mut((0, 0), (n, n)).copy_from(&fx);
        e.view_mut((0, n), (n, 1)).copy_from(&fp);
        // Null space of E: eigenvectors of EᵀE with the two smallest
        // eigenvalues; the new direction is the part orthogonal to τ.
        let ete = e.transpose() * &e;
        let eig = ete.symmetric_eigen();
        let mut idx: Vec<usize> = (0..=n).collect();
        idx.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let (mut rn, mut jn) = (DVector::zeros(n), DMatrix::zeros(n, n));
        if self
            .family
            .residual(&neighbour.unknowns, neighbour.parameter, &mut rn, &mut jn)
            .is_err()
        {
            return vec![];
        }
        let scale = jn
            .norm_squared()
            .max(eig.eigenvalues[idx[n]].abs())
            .max(f64::MIN_POSITIVE);
        if eig.eigenvalues[idx[1]].abs() > 1e-6 * scale {
            return vec![];
        }
        let tau = DVector::from_column_slice(&sp.point.tangent);
        let mut best: Option<DVector<f64>> = None;
        for &i in &idx[..2] {
            let v: DVector<f64> = eig.eigenvectors.column(i).into_owned();
            let w = &v - &tau * tau.dot(&v);
            if best.as_ref().is_none_or(|b| w.norm() > b.norm()) {
                best = Some(w);
            }
        }
        let phi = best.expect("two null vectors").normalize();
        let eps = 0.5 * self.opts.step;
        let mut z = x.clone();
        z.push(p);
        let mut starts = vec![];
        for dir in [1.0, -1.0] {
            let t: Vec<f64> = phi.iter().map(|v| v * dir).collect();
            let pred: Vec<f64> = z.iter().zip(&t).map(|(a, b)| a + eps * b).collect();
            let Ok(Some((zn, _, _))) = self.correct(&pred, &t) else {
                continue;
            };
            let Ok(tangent) = self.tangent(&zn[..n], zn[n], &t) else {
                continue;
            };
            self.tracker.reset();
            if let Ok(pt) = self.point(zn[..n].to_vec(), zn[n], tangent) {
                starts.push((pt, 1.0));
            }
        }
        starts
    }
}

/// Out-of-plane modes of a planar branch, and bending modes of a straight
/// one, break a symmetry of the branch.
fn symmetry_breaking(block: Block, point: &Point, mode: &[nalgebra::Vector3<f64>]) -> bool {
    let straight = point.norm < 1e-8;
    let out_of_plane = mode.iter().map(|w| w[0].abs() + w[2].abs()).sum::<f64>();
    let in_plane = mode.iter().map(|w| w[1].abs()).sum::<f64>();
    match block {
        Block::OutOfPlane => true,
        Block::InPlane => straight,
        Block::Full => out_of_plane > in_plane || straight,
    }
}
