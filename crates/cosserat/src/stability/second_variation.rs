//! The second variation of the potential energy of a Kirchhoff rod under
//! dead forces, for any stored energy, and its finite-element
//! discretization.
//!
//! # Derivation
//!
//! Perturb the frame by a rotation field in body components,
//! R_ε = R exp(ε ω̂), ω(0) = 0 at the clamp. With the Lie-group expansions
//! exp(−εω̂) κ̂ exp(εω̂) = (κ − ε ω×κ + ½ε² ω×(ω×κ))^ and
//! exp(−εω̂)(exp εω̂)' = (εω' − ½ε² ω×ω')^ + O(ε³), the curvature of R_ε is
//!
//!   κ_ε = κ + ε (ω' + κ×ω) + ε² (½ ω×(ω×κ) − ½ ω×ω') + O(ε³),
//!
//! and the tangent is d3_ε = R (e3 + ε ω×e3 + ½ε² ω×(ω×e3)) + O(ε³).
//! The potential energy with dead forces is
//! V = ∫ W(s, κ) ds − ∫ n·r' ds + const (n = P + ∫_s^L f, integration by
//! parts), so with N = Rᵀn the body force,
//!
//!   δ²V = ∫ (ω' + κ×ω)ᵀ H (ω' + κ×ω) + M·(ω×(ω×κ)) − M·(ω×ω')
//!           − N·(ω×(ω×e3)) ds,
//!
//! H = ∂²W/∂κ², M = ∂W/∂κ. At an equilibrium this does not depend on how
//! the second-order part of the perturbation is chosen.
//!
//! # Shear and extension (the Cosserat level)
//!
//! With W(κ, ν) = W_b(κ) + ½ (ν − e3)ᵀ S (ν − e3) the load term is
//! −∫ N·ν ds with ν an independent field (r' = Rν, r(L) free). Along
//! ν_ε = ν + εη the terms in η are ηᵀSη − 2 (N × ω)·η, and e3 becomes ν in
//! the last term above. η enters without derivatives, so it is minimized
//! out pointwise, η = S⁻¹(N × ω), leaving
//!
//!   δ²V = … − N·(ω×(ω×ν)) − (N × ω)ᵀ S⁻¹ (N × ω),
//!
//! a form in ω alone with the same structure. For a column under a thrust P
//! this gives B (π/2L)² = P (1 − P/S3) + P²/S1: Haringx's critical load when
//! S3 → ∞ (tests/cosserat.rs).
//!
//! # Any energy W(s, κ, ν)
//!
//! With the 6 × 6 Hessian H = [[H_κκ, H_κν], [H_νκ, H_νν]] at the
//! equilibrium strains (κ, ν), ν_ε = ν + εη + ε²ν₂ and κ_ε as above, the
//! second-order terms of W are ½ (a, η)ᵀ H (a, η) + M·κ₂ + N·ν₂ with
//! a = ω' + κ×ω and κ₂ = ½ ω×(ω×κ) − ½ ω×ω' (M = W_κ, N = W_ν). Those of
//! −n·r' = −N·(exp(εω̂) ν_ε) are −N·ν₂ − N·(ω×η) − ½ N·(ω×(ω×ν)), so ν₂
//! cancels and, with p = N × ω (N·(ω×η) = η·(N×ω)),
//!
//!   δ²V = ∫ aᵀH_κκa + 2aᵀH_κνη + ηᵀH_ννη − 2pᵀη + M·(ω×(ω×κ))
//!           − M·(ω×ω') − N·(ω×(ω×ν)) ds.
//!
//! η enters without derivatives; minimized pointwise (H_νν positive
//! definite), η = H_νν⁻¹ (p − H_νκ a), which leaves
//!
//!   aᵀ (H_κκ − H_κν H_νν⁻¹ H_νκ) a + 2 aᵀ H_κν H_νν⁻¹ p − pᵀ H_νν⁻¹ p
//!
//! in place of the first four terms: the Schur complement where H stood,
//! a cross term between a = ω' + κ×ω and p = N×ω, and −pᵀH_νν⁻¹p. With
//! H_κν = 0 and H_νν = S this is the quadratic case above
//! ([`FormCoefficients::strained`]; tests/strain_energy.rs checks the two
//! agree and the form against differences of the exact potential).
//!
//! For the linear energy at a planar equilibrium (κ = κ2 e2, M = M2 e2,
//! N = (F cos φ, 0, F sin φ)) and ω = (ψ, ζ, χ) this is the paper's (45):
//! B1(ψ' + κ2χ)² + B2ζ'² + B3(χ' − κ2ψ)² + F(−ψχ cos φ + (ζ² + ψ²) sin φ)
//! plus M2(ψχ' − χψ' − κ2ψ² − κ2χ²). The printed (45) has +χ²κ2 in the
//! last term; the term M·(ω×(ω×κ)) = −M2κ2(ψ² + χ²) is symmetric in ψ and
//! χ, and tests/stability.rs shows that only the symmetric form is singular
//! where the shooting Jacobian is. The in-plane part (ζ) and the
//! out-of-plane part (ψ, χ) decouple: the paper's (50) and (51).
//!
//! # A held position on a Cosserat rod
//!
//! A held tip position δr(L) = ∫ δ(Rν) ds = ∫ R(ω×ν + η) ds = 0 couples η
//! across the rod, so η is no longer minimized out pointwise alone. With a
//! multiplier μ (the variation of the support's force), minimizing over η
//! gives η = η₀(ω) − H_νν⁻¹Rᵀμ, η₀ = H_νν⁻¹(p − H_νκ a) the free minimizer
//! above; the constraint then fixes μ = D⁻¹ c(ω) with
//!
//!   c(ω) = ∫ R(ω×ν + η₀(ω)) ds,   D = ∫ R H_νν⁻¹ Rᵀ ds,
//!
//! and the form on ω is the free one plus c(ω)ᵀD⁻¹c(ω): the shear and
//! extension that bring the tip back cost strain energy, a rank-3 *spring*
//! (per held direction), not a constraint on ω (`numerics::constrained`
//! with springs: U = Cᵀ L⁻ᵀ, D = LLᵀ restricted to the held directions).
//! As H_νν⁻¹ → 0 (the Kirchhoff rod) D vanishes, ν = e3, and the spring
//! stiffens into the constraint ∫ R(ω×e3) ds = 0 below. In body
//! components, with T₀ = −[ν]× + H_νν⁻¹([N]× − H_νκ[κ]×) and
//! T₁ = −H_νν⁻¹H_νκ, the integrand of c is R(T₀ω + T₁ω') ([`TipMotion`]).
//!
//! # Discretization
//!
//! Lagrange finite elements of order p (1 to 3) on a uniform mesh, Gauss
//! quadrature with p + 1 points, nodal unknowns ω at every node but the
//! clamp. q = ω'ᵀAω' + 2ω'ᵀBω + ωᵀCω gives K; the L² Gram matrix G makes
//! the eigenvalues of K v = λ G v converge to those of the continuous form
//! (at order 2p).

