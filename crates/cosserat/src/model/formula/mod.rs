//! Energies written as formulas: a small expression language parsed once
//! and evaluated over dual numbers (num-dual), so that the moment, the
//! stiffness, their s-rates and the third derivative the equations need
//! come out exact — no derivative is written by hand.
//!
//! A formula reads the strains `k1, k2, k3` (κ − κ⁰(s), the curvature-twist
//! less its intrinsic value), `v1, v2, v3` (the shear-extension strains),
//! the arc length `s`, the stiffness profiles `B1, B2, B3` of the file, the
//! constant `pi` and the names of `energy.parameters`; it combines them
//! with `+ - * / ^`, parentheses and the functions `sqrt exp log sin cos
//! tan sinh cosh tanh atan abs min max` (see docs/problem-files.md).

mod derivative;
mod energy;
mod expr;
mod parse;

pub use energy::FormulaEnergy;
pub use expr::{Variable, FUNCTIONS};

use std::fmt;

use num_dual::DualNum;

use expr::{Expr, Inputs, Parity};

/// A refused formula: what is wrong and where (1-based line and column).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FormulaError {
    line: usize,
    column: usize,
    message: String,
}

impl FormulaError {
    fn at(line: usize, column: usize, message: String) -> Self {
        FormulaError {
            line,
            column,
            message,
        }
    }

    /// The line of the offending text (1-based).
    pub fn line(&self) -> usize {
        self.line
    }

    /// The column of the offending text (1-based, in characters).
    pub fn column(&self) -> usize {
        self.column
    }
}

impl fmt::Display for FormulaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "line {}, column {}: {}",
            self.line, self.column, self.message
        )
    }
}

impl std::error::Error for FormulaError {}

/// A parsed and compiled formula with its parameters bound.
#[derive(Debug, Clone, PartialEq)]
pub struct Formula {
    text: String,
    tree: Expr,
    /// The parameter names the text reads.
    bound: Vec<String>,
    /// The derivatives the equations need, symbolically (None: too large,
    /// automatic differentiation instead).
    derivatives: Option<Box<derivative::Derivatives>>,
}

impl Formula {
    /// Parses `text`, binding each name that is not a variable to
    /// `parameter(name)`; refused with line and column where the text
    /// does not parse, names an unknown function or name, or calls a
    /// function with the wrong number of arguments.
    pub fn new(text: &str, parameter: &dyn Fn(&str) -> Option<f64>) -> Result<Self, FormulaError> {
        let node = parse::parse(text)?;
        let bound = std::cell::RefCell::new(Vec::new());
        let recording = |name: &str| {
            let v = parameter(name)?;
            bound.borrow_mut().push(name.to_owned());
            Some(v)
        };
        let tree = expr::compile(&node, &recording)?;
        let derivatives = derivative::Derivatives::of(&tree).map(Box::new);
        Ok(Formula {
            text: text.to_owned(),
            tree,
            bound: bound.into_inner(),
            derivatives,
        })
    }

    /// The symbolic derivatives, when their trees are small enough.
    fn derivatives(&self) -> Option<&derivative::Derivatives> {
        self.derivatives.as_deref()
    }

    /// Whether the text reads the parameter `name`.
    pub fn binds(&self, name: &str) -> bool {
        self.bound.iter().any(|b| b == name)
    }

    /// The text as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Whether the formula reads `v`.
    pub fn reads(&self, v: Variable) -> bool {
        self.tree.reads(v.slot())
    }

    /// The value at `inputs` (indexed by [`Variable::slot`]) in the
    /// arithmetic of `D`.
    pub fn value<D: DualNum<Primitive = f64> + Copy>(&self, inputs: &Inputs<D>) -> D {
        self.tree.eval(inputs)
    }

    /// Whether the formula is proved even under the sign change of the
    /// variables `flipped` (from its structure: powers, products and the
    /// parity of each function; `false` means "not proved", not "odd").
    pub fn is_even_in(&self, flipped: &[Variable]) -> bool {
        let slots: Vec<usize> = flipped.iter().map(|v| v.slot()).collect();
        self.tree.parity(&slots) == Parity::Even
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn formula(text: &str) -> Formula {
        Formula::new(text, &|n| (n == "c").then_some(2.0)).unwrap()
    }

    fn at(k: [f64; 3]) -> Inputs<f64> {
        [0.3, k[0], k[1], k[2], 0.0, 0.0, 1.0, 1.0, 2.0, 3.0]
    }

    #[test]
    fn values_follow_the_usual_rules() {
        let x = at([0.5, -1.0, 2.0]);
        let cases = [
            ("1 + 2 * 3", 7.0),
            ("-k2^2", -1.0),
            ("2^3^2", 512.0),
            ("c * k1 / 4", 0.25),
            ("min(k1, k2) + max(k1, k3)", 1.0),
            ("abs(k2) + sqrt(4) + exp(0) + log(1)", 4.0),
            ("B2 * k2^2 / 2", 1.0),
            ("k3^0.5", 2f64.sqrt()),
            ("k3^k1", 2f64.sqrt()),
            ("cos(pi) + s", -0.7),
        ];
        for (text, want) in cases {
            let got = formula(text).value(&x);
            assert!((got - want).abs() < 1e-15, "{text}: {got} vs {want}");
        }
    }

    #[test]
    fn unknown_names_functions_and_arities_are_refused_where_they_are() {
        let p = |_: &str| None;
        let e = Formula::new("k1 + kk2", &p).unwrap_err();
        assert_eq!((e.line(), e.column()), (1, 6));
        assert!(e.to_string().contains("kk2"), "{e}");
        let e = Formula::new("\n  besselj(k1)", &p).unwrap_err();
        assert_eq!((e.line(), e.column()), (2, 3));
        let e = Formula::new("min(k1)", &p).unwrap_err();
        assert!(e.to_string().contains("2 argument"), "{e}");
    }

    #[test]
    fn parity_is_proved_only_where_it_holds() {
        let planar = [Variable::Curvature(0), Variable::Curvature(2)];
        assert!(formula("B1*k1^2 + B2*k2^2 + B3*k3^2 + (k1^2+k2^2+k3^2)^2").is_even_in(&planar));
        assert!(formula("k1*k3 + cos(k1) + abs(k3)^3 + k2^3").is_even_in(&planar));
        assert!(!formula("k1^2 + k3").is_even_in(&planar));
        assert!(!formula("k1 * k2^2").is_even_in(&planar));
        assert!(!formula("exp(k1)").is_even_in(&planar));
    }

    #[test]
    fn reads_reports_the_variables_used() {
        let f = formula("B2 * k2^2 + s");
        assert!(f.reads(Variable::Curvature(1)) && f.reads(Variable::ArcLength));
        assert!(!f.reads(Variable::Curvature(0)) && !f.reads(Variable::ShearExtension(2)));
        // Constants are folded: 2^3 is read as 8.
        assert_eq!(formula("2^3 * k1").value(&at([1.0, 0.0, 0.0])), 8.0);
    }
}
