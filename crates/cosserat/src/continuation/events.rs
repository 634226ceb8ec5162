//! Folds and branch points between two points of a branch: detection,
//! location by regula falsi (Illinois) in the arclength on a test function
//! with a simple root — for a fold or a simple branch point then refined by
//! Newton on a minimally augmented system (`fold.rs`, `branch_point.rs`);
//! for a mode the model does not see, extrapolated from three
//! finite-element meshes —, classification, and branch switching.
//!
//! A fold is decided by the tangent's parameter component τ_p changing
//! sign, always, whatever the eigenvalues do; a branch point by a change
//! of a block's Morse index that no fold explains, its multiplicity the
//! size of the change. Where the BVP Jacobian sees the bifurcating mode, a
//! branch point is located on Govaerts' minimally augmented test function
//! (Govaerts, *Numerical Methods for Bifurcations of Dynamical Equilibria*,
//! SIAM 2000, Sec. 3.2; the `BorderedArray` branch-point test of
//! BifurcationKit.jl): with Φ, Ψ (n × m) the right and left singular
//! vectors of the m smallest singular values of F_x near the point, the
//! bordered system
//!
//!   [F_x Ψ; Φᵀ 0] [V; G] = [0; I_m]
//!
//! is regular at the singular point and G (m × m) vanishes there exactly
//! when dim ker F_x = m. An entry of G that changes sign has a simple
//! root, where det F_x has a root of order m (a double root for the pair
//! of an isotropic rod, which bisection on the determinant cannot see).
//! A simple branch point (m = 1) is bracketed on det F_x itself, whose
//! root is then simple; modes the model's Jacobian does not see (out of the
//! plane of a planar model) on the block's eigenvalue nearest zero, on
//! three meshes ([`Run::extrapolated_crossing`]).

use nalgebra::{DMatrix, DVector};

use super::corrector::{Linearization, DENSE_UP_TO};
use super::engine;
use super::kernel::BandedJacobian;
use super::Tracker;
use super::{Location, Point, Run, SpecialKind, SpecialPoint};
use crate::model::ModelLevel;
use crate::numerics::scalar::{End, Illinois};
use crate::numerics::staircase::{Staircase, StaircaseLu};
use crate::stability::Block;

/// A test function along the step from a point: f(σ) and the point there.
pub(super) type Located = (f64, Vec<f64>, f64, Vec<f64>);

/// A point of [`Run::point_at`]: unknowns, parameter, tangent, and F_x
/// there where its corrector evaluated it.
type Cut = (Vec<f64>, f64, Vec<f64>, Option<Linearization>);

/// A converged point of a location and its arclength σ from the start.
type Anchor = (f64, Located);

/// A root of a test function along a step: its arclength σ, the point
/// there, and the width of the parameter bracket it ended with.
struct Root {
    sigma: f64,
    located: Located,
    spread: f64,
    /// Where the bracket could not be closed and the root was interpolated
    /// from the samples on both sides (`interpolated_root.rs`): its
    /// estimated error in p.
    interpolated: Option<f64>,
}

/// The function whose sign change locates an event.
enum Test {
    /// The tangent's parameter component τ_p (folds).
    Fold,
    /// The entry `entry` of Govaerts' G with the borders Φ (`right`) and Ψ
    /// (`left`), fixed for the whole location.
    Bordered {
        right: DMatrix<f64>,
        left: DMatrix<f64>,
        entry: (usize, usize),
    },
    /// det F_x (a simple singularity the model sees: a simple root).
    Determinant,
    /// The block's eigenvalue nearest zero (modes the model's Jacobian
    /// does not see; accurate to the finite-element mesh).
    Eigenvalue(Block),
    /// The same on a finer mesh than the run's (the Richardson meshes of
    /// [`Run::extrapolated_crossing`]).
    EigenvalueOn(Block, Box<Tracker>),
}

