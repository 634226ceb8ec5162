//! The compiled formula: names resolved to strain, profile or parameter
//! slots, constants folded, powers with constant exponents specialized;
//! evaluated by a walk of the tree over any dual-number type (no
//! allocation, the recursion as deep as the formula).

use num_dual::DualNum;

use super::parse::{BinaryOp, Node, Position};
use super::FormulaError;

/// What a formula may read besides its named parameters: the arc length,
/// the strains and the stiffness profiles at s.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variable {
    /// s, the arc length (m).
    ArcLength,
    /// k_i = κ_i − κ⁰_i(s), i = 1, 2, 3: curvature-twist strain less its
    /// intrinsic value.
    Curvature(usize),
    /// v_i, i = 1, 2, 3: the shear-extension strains ν (ν = (0, 0, 1)
    /// unstrained).
    ShearExtension(usize),
    /// B_i(s), i = 1, 2, 3: the file's `energy.stiffness` profiles.
    Stiffness(usize),
}

impl Variable {
    /// Every variable's name in the formula language.
    pub const NAMES: [&'static str; 10] =
        ["s", "k1", "k2", "k3", "v1", "v2", "v3", "B1", "B2", "B3"];

    /// The slot of the variable in the array a formula is evaluated at.
    pub fn slot(self) -> usize {
        match self {
            Variable::ArcLength => 0,
            Variable::Curvature(i) => 1 + i,
            Variable::ShearExtension(i) => 4 + i,
            Variable::Stiffness(i) => 7 + i,
        }
    }

    fn named(name: &str) -> Option<Variable> {
        let slot = Self::NAMES.iter().position(|n| *n == name)?;
        Some(match slot {
            0 => Variable::ArcLength,
            1..=3 => Variable::Curvature(slot - 1),
            4..=6 => Variable::ShearExtension(slot - 4),
            _ => Variable::Stiffness(slot - 7),
        })
    }
}

/// The values of the variables, indexed by [`Variable::slot`].
pub type Inputs<D> = [D; 10];

/// A function of one argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Function {
    Sqrt,
    Exp,
    Log,
    Sin,
    Cos,
    Tan,
    Sinh,
    Cosh,
    Tanh,
    Atan,
    Abs,
    /// sign(x) ∈ {−1, 1} (the derivative of |x|; not in the language).
    Sign,
}

/// The functions of the language, by name: one argument, or two for
/// `min`, `max`.
pub const FUNCTIONS: [&str; 13] = [
    "sqrt", "exp", "log", "sin", "cos", "tan", "sinh", "cosh", "tanh", "atan", "abs", "min", "max",
];

fn function(name: &str) -> Option<Function> {
    Some(match name {
        "sqrt" => Function::Sqrt,
        "exp" => Function::Exp,
        "log" => Function::Log,
        "sin" => Function::Sin,
        "cos" => Function::Cos,
        "tan" => Function::Tan,
        "sinh" => Function::Sinh,
        "cosh" => Function::Cosh,
        "tanh" => Function::Tanh,
        "atan" => Function::Atan,
        "abs" => Function::Abs,
        _ => return None,
    })
}

/// A node of the compiled tree.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Expr {
    Constant(f64),
    Variable(usize),
    Negate(Box<Expr>),
    Add(Box<Expr>, Box<Expr>),
    Subtract(Box<Expr>, Box<Expr>),
    Multiply(Box<Expr>, Box<Expr>),
    Divide(Box<Expr>, Box<Expr>),
    /// x^n, n a constant integer.
    PowInteger(Box<Expr>, i32),
    /// x^c, c a constant.
    PowReal(Box<Expr>, f64),
    /// x^y = exp(y ln x), both varying.
    Power(Box<Expr>, Box<Expr>),
    Apply(Function, Box<Expr>),
    Min(Box<Expr>, Box<Expr>),
    Max(Box<Expr>, Box<Expr>),
    /// if a < b { then } else { otherwise } (derivatives of min, max).
    Less(Box<[Expr; 4]>),
}

/// Resolves names against the variables, `pi` and `parameter`.
pub(super) fn compile(
    node: &Node,
    parameter: &dyn Fn(&str) -> Option<f64>,
) -> Result<Expr, FormulaError> {
    let expr = match node {
        Node::Number(v) => Expr::Constant(*v),
        Node::Name(name, at) => name_value(name, *at, parameter)?,
        Node::Negate(x) => Expr::Negate(Box::new(compile(x, parameter)?)),
        Node::Binary(op, a, b) => binary(*op, compile(a, parameter)?, compile(b, parameter)?),
        Node::Call(name, args, at) => call(name, args, *at, parameter)?,
    };
    Ok(fold(expr))
}