use nalgebra::{DVector, Matrix3, Vector3};

use super::constrained::Constraints;
use crate::equations::RodSample;
use crate::model::{across, Freedom, TipSupport};
use crate::numerics::banded::SymmetricBanded;

/// The coefficients of the quadratic form at one point:
/// q(ω, ω') = ω'ᵀAω' + 2ω'ᵀBω + ωᵀCω.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FormCoefficients {
    /// A = H.
    pub a: Matrix3<f64>,
    /// `B = H[κ]× − ½[M]×`.
    pub b: Matrix3<f64>,
    /// `C = [κ]×ᵀH[κ]× + sym(Mκᵀ) − (M·κ)I − sym(Nνᵀ) + (N·ν) I
    ///     − [N]×ᵀ S⁻¹ [N]×` (ν = e3 and S⁻¹ = 0 for the Kirchhoff rod).
    pub c: Matrix3<f64>,
}

fn sym(m: Matrix3<f64>) -> Matrix3<f64> {
    (m + m.transpose()) * 0.5
}

impl FormCoefficients {
    /// From the stiffness H, curvature κ, moment M and internal force N
    /// (all body components) at a point.
    pub fn at(
        h: &Matrix3<f64>,
        kappa: &Vector3<f64>,
        moment: &Vector3<f64>,
        force: &Vector3<f64>,
    ) -> Self {
        Self::sheared(h, kappa, moment, force, &Vector3::zeros())
    }

    /// The same for a shearable, extensible rod with compliance
    /// c = S⁻¹ = (1/S1, 1/S2, 1/S3): the strain is ν = e3 + c∘N.
    pub fn sheared(
        h: &Matrix3<f64>,
        kappa: &Vector3<f64>,
        moment: &Vector3<f64>,
        force: &Vector3<f64>,
        compliance: &Vector3<f64>,
    ) -> Self {
        let k = kappa.cross_matrix();
        let nu = Vector3::z() + compliance.component_mul(force);
        let nx = force.cross_matrix();
        let id = Matrix3::identity();
        FormCoefficients {
            a: *h,
            b: h * k - moment.cross_matrix() * 0.5,
            c: sym(k.transpose() * h * k) + sym(moment * kappa.transpose())
                - id * moment.dot(kappa)
                - sym(force * nu.transpose())
                + id * force.dot(&nu)
                - nx.transpose() * Matrix3::from_diagonal(compliance) * nx,
        }
    }

