//! The Hessian spectrum along a branch, tracked by eigenvector overlap.
//!
//! Sorting eigenvalues by size mixes up modes where two curves cross; the
//! tracker matches each new eigenvector to the previous one it overlaps
//! most in the G (L²) inner product, so that a column of the diagram is one
//! mode.
//!
//! Each point's eigenpairs start from the previous point's vectors
//! ([`crate::numerics::subspace`]: a few shift-invert sweeps with
//! Rayleigh–Ritz, certified by one Sturm count, which also gives the Morse
//! index where the spectrum keeps clear of zero); the full solve runs only at
//! the first point of a branch, on a constrained pencil, and where the warm
//! start cannot vouch for its pairs.

use std::cell::{Ref, RefCell};

use nalgebra::Vector3;

use super::family::{Family, PointError};
use crate::equations::RodSample;
use crate::numerics::banded::SymmetricBanded;
use crate::numerics::eigen::Eigenpairs;
use crate::numerics::subspace::lowest_eigenpairs_from;
use crate::stability::constrained::{
    count_below_constrained, lowest_eigenpairs_constrained, Constraints,
};
use crate::stability::{
    coefficients, support_constraints, Block, FiniteElements, StabilityOptions,
};

/// Tracked modes: per block, the eigenvector of each tracked eigenvalue (in
/// tracked order), then the `GUARD` (2) next Ritz vectors that keep the warm
/// start of the next point converging fast.
pub type Modes = Vec<Vec<Vec<f64>>>;

/// Ritz vectors carried beyond the tracked ones: the warm start's error in
/// λ_i shrinks by (λ_i − σ)/(λ_{count+GUARD+1} − σ) per sweep.
pub const GUARD: usize = 2;

/// The measured spectrum at one point.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrum {
    /// Tracked eigenvalues, block after block.
    pub values: Vec<f64>,
    /// Eigenvectors per block, in tracked order, then the guard vectors.
    pub vectors: Modes,
    /// Morse index per block.
    pub block_morse: Vec<usize>,
    /// Total Morse index.
    pub morse_index: usize,
    /// √∫|κ|² ds.
    pub curvature_norm: f64,
    /// The rod at the tracker's equally spaced shape points (position,
    /// directors, curvature, moment, force).
    pub shape: Vec<RodSample>,
    /// The tip sample.
    pub tip: RodSample,
}

/// K and G of one block.
type BlockMatrices = (SymmetricBanded, SymmetricBanded, Constraints);

/// The tracker's data on one mesh ([`Tracker::mesh_on`]).
#[derive(Debug, Clone)]
struct MeshData {
    /// The mesh.
    fe: FiniteElements,
    /// G of every block: the L² Gram matrix.
    masses: Vec<SymmetricBanded>,
    /// The quadrature points and the shape points (the last is the tip),
    /// merged in increasing order: one integration samples them all.
    points: Vec<f64>,
    /// Whether each of `points` is a quadrature point (else a shape point).
    quadrature: Vec<bool>,
    /// The quadrature weights.
    weights: Vec<f64>,
}

/// Measures spectra and keeps the last eigenvectors for matching.
#[derive(Debug, Clone)]
pub struct Tracker {
    blocks: Vec<Block>,
    opts: StabilityOptions,
    base_length: f64,
    /// The base rod's interior point loads: element boundaries there.
    base_breaks: Vec<f64>,
    /// Equally spaced points of the stored shape (≥ 2; the last is the tip).
    shape_points: usize,
    previous: Option<Modes>,
    previous_values: Option<Vec<Vec<f64>>>,
    /// What depends on the mesh alone (length, elements, order, base),
    /// not on the shape: along a branch that keeps the length it is made
    /// once (the same sums, so bit for bit the same matrices and points).
    masses: RefCell<Option<MeshData>>,
    /// The block and eigenvectors (tracked and guard) of the last trial
    /// point of an event's location ([`Tracker::trial_nearest_zero`]),
    /// which start the next trial's eigenpairs; cleared when a location
    /// begins ([`Tracker::begin_trials`]).
    trials: RefCell<Option<(Block, Vec<Vec<f64>>)>>,
}

