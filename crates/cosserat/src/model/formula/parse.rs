//! The formula language: tokens and a recursive-descent parser to an
//! expression tree, every error with its line and column.
//!
//! Grammar (usual precedence, `^` binds tighter than unary minus and is
//! right-associative, so `-k1^2 = -(k1^2)` and `2^3^2 = 2^9`):
//!
//! ```text
//! sum     = product { ("+" | "-") product }
//! product = unary { ("*" | "/") unary }
//! unary   = ("-" | "+") unary | power
//! power   = primary [ "^" unary ]
//! primary = number | name | name "(" sum { "," sum } ")" | "(" sum ")"
//! ```
//!
//! Written by hand (about 200 lines) rather than with a parser crate: the
//! tree must be evaluated over any dual-number type, and the crates that
//! evaluate expressions (meval, evalexpr, fasteval) do so over `f64` only.

use super::FormulaError;

/// A node of the expression tree.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Node {
    Number(f64),
    Name(String, Position),
    Negate(Box<Node>),
    Binary(BinaryOp, Box<Node>, Box<Node>),
    Call(String, Vec<Node>, Position),
}

/// The four arithmetic operations and the power.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum BinaryOp {
    Add,
    Subtract,
    Multiply,
    Divide,
    Power,
}

/// A place in the formula text (1-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Position {
    pub line: usize,
    pub column: usize,
}

#[derive(Debug, Clone, PartialEq)]
enum Token {
    Number(f64),
    Name(String),
    Symbol(char),
    End,
}

/// The longest formula accepted, in characters.
pub(super) const MAX_LENGTH: usize = 10_000;
/// The deepest nesting of parentheses, calls and operators accepted.
const MAX_NESTING: usize = 64;

struct Parser {
    tokens: Vec<(Token, Position)>,
    next: usize,
    depth: usize,
}

/// The expression tree of `text`.
pub(super) fn parse(text: &str) -> Result<Node, FormulaError> {
    if text.chars().count() > MAX_LENGTH {
        return Err(FormulaError::at(
            1,
            1,
            format!("longer than {MAX_LENGTH} characters"),
        ));
    }
    let mut parser = Parser {
        tokens: tokens(text)?,
        next: 0,
        depth: 0,
    };
    let node = parser.sum()?;
    match parser.peek() {
        (Token::End, _) => Ok(node),
        (token, at) => Err(FormulaError::at(
            at.line,
            at.column,
            format!("unexpected {}", describe(token)),
        )),
    }
}

fn tokens(text: &str) -> Result<Vec<(Token, Position)>, FormulaError> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let (mut i, mut line, mut column) = (0, 1, 1);
    while i < chars.len() {
        let c = chars[i];
        let at = Position { line, column };
        let start = i;
        if c == '\n' {
            i += 1;
            line += 1;
            column = 1;
            continue;
        }
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            i = number_end(&chars, i);
            let word: String = chars[start..i].iter().collect();
            let value: f64 = word
                .parse()
                .map_err(|_| FormulaError::at(line, column, format!("`{word}` is not a number")))?;
            out.push((Token::Number(value), at));
        } else if c.is_alphabetic() || c == '_' {
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push((Token::Name(chars[start..i].iter().collect()), at));
        } else if "+-*/^(),".contains(c) {
            i += 1;
            out.push((Token::Symbol(c), at));
        } else {
            return Err(FormulaError::at(
                line,
                column,
                format!("unexpected character `{c}`"),
            ));
        }
        column += i - start;
    }
    out.push((Token::End, Position { line, column }));
    Ok(out)
}

/// The end of the number starting at `i`: digits, one point, an exponent.
fn number_end(chars: &[char], mut i: usize) -> usize {
    while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
        i += 1;
    }
    if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
        let mut j = i + 1;
        if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
            j += 1;
        }
        if j < chars.len() && chars[j].is_ascii_digit() {
            i = j;
            while i < chars.len() && chars[i].is_ascii_digit() {
                i += 1;
            }
        }
    }
    i
}

fn describe(token: &Token) -> String {
    match token {
        Token::Number(v) => format!("number {v}"),
        Token::Name(n) => format!("name `{n}`"),
        Token::Symbol(c) => format!("`{c}`"),
        Token::End => "end of the formula".into(),
    }
}

impl Parser {
    fn peek(&self) -> (&Token, Position) {
        let (t, p) = &self.tokens[self.next];
        (t, *p)
    }

    fn advance(&mut self) -> (Token, Position) {
        let item = self.tokens[self.next].clone();
        if self.next + 1 < self.tokens.len() {
            self.next += 1;
        }
        item
    }

    fn error(&self, message: &str) -> FormulaError {
        let (token, at) = self.peek();
        FormulaError::at(
            at.line,
            at.column,
            format!("{message}, found {}", describe(token)),
        )
    }

