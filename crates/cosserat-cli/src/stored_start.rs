//! `cosserat continue PROBLEM --from DIAGRAM.h5 --point B/I`: a
//! continuation started from a point of a stored diagram; and
//! `--from SOLVE.h5` (no point): started from the equilibrium a
//! `cosserat solve` stored, of the same rod.
//!
//! The point's unknowns start Newton at the new run's start value. The
//! stored parameter carries over: the number it names is set to the
//! stored value (before the user's own `--set`, which win), and when the
//! new run continues the same parameter it starts at that value, in the
//! stored direction of travel — so a branch restarted from one of its own
//! points goes on as the uninterrupted run did. A stage continued in
//! another parameter (bend a rod shut, then twist it) starts from the
//! stored shape with the stored value of the first parameter held; a
//! point of a later stage of a chained run holds that stage's held keys
//! too.
//!
//! A diagram stores its unknowns scaled by its own problem's state scales
//! (lengths, curvatures, reactions of the base rod, which move with the
//! loads, the length and the stiffness). So the stored point is carried
//! over ([`StoredStart::onto`]): unscaled by the family the stored problem
//! text (the branch's held keys set) makes, integrated onto the new
//! family's nodes where the mesh differs, scaled by the new family. A
//! point of another model level or state layout is refused by name.

use std::path::Path;

use cosserat::continuation::{Family, Parameter, SavedDiagram, StartPoint};
use cosserat::output::{read_saved, read_solved};

use crate::energies::read_problem_text;

/// Where the new run begins.
pub enum Start {
    /// From a point's unknowns.
    Point(StartPoint),
    /// The switch at a stored branch point.
    Switch {
        /// The stored diagram.
        saved: Box<SavedDiagram>,
        /// The branch point's index.
        special: usize,
    },
}

/// What a stored point gives a new run.
pub struct StoredStart {
    /// `KEY=VALUE` overrides to apply before the user's.
    pub sets: Vec<String>,
    /// The unknowns and direction, or the branch point: in the scaling of
    /// the family that stored them until [`StoredStart::onto`] carries
    /// them onto the new run's.
    pub start: Start,
    /// One line for the report.
    pub summary: String,
    /// The family that stored the point and the point's parameter value,
    /// for a start read from a diagram (none from a solve file, whose
    /// unknowns are raw).
    stored: Option<(Box<Family>, f64)>,
}

impl StoredStart {
    /// The start carried onto `family` (the new run's, read with
    /// [`StoredStart::sets`]): the stored unknowns (and direction, and for
    /// a switch the whole stored diagram) unscaled by the family that
    /// stored them and scaled by `family` ([`Family::carried`]). Refused
    /// by name where they cannot be (another model level, a switch on
    /// another mesh).
    pub fn onto(mut self, family: &Family) -> Result<StoredStart, String> {
        let Some((from, p)) = self.stored.take() else {
            return Ok(self);
        };
        let refuse = |e: &dyn std::fmt::Display| format!("--from: {e}");
        self.start = match self.start {
            Start::Point(point) => {
                let x = family
                    .carried(&from, point.unknowns(), p)
                    .map_err(|e| refuse(&e))?;
                let direction = point
                    .direction()
                    .and_then(|t| family.carried_direction(&from, t));
                Start::Point(StartPoint::new(x, direction))
            }
            Start::Switch { saved, special } => Start::Switch {
                saved: Box::new(carried_diagram(*saved, &from, family).map_err(|e| refuse(&e))?),
                special,
            },
        };
        Ok(self)
    }
}

/// A stored diagram's unknowns and tangents in `family`'s scaling: every
/// point is rescaled as [`Family::carried`] does on the same mesh. A
/// switch replays the stored branch on its own points, so a diagram of
/// another mesh is refused.
fn carried_diagram(
    mut saved: SavedDiagram,
    from: &Family,
    family: &Family,
) -> Result<SavedDiagram, String> {
    if from.size() != family.size() {
        return Err(format!(
            "the stored diagram has {} unknowns per point, this problem's discretization {}: \
             switch at a stored branch point with the stored solver.method and mesh",
            from.size(),
            family.size()
        ));
    }
    let carry = |x: &mut Vec<f64>, p: f64| -> Result<(), String> {
        *x = family.carried(from, x, p).map_err(|e| e.to_string())?;
        Ok(())
    };
    let turn = |t: &mut Vec<f64>| {
        if let Some(d) = family.carried_direction(from, t) {
            *t = d;
        }
    };
    for b in &mut saved.branches {
        for ((x, t), p) in b.unknowns.iter_mut().zip(&mut b.tangent).zip(&b.parameter) {
            carry(x, *p)?;
            turn(t);
        }
    }
    for sp in &mut saved.specials {
        carry(&mut sp.unknowns, sp.parameter)?;
        turn(&mut sp.tangent);
    }
    Ok(saved)
}

