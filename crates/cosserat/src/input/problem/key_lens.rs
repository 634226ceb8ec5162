//! A continuation parameter for any numeric key of the tables that define
//! the rod (`[rod]`, `[energy]`, `[clamp]`, `[support]`, `[loads]`): the
//! rod at p is the problem reread with the key set to p, through the same
//! checks as the file and `--set`. So every number a problem file gives
//! the rod can be continued — the held tip position (displacement
//! control), the end turns `clamp.turn.angle` and `support.turn.angle`
//! through any number of turns, the shear stiffnesses, the parameters of
//! any energy, a registered one included — without a list in the engine.
//!
//! Rereading costs a clone of the parsed document and its reading (tens of
//! µs); the last rod is kept, so the repeated evaluations at one p (the
//! residual, then the Jacobian's columns) read it once.

use std::sync::Mutex;

use super::rod::build_rod;
use super::sections::ProblemFile;
use super::{invalid, overrides, ProblemError};
use nalgebra::Vector3;

use crate::continuation::{FamilyError, Lens, Lens2, Parameter, RodLens};
use crate::input::strict;
use crate::model::{DeadLoads, EnergyCatalog, PointLoad, Rod, RodTangent};

/// The tables whose numbers make the rod.
const ROD_TABLES: [&str; 5] = ["rod", "energy", "clamp", "support", "loads"];

/// The rod of a problem document with one numeric key set to p.
#[derive(Debug)]
pub(crate) struct KeyLens {
    key: String,
    doc: toml::Table,
    catalog: EnergyCatalog,
    /// The last rod built, by the bits of its p.
    last: Mutex<Option<(u64, Rod)>>,
}

impl KeyLens {
    /// The lens of `key` in the effective problem `text` (overrides
    /// applied), refused unless the key names a number the file gives in
    /// one of the rod's tables.
    pub(super) fn new(
        key: &str,
        text: &str,
        catalog: &EnergyCatalog,
    ) -> Result<KeyLens, ProblemError> {
        let field = "continuation.parameter";
        let table = key.split('.').next().unwrap_or_default().trim();
        if !ROD_TABLES.contains(&table) {
            return Err(invalid(
                field,
                format!(
                    "`{key}` is not a number of the rod: a continued key lies in [{}] (or is \
                     load_scale or control_scale)",
                    ROD_TABLES.join("], [")
                ),
            ));
        }
        let doc: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| ProblemError::Parse(e.to_string()))?;
        match overrides::get_key(&doc, key) {
            Some(toml::Value::Float(_) | toml::Value::Integer(_)) => {}
            Some(other) => {
                return Err(invalid(
                    field,
                    format!(
                        "`{key}` is a {}, not a number; name one number (an array element as \
                         `name[i]`)",
                        other.type_str()
                    ),
                ))
            }
            None => {
                return Err(invalid(
                    field,
                    format!(
                        "`{key}` is not given in the problem; write it in the file (with the \
                         start value) so that its table is complete"
                    ),
                ))
            }
        }
        let mut doc = doc;
        pin_support_defaults(&mut doc, catalog);
        Ok(KeyLens {
            key: key.trim().to_string(),
            doc,
            catalog: catalog.clone(),
            last: Mutex::new(None),
        })
    }

    /// The unit axis of a turn table (`clamp.turn.axis`), None when the
    /// document does not give three finite numbers with a non-zero norm.
    fn turn_axis(&self, key: &str) -> Option<Vector3<f64>> {
        let toml::Value::Array(a) = overrides::get_key(&self.doc, key)? else {
            return None;
        };
        let v: Vec<f64> = a
            .iter()
            .map(|x| match x {
                toml::Value::Float(f) => Some(*f),
                toml::Value::Integer(i) => Some(*i as f64),
                _ => None,
            })
            .collect::<Option<_>>()?;
        let axis = Vector3::from_column_slice(v.get(..3).filter(|_| v.len() == 3)?);
        let norm = axis.norm();
        (norm.is_finite() && norm > 0.0).then(|| axis / norm)
    }

    /// The rod at p by `build`, or the last one built if p is the same
    /// number (the residual and the Jacobian's columns at one p read the
    /// problem once); a non-finite p or a refused build named by the key.
    fn cached(
        &self,
        p: f64,
        build: impl FnOnce(f64) -> Result<Rod, ProblemError>,
    ) -> Result<Rod, FamilyError> {
        let refused = |reason: String| FamilyError::Refused {
            parameter: self.key.clone(),
            value: p,
            reason,
        };
        if !p.is_finite() {
            return Err(refused("not a finite number".into()));
        }
        let mut last = self
            .last
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some((bits, rod)) = last.as_ref() {
            if *bits == p.to_bits() {
                return Ok(rod.clone());
            }
        }
        let rod = build(p).map_err(|e| refused(e.to_string()))?;
        *last = Some((p.to_bits(), rod.clone()));
        Ok(rod)
    }

    fn build(&self, p: f64) -> Result<Rod, ProblemError> {
        let mut doc = self.doc.clone();
        overrides::set_key(&mut doc, &self.key, toml::Value::Float(p))
            .map_err(|m| invalid(&self.key, m))?;
        let file: ProblemFile = strict::from_table(doc)?;
        build_rod(&file, &self.catalog)
    }
}

