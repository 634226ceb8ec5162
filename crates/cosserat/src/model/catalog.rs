//! Stored energies by name: what `energy.kind` in a problem file refers to.
//!
//! A catalog maps a name to a builder that turns the `[energy]` table (the
//! stiffness and intrinsic-curvature profiles and the named parameters of
//! `[energy.parameters]`) into a [`StoredEnergy`]. The standard catalog
//! holds "linear" and "quartic"; a program adds its own energy with
//! [`EnergyCatalog::register`] and reads problem files through
//! `input::Problem::from_path_in` — see examples/custom_energy.rs.

use std::collections::BTreeMap;
use std::sync::Arc;

use super::formula::{Formula, FormulaEnergy, Variable as FormulaVariable};
use super::{LinearElastic, ModelError, Profile, QuarticStiffening, StoredEnergy};

/// The `[energy]` table of a problem file, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct EnergySpec {
    /// B1, B2, B3 as profiles of s, positive on [0, L].
    pub stiffness: [Profile; 3],
    /// κ⁰ as profiles of s.
    pub intrinsic_curvature: [Profile; 3],
    /// `[energy.parameters]`: further numbers an energy needs, finite.
    pub parameters: BTreeMap<String, f64>,
    /// `energy.density`: the formula of a `kind = "formula"` energy.
    pub density: Option<String>,
}

/// A problem in an energy specification: the parameter (the key under
/// `energy.parameters`, or a field of `[energy]`) and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct EnergySpecError {
    /// The field, e.g. "energy.parameters.quartic".
    pub field: String,
    /// What is wrong with it.
    pub message: String,
}

impl From<ModelError> for EnergySpecError {
    /// The `[energy]` field a refused model value comes from.
    fn from(e: ModelError) -> Self {
        let field = match &e {
            ModelError::Stiffness { index, .. } => format!("energy.stiffness[{index}]"),
            ModelError::IntrinsicCurvature { index } => {
                format!("energy.intrinsic_curvature[{index}]")
            }
            ModelError::Coefficient { .. } => "energy.parameters.quartic".into(),
            _ => "energy".into(),
        };
        EnergySpecError {
            field,
            message: e.to_string(),
        }
    }
}

impl EnergySpec {
    /// The linear-elastic energy of the profiles (paper (17)); a refusal
    /// of [`LinearElastic::new`] names its profile
    /// (`energy.stiffness[i]`, `energy.intrinsic_curvature[i]`).
    pub fn linear(&self) -> Result<LinearElastic, EnergySpecError> {
        LinearElastic::new(self.stiffness.clone(), self.intrinsic_curvature.clone())
            .map_err(EnergySpecError::from)
    }

    /// A required parameter.
    pub fn parameter(&self, name: &str) -> Result<f64, EnergySpecError> {
        self.parameters
            .get(name)
            .copied()
            .ok_or_else(|| EnergySpecError {
                field: format!("energy.parameters.{name}"),
                message: "required by this energy".into(),
            })
    }

    /// Rejects parameters the energy does not know (typos would otherwise
    /// pass silently), and a `density` formula (only `kind = "formula"`
    /// reads one).
    pub fn only(&self, known: &[&str]) -> Result<(), EnergySpecError> {
        if self.density.is_some() {
            return Err(EnergySpecError {
                field: "energy.density".into(),
                message: "only an energy of kind \"formula\" reads a density formula".into(),
            });
        }
        match self
            .parameters
            .keys()
            .find(|k| !known.contains(&k.as_str()))
        {
            None => Ok(()),
            Some(k) => Err(EnergySpecError {
                field: format!("energy.parameters.{k}"),
                message: if known.is_empty() {
                    "this energy takes no parameters".into()
                } else {
                    format!("unknown; this energy takes {}", known.join(", "))
                },
            }),
        }
    }
}

/// Builds an energy from its specification.
pub type EnergyBuilder =
    dyn Fn(&EnergySpec) -> Result<Arc<dyn StoredEnergy>, EnergySpecError> + Send + Sync;

/// Named energy builders. Cloning shares the builders (a continuation
/// lens rebuilds the rod at every parameter value with the catalog the
/// problem was read with).
#[derive(Clone)]
pub struct EnergyCatalog {
    builders: BTreeMap<String, Arc<EnergyBuilder>>,
}

impl std::fmt::Debug for EnergyCatalog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.builders.keys()).finish()
    }
}

impl Default for EnergyCatalog {
    fn default() -> Self {
        Self::standard()
    }
}