    /// The same for any energy W(s, κ, ν): `h` the 6 × 6 Hessian at the
    /// equilibrium strains (κ, ν), M = W_κ, N = W_ν (the body force). With
    /// X = H_κν H_νν⁻¹ and Hs = H_κκ − X H_νκ (module doc):
    /// A = Hs, `B = Hs[κ]× − ½[M]× + X[N]×`, C = `[κ]×ᵀHs[κ]× + 2 sym([κ]×ᵀX[N]×)`
    /// `+ sym(Mκᵀ) − (M·κ)I − sym(Nνᵀ) + (N·ν)I − [N]×ᵀH_νν⁻¹[N]×`.
    /// None where H_νν is not positive definite (no minimizing η).
    pub fn strained(
        h: &nalgebra::Matrix6<f64>,
        kappa: &Vector3<f64>,
        moment: &Vector3<f64>,
        force: &Vector3<f64>,
        nu: &Vector3<f64>,
    ) -> Option<Self> {
        let block =
            |r: usize, c: usize| -> Matrix3<f64> { h.fixed_view::<3, 3>(r, c).into_owned() };
        let (kk, kn, nn) = (block(0, 0), block(0, 3), block(3, 3));
        let nn_inv = nn.cholesky()?.inverse();
        let x = kn * nn_inv;
        let hs = kk - x * kn.transpose();
        let k = kappa.cross_matrix();
        let nx = force.cross_matrix();
        let id = Matrix3::identity();
        Some(FormCoefficients {
            a: sym(hs),
            b: hs * k - moment.cross_matrix() * 0.5 + x * nx,
            c: sym(k.transpose() * hs * k)
                + sym(k.transpose() * x * nx) * 2.0
                + sym(moment * kappa.transpose())
                - id * moment.dot(kappa)
                - sym(force * nu.transpose())
                + id * force.dot(nu)
                - sym(nx.transpose() * nn_inv * nx),
        })
    }

    /// The quadratic form at (ω, ω').
    pub fn evaluate(&self, w: &Vector3<f64>, dw: &Vector3<f64>) -> f64 {
        dw.dot(&(self.a * dw)) + 2.0 * dw.dot(&(self.b * w)) + w.dot(&(self.c * w))
    }

    /// [`Self::evaluate`] for ω with only the `components` nonzero (a
    /// block's): the same sums without their zero terms.
    pub fn evaluate_on(&self, components: &[usize], w: &Vector3<f64>, dw: &Vector3<f64>) -> f64 {
        if components.len() == 3 {
            return self.evaluate(w, dw);
        }
        let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
        for &i in components {
            let (mut ai, mut bi, mut ci) = (0.0, 0.0, 0.0);
            for &j in components {
                ai += self.a[(i, j)] * dw[j];
                bi += self.b[(i, j)] * w[j];
                ci += self.c[(i, j)] * w[j];
            }
            a += dw[i] * ai;
            b += dw[i] * bi;
            c += w[i] * ci;
        }
        a + 2.0 * b + c
    }
}

/// How a rotation field moves the tip at one point of a shearable,
/// extensible rod whose shear and extension are minimized out: δr'(s) =
/// R(T₀ω + T₁ω') + R H_νν⁻¹Rᵀ(−μ) (module doc, "A held position on a
/// Cosserat rod"), body components.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipMotion {
    /// T₀ = −\[ν\]× + H_νν⁻¹(\[N\]× − H_νκ\[κ\]×).
    pub t0: Matrix3<f64>,
    /// T₁ = −H_νν⁻¹H_νκ.
    pub t1: Matrix3<f64>,
    /// H_νν⁻¹, the shear–extension compliance.
    pub compliance: Matrix3<f64>,
}

impl TipMotion {
    /// From the 6 × 6 Hessian of W(κ, ν) at the equilibrium strains, the
    /// curvature, the strain and the body force N; None where H_νν is not
    /// positive definite.
    pub fn strained(
        h: &nalgebra::Matrix6<f64>,
        kappa: &Vector3<f64>,
        nu: &Vector3<f64>,
        force: &Vector3<f64>,
    ) -> Option<Self> {
        let nn = h.fixed_view::<3, 3>(3, 3).into_owned();
        let nk = h.fixed_view::<3, 3>(3, 0).into_owned();
        let compliance = nn.cholesky()?.inverse();
        let coupling = compliance * nk;
        Some(TipMotion {
            t0: -nu.cross_matrix() + compliance * force.cross_matrix()
                - coupling * kappa.cross_matrix(),
            t1: -coupling,
            compliance,
        })
    }