/// The held tip's defaults written into the document at their start
/// values: `support.d1`, `support.d3` (default: the clamp's directors,
/// after its `angle` and `turn`) and `support.position` (default
/// r(0) + L d3(0)). Rereading the problem with a clamp key or the length
/// set would otherwise move the held tip with the clamp — a rigid motion,
/// not the turn or shift the key asks for (a ring clamped at both ends
/// and twisted by `clamp.turn.angle` turned both ends together and did
/// not twist) — while the key's tangent (`RodTangent`) and the keys
/// edited in the rod directly (`clamp.angle`, `rod.length`) hold the
/// support where the start put it. Left alone where the document does not
/// build (its error surfaces where it is read).
fn pin_support_defaults(doc: &mut toml::Table, catalog: &EnergyCatalog) {
    let Ok(file) = strict::from_table::<ProblemFile>(doc.clone()) else {
        return;
    };
    let Ok(rod) = build_rod(&file, catalog) else {
        return;
    };
    let Some(support) = rod.support() else {
        return;
    };
    let Some(toml::Value::Table(table)) = doc.get_mut("support") else {
        return;
    };
    let vector =
        |v: Vector3<f64>| toml::Value::Array(v.iter().map(|x| toml::Value::Float(*x)).collect());
    for (name, i) in [("d1", 0), ("d3", 2)] {
        if !table.contains_key(name) {
            table.insert(name.into(), vector(rod.clamp().director(i)));
        }
    }
    if support.holds_position() && !table.contains_key("position") {
        table.insert("position".into(), vector(support.position));
    }
}

/// (k, j) of `loads.point[k].force[j]`, j < 3.
fn point_force_component(key: &str) -> Option<(usize, usize)> {
    let rest = key.strip_prefix("loads.point[")?;
    let (k, rest) = rest.split_once(']')?;
    let j = indexed(rest, ".force")?;
    Some((k.trim().parse().ok()?, j))
}

/// i of a key `prefix[i]`, i < 3.
fn indexed(key: &str, prefix: &str) -> Option<usize> {
    let rest = key
        .strip_prefix(prefix)?
        .strip_prefix('[')?
        .strip_suffix(']')?;
    rest.parse().ok().filter(|i| *i < 3)
}

impl Lens for KeyLens {
    fn key(&self) -> String {
        self.key.clone()
    }

