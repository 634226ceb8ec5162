//! The derivatives of a formula the equations need, differentiated
//! symbolically once when the formula is read: M = ∂W/∂k, H = ∂²W/∂k²,
//! their total s-rates, and the third derivative contracted with a vector,
//! each a simplified tree evaluated in plain `f64` (no dual numbers at
//! run time, so the cost is that of the expressions themselves).
//!
//! The total s-rate at fixed κ is D_s = ∂_s + Σ B_i′ ∂_{B_i} − Σ κ⁰_i′ ∂_{k_i}
//! (k = κ − κ⁰(s)), with B_i′ and κ⁰_i′ extra inputs; the contraction
//! (∂(Hv)/∂κ)_ij = Σ_l W_ijl v_l is D_v H_ij with D_v = Σ v_l ∂_{k_l}, v extra
//! inputs. Trees are simplified as they are built (constants folded, 0 and
//! 1 absorbed); where they would grow beyond [`MAX_NODES`] the formula
//! keeps automatic differentiation instead.

use super::expr::{Expr, Function};

/// Input slots beyond the formula's own ten: B′ (10–12), κ⁰′ (13–15), v
/// (16–18).
pub(super) const STIFFNESS_RATE: usize = 10;
pub(super) const CURVATURE_RATE: usize = 13;
pub(super) const DIRECTION: usize = 16;
/// All slots.
pub(super) const SLOTS: usize = 19;

/// The largest total size of the derivative trees kept.
pub(super) const MAX_NODES: usize = 200_000;

/// The upper triangle of a symmetric 3 × 3 matrix, row by row.
pub(super) const PAIRS: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// M, H (upper triangle), D_s M, D_s H and D_v H of a formula.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Derivatives {
    pub moment: [Expr; 3],
    pub stiffness: [Expr; 6],
    pub moment_rate: [Expr; 3],
    pub stiffness_rate: [Expr; 6],
    pub contracted: [Expr; 6],
}

impl Derivatives {
    /// The derivatives of `w`, or None when their trees would exceed
    /// [`MAX_NODES`].
    pub(super) fn of(w: &Expr) -> Option<Derivatives> {
        let k = |i: usize| 1 + i;
        let moment: [Expr; 3] = std::array::from_fn(|i| diff(w, k(i)));
        let stiffness: [Expr; 6] = PAIRS.map(|(i, j)| diff(&moment[i], k(j)));
        let along_s = |e: &Expr| {
            let mut d = diff(e, 0);
            for i in 0..3 {
                d = add(d, mul(var(STIFFNESS_RATE + i), diff(e, 7 + i)));
                d = sub(d, mul(var(CURVATURE_RATE + i), diff(e, k(i))));
            }
            d
        };
        let moment_rate = moment.clone().map(|m| along_s(&m));
        let stiffness_rate = stiffness.clone().map(|h| along_s(&h));
        let contracted = stiffness.clone().map(|h| {
            (0..3).fold(Expr::Constant(0.0), |acc, l| {
                add(acc, mul(var(DIRECTION + l), diff(&h, k(l))))
            })
        });
        let d = Derivatives {
            moment,
            stiffness,
            moment_rate,
            stiffness_rate,
            contracted,
        };
        (d.size() <= MAX_NODES).then_some(d)
    }

    fn size(&self) -> usize {
        [
            &self.moment[..],
            &self.stiffness[..],
            &self.moment_rate[..],
            &self.stiffness_rate[..],
            &self.contracted[..],
        ]
        .iter()
        .flat_map(|a| a.iter())
        .map(nodes)
        .sum()
    }
}

fn nodes(e: &Expr) -> usize {
    1 + e.children().into_iter().map(nodes).sum::<usize>()
}

fn var(slot: usize) -> Expr {
    Expr::Variable(slot)
}

fn constant(e: &Expr) -> Option<f64> {
    match e {
        Expr::Constant(c) => Some(*c),
        _ => None,
    }
}

fn add(a: Expr, b: Expr) -> Expr {
    match (constant(&a), constant(&b)) {
        (Some(x), Some(y)) => Expr::Constant(x + y),
        (Some(0.0), _) => b,
        (_, Some(0.0)) => a,
        _ => Expr::Add(Box::new(a), Box::new(b)),
    }
}

fn sub(a: Expr, b: Expr) -> Expr {
    match (constant(&a), constant(&b)) {
        (Some(x), Some(y)) => Expr::Constant(x - y),
        (_, Some(0.0)) => a,
        (Some(0.0), _) => neg(b),
        _ => Expr::Subtract(Box::new(a), Box::new(b)),
    }
}