    /// The quadratic shear–extension energy ½(ν − e3)ᵀS(ν − e3) with
    /// compliance c = S⁻¹ (no coupling to κ): ν = e3 + c∘N.
    pub fn sheared(compliance: &Vector3<f64>, force: &Vector3<f64>) -> Self {
        let c = Matrix3::from_diagonal(compliance);
        let nu = Vector3::z() + compliance.component_mul(force);
        TipMotion {
            t0: -nu.cross_matrix() + c * force.cross_matrix(),
            t1: Matrix3::zeros(),
            compliance: c,
        }
    }
}

/// Which components of ω a matrix acts on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Block {
    /// All three: ω = (ω1, ω2, ω3).
    Full,
    /// Bending in the plane (about d2): ω2 = ζ, paper (50).
    InPlane,
    /// Out of the plane: ω1 = ψ (about d1) and ω3 = χ (twist), paper (51).
    OutOfPlane,
}

impl Block {
    /// The components of ω in the block.
    pub fn components(self) -> &'static [usize] {
        match self {
            Block::Full => &[0, 1, 2],
            Block::InPlane => &[1],
            Block::OutOfPlane => &[0, 2],
        }
    }

    /// The name used in reports and HDF5 groups.
    pub fn name(self) -> &'static str {
        match self {
            Block::Full => "full",
            Block::InPlane => "in_plane",
            Block::OutOfPlane => "out_of_plane",
        }
    }
}

/// Lagrange elements of order p on a mesh of [0, L]: uniform, or uniform
/// on each piece between break points (interior point loads, where the
/// coefficients jump: an element straddling a jump would lose the
/// elements' order, silently).
#[derive(Debug, Clone, PartialEq)]
pub struct FiniteElements {
    length: f64,
    /// The element boundaries 0 = b_0 < … < b_E = L.
    boundaries: Vec<f64>,
    order: usize,
    /// A hinged base: ω2(0) is free (the in-plane block keeps node 0).
    hinged: bool,
}

/// Gauss–Legendre nodes and weights on [0, 1] with `m` points (m = 2..4).
fn gauss(m: usize) -> (Vec<f64>, Vec<f64>) {
    let m = if matches!(m, 2 | 3) { m } else { 4 };
    crate::numerics::quadrature::gauss_legendre(m, 0.0, 1.0).expect("tabulated")
}

/// The elements of each piece [ends[j], ends[j+1]] when `total` are shared
/// in proportion to the pieces' lengths: the floors of the exact shares,
/// then one more to the largest remainders (the first of equal ones), and
/// at least one each (the total grows where a piece would get none).
fn shares(ends: &[f64], total: usize) -> Vec<usize> {
    let length = ends[ends.len() - 1] - ends[0];
    let exact: Vec<f64> = ends
        .windows(2)
        .map(|w| (w[1] - w[0]) / length * total as f64)
        .collect();
    let mut counts: Vec<usize> = exact.iter().map(|x| x.floor() as usize).collect();
    let mut order: Vec<usize> = (0..exact.len()).collect();
    order.sort_by(|&i, &j| (exact[j] - exact[j].floor()).total_cmp(&(exact[i] - exact[i].floor())));
    let missing = total.saturating_sub(counts.iter().sum());
    for &i in order.iter().take(missing) {
        counts[i] += 1;
    }
    counts.iter().map(|&n| n.max(1)).collect()
}

impl FiniteElements {
    /// `elements` ≥ 1 elements of order `order` (1 to 3) on [0, length].
    /// Other values are a caller's error (the analyses check their options,
    /// [`super::StabilityOptions::new`]); they used to be clamped
    /// silently, so that an order 5 ran at order 3.
    pub fn new(length: f64, elements: usize, order: usize) -> Self {
        assert!(
            elements >= 1 && (1..=3).contains(&order),
            "finite elements: {elements} elements of order {order}; need ≥ 1 of order 1 to 3"
        );
        // L·(e/E): the last boundary is L exactly, never an ulp beyond it.
        let boundaries = (0..=elements)
            .map(|e| length * (e as f64 / elements as f64))
            .collect();
        FiniteElements {
            length,
            boundaries,
            order,
            hinged: false,
        }
    }