    /// The rates of the library's own [`Parameter`] where the key is one
    /// (a load component, `rod.length`, a constant `energy.stiffness[i]` or
    /// `energy.intrinsic_curvature[i]`, `clamp.angle`: the reader sets the
    /// rod's number to the key's value, so the rod moves as
    /// [`crate::continuation::RodLens`] moves it), the spin of
    /// `clamp.turn.angle` and `support.turn.angle` (the frame turned about
    /// the fixed unit axis), the shift of `support.position[i]` (the held
    /// position, global), the unit rate of a point force's component
    /// `loads.point[k].force[j]` at its s_k; None for every other key (a shear stiffness, a
    /// registered energy's parameter, the support's axes), whose F_p is then a central difference
    /// ([`crate::continuation::Family::derivative_method`]).
    fn tangent(&self, p: f64) -> Option<RodTangent> {
        if self.key == "clamp.turn.angle" {
            let axis = self.turn_axis("clamp.turn.axis")?;
            return RodTangent::zero().with_clamp_spin(axis).ok();
        }
        if self.key == "support.turn.angle" {
            let axis = self.turn_axis("support.turn.axis")?;
            return RodTangent::zero().with_support_spin(axis).ok();
        }
        if let Some(i) = indexed(&self.key, "support.position") {
            return RodTangent::zero()
                .with_support_shift(Vector3::ith(i, 1.0))
                .ok();
        }
        if let Some((k, j)) = point_force_component(&self.key) {
            let rod = self.rod_at(p).ok()?;
            let s = rod.loads().point_loads.get(k)?.s;
            let rate = DeadLoads {
                point_loads: vec![PointLoad::force(s, Vector3::ith(j, 1.0))],
                ..DeadLoads::default()
            };
            return RodTangent::zero().with_loads(rate).ok();
        }
        let parameter = Parameter::from_key(&self.key).filter(|q| q.is_file_key())?;
        RodLens::new(self.rod_at(p).ok()?, parameter).tangent(p)
    }

    fn rod_at(&self, p: f64) -> Result<Rod, FamilyError> {
        self.cached(p, |p| self.build(p))
    }
}

/// Two numeric keys of the rod's tables set together: the pair of a curve
/// whose first parameter is itself a file key.
#[derive(Debug)]
pub(crate) struct KeyPair {
    first: KeyLens,
    second: String,
}

impl KeyPair {
    pub(super) fn new(
        first: &str,
        second: &str,
        text: &str,
        catalog: &EnergyCatalog,
    ) -> Result<KeyPair, ProblemError> {
        // Both keys checked as a continued key would be.
        KeyLens::new(second, text, catalog).map_err(|e| match e {
            ProblemError::Invalid { message, .. } => {
                invalid("continuation.curve.parameter", message)
            }
            other => other,
        })?;
        Ok(KeyPair {
            first: KeyLens::new(first, text, catalog)?,
            second: second.trim().to_string(),
        })
    }
}

impl Lens2 for KeyPair {
    fn keys(&self) -> [String; 2] {
        [self.first.key.clone(), self.second.clone()]
    }

    fn rod_at(&self, p: [f64; 2]) -> Result<Rod, FamilyError> {
        let refused = |reason: String| FamilyError::Refused {
            parameter: format!("{}, {}", self.first.key, self.second),
            value: p[0],
            reason,
        };
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(refused("not a finite number".into()));
        }
        let mut doc = self.first.doc.clone();
        for (key, v) in [(&self.first.key, p[0]), (&self.second, p[1])] {
            overrides::set_key(&mut doc, key, toml::Value::Float(v)).map_err(&refused)?;
        }
        let file: ProblemFile = strict::from_table(doc).map_err(|e| refused(e.to_string()))?;
        build_rod(&file, &self.first.catalog).map_err(|e| refused(e.to_string()))
    }
}

/// One parameter p setting several numeric keys of the rod's tables: the
/// continued key to p and each linked key to factor·p + offset
/// (`continuation.link`), e.g. both end turns of a strip by one angle.
/// The rod at p is the problem reread with every key set; the tangent is
/// Σ factor_j · (key j's tangent), exact where every key's is, else None
/// (a central difference, said by the family).
#[derive(Debug)]
pub(crate) struct LinkedLens {
    first: KeyLens,
    /// Each linked key's own lens (for its tangent), factor and offset.
    links: Vec<(KeyLens, f64, f64)>,
}

