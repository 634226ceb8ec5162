//! Chained stages of one continuation run (`[[continuation.stage]]`): a
//! rod bent by one number, then followed in another with the first held
//! where the first stage ended. Each stage is a run of its own (started
//! by [`super::continuation_from`] from the last point of the stage
//! before); their diagrams are appended into one, and every branch keeps
//! the stage it belongs to, the key it continues and the keys held.

use super::Diagram;

/// What a stage of a chained run continues and where its branches begin
/// in the joint diagram.
#[derive(Debug, Clone, PartialEq)]
pub struct Stage {
    key: String,
    held: Vec<(String, f64)>,
    first_branch: usize,
}

impl Stage {
    /// The first (or only) stage of a diagram: `key` continued, nothing
    /// held, its branches from 0.
    pub fn first(key: &str) -> Stage {
        Stage {
            key: key.to_string(),
            held: vec![],
            first_branch: 0,
        }
    }

    /// A later stage: `key` continued with the earlier stages' keys held
    /// at the values of `held`, its branches from `first_branch`.
    pub fn later(key: &str, held: Vec<(String, f64)>, first_branch: usize) -> Stage {
        Stage {
            key: key.to_string(),
            held,
            first_branch,
        }
    }

    /// The continued key.
    pub fn key(&self) -> &str {
        &self.key
    }

    /// The keys of the earlier stages and the values they are held at.
    pub fn held(&self) -> &[(String, f64)] {
        &self.held
    }

    /// The index of the stage's first branch in the joint diagram.
    pub fn first_branch(&self) -> usize {
        self.first_branch
    }
}

/// The index (0-based) of the stage branch `branch` belongs to: the last
/// stage whose first branch is at or before it.
pub fn stage_of(stages: &[Stage], branch: usize) -> usize {
    stages
        .iter()
        .rposition(|s| s.first_branch <= branch)
        .unwrap_or(0)
}

impl Diagram {
    /// Appends the diagram of a later stage: its branches and special
    /// points after this one's (their cross references shifted), its
    /// warnings named by `stage` (the stage's number), its run state
    /// taken over. Returns the index of its first branch; refused when the
    /// two diagrams do not share their columns (eigenvalues, measures,
    /// null-mode nodes), which one file cannot hold.
    pub fn append(&mut self, later: Diagram, stage: usize) -> Result<usize, String> {
        if later.eigenvalue_names != self.eigenvalue_names
            || later.measure_names != self.measure_names
            || later.nodes != self.nodes
        {
            return Err(format!(
                "stage {stage} tracks other eigenvalues, measures or nodes than the stages \
                 before it; one diagram holds one set of columns"
            ));
        }
        let (branches, specials) = (self.branches.len(), self.special_points.len());
        self.branches
            .extend(later.branches.into_iter().map(|mut b| {
                b.parent = b.parent.map(|p| p + specials);
                b
            }));
        self.special_points
            .extend(later.special_points.into_iter().map(|mut s| {
                s.branch += branches;
                for c in &mut s.children {
                    *c += branches;
                }
                s
            }));
        self.warnings.extend(
            later
                .warnings
                .into_iter()
                .map(|w| format!("stage {stage}: {w}")),
        );
        self.stop_reason = later.stop_reason;
        Ok(branches)
    }
}