    /// The same number of elements (at least one per piece) with every
    /// break point in (0, L) on an element boundary: each piece between
    /// consecutive breaks gets its share of the elements in proportion to
    /// its length (largest remainders, at least one), uniform within the
    /// piece. No break leaves the mesh as it was. The element sizes stay
    /// within a factor 1 + O(1/E) of L/E where the pieces are long, so the
    /// convergence order and a Richardson estimate on doubled meshes keep
    /// their meaning (the pieces' shares differ from E·ℓ/L by less than
    /// one element).
    #[must_use]
    pub fn with_breaks(self, breaks: &[f64]) -> Self {
        let mut cuts: Vec<f64> = breaks
            .iter()
            .copied()
            .filter(|s| *s > 0.0 && *s < self.length)
            .collect();
        if cuts.is_empty() {
            return self;
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let ends: Vec<f64> = std::iter::once(0.0)
            .chain(cuts)
            .chain(std::iter::once(self.length))
            .collect();
        let counts = shares(&ends, self.elements());
        let mut boundaries = vec![0.0];
        for (piece, &n) in ends.windows(2).zip(&counts) {
            let (a, b) = (piece[0], piece[1]);
            boundaries.extend((1..n).map(|i| a + (b - a) * (i as f64 / n as f64)));
            boundaries.push(b);
        }
        FiniteElements { boundaries, ..self }
    }

    /// The number of elements.
    pub fn elements(&self) -> usize {
        self.boundaries.len() - 1
    }

    /// Start and size of element `e`.
    fn element(&self, e: usize) -> (f64, f64) {
        let (a, b) = (self.boundaries[e], self.boundaries[e + 1]);
        (a, b - a)
    }

    /// The same elements for a base that is a hinge about d2(0) (true) or a
    /// clamp (false): with a hinge the in-plane rotation ω2 at s = 0 is an
    /// unknown too.
    #[must_use]
    pub fn with_hinged_base(self, hinged: bool) -> Self {
        FiniteElements { hinged, ..self }
    }

    /// The first node carrying unknowns of a block: 0 where the base lets
    /// the block's rotation free, 1 at a clamp.
    fn first_node(&self, block: Block) -> usize {
        usize::from(!(self.hinged && block == Block::InPlane))
    }

    /// The largest element size.
    pub fn h(&self) -> f64 {
        (0..self.elements())
            .map(|e| self.element(e).1)
            .fold(0.0, f64::max)
    }

    /// All nodes s_0 = 0, …, s_{pE} = L (each element's boundaries exact,
    /// so the last node is L, never an ulp beyond it).
    pub fn nodes(&self) -> Vec<f64> {
        let p = self.order;
        let mut nodes = vec![0.0];
        for e in 0..self.elements() {
            let (a, h) = self.element(e);
            nodes.extend((1..p).map(|i| a + h * (i as f64 / p as f64)));
            nodes.push(self.boundaries[e + 1]);
        }
        nodes
    }

    /// The quadrature points in increasing order (where the equilibrium
    /// must be sampled).
    pub fn quadrature_points(&self) -> Vec<f64> {
        let (x, _) = gauss(self.order + 1);
        (0..self.elements())
            .flat_map(|e| {
                let (a, h) = self.element(e);
                x.iter().map(move |xi| a + xi * h).collect::<Vec<_>>()
            })
            .collect()
    }

    /// Lagrange shape functions and their ξ-derivatives at ξ ∈ [0, 1].
    fn shape(&self, xi: f64) -> (Vec<f64>, Vec<f64>) {
        let p = self.order;
        let nodes: Vec<f64> = (0..=p).map(|a| a as f64 / p as f64).collect();
        let mut value = vec![1.0; p + 1];
        let mut deriv = vec![0.0; p + 1];
        for a in 0..=p {
            for b in (0..=p).filter(|&b| b != a) {
                let denom = nodes[a] - nodes[b];
                let mut term = 1.0 / denom;
                for c in (0..=p).filter(|&c| c != a && c != b) {
                    term *= (xi - nodes[c]) / (nodes[a] - nodes[c]);
                }
                deriv[a] += term;
                value[a] *= (xi - nodes[b]) / denom;
            }
        }
        (value, deriv)
    }

    /// Number of unknowns of a block (the clamp node is fixed, unless the
    /// base is hinged and the block is in-plane).
    pub fn size(&self, block: Block) -> usize {
        block.components().len() * (self.elements() * self.order + 1 - self.first_node(block))
    }

    /// K for the coefficients at the quadrature points (in the order of
    /// [`Self::quadrature_points`]): element by element, ∫ φ_a'φ_b' A +
    /// φ_a'φ_b B + φ_aφ_b' Bᵀ + φ_aφ_b C over the block's components, by
    /// Gauss–Legendre with order + 1 points. Each point's block entries of
    /// A, B, Bᵀ, C and each element's φ' = dφ/dξ / h are read once, not
    /// once per pair of shape functions (the same products in the same
    /// order as a term-by-term sum, so the same K bit for bit).
    pub fn stiffness(&self, coeffs: &[FormCoefficients], block: Block) -> SymmetricBanded {
        assert_eq!(
            coeffs.len(),
            self.elements() * (self.order + 1),
            "one set per quadrature point"
        );
        let comps = block.components();
        let nc = comps.len();
        let p = self.order;
        let mut k = SymmetricBanded::zeros(self.size(block), nc * (p + 1) - 1);
        let first = self.first_node(block);
        let (xs, ws) = gauss(p + 1);
        let shapes: Vec<_> = xs.iter().map(|&x| self.shape(x)).collect();
        // [A, B, Bᵀ, C]_{c_x c_y} of the block's components x, y (≤ 3 each).
        let mut local = [[0.0; 4]; 9];
        let mut slopes = vec![0.0; p + 1];
        for e in 0..self.elements() {
            let (_, h) = self.element(e);
            for (g, ((values, derivatives), w)) in shapes.iter().zip(&ws).enumerate() {
                let c = &coeffs[e * (p + 1) + g];
                for (x, &ci) in comps.iter().enumerate() {
                    for (y, &cj) in comps.iter().enumerate() {
                        local[x * nc + y] =
                            [c.a[(ci, cj)], c.b[(ci, cj)], c.b[(cj, ci)], c.c[(ci, cj)]];
                    }
                }
                for (slope, d) in slopes.iter_mut().zip(derivatives) {
                    *slope = d / h;
                }
                let weight = w * h;
                for a in 0..=p {
                    let Some(ia) = (e * p + a).checked_sub(first) else {
                        continue;
                    };
                    let (va, da) = (values[a], slopes[a]);
                    for b in 0..=p {
                        let Some(ib) = (e * p + b).checked_sub(first) else {
                            continue;
                        };
                        let (vb, db) = (values[b], slopes[b]);
                        for x in 0..nc {
                            for y in 0..nc {
                                let (i, j) = (ia * nc + x, ib * nc + y);
                                if i < j {
                                    continue;
                                }
                                let [ca, cb, cbt, cc] = local[x * nc + y];
                                let v = da * db * ca + da * vb * cb + va * db * cbt + va * vb * cc;
                                k.add(i, j, weight * v);
                            }
                        }
                    }
                }
            }
        }
        k
    }

    /// The L² Gram matrix G (ω·ω integrated): each element adds h times
    /// the reference Gram matrix of the shape functions, component by
    /// component.
    pub fn mass(&self, block: Block) -> SymmetricBanded {
        let nc = block.components().len();
        let p = self.order;
        let mut g = SymmetricBanded::zeros(self.size(block), nc * (p + 1) - 1);
        let first = self.first_node(block);
        let (xs, ws) = gauss(p + 1);
        let shapes: Vec<_> = xs.iter().map(|&x| self.shape(x).0).collect();
        let reference: Vec<f64> = (0..(p + 1) * (p + 1))
            .map(|ab| {
                let (a, b) = (ab / (p + 1), ab % (p + 1));
                shapes
                    .iter()
                    .zip(&ws)
                    .map(|(val, w)| w * val[a] * val[b])
                    .sum()
            })
            .collect();
        for e in 0..self.elements() {
            let (_, h) = self.element(e);
            for a in 0..=p {
                let Some(ia) = (e * p + a).checked_sub(first) else {
                    continue;
                };
                for b in 0..=a {
                    let Some(ib) = (e * p + b).checked_sub(first) else {
                        continue;
                    };
                    for x in 0..nc {
                        g.add(ia * nc + x, ib * nc + x, h * reference[a * (p + 1) + b]);
                    }
                }
            }
        }
        g
    }

    /// The quadrature weights (times the element size), in the order of
    /// [`Self::quadrature_points`].
    pub fn quadrature_weights(&self) -> Vec<f64> {
        let (_, w) = gauss(self.order + 1);
        (0..self.elements())
            .flat_map(|e| {
                let (_, h) = self.element(e);
                w.iter().map(move |wi| wi * h).collect::<Vec<_>>()
            })
            .collect()
    }

    /// (ω, ω') at the quadrature points for a vector of block unknowns: the
    /// finite-element interpolant that K acts on.
    pub fn interpolate(&self, block: Block, v: &[f64]) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let mut out = Vec::with_capacity(self.elements() * (self.order + 1));
        self.for_each_point(block, v, |_, w, dw| out.push((*w, *dw)));
        out
    }

