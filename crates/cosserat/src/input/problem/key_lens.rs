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
use crate::continuation::{FamilyError, Lens, Lens2};
use crate::input::strict;
use crate::model::{EnergyCatalog, Rod};

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
        Ok(KeyLens {
            key: key.trim().to_string(),
            doc,
            catalog: catalog.clone(),
            last: Mutex::new(None),
        })
    }

    fn build(&self, p: f64) -> Result<Rod, ProblemError> {
        let mut doc = self.doc.clone();
        overrides::set_key(&mut doc, &self.key, toml::Value::Float(p))
            .map_err(|m| invalid(&self.key, m))?;
        let file: ProblemFile = strict::from_table(doc)?;
        build_rod(&file, &self.catalog)
    }
}

impl Lens for KeyLens {
    fn key(&self) -> String {
        self.key.clone()
    }

    fn rod_at(&self, p: f64) -> Result<Rod, FamilyError> {
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
        let rod = self.build(p).map_err(|e| refused(e.to_string()))?;
        *last = Some((p.to_bits(), rod.clone()));
        Ok(rod)
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