impl Tracker {
    /// A tracker of `blocks` with the discretization in `opts`.
    pub fn new(family: &Family, blocks: Vec<Block>, opts: StabilityOptions) -> Self {
        // The base rod's own length (a failed rod_at(0) used to fall back to
        // a length of 1 for the nodes of the written modes).
        let base_length = family.base_length();
        Tracker {
            blocks,
            opts,
            base_length,
            base_breaks: family.base_jumps(),
            shape_points: 21,
            previous: None,
            previous_values: None,
            masses: RefCell::new(None),
            trials: RefCell::new(None),
        }
    }

    /// The same tracker storing `points` shape points per point (at least
    /// 2: the clamp and the tip).
    #[must_use]
    pub fn with_shape_points(self, points: usize) -> Self {
        Tracker {
            shape_points: points.max(2),
            ..self
        }
    }

    /// The same tracker on `factor` times the elements (same order and
    /// eigenvalue count; no remembered vectors, a fresh mass cache): the
    /// finer meshes of a crossing located by Richardson extrapolation.
    /// None where the finer mesh is refused.
    pub fn refined(&self, factor: usize) -> Option<Tracker> {
        let opts = self
            .opts
            .with_elements(self.opts.elements() * factor)
            .ok()?;
        Some(Tracker {
            opts,
            previous: None,
            previous_values: None,
            masses: RefCell::new(None),
            trials: RefCell::new(None),
            ..self.clone()
        })
    }

    /// The Lagrange order of the elements: the eigenvalues converge at
    /// order 2·order in the element size.
    pub fn order(&self) -> usize {
        self.opts.order()
    }