    /// `visit(weight, ω, ω')` at each quadrature point in the order of
    /// [`Self::quadrature_points`] (weight as in
    /// [`Self::quadrature_weights`]): [`Self::interpolate`] without storing
    /// the points, for sums over them.
    pub fn for_each_point(
        &self,
        block: Block,
        v: &[f64],
        mut visit: impl FnMut(f64, &Vector3<f64>, &Vector3<f64>),
    ) {
        self.for_each_point_of(block, &[v], |_, weight, points| {
            visit(weight, &points[0].0, &points[0].1);
        });
    }

    /// `visit(q, weight, points)` at each quadrature point q, `points[k]`
    /// being (ω, ω') of `vectors[k]` there: one pass over the points for
    /// several vectors (the factored Rayleigh quotients of a block's
    /// eigenvectors read each point's coefficients once; at 10⁵ elements
    /// those are 65 MB). Only the block's components are formed; the
    /// others are zero.
    pub fn for_each_point_of(
        &self,
        block: Block,
        vectors: &[&[f64]],
        mut visit: impl FnMut(usize, f64, &[(Vector3<f64>, Vector3<f64>)]),
    ) {
        let comps = block.components();
        let nc = comps.len();
        let first = self.first_node(block);
        let (xs, weights) = gauss(self.order + 1);
        let p = self.order;
        let shapes: Vec<_> = xs.iter().map(|&x| self.shape(x)).collect();
        // nodal[(k·(p + 1) + a)·nc + x]: component x of vector k at the
        // element's node a.
        let mut nodal = vec![0.0; vectors.len() * (p + 1) * nc];
        let mut points = vec![(Vector3::zeros(), Vector3::zeros()); vectors.len()];
        for e in 0..self.elements() {
            let (_, h) = self.element(e);
            for (k, v) in vectors.iter().enumerate() {
                for a in 0..=p {
                    let at = (k * (p + 1) + a) * nc;
                    match (e * p + a).checked_sub(first) {
                        Some(i) => nodal[at..at + nc].copy_from_slice(&v[i * nc..(i + 1) * nc]),
                        None => nodal[at..at + nc].fill(0.0),
                    }
                }
            }
            for (g, ((val, der), weight)) in shapes.iter().zip(&weights).enumerate() {
                for (k, (w, dw)) in points.iter_mut().enumerate() {
                    for (x, &c) in comps.iter().enumerate() {
                        let (mut value, mut slope) = (0.0, 0.0);
                        for a in 0..=p {
                            let n = nodal[(k * (p + 1) + a) * nc + x];
                            value += n * val[a];
                            slope += n * (der[a] / h);
                        }
                        w[c] = value;
                        dw[c] = slope;
                    }
                }
                visit(e * (p + 1) + g, weight * h, &points);
            }
        }
    }