fn neg(a: Expr) -> Expr {
    match a {
        Expr::Constant(x) => Expr::Constant(-x),
        Expr::Negate(inner) => *inner,
        _ => Expr::Negate(Box::new(a)),
    }
}

fn mul(a: Expr, b: Expr) -> Expr {
    match (constant(&a), constant(&b)) {
        (Some(x), Some(y)) => Expr::Constant(x * y),
        (Some(0.0), _) | (_, Some(0.0)) => Expr::Constant(0.0),
        (Some(1.0), _) => b,
        (_, Some(1.0)) => a,
        _ => Expr::Multiply(Box::new(a), Box::new(b)),
    }
}

fn div(a: Expr, b: Expr) -> Expr {
    match (constant(&a), constant(&b)) {
        (Some(x), Some(y)) => Expr::Constant(x / y),
        (Some(0.0), _) => Expr::Constant(0.0),
        (_, Some(1.0)) => a,
        _ => Expr::Divide(Box::new(a), Box::new(b)),
    }
}

fn powi(a: Expr, n: i32) -> Expr {
    match (n, constant(&a)) {
        (0, _) => Expr::Constant(1.0),
        (1, _) => a,
        (_, Some(x)) => Expr::Constant(x.powi(n)),
        _ => Expr::PowInteger(Box::new(a), n),
    }
}

fn apply(f: Function, a: Expr) -> Expr {
    Expr::Apply(f, Box::new(a))
}

/// ∂e/∂(slot).
fn diff(e: &Expr, slot: usize) -> Expr {
    let d = |x: &Expr| diff(x, slot);
    match e {
        Expr::Constant(_) => Expr::Constant(0.0),
        Expr::Variable(i) => Expr::Constant(if *i == slot { 1.0 } else { 0.0 }),
        Expr::Negate(a) => neg(d(a)),
        Expr::Add(a, b) => add(d(a), d(b)),
        Expr::Subtract(a, b) => sub(d(a), d(b)),
        Expr::Multiply(a, b) => add(mul(d(a), (**b).clone()), mul((**a).clone(), d(b))),
        // (a/b)' = (a' − (a/b) b')/b
        Expr::Divide(a, b) => div(sub(d(a), mul(e.clone(), d(b))), (**b).clone()),
        Expr::PowInteger(a, n) => mul(
            mul(Expr::Constant(f64::from(*n)), powi((**a).clone(), n - 1)),
            d(a),
        ),
        Expr::PowReal(a, c) => {
            let lower = if c - 1.0 == 0.0 {
                Expr::Constant(1.0)
            } else {
                Expr::PowReal(a.clone(), c - 1.0)
            };
            mul(mul(Expr::Constant(*c), lower), d(a))
        }
        // (a^b)' = a^b (b' ln a + b a'/a)
        Expr::Power(a, b) => {
            let log = apply(Function::Log, (**a).clone());
            let inner = add(mul(d(b), log), div(mul((**b).clone(), d(a)), (**a).clone()));
            mul(e.clone(), inner)
        }
        Expr::Apply(f, a) => mul(outer(*f, a), d(a)),
        // min(a, b) = b if b < a else a
        Expr::Min(a, b) => less((**b).clone(), (**a).clone(), d(b), d(a)),
        // max(a, b) = b if a < b else a
        Expr::Max(a, b) => less((**a).clone(), (**b).clone(), d(b), d(a)),
        Expr::Less(p) => {
            let [a, b, then, otherwise] = p.as_ref();
            less(a.clone(), b.clone(), d(then), d(otherwise))
        }
    }
}

fn less(a: Expr, b: Expr, then: Expr, otherwise: Expr) -> Expr {
    if then == otherwise {
        return then;
    }
    Expr::Less(Box::new([a, b, then, otherwise]))
}

/// f′(a) as a tree.
fn outer(f: Function, a: &Expr) -> Expr {
    let a = a.clone();
    let one = || Expr::Constant(1.0);
    match f {
        Function::Sqrt => div(Expr::Constant(0.5), apply(Function::Sqrt, a)),
        Function::Exp => apply(Function::Exp, a),
        Function::Log => div(one(), a),
        Function::Sin => apply(Function::Cos, a),
        Function::Cos => neg(apply(Function::Sin, a)),
        Function::Tan => add(one(), powi(apply(Function::Tan, a), 2)),
        Function::Sinh => apply(Function::Cosh, a),
        Function::Cosh => apply(Function::Sinh, a),
        Function::Tanh => sub(one(), powi(apply(Function::Tanh, a), 2)),
        Function::Atan => div(one(), add(one(), powi(a, 2))),
        Function::Abs => apply(Function::Sign, a),
        Function::Sign => Expr::Constant(0.0),
    }
}