impl EnergyCatalog {
    /// The energies every problem file can name: "linear" (paper (17)) and
    /// "quartic" (`QuarticStiffening`, parameter `quartic` = C ≥ 0).
    pub fn standard() -> Self {
        let mut c = EnergyCatalog {
            builders: BTreeMap::new(),
        };
        c.register("linear", |spec| {
            spec.only(&[])?;
            Ok(Arc::new(spec.linear()?))
        });
        c.register("quartic", |spec| {
            spec.only(&["quartic"])?;
            let quartic = spec.parameter("quartic")?;
            if quartic < 0.0 {
                return Err(EnergySpecError {
                    field: "energy.parameters.quartic".into(),
                    message: format!("must be ≥ 0, got {quartic}"),
                });
            }
            Ok(Arc::new(QuarticStiffening::new(spec.linear()?, quartic)?))
        });
        c.register("formula", formula_energy);
        c
    }

    /// Adds (or replaces) the energy called `name`.
    pub fn register(
        &mut self,
        name: &str,
        builder: impl Fn(&EnergySpec) -> Result<Arc<dyn StoredEnergy>, EnergySpecError>
            + Send
            + Sync
            + 'static,
    ) {
        self.builders.insert(name.to_owned(), Arc::new(builder));
    }

    /// The registered names.
    pub fn names(&self) -> Vec<&str> {
        self.builders.keys().map(String::as_str).collect()
    }

    /// The energy `name` of a specification; None when no energy has that
    /// name.
    pub fn build(
        &self,
        name: &str,
        spec: &EnergySpec,
    ) -> Option<Result<Arc<dyn StoredEnergy>, EnergySpecError>> {
        self.builders.get(name).map(|b| b(spec))
    }
}

/// The `formula` energy: `energy.density` parsed with the parameters
/// bound; every parameter must be read by the formula (a typo in a name
/// would otherwise pass silently).
fn formula_energy(spec: &EnergySpec) -> Result<Arc<dyn StoredEnergy>, EnergySpecError> {
    let text = spec.density.as_deref().ok_or_else(|| EnergySpecError {
        field: "energy.density".into(),
        message: "required by kind = \"formula\": W as an expression in k1, k2, k3, s, B1, B2, B3 \
                  and energy.parameters"
            .into(),
    })?;
    if let Some(name) = spec
        .parameters
        .keys()
        .find(|n| FormulaVariable::NAMES.contains(&n.as_str()) || n.as_str() == "pi")
    {
        return Err(EnergySpecError {
            field: format!("energy.parameters.{name}"),
            message: "is a name the formula language reserves; rename it".into(),
        });
    }
    let bound = |name: &str| spec.parameters.get(name).copied();
    let formula = Formula::new(text, &bound).map_err(|e| EnergySpecError {
        field: "energy.density".into(),
        message: e.to_string(),
    })?;
    if let Some(name) = spec.parameters.keys().find(|n| !formula.binds(n)) {
        return Err(EnergySpecError {
            field: format!("energy.parameters.{name}"),
            message: "not read by energy.density".into(),
        });
    }
    let energy = FormulaEnergy::new(
        formula,
        spec.stiffness.clone(),
        spec.intrinsic_curvature.clone(),
    )
    .map_err(|e| EnergySpecError {
        field: "energy.density".into(),
        message: e.0,
    })?;
    Ok(Arc::new(energy))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A refusal of a checked constructor reaches the problem reader under
    /// the key of the value refused.
    #[test]
    fn refused_energies_name_their_key() {
        let spec = EnergySpec {
            stiffness: [1.0, -2.0, 1.0].map(Profile::Constant),
            intrinsic_curvature: Default::default(),
            parameters: BTreeMap::new(),
            density: None,
        };
        let catalog = EnergyCatalog::standard();
        let err = catalog.build("linear", &spec).unwrap().unwrap_err();
        assert_eq!(err.field, "energy.stiffness[1]");
        assert!(err.message.contains("B2"), "{}", err.message);
        let spec = EnergySpec {
            stiffness: [1.0; 3].map(Profile::Constant),
            intrinsic_curvature: [0.0, 0.0, f64::NAN].map(Profile::Constant),
            parameters: BTreeMap::from([("quartic".to_owned(), 0.5)]),
            density: None,
        };
        let err = catalog.build("quartic", &spec).unwrap().unwrap_err();
        assert_eq!(err.field, "energy.intrinsic_curvature[2]");
        let ok = EnergySpec {
            intrinsic_curvature: Default::default(),
            ..spec
        };
        assert_eq!(
            catalog.build("quartic", &ok).unwrap().unwrap().name(),
            "quartic"
        );
    }
}