    /// The linear constraints a tip support puts on ω: a position held
    /// along a is a·δr(L) = ∫ a·R(ω × e3) ds = Σ_c ∫ ω_c a·(d_c × d3) ds = 0
    /// (δd3 = R(ω × e3)); a frame held about b is b·R(L)ω(L) = 0. `samples`
    /// are at the quadrature points, `tip` at s = L. Constraints that the
    /// block does not see (zero rows) are dropped.
    pub fn support_constraints(
        &self,
        block: Block,
        support: &TipSupport,
        samples: &[RodSample],
        tip: &RodSample,
    ) -> Constraints {
        let n = self.size(block);
        let mut rows = Vec::new();
        let positions: Vec<Vector3<f64>> = match support.translation {
            Freedom::Free => vec![],
            Freedom::Fixed => (0..3).map(|j| Vector3::ith(j, 1.0)).collect(),
            Freedom::Axial(a) => across(&a).to_vec(),
        };
        for a in positions {
            rows.push(self.position_row(block, &a, samples));
        }
        let frame = nalgebra::Matrix3::from_columns(&tip.directors);
        let turns: Vec<Vector3<f64>> = match support.rotation {
            Freedom::Free => vec![],
            Freedom::Fixed => (0..3).map(|j| Vector3::ith(j, 1.0)).collect(),
            Freedom::Axial(a) => across(&a).map(|b| frame.transpose() * b).to_vec(),
        };
        let last = self.elements() * self.order - self.first_node(block);
        for v in turns {
            let mut row = DVector::zeros(n);
            for (x, &c) in block.components().iter().enumerate() {
                row[last * block.components().len() + x] = v[c];
            }
            rows.push(row);
        }
        Constraints::from_rows(&rows, n)
    }