    fn nested<T>(
        &mut self,
        f: impl FnOnce(&mut Self) -> Result<T, FormulaError>,
    ) -> Result<T, FormulaError> {
        self.depth += 1;
        if self.depth > MAX_NESTING {
            let at = self.peek().1;
            return Err(FormulaError::at(
                at.line,
                at.column,
                format!("nested more than {MAX_NESTING} deep"),
            ));
        }
        let out = f(self);
        self.depth -= 1;
        out
    }

    fn sum(&mut self) -> Result<Node, FormulaError> {
        self.nested(|p| {
            let mut left = p.product()?;
            loop {
                let op = match p.peek().0 {
                    Token::Symbol('+') => BinaryOp::Add,
                    Token::Symbol('-') => BinaryOp::Subtract,
                    _ => return Ok(left),
                };
                p.advance();
                let right = p.product()?;
                left = Node::Binary(op, Box::new(left), Box::new(right));
            }
        })
    }

    fn product(&mut self) -> Result<Node, FormulaError> {
        let mut left = self.unary()?;
        loop {
            let op = match self.peek().0 {
                Token::Symbol('*') => BinaryOp::Multiply,
                Token::Symbol('/') => BinaryOp::Divide,
                _ => return Ok(left),
            };
            self.advance();
            let right = self.unary()?;
            left = Node::Binary(op, Box::new(left), Box::new(right));
        }
    }

    fn unary(&mut self) -> Result<Node, FormulaError> {
        self.nested(|p| match p.peek().0 {
            Token::Symbol('-') => {
                p.advance();
                Ok(Node::Negate(Box::new(p.unary()?)))
            }
            Token::Symbol('+') => {
                p.advance();
                p.unary()
            }
            _ => p.power(),
        })
    }

    fn power(&mut self) -> Result<Node, FormulaError> {
        let base = self.primary()?;
        if self.peek().0 == &Token::Symbol('^') {
            self.advance();
            let exponent = self.unary()?;
            return Ok(Node::Binary(
                BinaryOp::Power,
                Box::new(base),
                Box::new(exponent),
            ));
        }
        Ok(base)
    }

    fn primary(&mut self) -> Result<Node, FormulaError> {
        match self.peek().0.clone() {
            Token::Number(v) => {
                self.advance();
                Ok(Node::Number(v))
            }
            Token::Symbol('(') => {
                self.advance();
                let inner = self.sum()?;
                self.expect(')', "`)` to close `(`")?;
                Ok(inner)
            }
            Token::Name(name) => {
                let at = self.advance().1;
                if self.peek().0 != &Token::Symbol('(') {
                    return Ok(Node::Name(name, at));
                }
                self.advance();
                let mut args = vec![self.sum()?];
                while self.peek().0 == &Token::Symbol(',') {
                    self.advance();
                    args.push(self.sum()?);
                }
                self.expect(')', "`,` or `)` in the arguments")?;
                Ok(Node::Call(name, args, at))
            }
            _ => Err(self.error("expected a number, a name or `(`")),
        }
    }

    fn expect(&mut self, symbol: char, what: &str) -> Result<(), FormulaError> {
        if self.peek().0 == &Token::Symbol(symbol) {
            self.advance();
            Ok(())
        } else {
            Err(self.error(&format!("expected {what}")))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precedence_and_associativity() {
        let n = parse("-k1^2").unwrap();
        assert!(matches!(n, Node::Negate(_)));
        let n = parse("2^3^2").unwrap();
        let Node::Binary(BinaryOp::Power, _, right) = n else {
            panic!()
        };
        assert!(matches!(*right, Node::Binary(BinaryOp::Power, _, _)));
        let n = parse("1 - 2 - 3").unwrap();
        let Node::Binary(BinaryOp::Subtract, left, _) = n else {
            panic!()
        };
        assert!(matches!(*left, Node::Binary(BinaryOp::Subtract, _, _)));
    }

    #[test]
    fn errors_carry_line_and_column() {
        let e = parse("0.5*B2*k2^2 +\n  3 $ k1").unwrap_err();
        assert_eq!((e.line(), e.column()), (2, 5), "{e}");
        let e = parse("sqrt(k1, ").unwrap_err();
        assert_eq!((e.line(), e.column()), (1, 10), "{e}");
        let e = parse("(k1 + k2").unwrap_err();
        assert!(e.to_string().contains("`)`"), "{e}");
        let e = parse("k1 k2").unwrap_err();
        assert_eq!((e.line(), e.column()), (1, 4), "{e}");
        let deep = "(".repeat(100) + "1" + &")".repeat(100);
        assert!(parse(&deep).unwrap_err().to_string().contains("nested"));
        assert!(parse("1e-3 * .5 + 2.5E+2").is_ok());
    }
}