fn name_value(
    name: &str,
    at: Position,
    parameter: &dyn Fn(&str) -> Option<f64>,
) -> Result<Expr, FormulaError> {
    if let Some(v) = Variable::named(name) {
        return Ok(Expr::Variable(v.slot()));
    }
    if name == "pi" {
        return Ok(Expr::Constant(std::f64::consts::PI));
    }
    if let Some(v) = parameter(name) {
        return Ok(Expr::Constant(v));
    }
    Err(FormulaError::at(
        at.line,
        at.column,
        format!(
            "unknown name `{name}`: a formula reads {}, `pi` and the names of \
             energy.parameters",
            Variable::NAMES.join(", ")
        ),
    ))
}

fn binary(op: BinaryOp, a: Expr, b: Expr) -> Expr {
    let (a, b) = (Box::new(a), Box::new(b));
    match op {
        BinaryOp::Add => Expr::Add(a, b),
        BinaryOp::Subtract => Expr::Subtract(a, b),
        BinaryOp::Multiply => Expr::Multiply(a, b),
        BinaryOp::Divide => Expr::Divide(a, b),
        BinaryOp::Power => match *b {
            Expr::Constant(c) if c.fract() == 0.0 && c.abs() <= 1024.0 => {
                Expr::PowInteger(a, c as i32)
            }
            Expr::Constant(c) => Expr::PowReal(a, c),
            _ => Expr::Power(a, b),
        },
    }
}

fn call(
    name: &str,
    args: &[Node],
    at: Position,
    parameter: &dyn Fn(&str) -> Option<f64>,
) -> Result<Expr, FormulaError> {
    let arity = if matches!(name, "min" | "max") { 2 } else { 1 };
    if !FUNCTIONS.contains(&name) {
        return Err(FormulaError::at(
            at.line,
            at.column,
            format!(
                "unknown function `{name}`; the functions are {}",
                FUNCTIONS.join(", ")
            ),
        ));
    }
    if args.len() != arity {
        return Err(FormulaError::at(
            at.line,
            at.column,
            format!("`{name}` takes {arity} argument(s), given {}", args.len()),
        ));
    }
    let mut compiled = args
        .iter()
        .map(|a| compile(a, parameter).map(Box::new))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(match (name, function(name)) {
        (_, Some(f)) => Expr::Apply(f, compiled.remove(0)),
        ("min", _) => Expr::Min(compiled.remove(0), compiled.remove(0)),
        _ => Expr::Max(compiled.remove(0), compiled.remove(0)),
    })
}

/// Folds a node whose operands are constants into a constant.
fn fold(expr: Expr) -> Expr {
    let foldable = !matches!(expr, Expr::Constant(_) | Expr::Variable(_))
        && expr
            .children()
            .iter()
            .all(|c| matches!(c, Expr::Constant(_)));
    if foldable {
        Expr::Constant(expr.eval::<f64>(&[]))
    } else {
        expr
    }
}

impl Expr {
    /// The value at `x`, in the arithmetic of `D` (derivatives carried
    /// exactly by dual numbers). `min`/`max` take the derivative of the
    /// argument chosen (one-sided at a tie), `abs` that of ±x (none at 0).
    pub(super) fn eval<D: DualNum<Primitive = f64> + Copy>(&self, x: &[D]) -> D {
        match self {
            Expr::Constant(c) => D::from(*c),
            Expr::Variable(i) => x[*i],
            Expr::Negate(a) => -a.eval(x),
            Expr::Add(a, b) => a.eval(x) + b.eval(x),
            Expr::Subtract(a, b) => a.eval(x) - b.eval(x),
            Expr::Multiply(a, b) => a.eval(x) * b.eval(x),
            Expr::Divide(a, b) => a.eval(x) / b.eval(x),
            Expr::PowInteger(a, n) => a.eval(x).powi(*n),
            Expr::PowReal(a, c) => a.eval(x).powf(*c),
            Expr::Power(a, b) => (b.eval(x) * a.eval(x).ln()).exp(),
            Expr::Apply(f, a) => apply(*f, a.eval(x)),
            Expr::Min(a, b) => {
                let (u, v) = (a.eval(x), b.eval(x));
                if v.re() < u.re() {
                    v
                } else {
                    u
                }
            }
            Expr::Max(a, b) => {
                let (u, v) = (a.eval(x), b.eval(x));
                if v.re() > u.re() {
                    v
                } else {
                    u
                }
            }
            Expr::Less(parts) => {
                let [a, b, then, otherwise] = parts.as_ref();
                if a.eval(x).re() < b.eval(x).re() {
                    then.eval(x)
                } else {
                    otherwise.eval(x)
                }
            }
        }
    }