/// An event to locate: its kind, block and multiplicity.
type Wanted = (SpecialKind, Block, usize);

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
        let (wanted, mut missed) = self.detect(a, b, branch, index);
        let mut found = vec![];
        for (kind, block, multiplicity) in wanted {
            let located = if kind == SpecialKind::Fold {
                let (located, note) =
                    self.locate_fold(a, b, sign, (branch, index), (kind, block, multiplicity));
                missed.extend(note);
                located
            } else {
                let (located, notes) =
                    self.locate(a, b, sign, (branch, index), (kind, block, multiplicity));
                missed.extend(notes);
                located
            };
            match located.len() {
                0 => missed.push(format!(
                    "branch {branch}: a {} ({} block, Morse index {} → {}, multiplicity \
                     {multiplicity}) between points {index} and {} at parameter {:.10} … {:.10} \
                     could not be located",
                    kind.name(),
                    block.name(),
                    a.morse_index,
                    b.morse_index,
                    index + 1,
                    a.parameter,
                    b.parameter
                )),
                _ => found.extend(located),
            }
        }
        (found, missed)
    }

    /// What happened between `a` and `b`: a fold where τ_p changes sign
    /// (whatever the eigenvalues did), else a branch point in every block
    /// whose Morse index changed, of multiplicity the change. Eigenvalues
    /// crossing zero at a fold beyond the one the fold explains are a
    /// note: a branch point there is not located (undecided), not dropped.
    fn detect(
        &mut self,
        a: &Point,
        b: &Point,
        branch: usize,
        index: usize,
    ) -> (Vec<Wanted>, Vec<String>) {
        let n = a.unknowns.len();
        let fold = a.tangent[n] * b.tangent[n] < 0.0;
        // Each block's Morse index as the tracker counted it, exact
        // whatever the number of tracked eigenvalues (counting the tracked
        // values below zero saturated at `eigenvalues`: the twisted rod's
        // second double crossing, Morse index 2 → 4 with three tracked,
        // was reported as a simple branch point).
        let (spectra_a, spectra_b) = (&a.block_morse, &b.block_morse);
        let changed: Vec<(Block, usize)> = self
            .tracker
            .blocks()
            .iter()
            .zip(spectra_a.iter().zip(spectra_b))
            .filter(|(_, (x, y))| x != y)
            .map(|(blk, (x, y))| (*blk, x.abs_diff(*y)))
            .collect();
        if !fold {
            let wanted = changed
                .into_iter()
                .map(|(block, jump)| (SpecialKind::BranchPoint, block, jump))
                .collect();
            return (wanted, vec![]);
        }
        let block = changed.first().map_or(self.tracker.blocks()[0], |c| c.0);
        let total: usize = changed.iter().map(|c| c.1).sum();
        let mut notes = vec![];
        if total > 1 {
            notes.push(format!(
                "branch {branch}: at the fold between points {index} and {} (parameter \
                 {:.10} … {:.10}) the Morse index changed by {total}: {} more eigenvalue(s) \
                 crossed zero than the fold explains; a branch point near the fold is not \
                 located",
                index + 1,
                a.parameter,
                b.parameter,
                total - 1
            ));
        }
        (vec![(SpecialKind::Fold, block, 1)], notes)
    }

    /// Whether the model's BVP Jacobian sees the block's mode.
    fn representable(&self, block: Block) -> bool {
        matches!(
            (self.family.level(), block),
            (ModelLevel::Kirchhoff | ModelLevel::Cosserat, _)
                | (ModelLevel::Planar, Block::InPlane)
        )
    }

    /// The test function at arclength σ from `a`, and the point there,
    /// corrected from the converged point `near` of the same location
    /// when there is one (see [`Self::point_at`]).
    fn test_at(
        &self,
        a: &Point,
        sign: f64,
        sigma: f64,
        near: Option<&Anchor>,
        test: &Test,
    ) -> Option<Located> {
        let (x, p, tangent, fx) = self.point_at(a, sign, sigma, near)?;
        let n = x.len();
        let value = match test {
            Test::Fold => tangent[n],
            Test::Determinant => self.det_with(&x, p, fx)?,
            Test::Bordered { right, left, entry } => {
                self.bordered_with(&x, p, right, left, fx)?[*entry]
            }
            Test::Eigenvalue(block) => self
                .tracker
                .trial_nearest_zero(self.family, &x, p, *block)
                .ok()?,
            Test::EigenvalueOn(block, tracker) => tracker
                .trial_nearest_zero(self.family, &x, p, *block)
                .ok()?,
        };
        Some((value, x, p, tangent))
    }

    /// The point where the plane τ_aᵀ(z − z_a) = σ cuts the branch, with
    /// F_x there where its corrector gave it (for the test functions, which
    /// would otherwise evaluate it again). From
    /// `a` the predictor is z_a + σ τ_a; from a converged point `near` of
    /// the same plane family (at σ_n, tangent τ_n) it is
    /// z_n + (σ − σ_n)/(τ_aᵀτ_n) τ_n, which lies on the same plane. Near a
    /// branch point the bordered matrix [F_x F_p; τ_aᵀ] is nearly singular
    /// and Newton's basin shrinks with the distance to it: a predictor a
    /// whole step long leaves it (the full bistable strip's and the full
    /// arch's asymmetric branch points were bracketed but never located),
    /// one from the nearer bracket end does not. None where the corrector
    /// does not converge.
    fn point_at(&self, a: &Point, sign: f64, sigma: f64, near: Option<&Anchor>) -> Option<Cut> {
        let travel = |t: &[f64]| -> Vec<f64> { t.iter().map(|v| v * sign).collect() };
        let t_a = travel(&a.tangent);
        let anchored = near.and_then(|(sigma_n, (_, x, p, t))| {
            let t_n = travel(t);
            let cosine: f64 = t_a.iter().zip(&t_n).map(|(u, v)| u * v).sum();
            (cosine > 0.5).then(|| {
                let along = (sigma - sigma_n) / cosine;
                x.iter()
                    .chain([p])
                    .zip(&t_n)
                    .map(|(z, t)| z + along * t)
                    .collect::<Vec<f64>>()
            })
        });
        let pred = match anchored {
            Some(pred) => pred,
            // The step from `a` itself (`Run::step`): sliced, or its
            // corrector below from the same predictor z_a + σ τ_a.
            None if self.sliced => {
                let (x, p, tangent, _) = self.step(a, sign, sigma).ok()??;
                return Some((x, p, tangent, None));
            }
            None => a
                .unknowns
                .iter()
                .chain([&a.parameter])
                .zip(&t_a)
                .map(|(z, t)| z + sigma * t)
                .collect(),
        };
        if self.sliced {
            // The slice through `a` (its copies' null vectors), as the
            // step from `a` itself would use.
            let kernel = self.symmetric_kernel(&a.unknowns, a.parameter)?;
            let (z, _) = self
                .correct_sliced(&a.unknowns, &pred, &t_a, &kernel)
                .ok()??;
            let n = z.len() - 1;
            let t = self.sliced_tangent(&z[..n], z[n], &kernel, &t_a).ok()?;
            return Some((z[..n].to_vec(), z[n], travel(&t), None));
        }
        let (z, _, fu) = self.correct(&pred, &t_a).ok()??;
        let n = z.len() - 1;
        let t = engine::tangent_from(self.family, &fu, &z[..n], z[n], &t_a).ok()?;
        Some((z[..n].to_vec(), z[n], travel(&t), Some(fu)))
    }

    fn jacobian(&self, x: &[f64], p: f64) -> Option<DMatrix<f64>> {
        self.dense_jacobian(x, p).ok().map(|(_, j)| j)
    }

    /// F_x at (x, p) as a staircase when the family's systems are solved
    /// in O(N) (multiple shooting and collocation above
    /// [`DENSE_UP_TO`] unknowns, as the corrector does); None for the
    /// small dense systems, whose results stay those of the dense SVD.
    fn large_jacobian(&self, x: &[f64], p: f64) -> Option<Staircase> {
        if x.len() <= DENSE_UP_TO {
            return None;
        }
        let mut a = self.family.staircase()?;
        let mut r = DVector::zeros(x.len());
        self.family.residual_staircase(x, p, &mut r, &mut a).ok()?;
        Some(a)
    }

    /// Whether the events of this family use the O(N) algebra.
    fn is_large(&self, n: usize) -> bool {
        n > DENSE_UP_TO && self.family.staircase().is_some()
    }

    /// det F_x, dense up to [`super::corrector::DENSE_UP_TO`] unknowns;
    /// above, from the O(N) staircase factors as sign · |det|^(1/N) (the
    /// geometric mean of the pivots: the same sign and root, without the
    /// overflow of a product of thousands of pivots).
    fn det(&self, x: &[f64], p: f64) -> Option<f64> {
        self.det_with(x, p, None)
    }

    /// [`Self::det`] with F_x at (x, p) where it is known (`fx`, as the
    /// corrector evaluated it: the same matrix).
    fn det_with(&self, x: &[f64], p: f64, fx: Option<Linearization>) -> Option<f64> {
        let n = x.len();
        if n > super::corrector::DENSE_UP_TO {
            if let Some(mut a) = self.family.staircase() {
                if let Some(Linearization::Staircase(known)) = fx {
                    a = known;
                } else {
                    let mut r = DVector::zeros(n);
                    self.family.residual_staircase(x, p, &mut r, &mut a).ok()?;
                }
                let mut lu = StaircaseLu::default();
                if lu.factor(&a, None).is_err() {
                    return Some(0.0);
                }
                let (sign, log) = lu.log_determinant()?;
                return Some(sign * (log / n as f64).exp());
            }
        }
        match fx {
            Some(Linearization::Dense(known)) => Some(known.determinant()),
            _ => Some(self.jacobian(x, p)?.determinant()),
        }
    }

    /// Govaerts' G (m × m) at (x, p): [F_x Ψ; Φᵀ 0] [V; G] = [0; I_m].
    /// None where the bordered matrix is singular (borders that do not
    /// complement F_x's kernel and range).
    pub(super) fn bordered(
        &self,
        x: &[f64],
        p: f64,
        right: &DMatrix<f64>,
        left: &DMatrix<f64>,
    ) -> Option<DMatrix<f64>> {
        self.bordered_with(x, p, right, left, None)
    }

    /// [`Self::bordered`] with F_x at (x, p) where it is known (`fx`, as
    /// the corrector evaluated it: the same matrix).
    fn bordered_with(
        &self,
        x: &[f64],
        p: f64,
        right: &DMatrix<f64>,
        left: &DMatrix<f64>,
        fx: Option<Linearization>,
    ) -> Option<DMatrix<f64>> {
        if self.is_large(x.len()) {
            let a = match fx {
                Some(Linearization::Staircase(known)) => known,
                _ => self.large_jacobian(x, p)?,
            };
            return bordered_banded(&a, right, left);
        }
        let fx = match fx {
            Some(Linearization::Dense(known)) => known,
            _ => self.jacobian(x, p)?,
        };
        let (n, m) = (x.len(), right.ncols());
        let mut big = DMatrix::zeros(n + m, n + m);
        big.view_mut((0, 0), (n, n)).copy_from(&fx);
        big.view_mut((0, n), (n, m)).copy_from(left);
        big.view_mut((n, 0), (m, n)).copy_from(&right.transpose());
        let mut rhs = DMatrix::zeros(n + m, m);
        rhs.view_mut((n, 0), (m, m)).fill_with_identity();
        let solution = big.lu().solve(&rhs)?;
        let g = solution.rows(n, m).into_owned();
        g.iter().all(|v| v.is_finite()).then_some(g)
    }

    /// The borders of the bordered test at (x, p): Φ and Ψ (n × m), the
    /// right and left singular vectors of the m smallest singular values
    /// of F_x there, and σ_m/σ_{m+1} (how well they stand apart: small
    /// near a singularity of multiplicity m). Dense SVD up to
    /// [`DENSE_UP_TO`] unknowns, above by inverse iteration on the band
    /// copy of the staircase ([`Self::banded_borders`]). None where m is
    /// not below n or F_x cannot be evaluated.
    pub(super) fn borders_at(
        &self,
        x: &[f64],
        p: f64,
        m: usize,
    ) -> Option<(f64, DMatrix<f64>, DMatrix<f64>)> {
        let n = x.len();
        if m == 0 || m >= n {
            return None;
        }
        if self.is_large(n) {
            return self.banded_borders(x, p, m);
        }
        let svd = self.jacobian(x, p)?.svd(true, true);
        let (u, v_t) = (svd.u.as_ref()?, svd.v_t.as_ref()?);
        let mut idx: Vec<usize> = (0..n).collect();
        idx.sort_by(|&i, &j| svd.singular_values[i].total_cmp(&svd.singular_values[j]));
        let ratio = svd.singular_values[idx[m - 1]] / svd.singular_values[idx[m]];
        let right = DMatrix::from_fn(n, m, |r, c| v_t[(idx[c], r)]);
        let left = DMatrix::from_fn(n, m, |r, c| u[(r, idx[c])]);
        Some((ratio, right, left))
    }

    /// The borders of the bordered test at (x, p) in O(N): the m
    /// smallest singular triplets of the staircase F_x by inverse
    /// iteration ([`BandedJacobian::smallest`]) and σ_m/σ_{m+1}.
    fn banded_borders(
        &self,
        x: &[f64],
        p: f64,
        m: usize,
    ) -> Option<(f64, DMatrix<f64>, DMatrix<f64>)> {
        let a = self.large_jacobian(x, p)?;
        let s = BandedJacobian::of(&a)?.smallest(m + 1)?;
        let ratio = s.values[m - 1] / s.values[m];
        Some((
            ratio,
            s.right.columns(0, m).into_owned(),
            s.left.columns(0, m).into_owned(),
        ))
    }

    /// The bordered test of multiplicity m for the step from `a` to `b`:
    /// borders from the singular vectors of F_x at whichever end is nearer
    /// singular (smaller σ_m/σ_{m+1}), and the entry of G that changes
    /// sign between the ends with the largest change. None when no entry
    /// changes sign (the singularity is not the model's: the caller falls
    /// back on the eigenvalue).
    fn bordered_test(&self, a: &Point, b: &Point, m: usize) -> Option<Test> {
        let n = a.unknowns.len();
        // On a branch of symmetric copies F_x keeps the copies' null
        // vector everywhere: the borders must complement it too, or the
        // bordered matrix is singular at the branch point (a twisted ring's
        // Michell point: the copies' direction and the pair that crosses).
        let m = m + usize::from(self.sliced);
        if m == 0 || m >= n {
            return None;
        }
        let mut best: Option<(f64, DMatrix<f64>, DMatrix<f64>)> = None;
        for end in [a, b] {
            let here = self.borders_at(&end.unknowns, end.parameter, m)?;
            if best.as_ref().is_none_or(|b| here.0 < b.0) {
                best = Some(here);
            }
        }
        let (_, right, left) = best?;
        let ga = self.bordered(&a.unknowns, a.parameter, &right, &left)?;
        let gb = self.bordered(&b.unknowns, b.parameter, &right, &left)?;
        let entry = sign_changing_entry(&ga, &gb)?;
        Some(Test::Bordered { right, left, entry })
    }

    /// Locates the event between `a` and `b` by the Illinois method on the
    /// arclength σ ∈ (0, σ_b), σ_b = τ_aᵀ(z_b − z_a): one special point,
    /// or two or more simple ones where eigenvalues crossing within one
    /// step did so at distinct parameters, or none (not located).
    fn locate(
        &mut self,
        a: &Point,
        b: &Point,
        sign: f64,
        (branch, index): (usize, usize),
        (kind, block, multiplicity): Wanted,
    ) -> (Vec<SpecialPoint>, Vec<String>) {
        let span = span_of(a, b, sign);
        let test = match kind {
            SpecialKind::Fold => Test::Fold,
            SpecialKind::BranchPoint if !self.representable(block) => Test::Eigenvalue(block),
            SpecialKind::BranchPoint if multiplicity == 1 => Test::Determinant,
            SpecialKind::BranchPoint => self
                .bordered_test(a, b, multiplicity)
                .unwrap_or(Test::Eigenvalue(block)),
        };
        let Some(root) = self.root(a, (sign, b.parameter), (0.0, span), &test) else {
            if matches!(test, Test::Determinant) {
                return self.unbracketed_branch_point(
                    a,
                    b,
                    sign,
                    (branch, index),
                    (kind, block, 1),
                );
            }
            return (vec![], vec![]);
        };
        // A bracket that could not be closed cannot tell one multiple
        // crossing from several simple ones: it is reported with its spread.
        let resolved = self.unresolved(&root, "", (branch, index)).is_none();
        if let Test::Bordered { right, left, .. } = &test {
            if resolved && !self.degenerate(a, b, &root.located, right, left) {
                return self.separate(
                    a,
                    b,
                    sign,
                    (root.sigma, root.located),
                    (branch, index),
                    block,
                );
            }
        }
        let wanted = (kind, block, multiplicity);
        if let Test::Eigenvalue(block) = test {
            let (point, note) = self.extrapolated_crossing(
                a,
                b,
                sign,
                (root.sigma, root.located),
                (branch, index),
                (wanted, block),
            );
            return (point.into_iter().collect(), note.into_iter().collect());
        }
        if matches!(test, Test::Determinant) {
            let (point, note) =
                self.refined_branch_point(a, b, sign, root, (branch, index), wanted);
            return (point.into_iter().collect(), note.into_iter().collect());
        }
        let interpolated = root.interpolated.is_some();
        let (point, note) = self.bracketed(a, b, sign, root, (branch, index), wanted, kind.name());
        // A multiple branch point (G wholly zero at the closed root) carries
        // its discretization error, located again on the refined family.
        if (resolved || interpolated) && matches!(test, Test::Bordered { .. }) {
            let reach = (b.parameter - a.parameter).abs();
            let (point, error_note) = if self.sliced {
                self.with_sliced_multiple_error(point, a, (sign, b.parameter, span), &test)
            } else {
                self.with_multiple_discretization_error(point, reach)
            };
            return (
                point.into_iter().collect(),
                note.into_iter().chain(error_note).collect(),
            );
        }
        (point.into_iter().collect(), note.into_iter().collect())
    }

    /// `sp`, a multiple branch point on a branch of symmetric copies (the
    /// root of an entry of G, `test`, in the step from `a`), with its
    /// discretization error: the root of the same entry with the same
    /// borders along the same step on the refined family's slice
    /// (`discretization.rs`). Where that fails — another number of
    /// unknowns, whose borders would differ — the error stays unknown and
    /// the note says why.
    fn with_sliced_multiple_error(
        &self,
        sp: Option<SpecialPoint>,
        a: &Point,
        (sign, p_b, span): (f64, f64, f64),
        test: &Test,
    ) -> (Option<SpecialPoint>, Option<String>) {
        super::discretization::with_estimate(sp, |sp| {
            self.relocated_on_slice(sp, a, &|run, start| match test {
                Test::Bordered { right, .. } if right.nrows() == start.unknowns.len() => {
                    run.closed_root(start, (sign, p_b), span, test, "the entry of G")
                }
                _ => {
                    Err("has another number of unknowns, for which G's borders do not hold".into())
                }
            })
        })
    }

    /// The special point kept at the bracketed root, recorded as
    /// [`Location::Bracketed`]; where its bracket could not be closed to
    /// the event tolerance, with the bracket's spread as its
    /// `parameter_error` and a note saying so.
    #[allow(clippy::too_many_arguments)]
    fn bracketed(
        &self,
        a: &Point,
        b: &Point,
        sign: f64,
        root: Root,
        (branch, index): (usize, usize),
        wanted: Wanted,
        what: &str,
    ) -> (Option<SpecialPoint>, Option<String>) {
        if let Some(error) = root.interpolated {
            let location = (wanted, Location::Interpolated);
            let point = self
                .special_point(a, b, sign, root.located, (branch, index), location)
                .map(|mut sp| {
                    sp.parameter_error = Some(error);
                    sp
                });
            return (point, None);
        }
        let unresolved = self.unresolved(&root, what, (branch, index));
        let spread = root.spread;
        let point = self
            .special_point(
                a,
                b,
                sign,
                root.located,
                (branch, index),
                (wanted, Location::Bracketed),
            )
            .map(|mut sp| {
                sp.parameter_error = unresolved.is_some().then_some(spread);
                sp
            });
        (point, unresolved)
    }

    /// The simple branch point bracketed at `best` on det F_x, refined by
    /// Newton on the minimally augmented system (`branch_point.rs`). Where
    /// Newton fails the bracketed root is kept, recorded as
    /// [`Location::Bracketed`], with a note saying why; on a branch of
    /// symmetric copies (`slice.rs`, F_x keeps the copies' null vector) it
    /// is not tried.
    fn refined_branch_point(
        &self,
        a: &Point,
        b: &Point,
        sign: f64,
        root: Root,
        (branch, index): (usize, usize),
        wanted: Wanted,
    ) -> (Option<SpecialPoint>, Option<String>) {
        let bracketed = |root: Root, note: Option<String>| {
            let (point, unresolved) =
                self.bracketed(a, b, sign, root, (branch, index), wanted, "branch point");
            (point, note.or(unresolved))
        };
        if self.sliced {
            let (point, unresolved) = bracketed(root, None);
            if unresolved.is_some() {
                return (point, unresolved);
            }
            return Self::without_discretization_error(
                point,
                "it lies on a branch of symmetric copies, where its bracket is not closed again \
                 on the refined family",
            );
        }
        let best = root.located.clone();
        let radius = span_of(a, b, sign).abs().max(distance(a, b));
        match self.refine_branch_point(&best.1, best.2, radius) {
            Ok((x, p, _)) => {
                let located = (0.0, x, p, best.3);
                let point = self.special_point(
                    a,
                    b,
                    sign,
                    located,
                    (branch, index),
                    (wanted, Location::Augmented),
                );
                self.with_discretization_error(point, radius)
            }
            Err(why) => {
                let note = format!(
                    "branch {branch}: the branch point between points {index} and {} is located \
                     only as the bracketed root of det F_x, at parameter {:.12}: the minimally \
                     augmented Newton failed: {why}",
                    index + 1,
                    best.2
                );
                bracketed(root, Some(note))
            }
        }
    }

    /// Locates the fold between `a` and `b`: the root of τ_p bracketed by
    /// Illinois in the arclength, then refined by Newton on the minimally
    /// augmented system (`fold.rs`). Where Newton fails the bracketed root
    /// is kept, recorded as [`Location::Bracketed`], with a note saying why;
    /// on a branch of symmetric copies (`slice.rs`) it is not tried.
    fn locate_fold(
        &self,
        a: &Point,
        b: &Point,
        sign: f64,
        (branch, index): (usize, usize),
        wanted: Wanted,
    ) -> (Vec<SpecialPoint>, Option<String>) {
        let span = span_of(a, b, sign);
        let Some(root) = self.root(a, (sign, b.parameter), (0.0, span), &Test::Fold) else {
            return (vec![], None);
        };
        let radius = span.abs().max(distance(a, b));
        if !self.sliced && self.turns_at_branch_point(&root.located) {
            let best = &root.located;
            if let Ok((x, p, _)) = self.refine_branch_point(&best.1, best.2, radius) {
                let located = (0.0, x, p, best.3.clone());
                let bp = (SpecialKind::BranchPoint, wanted.1, 1);
                let point = self.special_point(
                    a,
                    b,
                    sign,
                    located,
                    (branch, index),
                    (bp, Location::Augmented),
                );
                let (point, note) = self.with_discretization_error(point, radius);
                return (point.into_iter().collect(), note);
            }
        }
        let best = root.located;
        // On a branch of symmetric copies F_x keeps the copies' null vector,
        // so its kernel at a fold is two-dimensional and the one-bordered
        // system singular: the fold is the bracketed root, and its record
        // says so.
        if self.sliced {
            let point = self.special_point(
                a,
                b,
                sign,
                best,
                (branch, index),
                (wanted, Location::Bracketed),
            );
            let (point, note) = self.with_sliced_fold_error(point, a, (sign, b.parameter, span));
            return (point.into_iter().collect(), note);
        }
        let refined = self
            .refine_fold(&best.1, best.2, radius)
            .and_then(|(x, p, _)| {
                let t = self.tangent(&x, p, &best.3).map_err(|e| e.to_string())?;
                Ok((0.0, x, p, t))
            });
        let (located, location, note) = match refined {
            Ok(fold) => (fold, Location::Augmented, None),
            Err(why) => {
                let note = format!(
                    "branch {branch}: the fold between points {index} and {} is located only as \
                     the bracketed root of τ_p, at parameter {:.12}: the minimally augmented \
                     Newton failed: {why}",
                    index + 1,
                    best.2
                );
                (best, Location::Bracketed, Some(note))
            }
        };
        let point = self.special_point(a, b, sign, located, (branch, index), (wanted, location));
        let (point, error_note) = self.with_discretization_error(point, radius);
        (point.into_iter().collect(), note.or(error_note))
    }

    /// The direction of the branch through a simple branch point (x, p):
    /// `reference` (the tangent at the branch's last regular point)
    /// projected on the null plane of [F_x F_p] there, spanned by (φ, 0)
    /// and (v₀, 1), [F_x b; cᵀ 0][v₀; s] = [−F_p; 0] (φ = c, b the near
    /// null vectors), in F_x's shape (`bordering.rs`). None on a branch of
    /// symmetric copies or where a solve fails.
    fn branch_direction(&self, x: &[f64], p: f64, reference: &[f64]) -> Option<Vec<f64>> {
        let n = x.len();
        if self.sliced {
            return None;
        }
        let (_, fx) = self.linearization(x, p).ok()?;
        let fp = self.family.parameter_derivative(x, p).ok()?;
        let (c, b) = super::bordering::null_vectors(&fx)?;
        let mut k = super::bordering::BorderedJacobian::new(fx, b, c.clone())?;
        let v0 = super::branch_point::bordered_solve(&mut k, &(-&fp))?;
        let e1 = DVector::from_iterator(n + 1, c.iter().copied().chain([0.0])).normalize();
        let mut e2 = DVector::from_iterator(n + 1, v0.iter().copied().chain([1.0]));
        e2 -= &e1 * e1.dot(&e2);
        let e2 = e2.normalize();
        let r = DVector::from_column_slice(reference);
        let t = &e1 * e1.dot(&r) + &e2 * e2.dot(&r);
        let norm = t.norm();
        (norm.is_finite() && norm > 0.0).then(|| (t / norm).as_slice().to_vec())
    }

    /// Whether the branch may turn back (τ_p changes sign) at a branch
    /// point rather than at a fold: F_p nearly in the range of the singular
    /// F_x (|ψᵀF_p| ≤ 1e-2 |F_p|, ψ its left null vector; at a fold it is of
    /// the order of |F_p|, at a branch point of the distance to it). A
    /// branch that bifurcated at a pitchfork meets the branch it left there
    /// again and turns with p'(σ) = 0 (the parabola p − p* ∝ a²): the full
    /// shallow arch's asymmetric branch at both of its ends. There the
    /// fold's augmented system is singular — it did not converge, or
    /// converged 7e-8 off — while the branch point's is regular, so the
    /// caller tries the branch point's system first and keeps it only where
    /// it converges (μ = 0: a fold never satisfies it). In F_x's shape,
    /// as the fold's system.
    fn turns_at_branch_point(&self, best: &Located) -> bool {
        let (x, p) = (&best.1, best.2);
        let (Ok((_, fx)), Ok(fp)) = (
            self.linearization(x, p),
            self.family.parameter_derivative(x, p),
        ) else {
            return false;
        };
        let Some((_, left)) = super::bordering::null_vectors(&fx) else {
            return false;
        };
        left.dot(&fp).abs() <= 1e-2 * fp.norm()
    }

    /// A simple branch point between `a` and `b` whose bracket could not
    /// be narrowed (the corrector fails near it: a branch crossing
    /// another close to the crossing, where Newton's basin on the
    /// pseudo-arclength system shrinks): Newton on the minimally augmented
    /// system, which is regular there, from each end (the nearer-singular
    /// first), kept where it lands between them.
    fn unbracketed_branch_point(
        &self,
        a: &Point,
        b: &Point,
        sign: f64,
        (branch, index): (usize, usize),
        wanted: Wanted,
    ) -> (Vec<SpecialPoint>, Vec<String>) {
        if self.sliced {
            return (vec![], vec![]);
        }
        let radius = span_of(a, b, sign).abs().max(distance(a, b));
        let singularity = |e: &Point| {
            self.det(&e.unknowns, e.parameter)
                .map_or(f64::INFINITY, f64::abs)
        };
        let mut ends = [a, b];
        ends.sort_by(|x, y| singularity(x).total_cmp(&singularity(y)));
        let (lo, hi) = (a.parameter.min(b.parameter), a.parameter.max(b.parameter));
        for end in ends {
            let Ok((x, p, _)) = self.refine_branch_point(&end.unknowns, end.parameter, radius)
            else {
                continue;
            };
            if !(lo..=hi).contains(&p) {
                continue;
            }
            let located = (0.0, x, p, end.tangent.iter().map(|t| t * sign).collect());
            let point = self.special_point(
                a,
                b,
                sign,
                located,
                (branch, index),
                (wanted, Location::Augmented),
            );
            let (point, note) = self.with_discretization_error(point, radius);
            return (point.into_iter().collect(), note.into_iter().collect());
        }
        (vec![], vec![])
    }

    /// A crossing the model's BVP does not see, located on the block's
    /// finite-element eigenvalue — whose crossing carries the elements'
    /// error O(h^{2k}), k their order — on the run's mesh (σ₁, at
    /// `first`) and on two and four times its elements (σ₂, σ₄), then
    /// extrapolated: σ* = σ₄ + (σ₄ − σ₂)/(2^{2k} − 1), the point there by
    /// the corrector. The parameter's error estimate is the difference of
    /// the extrapolations from (σ₂, σ₄) and from (σ₁, σ₂) in p, a bound
    /// of the first's error by the second's; where the measured order of
    /// the three crossings is not 2k ± 1 (a crossing converged to the
    /// event tolerance already, or not yet in the asymptotic range) the
    /// finest crossing is kept with |p₄ − p₂| as its error; either error
    /// adds the event tolerance each crossing is located to. With a note
    /// where the finer meshes could not be used: the run's crossing is
    /// then reported as located on its own mesh, error unknown.
    fn extrapolated_crossing(
        &self,
        a: &Point,
        b: &Point,
        sign: f64,
        first: (f64, Located),
        (branch, index): (usize, usize),
        (wanted, block): (Wanted, Block),
    ) -> (Option<SpecialPoint>, Option<String>) {
        let span = span_of(a, b, sign);
        let finer: Option<Vec<(f64, Located)>> = [2, 4]
            .into_iter()
            .map(|factor| {
                let tracker = Box::new(self.tracker.refined(factor)?);
                let test = Test::EigenvalueOn(block, tracker);
                self.root(a, (sign, b.parameter), (0.0, span), &test)
                    .map(|r| (r.sigma, r.located))
            })
            .collect();
        let at = (branch, index);
        let Some(finer) = finer else {
            let note = format!(
                "branch {branch}: the {} branch point between points {index} and {} is located \
                 on the {}-element mesh only (the finer meshes of its extrapolation failed): \
                 parameter {:.10}, error not estimated",
                block.name(),
                index + 1,
                self.opts.stability.elements(),
                first.1 .2
            );
            let point = self.special_point(a, b, sign, first.1, at, (wanted, Location::Bracketed));
            return (point, Some(note));
        };
        let p1 = first.1 .2;
        let (s2, p2) = (finer[0].0, finer[0].1 .2);
        let (s4, p4) = (finer[1].0, finer[1].1 .2);
        let q = 2.0 * self.tracker.order() as f64;
        let r = 2f64.powf(q) - 1.0;
        let measured = ((p1 - p2) / (p2 - p4)).abs().log2();
        // Each crossing is itself located to the event tolerance.
        let resolution = self.opts.event_tolerance * p4.abs().max(1.0);
        let (sigma, error) = if (measured - q).abs() <= 1.0 {
            let fine = p4 + (p4 - p2) / r;
            let coarse = p2 + (p2 - p1) / r;
            (s4 + (s4 - s2) / r, (fine - coarse).abs() + resolution)
        } else {
            (s4, (p4 - p2).abs() + resolution)
        };
        // The crossings are of the family's discretized branch: add the
        // BVP discretization's part of the error, or leave the whole
        // unknown where it cannot be estimated.
        let bvp = self.crossing_bvp_error(a, (sign, b.parameter, span), block, p1);
        let near = &finer[1];
        let Some((x, p, tangent, _)) = self.point_at(a, sign, sigma, Some(near)) else {
            let point = self
                .special_point(
                    a,
                    b,
                    sign,
                    finer[1].1.clone(),
                    at,
                    (wanted, Location::Extrapolated),
                )
                .map(|mut sp| {
                    sp.parameter_error = Some((p4 - p2).abs() + resolution);
                    sp
                });
            return Self::with_bvp_part(point, bvp);
        };
        let point = self
            .special_point(
                a,
                b,
                sign,
                (0.0, x, p, tangent),
                at,
                (wanted, Location::Extrapolated),
            )
            .map(|mut sp| {
                sp.parameter_error = Some(error);
                sp
            });
        Self::with_bvp_part(point, bvp)
    }

    /// Whether the whole of G vanishes at the located point (relative to
    /// its change over the step): the kernel of F_x there has the full
    /// dimension m, not one crossing of several at distinct parameters.
    fn degenerate(
        &self,
        a: &Point,
        b: &Point,
        best: &Located,
        right: &DMatrix<f64>,
        left: &DMatrix<f64>,
    ) -> bool {
        let g = |x: &[f64], p: f64| self.bordered(x, p, right, left);
        match (
            g(&a.unknowns, a.parameter),
            g(&b.unknowns, b.parameter),
            g(&best.1, best.2),
        ) {
            (Some(ga), Some(gb), Some(here)) => here.amax() <= 1e-6 * (gb - ga).amax(),
            _ => false,
        }
    }

    /// Several simple crossings within one step: the located root of one
    /// entry of G splits the step at σ*, and each part whose Morse index
    /// changes by one holds a simple branch point, located on det F_x.
    fn separate(
        &self,
        a: &Point,
        b: &Point,
        sign: f64,
        (sigma, best): (f64, Located),
        at: (usize, usize),
        block: Block,
    ) -> (Vec<SpecialPoint>, Vec<String>) {
        let bi = self.tracker.blocks().iter().position(|&x| x == block);
        let morse = |x: &[f64], p: f64| -> Option<usize> {
            let s = self.tracker.evaluate(self.family, x, p).ok()?;
            Some(s.block_morse[bi?])
        };
        let (Some(lo), Some(mid), Some(hi)) = (
            morse(&a.unknowns, a.parameter),
            morse(&best.1, best.2),
            morse(&b.unknowns, b.parameter),
        ) else {
            return (vec![], vec![]);
        };
        let span = (sigma, span_of(a, b, sign));
        let (mut found, mut notes) = (vec![], vec![]);
        for (range, jump) in [((0.0, span.0), lo.abs_diff(mid)), (span, mid.abs_diff(hi))] {
            if jump != 1 {
                continue;
            }
            let Some(root) = self.root(a, (sign, b.parameter), range, &Test::Determinant) else {
                continue;
            };
            let wanted = (SpecialKind::BranchPoint, block, 1);
            let (point, note) = self.refined_branch_point(a, b, sign, root, at, wanted);
            found.extend(point);
            notes.extend(note);
        }
        (found, notes)
    }

    /// The root σ of the test function on σ ∈ (lo, hi) by Illinois, to
    /// the event tolerance on the parameter, and the point there. Each
    /// iterate is corrected from the converged bracket end nearer to it
    /// ([`Self::point_at`]), so the predictor stays short as the bracket
    /// closes on the root; where that corrector fails, from `a`, and then
    /// at points halfway towards the nearer end ([`Self::test_near`]):
    /// close to a branch point the corrector's basin shrinks, and the
    /// false position lands right on it. Where no point closer to the root
    /// can be corrected the bracket stops there: the root is the best
    /// point so far, its `spread` (the parameter bracket) wider than the
    /// event tolerance, which the caller reports.
    fn root(
        &self,
        a: &Point,
        (sign, p_b): (f64, f64),
        (lo, hi): (f64, f64),
        test: &Test,
    ) -> Option<Root> {
        // Each location's trials start their eigenpairs from the last
        // trial's, the first from a full solve.
        match test {
            Test::Eigenvalue(_) => self.tracker.begin_trials(),
            Test::EigenvalueOn(_, tracker) => tracker.begin_trials(),
            _ => {}
        }
        let span = hi - lo;
        let start = lo + 1e-12 * span;
        let lower = self.test_at(a, sign, start, None, test)?;
        let upper = self.test_at(a, sign, hi, None, test)?;
        let mut bracket = Illinois::new(lo, hi, lower.0, upper.0)?;
        let (mut p_lo, mut p_hi) = (a.parameter, p_b);
        let mut samples: Vec<Anchor> = vec![(start, lower.clone()), (hi, upper.clone())];
        let mut ends: [Anchor; 2] = [(start, lower), (hi, upper)];
        let mut best: Option<Anchor> = None;
        for _ in 0..80 {
            let Some((sigma, here)) = self.test_near(a, sign, bracket.next_point(), &ends, test)
            else {
                break;
            };
            let end = match bracket.update(sigma, here.0) {
                End::Lower => {
                    p_lo = here.2;
                    0
                }
                End::Upper => {
                    p_hi = here.2;
                    1
                }
            };
            ends[end] = (sigma, here.clone());
            samples.push((sigma, here.clone()));
            let tol = self.opts.event_tolerance * here.2.abs().max(1.0);
            let done = (p_hi - p_lo).abs() <= tol && bracket.width() <= 1e3 * tol
                || here.0 == 0.0
                || bracket.width() <= 1e-15 * span;
            best = Some((sigma, here));
            if done {
                break;
            }
        }
        // Without an interior point, the end with the smaller test value.
        let (sigma, located) = best.unwrap_or_else(|| {
            let [l, u] = ends;
            if l.1 .0.abs() <= u.1 .0.abs() {
                l
            } else {
                u
            }
        });
        let spread = (p_hi - p_lo).abs();
        let tol = self.opts.event_tolerance * located.2.abs().max(1.0);
        if spread > tol {
            // Each sample's p is itself resolved to the event tolerance.
            if let Some((sigma, located, error)) = super::interpolated_root::interpolated(&samples)
                .map(|(sigma, located, error)| (sigma, located, error + tol))
                .filter(|(_, _, error)| *error < spread)
            {
                return Some(Root {
                    sigma,
                    located,
                    spread,
                    interpolated: Some(error),
                });
            }
        }
        Some(Root {
            sigma,
            located,
            spread,
            interpolated: None,
        })
    }

    /// The test function at σ, or — where the corrector fails there — at
    /// up to three points each halfway from the last try towards the
    /// nearer bracket end; the σ used and the value. None where all fail.
    fn test_near(
        &self,
        a: &Point,
        sign: f64,
        sigma: f64,
        ends: &[Anchor; 2],
        test: &Test,
    ) -> Option<(f64, Located)> {
        let nearer = |s: f64| {
            ends.iter()
                .min_by(|x, y| (x.0 - s).abs().total_cmp(&(y.0 - s).abs()))
                .expect("two ends")
        };
        let mut s = sigma;
        for _ in 0..4 {
            let near = nearer(s);
            if let Some(here) = self
                .test_at(a, sign, s, Some(near), test)
                .or_else(|| self.test_at(a, sign, s, None, test))
            {
                return Some((s, here));
            }
            s = 0.5 * (s + near.0);
        }
        None
    }

    /// Whether a root's parameter bracket closed to the event tolerance;
    /// else a note naming the bracket it reached.
    /// The parameter at the root of τ_p in the step from `a` (`sign`,
    /// towards `p_b`, arclength `span`), its bracket closed to the event
    /// tolerance; Err says why not.
    pub(super) fn fold_root(
        &self,
        a: &Point,
        (sign, p_b): (f64, f64),
        span: f64,
    ) -> Result<f64, String> {
        self.closed_root(a, (sign, p_b), span, &Test::Fold, "τ_p")
    }

    /// The parameter where `block`'s eigenvalue nearest zero on `factor`
    /// times the run's finite elements crosses zero in the step from `a`
    /// (`sign`, towards `p_b`, arclength `span`), its bracket closed to the
    /// event tolerance; Err says why not.
    pub(super) fn crossing_root(
        &self,
        a: &Point,
        (sign, p_b): (f64, f64),
        span: f64,
        (block, factor): (Block, usize),
    ) -> Result<f64, String> {
        let tracker = self
            .tracker
            .refined(factor)
            .ok_or("the finer finite-element mesh cannot be made")?;
        let test = Test::EigenvalueOn(block, Box::new(tracker));
        self.closed_root(a, (sign, p_b), span, &test, "the eigenvalue")
    }

    /// The parameter at the root of `test` in the step from `a`, its
    /// bracket closed to the event tolerance; Err says why not.
    fn closed_root(
        &self,
        a: &Point,
        (sign, p_b): (f64, f64),
        span: f64,
        test: &Test,
        what: &str,
    ) -> Result<f64, String> {
        let root = self
            .root(a, (sign, p_b), (0.0, span), test)
            .ok_or_else(|| {
                format!("{what} does not change sign within the step, or a corrector failed")
            })?;
        match self.unresolved(&root, "root", (0, 0)) {
            _ if root.interpolated.is_some() => Ok(root.located.2),
            None => Ok(root.located.2),
            Some(_) => Err(format!(
                "the bracket of {what}'s root closed only to ±{:.1e}",
                root.spread
            )),
        }
    }

    fn unresolved(
        &self,
        root: &Root,
        what: &str,
        (branch, index): (usize, usize),
    ) -> Option<String> {
        let tol = self.opts.event_tolerance * root.located.2.abs().max(1.0);
        (root.spread > tol).then(|| {
            format!(
                "branch {branch}: the {what} between points {index} and {} is located at \
                 parameter {:.12} only to ±{:.1e} (the corrector fails closer to it)",
                index + 1,
                root.located.2,
                root.spread
            )
        })
    }

    /// The special point at the located `best`: its spectrum, null mode
    /// and the size of the singularity there.
    fn special_point(
        &self,
        a: &Point,
        b: &Point,
        sign: f64,
        (_, x, p, tangent): Located,
        (branch, index): (usize, usize),
        ((kind, block, multiplicity), location): (Wanted, Location),
    ) -> Option<SpecialPoint> {
        // At a branch point the null space of [F_x F_p] is a plane, and the
        // tangent computed at a point that close to it may lie anywhere in
        // it — along the crossing branch, so that switching, which removes
        // the stored tangent from that plane, followed the branch it was on
        // (the pinned arch's asymmetric point). A simple one stores the
        // branch's own direction: its last regular point's, projected on
        // that plane ([`Self::branch_direction`]).
        let stored: Vec<f64> = match kind {
            SpecialKind::BranchPoint if multiplicity == 1 => self
                .branch_direction(&x, p, &a.tangent)
                .unwrap_or_else(|| tangent.iter().map(|v| v * sign).collect()),
            _ => tangent.iter().map(|v| v * sign).collect(),
        };
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
            multiplicity,
            location,
            parameter_error: None,
        })
    }

    /// New branches from a branch point the model represents: the null
    /// space of [F_x F_p] there has dimension m + 1 (the branch tangent τ
    /// and the m-dimensional kernel of F_x, m the multiplicity); each of m
    /// orthonormal directions of it orthogonal to τ is followed both ways.
    /// For the pair of an isotropic rod any two independent directions
    /// give congruent branches (turned about the axis). `neighbour` is a
    /// regular point of the same branch: its Jacobian sets the scale
    /// against which the null space of [F_x F_p] is judged.
    pub(super) fn switch(&mut self, sp: &SpecialPoint, neighbour: &Point) -> Vec<(Point, f64)> {
        if sp.kind != SpecialKind::BranchPoint || !self.representable(sp.block) {
            return vec![];
        }
        let at = format!(
            "branch point at parameter {:.10} on branch {} (multiplicity {})",
            sp.point.parameter, sp.branch, sp.multiplicity
        );
        let Some(directions) = self.kernel_directions(sp, neighbour) else {
            self.unswitched.push(format!(
                "{at}: not switched: [F_x F_p] has no null space of that dimension there"
            ));
            return vec![];
        };
        let (x, p) = (&sp.point.unknowns, sp.point.parameter);
        let eps = 0.5 * self.opts.step;
        let mut z = x.clone();
        z.push(p);
        let mut starts = vec![];
        for phi in &directions {
            for dir in [1.0, -1.0] {
                let t: Vec<f64> = phi.iter().map(|v| v * dir).collect();
                let pred: Vec<f64> = z.iter().zip(&t).map(|(a, b)| a + eps * b).collect();
                let Some((zn, tangent)) = self.switch_step(&pred, &t, directions.len()) else {
                    continue;
                };
                let (xn, pn, tangent) = self.switched_within_bounds(sp, &zn, tangent);
                self.tracker.reset();
                if let Ok(pt) = self.point(xn, pn, tangent) {
                    starts.push((pt, 1.0));
                }
            }
        }
        let asked = 2 * directions.len();
        if starts.len() < asked {
            self.unswitched.push(format!(
                "{at}: {} of {asked} switched branches started; the corrector did not converge \
                 off the others (a branch of symmetric copies, e.g. rotations about an \
                 isotropic rod's axis, keeps a zero eigenvalue and needs a phase condition)",
                starts.len()
            ));
        }
        starts
    }

    /// A switched branch's first point `zn` = (x, p), pulled back onto the
    /// bound it crossed when it lies beyond the bounds (the pinned
    /// column's second-mode branch, switched at 4π² = 39.48 with the
    /// bound 40, began at 40.74 and ended there, "left the bounds"): by
    /// Newton at the bound from the interpolant between the branch point
    /// and `zn`, as a step that ends beyond a bound ([`Run::land_on_bound`];
    /// by the plain corrector — a switch through the slice keeps its point).
    fn switched_within_bounds(
        &mut self,
        sp: &SpecialPoint,
        zn: &[f64],
        tangent: Vec<f64>,
    ) -> (Vec<f64>, f64, Vec<f64>) {
        let n = zn.len() - 1;
        let (lo, hi) = self.opts.bounds;
        if (lo..=hi).contains(&zn[n]) {
            return (zn[..n].to_vec(), zn[n], tangent);
        }
        let sliced = std::mem::replace(&mut self.sliced, false);
        let landed = self.land_on_bound(&sp.point, zn[..n].to_vec(), zn[n], tangent);
        self.sliced = sliced;
        landed
    }

    /// The first point off a branch point along `t` from the predictor: the
    /// plain corrector, or — off a multiple point, whose branches are
    /// continua of copies (an isotropic rod turned about its axis) — the
    /// slice corrector through the predictor (`slice.rs`).
    fn switch_step(
        &self,
        pred: &[f64],
        t: &[f64],
        multiplicity: usize,
    ) -> Option<(Vec<f64>, Vec<f64>)> {
        let n = pred.len() - 1;
        if let Ok(Some((zn, _, _))) = self.correct(pred, t) {
            if let Ok(tangent) = self.tangent(&zn[..n], zn[n], t) {
                return Some((zn, tangent));
            }
        }
        if multiplicity < 2 {
            return None;
        }
        let kernel = self.nearest_kernel(&pred[..n], pred[n])?;
        let (zn, _) = self.correct_sliced(&pred[..n], pred, t, &kernel).ok()??;
        let kernel = self.symmetric_kernel(&zn[..n], zn[n]).unwrap_or(kernel);
        let tangent = self.sliced_tangent(&zn[..n], zn[n], &kernel, t).ok()?;
        Some((zn, tangent))
    }

    /// m orthonormal directions of the null space of E = [F_x F_p] at the
    /// branch point, orthogonal to the branch tangent: the m + 1
    /// eigenvectors of EᵀE with the smallest eigenvalues (all of them
    /// ≤ 1e-6 of the neighbour's ‖F_x‖², else None: the kernel is not
    /// that large), their τ-components removed, then the m leading left
    /// singular vectors of what remains.
    fn kernel_directions(&self, sp: &SpecialPoint, neighbour: &Point) -> Option<Vec<DVector<f64>>> {
        let (x, p, m) = (
            &sp.point.unknowns,
            sp.point.parameter,
            sp.multiplicity.max(1),
        );
        let n = x.len();
        if m > n {
            return None;
        }
        if self.is_large(n) {
            return self.banded_kernel_directions(sp, neighbour);
        }
        let fx = self.jacobian(x, p)?;
        let fp = self.family.parameter_derivative(x, p).ok()?;
        let mut e = DMatrix::zeros(n, n + 1);
        e.view_mut((0, 0), (n, n)).copy_from(&fx);
        e.view_mut((0, n), (n, 1)).copy_from(&fp);
        let eig = (e.transpose() * &e).symmetric_eigen();
        let mut idx: Vec<usize> = (0..=n).collect();
        idx.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let jn = self.jacobian(&neighbour.unknowns, neighbour.parameter)?;
        let scale = jn
            .norm_squared()
            .max(eig.eigenvalues[idx[n]].abs())
            .max(f64::MIN_POSITIVE);
        if eig.eigenvalues[idx[m]].abs() > 1e-6 * scale {
            return None;
        }
        let tau = DVector::from_column_slice(&sp.point.tangent);
        let projected = DMatrix::from_fn(n + 1, m + 1, |r, c| {
            let v = eig.eigenvectors.column(idx[c]);
            v[r] - tau[r] * tau.dot(&v)
        });
        let svd = projected.svd(true, false);
        let u = svd.u.as_ref()?;
        let mut order: Vec<usize> = (0..=m).collect();
        order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
        Some(
            order[..m]
                .iter()
                .map(|&c| u.column(c).into_owned().normalize())
                .collect(),
        )
    }
}