/// The family of the stored problem `text` that made a branch holding
/// `held` (a later stage of a chained run holds the keys of the stages
/// before it, one per stage): the problem's own continuation, or that of
/// stage `held.len() + 1` with `held` set.
fn stored_family(file: &Path, text: &str, held: &[(String, f64)]) -> Result<Family, String> {
    let unreadable = |e: &dyn std::fmt::Display| {
        format!(
            "{}: its problem does not read, so its scaled unknowns cannot be carried over: {e}",
            file.display()
        )
    };
    let mut problem = read_problem_text(text, &[]).map_err(|e| unreadable(&e))?;
    if !held.is_empty() {
        problem = problem
            .stage_in(held.len() + 1, held, crate::energies::catalog())
            .map_err(|e| unreadable(&e))?;
    }
    problem
        .continuation
        .map(|(family, _)| family)
        .ok_or_else(|| unreadable(&"it has no [continuation] table"))
}

/// `B/I`: branch B, point I (`last` for its last point).
fn parse_point(spec: &str, saved: &SavedDiagram) -> Result<(usize, usize), String> {
    let (b, i) = spec
        .split_once('/')
        .ok_or_else(|| format!("--point {spec}: expected BRANCH/POINT, e.g. 1/10 or 1/last"))?;
    let b: usize = b
        .trim()
        .parse()
        .map_err(|_| format!("--point {spec}: the branch `{b}` is not an index"))?;
    let branch = saved.branches.get(b).ok_or_else(|| {
        format!(
            "--point {spec}: the diagram has {} branches (0 to {})",
            saved.branches.len(),
            saved.branches.len().saturating_sub(1)
        )
    })?;
    let count = branch.parameter.len();
    let i = match i.trim() {
        "last" => count.checked_sub(1),
        other => other.parse::<usize>().ok().filter(|i| *i < count),
    }
    .ok_or_else(|| {
        format!(
            "--point {spec}: branch {b} has {count} points (0 to {})",
            count.saturating_sub(1)
        )
    })?;
    Ok((b, i))
}

/// The start from point `spec` of the diagram `file`, for a run that
/// continues `new_key`.
pub fn stored_start(file: &Path, spec: &str, new_key: &str) -> Result<StoredStart, String> {
    let (text, saved) =
        read_saved(file).map_err(|e| format!("{}: not a diagram file: {e}", file.display()))?;
    let old_key = stored_key(&text).ok_or_else(|| {
        format!(
            "{}: its problem names no continuation parameter",
            file.display()
        )
    })?;
    if let Some(k) = spec.strip_prefix("special/") {
        return switch_start(file, &text, k, saved, &old_key, new_key);
    }
    let (b, i) = parse_point(spec, &saved)?;
    let branch = &saved.branches[b];
    let value = branch.parameter[i];
    // A branch of a later stage of a chained run continues its own key,
    // the earlier stages' keys held.
    let old_key = branch.parameter_name.clone().unwrap_or(old_key);
    let mut sets: Vec<String> = branch
        .held
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    // A number of the problem file is set to the stored value; the
    // library's scalings (load_scale, control_scale) are not file keys.
    if Parameter::from_key(&old_key).is_none_or(Parameter::is_file_key) {
        sets.push(format!("{old_key}={value}"));
    }
    let same = old_key == new_key;
    if same {
        sets.push(format!("continuation.start={value}"));
    } else if Parameter::from_key(&old_key).is_some_and(|p| !p.is_file_key()) {
        return Err(format!(
            "--from {}: the point is at {old_key} = {value}, a scaling of the problem that a \
             continuation in {new_key} cannot hold; continue {old_key} from it, or write the \
             scaled values in the problem",
            file.display()
        ));
    }
    let direction = same.then(|| branch.tangent[i].clone());
    let from = stored_family(file, &text, &branch.held)?;
    Ok(StoredStart {
        sets,
        stored: Some((Box::new(from), value)),
        start: Start::Point(StartPoint::new(branch.unknowns[i].clone(), direction)),
        summary: format!(
            "{} branch {b} point {i}: {old_key} = {value}{}",
            file.display(),
            if same {
                ", in its direction of travel"
            } else {
                ""
            }
        ),
    })
}

