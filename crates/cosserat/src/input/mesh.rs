//! The finite elements of a second variation as every table that asks for
//! them writes them (`[stability]`, `[continuation]`, `[arm]`): the same
//! keys `elements`, `order` and `eigenvalues`, the same checks, and one
//! default, [`StabilityOptions::default`] (100 elements of order 2, the 4
//! lowest eigenvalues per block). Each table used to carry its own
//! defaults (40 elements for the tracked spectrum, order 1 for the arm), so
//! the same key meant a different mesh in each table.

use super::problem::{invalid, ProblemError};
use crate::stability::StabilityOptions;

/// The mesh keys of one table, as written (absent keys are `None`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct MeshKeys<'a> {
    /// The table's name, e.g. `continuation`: the prefix of every error.
    pub table: &'a str,
    /// `elements`.
    pub elements: Option<usize>,
    /// `order`.
    pub order: Option<usize>,
    /// `eigenvalues`.
    pub eigenvalues: Option<usize>,
    /// The fewest elements the table's computation can use (continuation
    /// resamples the tracked eigenvectors between meshes, the arm
    /// refines its mesh: both need 2).
    pub min_elements: usize,
}

impl MeshKeys<'_> {
    /// The checked settings, every absent key from the one default; every
    /// refusal names its key.
    pub(crate) fn build(&self) -> Result<StabilityOptions, ProblemError> {
        let default = StabilityOptions::default();
        let key = |k: &str| format!("{}.{k}", self.table);
        let elements = self.elements.unwrap_or(default.elements());
        if elements < self.min_elements {
            return Err(invalid(
                key("elements"),
                format!("must be at least {}, got {elements}", self.min_elements),
            ));
        }
        let order = self.order.unwrap_or(default.order());
        if !(1..=3).contains(&order) {
            return Err(invalid(
                key("order"),
                format!("must be 1, 2 or 3, got {order}"),
            ));
        }
        let eigenvalues = self.eigenvalues.unwrap_or(default.eigenvalues());
        if eigenvalues < 1 {
            return Err(invalid(key("eigenvalues"), "must be at least 1"));
        }
        StabilityOptions::new(elements, order, eigenvalues)
            .map_err(|e| invalid(self.table, e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use crate::input::Problem;
    use crate::stability::StabilityOptions;

    const ROD: &str = "[rod]\nlength = 1.0\n[energy]\nstiffness = [1.0, 1.0, 1.0]\n\
                       [loads]\ntip_force = [0.0, 0.0, -1.0]\n";

    /// `[stability]` and `[continuation]` without mesh keys mean the same
    /// mesh: the one default.
    #[test]
    fn every_table_has_the_one_default() {
        let text = format!(
            "{ROD}[continuation]\nparameter = \"load_scale\"\nstart = 0.1\nbounds = [0.0, 1.0]\n"
        );
        let p = Problem::from_str_with(&text, &[]).unwrap();
        assert_eq!(p.stability, StabilityOptions::default());
        assert_eq!(
            p.continuation.unwrap().1.stability,
            StabilityOptions::default()
        );
    }

    /// A refused value names its table and key.
    #[test]
    fn refusals_name_the_key() {
        for (table, extra, key) in [
            ("stability", "order = 4", "stability.order"),
            ("stability", "elements = 0", "stability.elements"),
            ("stability", "eigenvalues = 0", "stability.eigenvalues"),
        ] {
            let text = format!("{ROD}[{table}]\n{extra}\n");
            let e = Problem::from_str_with(&text, &[]).unwrap_err().to_string();
            assert!(e.starts_with(key), "{e}");
        }
        let text = format!(
            "{ROD}[continuation]\nparameter = \"load_scale\"\nstart = 0.1\nbounds = [0.0, 1.0]\n\
             elements = 1\n"
        );
        let e = Problem::from_str_with(&text, &[]).unwrap_err().to_string();
        assert!(
            e.starts_with("continuation.elements: must be at least 2"),
            "{e}"
        );
    }
}