impl Run<'_> {
    /// [`Run::kernel_directions`] in O(N) where F_x is a large staircase.
    /// At a branch point of multiplicity m, F_x has the m null vectors
    /// φ_i (the smallest singular triplets by inverse iteration,
    /// [`BandedJacobian::smallest`]) and F_p lies in its range, so the
    /// null space of E = [F_x F_p] is spanned by the (φ_i, 0) and the
    /// branch tangent τ: the directions are the (φ_i, 0) with their
    /// τ-components removed, orthonormalized. Accepted where σ_i² and
    /// ‖E τ‖² are all ≤ 1e-6 of the neighbour's ‖F_x‖_F² — the dense
    /// test's bound on the m + 1 smallest eigenvalues of EᵀE, whose scale
    /// is at least that — and the projected vectors stay independent
    /// (a tangent inside the kernel of F_x leaves fewer than m).
    fn banded_kernel_directions(
        &self,
        sp: &SpecialPoint,
        neighbour: &Point,
    ) -> Option<Vec<DVector<f64>>> {
        let (x, p, m) = (
            &sp.point.unknowns,
            sp.point.parameter,
            sp.multiplicity.max(1),
        );
        let n = x.len();
        let fx = BandedJacobian::of(&self.large_jacobian(x, p)?)?;
        let kernel = fx.smallest(m)?;
        let near = self.large_jacobian(&neighbour.unknowns, neighbour.parameter)?;
        let scale = BandedJacobian::of(&near)?
            .frobenius()
            .powi(2)
            .max(f64::MIN_POSITIVE);
        let fp = self.family.parameter_derivative(x, p).ok()?;
        let tau = DVector::from_column_slice(&sp.point.tangent);
        let mut e_tau = vec![0.0; n];
        fx.apply(&sp.point.tangent[..n], &mut e_tau);
        let e_tau: f64 = e_tau
            .iter()
            .zip(fp.iter())
            .map(|(a, b)| (a + b * tau[n]).powi(2))
            .sum();
        if kernel.values.iter().any(|s| s * s > 1e-6 * scale) || e_tau > 1e-6 * scale {
            return None;
        }
        // τᵀ(φ_c, 0) once per column: O(N m).
        let along: Vec<f64> = kernel
            .right
            .column_iter()
            .map(|phi| phi.iter().zip(tau.iter()).map(|(a, b)| a * b).sum())
            .collect();
        let projected = DMatrix::from_fn(n + 1, m, |r, c| {
            let v = if r < n { kernel.right[(r, c)] } else { 0.0 };
            v - tau[r] * along[c]
        });
        let qr = projected.qr();
        let independent = qr.r().diagonal().iter().all(|d| d.abs() > 1e-3);
        independent.then(|| {
            qr.q()
                .column_iter()
                .map(nalgebra::Matrix::into_owned)
                .collect()
        })
    }
}