    /// The blocks, in the order of the eigenvalue columns.
    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }

    /// Names of the eigenvalue columns.
    pub fn names(&self) -> Vec<String> {
        self.blocks
            .iter()
            .flat_map(|b| (0..self.opts.eigenvalues()).map(move |i| format!("{}[{i}]", b.name())))
            .collect()
    }

    /// Finite-element nodes of the modes (at the base length).
    pub fn nodes(&self) -> Vec<f64> {
        FiniteElements::new(self.base_length, self.opts.elements(), self.opts.order())
            .with_breaks(&self.base_breaks)
            .nodes()
    }

    /// Forget the previous eigenvectors (a new branch starts).
    pub fn reset(&mut self) {
        self.previous = None;
        self.previous_values = None;
    }

    /// K and G of every block at (x, p), with the curvature norm.
    fn matrices(
        &self,
        family: &Family,
        x: &[f64],
        p: f64,
    ) -> Result<(FiniteElements, Vec<BlockMatrices>, f64, Vec<RodSample>), PointError> {
        let rod = family.rod_at(p)?;
        let fe = FiniteElements::new(rod.length(), self.opts.elements(), self.opts.order())
            .with_breaks(&rod.loads().jumps())
            .with_hinged_base(rod.clamp().hinge);
        // One integration for the quadrature points and the shape points
        // (the last is the tip), merged once per mesh.
        let mesh = self.mesh_on(&fe, rod.length());
        let mut samples = Vec::with_capacity(mesh.weights.len());
        let mut shape = Vec::with_capacity(self.shape_points);
        let all = family.samples(x, p, &mesh.points)?;
        for (sample, &at_quadrature) in all.into_iter().zip(&mesh.quadrature) {
            if at_quadrature {
                samples.push(sample);
            } else {
                shape.push(sample);
            }
        }
        let turn = fe.h()
            * samples
                .iter()
                .map(|s| s.curvature.norm())
                .fold(0.0, f64::max);
        if turn.is_nan() || turn > crate::stability::MAX_TURN_PER_ELEMENT {
            return Err(PointError::Unresolved {
                p,
                turn,
                elements: (turn / crate::stability::TURN_PER_ELEMENT * self.opts.elements() as f64)
                    .ceil(),
            });
        }
        let norm = samples
            .iter()
            .zip(&mesh.weights)
            .map(|(s, w)| w * s.curvature.norm_squared())
            .sum::<f64>()
            .sqrt();
        let c = coefficients(&rod, &samples);
        let tip = shape.last().expect("at least two shape points");
        let mats = self
            .blocks
            .iter()
            .zip(&mesh.masses)
            .map(|(&b, g)| {
                let constraints = support_constraints(&rod, &fe, b, &samples, tip)
                    .map_err(|e| PointError::Eigen(e.to_string()))?;
                Ok((fe.stiffness(&c, b), g.clone(), constraints))
            })
            .collect::<Result<_, PointError>>()?;
        Ok((fe, mats, norm, shape))
    }

    /// The spectrum at (x, p), matched to the previous point's modes, which
    /// it then replaces ([`Tracker::evaluate`], then [`Tracker::remember`]).
    pub fn measure(&mut self, family: &Family, x: &[f64], p: f64) -> Result<Spectrum, PointError> {
        let spectrum = self.evaluate(family, x, p)?;
        self.remember(&spectrum.values, spectrum.vectors.clone());
        Ok(spectrum)
    }

    /// The modes (and their eigenvalues, `eigenvalues` per block) of the
    /// point the next one is matched to.
    pub fn remember(&mut self, values: &[f64], vectors: Modes) {
        self.previous = Some(vectors);
        let k = self.opts.eigenvalues();
        self.previous_values = Some(values.chunks(k).map(<[f64]>::to_vec).collect());
    }

    /// The spectrum at (x, p), matched to the previous point's modes,
    /// which stay remembered (a trial point need not replace them).
    pub fn evaluate(&self, family: &Family, x: &[f64], p: f64) -> Result<Spectrum, PointError> {
        let (_, mats, norm, shape_samples) = self.matrices(family, x, p)?;
        let mut values = vec![];
        let mut vectors = vec![];
        let mut block_morse = vec![];
        for (bi, (k, g, constraints)) in mats.iter().enumerate() {
            // The previous point's lowest two eigenvalues place the shift.
            let near = self
                .previous_values
                .as_ref()
                .and_then(|v| v.get(bi))
                .filter(|b| !b.is_empty())
                .map(|b| {
                    let mut b: Vec<f64> = b.clone();
                    b.sort_by(f64::total_cmp);
                    // One tracked eigenvalue: it is both of the lowest two.
                    (b[0], *b.get(1).unwrap_or(&b[0]))
                });
            let (pairs, certified_morse) = self.pairs(bi, k, g, constraints, near)?;
            let count = self.opts.eigenvalues();
            // Every block fills its `eigenvalues` columns of the diagram; a
            // mesh with fewer unknowns than that cannot (the eigensolver
            // returns at most the block's dimension).
            if pairs.values.len() < count {
                return Err(PointError::Eigen(format!(
                    "the {} block has only {} eigenvalues on {} elements of order {}, \
                     {} are tracked: lower continuation.eigenvalues or raise continuation.elements",
                    self.blocks[bi].name(),
                    pairs.values.len(),
                    self.opts.elements(),
                    self.opts.order(),
                    self.opts.eigenvalues()
                )));
            }
            let (tracked, guard) = pairs.vectors.split_at(count);
            let order = match &self.previous {
                Some(prev) => match_modes(&prev[bi][..count.min(prev[bi].len())], tracked, g),
                None => (0..count).collect(),
            };
            values.extend(order.iter().map(|&i| pairs.values[i]));
            vectors.push(
                order
                    .iter()
                    .map(|&i| tracked[i].clone())
                    .chain(guard.iter().cloned())
                    .collect::<Vec<_>>(),
            );
            // The warm pairs' certificate gives the count below 0 where
            // the spectrum keeps clear of it; else Sylvester's inertia of K.
            let morse = match certified_morse {
                Some(morse) => morse,
                None => count_below_constrained(k, g, constraints, 0.0)
                    .below()
                    .ok_or_else(|| {
                        PointError::Eigen(format!(
                            "the Morse index of the {} block cannot be counted (K singular to working precision)",
                            self.blocks[bi].name()
                        ))
                    })?,
            };
            block_morse.push(morse);
        }
        Ok(Spectrum {
            tip: shape_samples
                .last()
                .expect("at least two shape points")
                .clone(),
            values,
            vectors,
            morse_index: block_morse.iter().sum(),
            block_morse,
            curvature_norm: norm,
            shape: shape_samples,
        })
    }

    /// The eigenvalue of `block` nearest zero at (x, p) and its mode as
    /// nodal rotations (for locating and classifying events).
    pub fn nearest_zero(
        &self,
        family: &Family,
        x: &[f64],
        p: f64,
        block: Block,
    ) -> Result<(f64, Vec<Vector3<f64>>), PointError> {
        let (fe, mats, _, _) = self.matrices(family, x, p)?;
        let bi = self.block_index(block);
        let (k, g, constraints) = &mats[bi];
        // The full solve, never the warm start: the located point and its
        // null mode (sign included) must not depend on the path that led
        // there, so that a resumed diagram is the uninterrupted one.
        let pairs = lowest_eigenpairs_constrained(k, g, constraints, self.opts.eigenvalues(), None)
            .map_err(|e| PointError::Eigen(e.to_string()))?;
        let i = (0..pairs.values.len())
            .min_by(|&a, &b| pairs.values[a].abs().total_cmp(&pairs.values[b].abs()))
            .expect("at least one eigenvalue");
        Ok((
            pairs.values[i],
            fe.nodal_rotations(block, &pairs.vectors[i]),
        ))
    }
}