    /// The operands of this node.
    pub(super) fn children(&self) -> Vec<&Expr> {
        match self {
            Expr::Constant(_) | Expr::Variable(_) => vec![],
            Expr::Negate(a) | Expr::PowInteger(a, _) | Expr::PowReal(a, _) | Expr::Apply(_, a) => {
                vec![a]
            }
            Expr::Add(a, b)
            | Expr::Subtract(a, b)
            | Expr::Multiply(a, b)
            | Expr::Divide(a, b)
            | Expr::Power(a, b)
            | Expr::Min(a, b)
            | Expr::Max(a, b) => vec![a, b],
            Expr::Less(parts) => parts.iter().collect(),
        }
    }

    /// Whether the tree reads slot `i`.
    pub(super) fn reads(&self, i: usize) -> bool {
        match self {
            Expr::Variable(j) => *j == i,
            _ => self.children().iter().any(|c| c.reads(i)),
        }
    }

    /// The parity of the tree under the sign change of the slots in
    /// `flipped`, proved from its structure (sound: `Even` only when the
    /// formula is even for every value of the other slots).
    pub(super) fn parity(&self, flipped: &[usize]) -> Parity {
        use Parity::{Even, Neither, Odd};
        match self {
            Expr::Constant(_) => Even,
            Expr::Variable(i) => {
                if flipped.contains(i) {
                    Odd
                } else {
                    Even
                }
            }
            Expr::Negate(a) => a.parity(flipped),
            Expr::Add(a, b) | Expr::Subtract(a, b) => {
                match (a.parity(flipped), b.parity(flipped)) {
                    (p, q) if p == q => p,
                    _ => Neither,
                }
            }
            Expr::Multiply(a, b) | Expr::Divide(a, b) => {
                product_parity(a.parity(flipped), b.parity(flipped))
            }
            Expr::PowInteger(a, n) => match a.parity(flipped) {
                Odd if n % 2 != 0 => Odd,
                Odd | Even => Even,
                Neither => Neither,
            },
            Expr::PowReal(a, _) | Expr::Power(a, _) => {
                let exponent_even = match self {
                    Expr::Power(_, b) => b.parity(flipped) == Even,
                    _ => true,
                };
                if a.parity(flipped) == Even && exponent_even {
                    Even
                } else {
                    Neither
                }
            }
            Expr::Apply(f, a) => function_parity(*f, a.parity(flipped)),
            Expr::Min(a, b) | Expr::Max(a, b) => {
                if a.parity(flipped) == Even && b.parity(flipped) == Even {
                    Even
                } else {
                    Neither
                }
            }
            Expr::Less(parts) => {
                if parts.iter().all(|p| p.parity(flipped) == Even) {
                    Even
                } else {
                    Neither
                }
            }
        }
    }
}

/// Parity under a sign change of some variables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Parity {
    Even,
    Odd,
    Neither,
}

fn product_parity(p: Parity, q: Parity) -> Parity {
    use Parity::{Even, Neither, Odd};
    match (p, q) {
        (Neither, _) | (_, Neither) => Neither,
        (a, b) if a == b => Even,
        _ => Odd,
    }
}

fn function_parity(f: Function, p: Parity) -> Parity {
    use Parity::{Even, Neither, Odd};
    let odd_in_odd_out = matches!(
        f,
        Function::Sin
            | Function::Tan
            | Function::Sinh
            | Function::Tanh
            | Function::Atan
            | Function::Sign
    );
    let even_of_odd = matches!(f, Function::Abs | Function::Cos | Function::Cosh);
    match p {
        Odd if odd_in_odd_out => Odd,
        Odd if even_of_odd => Even,
        Even => Even,
        Odd | Neither => Neither,
    }
}

fn apply<D: DualNum<Primitive = f64> + Copy>(f: Function, x: D) -> D {
    match f {
        Function::Sqrt => x.sqrt(),
        Function::Exp => x.exp(),
        Function::Log => x.ln(),
        Function::Sin => x.sin(),
        Function::Cos => x.cos(),
        Function::Tan => x.tan(),
        Function::Sinh => x.sinh(),
        Function::Cosh => x.cosh(),
        Function::Tanh => x.tanh(),
        Function::Atan => x.atan(),
        Function::Abs => {
            if x.re() < 0.0 {
                -x
            } else {
                x
            }
        }
        Function::Sign => D::from(if x.re() < 0.0 { -1.0 } else { 1.0 }),
    }
}