/// The arclength σ_b = τ_aᵀ(z_b − z_a) from `a` to `b` along a's tangent
/// (times the direction of travel).
fn span_of(a: &Point, b: &Point, sign: f64) -> f64 {
    let n = a.unknowns.len();
    (0..=n)
        .map(|i| {
            let (za, zb) = if i < n {
                (a.unknowns[i], b.unknowns[i])
            } else {
                (a.parameter, b.parameter)
            };
            sign * a.tangent[i] * (zb - za)
        })
        .sum()
}

/// The Euclidean distance between two points in z = (x, p).
fn distance(a: &Point, b: &Point) -> f64 {
    let dx: f64 = a
        .unknowns
        .iter()
        .zip(&b.unknowns)
        .map(|(u, v)| (u - v).powi(2))
        .sum();
    (dx + (a.parameter - b.parameter).powi(2)).sqrt()
}

/// Out-of-plane modes of a planar branch, and bending modes of a straight
/// one, break a symmetry of the branch.
fn symmetry_breaking(block: Block, point: &Point, mode: &[nalgebra::Vector3<f64>]) -> bool {
    // Straight: no curvature, or a twisted rod whose centreline is a line
    // (Greenhill's shaft carries its twist κ3 ≠ 0 before it buckles).
    let straight =
        point.norm < 1e-8 || collinear(&point.shape.iter().map(|r| r.position).collect::<Vec<_>>());
    let out_of_plane = mode.iter().map(|w| w[0].abs() + w[2].abs()).sum::<f64>();
    let in_plane = mode.iter().map(|w| w[1].abs()).sum::<f64>();
    match block {
        Block::OutOfPlane => true,
        Block::InPlane => straight,
        Block::Full => out_of_plane > in_plane || straight,
    }
}