impl Tracker {
    /// The index of `block` among the tracked blocks (the order of the
    /// matrices); a block not tracked is a caller's error.
    fn block_index(&self, block: Block) -> usize {
        self.blocks
            .iter()
            .position(|&b| b == block)
            .expect("a tracked block")
    }

    /// Forget the trial vectors: an event's location begins, and its first
    /// trial solves in full, so that the location depends only on its
    /// bracket (the same in a resumed run).
    pub fn begin_trials(&self) {
        *self.trials.borrow_mut() = None;
    }

    /// The eigenvalue of `block` nearest zero at (x, p), among the
    /// `eigenvalues` lowest, at a trial point of an event's location: the
    /// eigenpairs warm-started from the last trial's vectors
    /// ([`lowest_eigenpairs_from`], certified by a Sturm count) where there
    /// are such and the pencil is unconstrained, else the full solve; the
    /// vectors are kept for the next trial. The located point's own
    /// eigenvalue and null mode come from [`Tracker::nearest_zero`]'s full
    /// solve. The warm pairs meet the backward error
    /// [`crate::numerics::subspace::ACCEPT`], which moves an eigenvalue near
    /// zero by round-off (4e-15 at 3e-7 on the Euler column) and so its
    /// root in p by far less than the event tolerance.
    pub fn trial_nearest_zero(
        &self,
        family: &Family,
        x: &[f64],
        p: f64,
        block: Block,
    ) -> Result<f64, PointError> {
        let (_, mats, _, _) = self.matrices(family, x, p)?;
        let bi = self.block_index(block);
        let (k, g, constraints) = &mats[bi];
        let count = self.opts.eigenvalues();
        let start = self
            .trials
            .borrow_mut()
            .take()
            .filter(|(b, _)| *b == block && constraints.is_empty());
        let warm = start.and_then(|(_, start)| lowest_eigenpairs_from(k, g, count, &start));
        let pairs = match warm {
            Some(warm) => warm.pairs,
            None => lowest_eigenpairs_constrained(k, g, constraints, count + GUARD, None)
                .or_else(|_| lowest_eigenpairs_constrained(k, g, constraints, count, None))
                .map_err(|e| PointError::Eigen(e.to_string()))?,
        };
        let nearest = pairs.values[..count.min(pairs.values.len())]
            .iter()
            .copied()
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            .ok_or_else(|| PointError::Eigen("no eigenvalue".into()))?;
        if pairs.vectors.len() > count {
            *self.trials.borrow_mut() = Some((block, pairs.vectors));
        }
        Ok(nearest)
    }