    /// The tip support of a shearable, extensible rod: a frame held as in
    /// [`Self::support_constraints`], a position held along a_1 … a_k as
    /// springs (module doc, "A held position on a Cosserat rod"): rows
    /// c_i = a_i·∫ R(T₀ω + T₁ω') ds, D_ij = a_i·(∫ R H_νν⁻¹ Rᵀ ds) a_j =
    /// LLᵀ, springs the rows of L⁻¹C. `motions` at the quadrature points.
    /// None where D is not positive definite.
    pub fn support_springs(
        &self,
        block: Block,
        support: &TipSupport,
        samples: &[RodSample],
        tip: &RodSample,
        motions: &[TipMotion],
    ) -> Option<Constraints> {
        let held = TipSupport {
            translation: Freedom::Free,
            ..support.clone()
        };
        let turns = self.support_constraints(block, &held, samples, tip);
        let directions: Vec<Vector3<f64>> = match support.translation {
            Freedom::Free => return Some(turns),
            Freedom::Fixed => (0..3).map(|j| Vector3::ith(j, 1.0)).collect(),
            Freedom::Axial(a) => across(&a).to_vec(),
        };
        let rows: Vec<DVector<f64>> = directions
            .iter()
            .map(|a| self.motion_row(block, a, samples, motions))
            .collect();
        let weights = self.quadrature_weights();
        let compliance = samples.iter().zip(motions).zip(&weights).fold(
            Matrix3::zeros(),
            |sum, ((sample, m), w)| {
                let r = Matrix3::from_columns(&sample.directors);
                sum + r * m.compliance * r.transpose() * *w
            },
        );
        let k = directions.len();
        let d = nalgebra::DMatrix::from_fn(k, k, |i, j| {
            directions[i].dot(&(compliance * directions[j]))
        });
        let l = d.cholesky()?.l();
        let c = nalgebra::DMatrix::from_fn(k, self.size(block), |i, j| rows[i][j]);
        let springs = l.solve_lower_triangular(&c)?;
        let springs: Vec<DVector<f64>> = springs.row_iter().map(|r| r.transpose()).collect();
        Some(turns.with_springs(&springs))
    }

    /// Σ_q w_q a·R(T₀ φ_node e_c + T₁ φ'_node e_c)(s_q) for every unknown:
    /// a·δr(L) of the rotation field with the strain minimized out.
    fn motion_row(
        &self,
        block: Block,
        a: &Vector3<f64>,
        samples: &[RodSample],
        motions: &[TipMotion],
    ) -> DVector<f64> {
        let comps = block.components();
        let p = self.order;
        let (xs, ws) = gauss(p + 1);
        let mut row = DVector::zeros(self.size(block));
        for e in 0..self.elements() {
            let (_, h) = self.element(e);
            for (g, (&x, w)) in xs.iter().zip(&ws).enumerate() {
                let q = e * (p + 1) + g;
                let body = Matrix3::from_columns(&samples[q].directors).transpose() * a;
                let (along, rate) = (
                    motions[q].t0.transpose() * body,
                    motions[q].t1.transpose() * body,
                );
                let (val, der) = self.shape(x);
                for (local, (phi, dphi)) in val.iter().zip(&der).enumerate() {
                    let Some(node) = (e * p + local).checked_sub(self.first_node(block)) else {
                        continue;
                    };
                    for (i, &c) in comps.iter().enumerate() {
                        row[node * comps.len() + i] +=
                            w * h * (phi * along[c] + dphi / h * rate[c]);
                    }
                }
            }
        }
        row
    }

    /// Σ_q w_q φ_node(s_q) a·(d_c × d3)(s_q) for every unknown.
    fn position_row(&self, block: Block, a: &Vector3<f64>, samples: &[RodSample]) -> DVector<f64> {
        let comps = block.components();
        let p = self.order;
        let (xs, ws) = gauss(p + 1);
        let mut row = DVector::zeros(self.size(block));
        for e in 0..self.elements() {
            let (_, h) = self.element(e);
            for (g, (&x, w)) in xs.iter().zip(&ws).enumerate() {
                let sample = &samples[e * (p + 1) + g];
                let d = &sample.directors;
                let (val, _) = self.shape(x);
                for (local, phi) in val.iter().enumerate() {
                    let Some(node) = (e * p + local).checked_sub(self.first_node(block)) else {
                        continue;
                    };
                    for (i, &c) in comps.iter().enumerate() {
                        row[node * comps.len() + i] += w * h * phi * a.dot(&d[c].cross(&d[2]));
                    }
                }
            }
        }
        row
    }

    /// Nodal values of ω (3 components, zero at the clamp) from a vector of
    /// block unknowns.
    pub fn nodal_rotations(&self, block: Block, v: &[f64]) -> Vec<Vector3<f64>> {
        let comps = block.components();
        let first = self.first_node(block);
        let mut out = vec![Vector3::zeros(); self.elements() * self.order + 1];
        for (node, w) in out.iter_mut().enumerate().skip(first) {
            for (x, &c) in comps.iter().enumerate() {
                w[c] = v[(node - first) * comps.len() + x];
            }
        }
        out
    }
}