/// Whether the points lie on the line through the first and the last, to
/// 1e-8 of its length.
fn collinear(points: &[nalgebra::Vector3<f64>]) -> bool {
    let (Some(first), Some(last)) = (points.first(), points.last()) else {
        return false;
    };
    let chord = last - first;
    let length = chord.norm();
    length > 0.0
        && points
            .iter()
            .all(|q| (q - first).cross(&chord).norm() <= 1e-8 * length * length)
}

/// The entry of G that changes sign from `ga` to `gb` with the largest
/// change (the test function of a multiple branch point: a simple root
/// there); None where no entry changes sign.
pub(super) fn sign_changing_entry(ga: &DMatrix<f64>, gb: &DMatrix<f64>) -> Option<(usize, usize)> {
    let m = ga.nrows();
    (0..m)
        .flat_map(|i| (0..m).map(move |j| (i, j)))
        .filter(|&e| ga[e] * gb[e] < 0.0)
        .max_by(|&e, &f| (gb[e] - ga[e]).abs().total_cmp(&(gb[f] - ga[f]).abs()))
}

/// Govaerts' G in O(N) where F_x is a large staircase: with F_x
/// regular, block elimination of [F_x Ψ; Φᵀ 0] [V; G] = [0; I_m]
/// gives V = −F_x⁻¹ Ψ G and G = −(Φᵀ F_x⁻¹ Ψ)⁻¹ (the Schur
/// complement; det of the bordered matrix = det F_x · det(−Φᵀ F_x⁻¹ Ψ),
/// so G exists exactly where the bordered matrix is regular). m band
/// solves with the LU of F_x; None where F_x has an exactly zero pivot
/// or the Schur complement is singular.
fn bordered_banded(
    a: &Staircase,
    right: &DMatrix<f64>,
    left: &DMatrix<f64>,
) -> Option<DMatrix<f64>> {
    let mut lu = StaircaseLu::default();
    lu.factor(a, None).ok()?;
    let m = right.ncols();
    let mut schur = DMatrix::zeros(m, m);
    let mut y = vec![0.0; a.size()];
    for c in 0..m {
        y.copy_from_slice(left.column(c).as_slice());
        if !lu.solve(&mut y) {
            return None;
        }
        for r in 0..m {
            schur[(r, c)] = right.column(r).iter().zip(&y).map(|(u, v)| u * v).sum();
        }
    }
    let g: DMatrix<f64> = -schur.try_inverse()?;
    g.iter().all(|v| v.is_finite()).then_some(g)
}