    /// On the mesh `fe` of a rod of length `length`: the sample points
    /// (quadrature and shape points merged in increasing order), which of
    /// them are quadrature points, the quadrature weights and G of every
    /// block — made only when the mesh differs from the last one's.
    fn mesh_on(&self, fe: &FiniteElements, length: f64) -> Ref<'_, MeshData> {
        {
            let mut cache = self.masses.borrow_mut();
            if cache.as_ref().is_none_or(|data| data.fe != *fe) {
                *cache = Some(self.mesh_data(fe, length));
            }
        }
        Ref::map(self.masses.borrow(), |cache| {
            cache.as_ref().expect("made just above")
        })
    }

    /// [`Tracker::mesh_on`]'s data, made.
    fn mesh_data(&self, fe: &FiniteElements, length: f64) -> MeshData {
        // L·(i/last), not L·i/last: i/last ≤ 1 rounds to exactly 1 at the
        // tip, so no shape point lands an ulp beyond the rod (the
        // sampler serves [0, L] and would leave such a point out).
        let last = (self.shape_points - 1) as f64;
        let mut all: Vec<(f64, bool)> = fe
            .quadrature_points()
            .into_iter()
            .map(|s| (s, true))
            .chain((0..self.shape_points).map(|i| (length * (i as f64 / last), false)))
            .collect();
        all.sort_by(|a, b| a.0.total_cmp(&b.0));
        MeshData {
            fe: fe.clone(),
            masses: self.blocks.iter().map(|&b| fe.mass(b)).collect(),
            points: all.iter().map(|a| a.0).collect(),
            quadrature: all.iter().map(|a| a.1).collect(),
            weights: fe.quadrature_weights(),
        }
    }

    /// The lowest `eigenvalues` + [`GUARD`] eigenpairs of block `bi`
    /// (fewer when the block has fewer unknowns), in increasing order:
    /// warm-started from the previous point's vectors when there are such
    /// and the pencil is unconstrained, else — or when the warm start
    /// cannot vouch for its pairs — the full solve, its shift placed by
    /// `near` (the previous lowest two eigenvalues). With them the Morse
    /// index of the block where the warm start's certificate reads it
    /// ([`crate::numerics::subspace::WarmPairs::count_below`] at 0), None
    /// where it must be counted.
    fn pairs(
        &self,
        bi: usize,
        k: &SymmetricBanded,
        g: &SymmetricBanded,
        constraints: &Constraints,
        near: Option<(f64, f64)>,
    ) -> Result<(Eigenpairs, Option<usize>), PointError> {
        let count = self.opts.eigenvalues();
        let warm = self
            .previous
            .as_ref()
            .and_then(|prev| prev.get(bi))
            .filter(|_| constraints.is_empty())
            .and_then(|start| lowest_eigenpairs_from(k, g, count, start));
        match warm {
            Some(warm) => {
                let morse = warm.count_below(0.0);
                Ok((warm.pairs, morse))
            }
            // With the guard vectors when they converge too; else the
            // tracked ones alone (the next point then solves in full again).
            None => lowest_eigenpairs_constrained(k, g, constraints, count + GUARD, near)
                .or_else(|_| lowest_eigenpairs_constrained(k, g, constraints, count, near))
                .map(|pairs| (pairs, None))
                .map_err(|e| PointError::Eigen(e.to_string())),
        }
    }
}

/// For each previous mode (in order), the unused new mode with the largest
/// |⟨v_old, G v_new⟩|.
fn match_modes(previous: &[Vec<f64>], new: &[Vec<f64>], g: &SymmetricBanded) -> Vec<usize> {
    let mut used = vec![false; new.len()];
    let mut order = Vec::with_capacity(new.len());
    for old in previous {
        if old.len() != g.size() {
            break;
        }
        let best = (0..new.len()).filter(|&j| !used[j]).max_by(|&a, &b| {
            g.inner(old, &new[a])
                .abs()
                .total_cmp(&g.inner(old, &new[b]).abs())
        });
        if let Some(j) = best {
            used[j] = true;
            order.push(j);
        }
    }
    order.extend((0..new.len()).filter(|&j| !used[j]));
    order
}