impl LinkedLens {
    /// `key` and its `links` ((key, factor, offset)) in the effective
    /// problem `text`. Refused, naming `continuation.link[i]`: a key that
    /// is not a number of the rod (as for `continuation.parameter`), a key
    /// linked twice or linked to itself, a factor or offset that is not
    /// finite, a zero factor, and a file value that is not the link's at
    /// p = `start` (the start's rod would not be the file's).
    pub(super) fn new(
        key: &str,
        links: &[(String, f64, f64)],
        start: f64,
        text: &str,
        catalog: &EnergyCatalog,
    ) -> Result<LinkedLens, ProblemError> {
        let first = KeyLens::new(key, text, catalog)?;
        let mut seen = vec![first.key.clone()];
        let mut out = Vec::with_capacity(links.len());
        for (i, (link, factor, offset)) in links.iter().enumerate() {
            let field = format!("continuation.link[{i}]");
            let lens = KeyLens::new(link, text, catalog).map_err(|e| match e {
                ProblemError::Invalid { message, .. } => invalid(format!("{field}.key"), message),
                other => other,
            })?;
            if seen.contains(&lens.key) {
                return Err(invalid(
                    format!("{field}.key"),
                    format!(
                        "`{}` is already set by the parameter or an earlier link; link each key \
                         once",
                        lens.key
                    ),
                ));
            }
            if !(factor.is_finite() && *factor != 0.0) {
                return Err(invalid(
                    format!("{field}.factor"),
                    format!("must be a finite non-zero number, got {factor}"),
                ));
            }
            if !offset.is_finite() {
                return Err(invalid(
                    format!("{field}.offset"),
                    format!("must be a finite number, got {offset}"),
                ));
            }
            let given = match overrides::get_key(&lens.doc, &lens.key) {
                Some(toml::Value::Float(v)) => *v,
                Some(toml::Value::Integer(v)) => *v as f64,
                _ => f64::NAN,
            };
            let linked = factor * start + offset;
            if (given - linked).abs() > 1e-12 * linked.abs().max(1.0) {
                return Err(invalid(
                    field,
                    format!(
                        "the file gives {} = {given}, the link gives {linked} at the start \
                         {start}: write the start's value in the file",
                        lens.key
                    ),
                ));
            }
            seen.push(lens.key.clone());
            out.push((lens, *factor, *offset));
        }
        Ok(LinkedLens { first, links: out })
    }

    fn build(&self, p: f64) -> Result<Rod, ProblemError> {
        let mut doc = self.first.doc.clone();
        overrides::set_key(&mut doc, &self.first.key, toml::Value::Float(p))
            .map_err(|m| invalid(&self.first.key, m))?;
        for (lens, factor, offset) in &self.links {
            overrides::set_key(&mut doc, &lens.key, toml::Value::Float(factor * p + offset))
                .map_err(|m| invalid(&lens.key, m))?;
        }
        let file: ProblemFile = strict::from_table(doc)?;
        build_rod(&file, &self.first.catalog)
    }
}

impl Lens for LinkedLens {
    fn key(&self) -> String {
        self.first.key.clone()
    }

    /// Σ_j factor_j t_j with t_j the tangent of key j alone at its value
    /// (each a constant of the key: a unit load rate, a turn's fixed axis,
    /// the clamp's d2), None unless every key has one.
    fn tangent(&self, p: f64) -> Option<RodTangent> {
        let mut t = self.first.tangent(p)?;
        for (lens, factor, offset) in &self.links {
            t = t.plus(&lens.tangent(factor * p + offset)?, *factor);
        }
        Some(t)
    }

    fn rod_at(&self, p: f64) -> Result<Rod, FamilyError> {
        self.first.cached(p, |p| self.build(p))
    }
}
