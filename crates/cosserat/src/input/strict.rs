//! The strict reading of a problem file: every error names the key it is
//! about, and fixed-length arrays take exactly their length.
//!
//! The TOML deserializer hands a fixed-length Rust array (`[f64; 3]`) or
//! tuple the first N entries of a longer TOML array and drops the rest
//! without a word: `tip_force = [1, 0, 0, 5]` was read as `[1, 0, 0]`.
//! [`Exact`] reads a whole array and refuses any other length; every
//! fixed-length key of every section goes through it (`array`, `option`,
//! `vec`, `spacing` for `#[serde(deserialize_with = …)]`). The key's name
//! comes from the path that `serde_path_to_error` records while reading
//! ([`parse`]), so the shared deserializer does not need to know it.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{self, DeserializeOwned, IgnoredAny, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer};

use super::problem::ProblemError;

/// An array of exactly N entries.
pub(crate) struct Exact<T, const N: usize>(pub [T; N]);

struct ExactVisitor<T, const N: usize>(PhantomData<T>);

impl<'de, T: Deserialize<'de>, const N: usize> Visitor<'de> for ExactVisitor<T, N> {
    type Value = Exact<T, N>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "an array of exactly {N} entries")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut entries: Vec<T> = Vec::with_capacity(N);
        while entries.len() < N {
            match seq.next_element()? {
                Some(v) => entries.push(v),
                None => return Err(wrong_length(entries.len(), N)),
            }
        }
        let mut extra = 0;
        while seq.next_element::<IgnoredAny>()?.is_some() {
            extra += 1;
        }
        if extra > 0 {
            return Err(wrong_length(N + extra, N));
        }
        match entries.try_into() {
            Ok(a) => Ok(Exact(a)),
            Err(_) => unreachable!("exactly N entries were read"),
        }
    }
}

fn wrong_length<E: de::Error>(got: usize, want: usize) -> E {
    E::custom(format!(
        "has {got} entr{}, expected exactly {want}: give an array of {want} entries",
        if got == 1 { "y" } else { "ies" }
    ))
}

impl<'de, T: Deserialize<'de>, const N: usize> Deserialize<'de> for Exact<T, N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_seq(ExactVisitor(PhantomData))
    }
}

/// `[T; N]`, exactly N entries.
pub(crate) fn array<'de, D, T, const N: usize>(d: D) -> Result<[T; N], D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    Exact::<T, N>::deserialize(d).map(|e| e.0)
}

/// `Option<[T; N]>`, exactly N entries when present.
pub(crate) fn option<'de, D, T, const N: usize>(d: D) -> Result<Option<[T; N]>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    Option::<Exact<T, N>>::deserialize(d).map(|o| o.map(|e| e.0))
}

/// `Vec<[T; N]>`, each element exactly N entries.
pub(crate) fn vec<'de, D, T, const N: usize>(d: D) -> Result<Vec<[T; N]>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    Vec::<Exact<T, N>>::deserialize(d).map(|v| v.into_iter().map(|e| e.0).collect())
}

/// `Option<(f64, f64, usize)>`: `[start, stop, count]`, exactly three.
pub(crate) fn spacing<'de, D>(d: D) -> Result<Option<(f64, f64, usize)>, D::Error>
where
    D: Deserializer<'de>,
{
    struct Spacing;
    impl<'de> Visitor<'de> for Spacing {
        type Value = (f64, f64, usize);
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("[start, stop, count]")
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let a: Option<f64> = seq.next_element()?;
            let b: Option<f64> = seq.next_element()?;
            let n: Option<usize> = seq.next_element()?;
            let got = [a.is_some(), b.is_some(), n.is_some()]
                .iter()
                .filter(|x| **x)
                .count();
            let mut extra = 0;
            while seq.next_element::<IgnoredAny>()?.is_some() {
                extra += 1;
            }
            match (a, b, n) {
                (Some(a), Some(b), Some(n)) if extra == 0 => Ok((a, b, n)),
                _ => Err(de::Error::custom(format!(
                    "has {} entries, expected exactly 3: [start, stop, count]",
                    got + extra
                ))),
            }
        }
    }
    struct Wrapped((f64, f64, usize));
    impl<'de> Deserialize<'de> for Wrapped {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            d.deserialize_seq(Spacing).map(Wrapped)
        }
    }
    Option::<Wrapped>::deserialize(d).map(|o| o.map(|w| w.0))
}

/// Reads `text` as a `T`, naming the key of any error: "loads.tip_force:
/// has 4 entries, expected exactly 3 … (line 12, column 13)". Syntax
/// errors (no key yet) keep the TOML reader's report with its line and
/// column.
pub(crate) fn parse<T: DeserializeOwned>(text: &str) -> Result<T, ProblemError> {
    let de = toml::Deserializer::parse(text).map_err(|e| ProblemError::Parse(e.to_string()))?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        if path == "." || path.is_empty() {
            return ProblemError::Parse(inner.to_string());
        }
        let at = inner
            .span()
            .map(|span| {
                let (line, column) = line_column(text, span.start);
                format!(" (line {line}, column {column})")
            })
            .unwrap_or_default();
        ProblemError::Parse(format!("{path}: {}{at}", inner.message().trim_end()))
    })
}

/// 1-based line and column (in characters) of a byte offset.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..text.floor_char_boundary_compat(offset)];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

trait FloorCharBoundary {
    fn floor_char_boundary_compat(&self, i: usize) -> usize;
}

impl FloorCharBoundary for str {
    fn floor_char_boundary_compat(&self, i: usize) -> usize {
        let mut i = i.min(self.len());
        while !self.is_char_boundary(i) {
            i -= 1;
        }
        i
    }
}

/// Reads an already parsed document as a `T`, naming the key of any error
/// (without line and column: the document has no text).
pub(crate) fn from_table<T: DeserializeOwned>(table: toml::Table) -> Result<T, ProblemError> {
    serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        ProblemError::Parse(format!("{path}: {}", inner.message().trim_end()))
    })
}