/// `--point special/K`: the switch at stored branch point K, in the
/// stored parameter (at its stored value: the branch point's own family).
fn switch_start(
    file: &Path,
    text: &str,
    k: &str,
    saved: SavedDiagram,
    old_key: &str,
    new_key: &str,
) -> Result<StoredStart, String> {
    let special: usize = k
        .trim()
        .parse()
        .ok()
        .filter(|k| *k < saved.specials.len())
        .ok_or_else(|| {
            format!(
                "--point special/{k}: the diagram has {} special points",
                saved.specials.len()
            )
        })?;
    // The branch point of a later stage of a chained run is one of that
    // stage's key, the earlier keys held.
    let branch = saved.branches.get(saved.specials[special].branch);
    let old_key = branch
        .and_then(|b| b.parameter_name.as_deref())
        .unwrap_or(old_key)
        .to_string();
    if old_key != new_key {
        return Err(format!(
            "--point special/{special}: the branch point is one of {old_key}; switch at it in \
             the same parameter (this problem continues {new_key})"
        ));
    }
    let value = saved.specials[special].parameter;
    let held = branch.map(|b| b.held.clone()).unwrap_or_default();
    let mut sets: Vec<String> = held.iter().map(|(k, v)| format!("{k}={v}")).collect();
    sets.push(format!("continuation.start={value}"));
    let from = stored_family(file, text, &held)?;
    Ok(StoredStart {
        sets,
        stored: Some((Box::new(from), value)),
        summary: format!(
            "{} special point {special}: {} at {old_key} = {value}",
            file.display(),
            saved.specials[special].kind.name()
        ),
        start: Start::Switch {
            saved: Box::new(saved),
            special,
        },
    })
}

/// The continued key of a stored problem text.
fn stored_key(text: &str) -> Option<String> {
    let table: toml::Table = toml::from_str(text).ok()?;
    Some(
        table
            .get("continuation")?
            .get("parameter")?
            .as_str()?
            .trim()
            .to_string(),
    )
}

/// The tables whose numbers make the rod: a solve of the same problem has
/// the same ones.
const ROD_TABLES: [&str; 5] = ["rod", "energy", "clamp", "support", "loads"];

/// The start from the equilibrium of the solve file `file` for a run of
/// the problem `text` continuing `family` from `start`: Newton at the
/// start value from the stored unknowns. Refused when the file is not a
/// solve file, was solved for another rod (a table of the rod differs),
/// at another model level, or with another discretization.
pub fn solved_start(
    file: &Path,
    text: &str,
    family: &Family,
    start: f64,
) -> Result<StoredStart, String> {
    let solved = read_solved(file).map_err(|e| {
        format!(
            "{}: not a solve file ({e}); a diagram needs --point B/I",
            file.display()
        )
    })?;
    let (stored, own): (toml::Table, toml::Table) = (
        toml::from_str(&solved.problem)
            .map_err(|e| format!("{}: its problem text does not read: {e}", file.display()))?,
        toml::from_str(text).map_err(|e| e.to_string())?,
    );
    if let Some(table) = ROD_TABLES.iter().find(|t| stored.get(**t) != own.get(**t)) {
        return Err(format!(
            "--from {}: solved for another problem: its [{table}] differs from this problem's",
            file.display()
        ));
    }
    if solved.model != family.level().name() {
        return Err(format!(
            "--from {}: solved at the {} model; this continuation runs the {} model",
            file.display(),
            solved.model,
            family.level().name()
        ));
    }
    if solved.unknowns.is_empty() {
        return Err(format!(
            "--from {}: solved by {}, which keeps no shooting unknowns; solve with \
             solver.method = \"shooting\" or \"multiple-shooting\"",
            file.display(),
            solved.method
        ));
    }
    let x = family
        .solved_unknowns(&solved.unknowns, start)
        .map_err(|e| format!("--from {}: {e}", file.display()))?;
    Ok(StoredStart {
        sets: vec![],
        stored: None,
        start: Start::Point(StartPoint::new(x, None)),
        summary: format!(
            "{}: the equilibrium solved by {} ({} unknowns), Newton at {} = {start}",
            file.display(),
            solved.method,
            solved.unknowns.len(),
            family.key()
        ),
    })
}
