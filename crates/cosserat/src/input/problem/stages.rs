//! The later stages of a chained continuation (`[[continuation.stage]]`).
//!
//! Stage n (n ≥ 2) is the problem as written with its `[continuation]`
//! table overwritten by the stage's keys (what the stage leaves out is
//! the table's), the list of stages and any `[continuation.curve]`
//! removed, and the keys of the earlier stages set to the values they
//! ended at — the problem that `cosserat continue --from … --point
//! 0/last` with the stage's key would read. So a chained run is, point by
//! point, the chain of commands it replaces.
//!
//! Every stage is read once with the earlier keys at their file values
//! when the problem is read, so that a wrong key or bound is refused
//! before anything runs, naming the stage.

use super::{invalid, overrides, Problem, ProblemError};
use crate::continuation::Parameter;
use crate::model::EnergyCatalog;

/// The field of the stage numbered `number` (2, 3, …) in errors.
fn field(number: usize) -> String {
    format!("continuation.stage[{}]", number - 2)
}

/// The effective text of stage `number`, the `held` keys set.
fn stage_text(text: &str, number: usize, held: &[(String, f64)]) -> Result<String, ProblemError> {
    let mut doc: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| ProblemError::Parse(e.to_string()))?;
    let missing = || invalid(field(number), format!("the problem has no stage {number}"));
    let table = doc
        .get_mut("continuation")
        .and_then(toml::Value::as_table_mut)
        .ok_or_else(missing)?;
    let stages = table.remove("stage").ok_or_else(missing)?;
    table.remove("curve");
    // The first stage's links belong to its parameter; a stage links its
    // own keys or none. Its stop values likewise: a stage stops where it
    // says, on the diagram's shared measures.
    table.remove("link");
    table.remove("stop_at");
    let stage = stages
        .as_array()
        .and_then(|a| a.get(number.checked_sub(2)?))
        .and_then(toml::Value::as_table)
        .ok_or_else(missing)?;
    for (key, value) in stage {
        table.insert(key.clone(), value.clone());
    }
    for (key, value) in held {
        overrides::set_key(&mut doc, key, toml::Value::Float(*value))
            .map_err(|m| invalid(field(number), format!("holding {key} = {value}: {m}")))?;
    }
    toml::to_string(&doc).map_err(|e| invalid(field(number), e.to_string()))
}

impl Problem {
    /// The problem of stage `number` (2 for the first `[[continuation.stage]]`)
    /// with the earlier stages' keys held at `held` (in stage order),
    /// energies from the standard catalog.
    pub fn stage(&self, number: usize, held: &[(String, f64)]) -> Result<Problem, ProblemError> {
        self.stage_in(number, held, &EnergyCatalog::standard())
    }

    /// [`Problem::stage`] with the energies of `catalog`.
    pub fn stage_in(
        &self,
        number: usize,
        held: &[(String, f64)],
        catalog: &EnergyCatalog,
    ) -> Result<Problem, ProblemError> {
        let text = stage_text(&self.text, number, held)?;
        Problem::from_str_in(&text, &[], catalog).map_err(|e| named(number, &e))
    }
}

/// An error of stage `number`'s problem, named by the stage.
fn named(number: usize, e: &ProblemError) -> ProblemError {
    invalid(field(number), format!("stage {number}: {e}"))
}

/// The keys of the later stages of `problem` (read from its text), each
/// stage read once and checked against the stage before: a key the
/// stage before did not continue, a key that can be held (a number of
/// the file, not a scaling), and the same model level, so that the
/// stage's first point starts from the unknowns the stage before ended
/// with.
pub(super) fn check_stages(
    problem: &Problem,
    first_key: Option<&str>,
    count: usize,
    catalog: &EnergyCatalog,
) -> Result<Vec<String>, ProblemError> {
    let Some(first_key) = first_key else {
        return Ok(vec![]);
    };
    let mut keys = vec![first_key.to_string()];
    for number in 2..count + 2 {
        let stage = problem.stage_in(number, &[], catalog)?;
        let Some((family, _)) = &stage.continuation else {
            unreachable!("a stage problem keeps its [continuation] table");
        };
        let (key, before) = (family.key(), keys.last().expect("stage 1's key"));
        if Parameter::from_key(before).is_some_and(|p| !p.is_file_key()) {
            return Err(invalid(
                field(number),
                format!(
                    "stage {number} would hold {before} of the stage before, a scaling of the \
                     problem that no key of the file can hold; continue a number the file \
                     writes (loads.tip_force[i], …) in stage {}",
                    number - 1
                ),
            ));
        }
        if key == *before {
            return Err(invalid(
                field(number),
                format!(
                    "stage {number} continues {key} again; widen the bounds of stage {} instead",
                    number - 1
                ),
            ));
        }
        if stage.model.level != problem.model.level {
            return Err(invalid(
                field(number),
                format!(
                    "stage {number} runs the {} model, stage 1 the {}; set solver.model so that \
                     all stages share one",
                    stage.model.level.name(),
                    problem.model.level.name()
                ),
            ));
        }
        keys.push(key);
    }
    Ok(keys.split_off(1))
}
