//! Axis titles in the problem's own terms: one table from the `--set` /
//! continuation keys and the diagram measures to mathematical labels with
//! their units, so that a chart says "F₃ L²/B₂", not `loads.tip_force[2]`.
//!
//! Units are those of the problem file (docs/problem-files.md: m, N,
//! N·m, N·m²). A problem with `rod.length = 1` and a constant
//! `energy.stiffness[1] = 1` (B₂), neither of them varied, is written in
//! the units L and B₂ — every number it shows *is* the dimensionless group
//! (a force is F L²/B₂, a length x/L), whatever consistent units the user
//! had in mind — so its labels name the groups ([`Scale::Nondimensional`]);
//! any other problem gets the documented units ([`Scale::Dimensional`]).
//!
//! Subscripts: 1, 2, 3 for the components of forces, couples and moments
//! (global e₁, e₂, e₃ = x, y, z) and of stiffness and curvature (body d₁,
//! d₂, d₃); positions are x, y, z. A key or measure the table does not
//! know is shown as it is, never given a label that could be wrong.

/// How the numbers of a problem are to be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// The documented units of the problem file (m, N, N·m, N·m²).
    Dimensional,
    /// L = 1 and B₂ = 1: every number is its dimensionless group.
    Nondimensional,
}

impl Scale {
    /// The scale of the effective problem text `text` (as stored in every
    /// result file) of which the keys `varied` are continued or swept:
    /// nondimensional when `rod.length` and `energy.stiffness[1]` are both
    /// the number 1 and neither is varied. A text that does not parse is
    /// dimensional (the documented units).
    pub fn of_problem(text: &str, varied: &[&str]) -> Scale {
        let Ok(table) = toml::from_str::<toml::Table>(text) else {
            return Scale::Dimensional;
        };
        let number = |v: Option<&toml::Value>| match v {
            Some(toml::Value::Float(f)) => Some(*f),
            Some(toml::Value::Integer(i)) => Some(*i as f64),
            _ => None,
        };
        let length = number(table.get("rod").and_then(|r| r.get("length")));
        let b2 = number(
            table
                .get("energy")
                .and_then(|e| e.get("stiffness"))
                .and_then(|s| s.get(1)),
        );
        let held = !varied
            .iter()
            .any(|k| matches!(*k, "rod.length" | "energy.stiffness[1]"));
        if length == Some(1.0) && b2 == Some(1.0) && held {
            Scale::Nondimensional
        } else {
            Scale::Dimensional
        }
    }
}

/// What a number measures: its unit, or its dimensionless group.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Dimension {
    /// A pure number.
    Ratio,
    /// Degrees (already so in the data).
    Degrees,
    /// Radians.
    Radians,
    /// m.
    Length,
    /// 1/m.
    Curvature,
    /// N.
    Force,
    /// N/m.
    ForcePerLength,
    /// N·m, a couple or a moment.
    Couple,
    /// N·m, an energy.
    Energy,
    /// N·m², a bending or twisting stiffness.
    Stiffness,
    /// N·m⁴, the quartic energy's C.
    Quartic,
}

impl Dimension {
    /// `symbol` with its unit or its group.
    fn label(self, symbol: &str, scale: Scale) -> String {
        let (unit, group) = match self {
            Dimension::Ratio => return symbol.to_string(),
            Dimension::Degrees => return format!("{symbol} (°)"),
            Dimension::Radians => return format!("{symbol} (rad)"),
            Dimension::Length => ("m", format!("{symbol}/L")),
            Dimension::Curvature => ("1/m", format!("{symbol} L")),
            Dimension::Force => ("N", format!("{symbol} L²/B₂")),
            Dimension::ForcePerLength => ("N/m", format!("{symbol} L³/B₂")),
            // A couple and an energy share N·m and the group L/B₂.
            Dimension::Couple | Dimension::Energy => ("N·m", format!("{symbol} L/B₂")),
            Dimension::Stiffness => ("N·m²", format!("{symbol}/B₂")),
            Dimension::Quartic => ("N·m⁴", format!("{symbol}/(B₂ L²)")),
        };
        match scale {
            Scale::Dimensional => format!("{symbol} ({unit})"),
            Scale::Nondimensional => group,
        }
    }
}

/// ₁, ₂, ₃ for components 0, 1, 2.
fn sub(i: usize) -> &'static str {
    ["₁", "₂", "₃"][i]
}

/// x, y, z for components 0, 1, 2.
fn axis(i: usize) -> &'static str {
    ["x", "y", "z"][i]
}

/// `name[i]` → (name, Some(i)) for i in 0..3; `name` → (name, None).
fn indexed(key: &str) -> Option<(&str, Option<usize>)> {
    let Some((head, rest)) = key.split_once('[') else {
        return Some((key, None));
    };
    let i: usize = rest.strip_suffix(']')?.trim().parse().ok()?;
    (i < 3).then_some((head, Some(i)))
}

/// The symbol and dimension of a `--set` / continuation key, if known.
fn key_entry(key: &str) -> Option<(String, Dimension)> {
    let (head, index) = indexed(key.trim())?;
    let entry = match (head, index) {
        ("load_scale", None) => ("load factor λ".into(), Dimension::Ratio),
        ("control_scale", None) => ("control factor λ (loads and κ⁰)".into(), Dimension::Ratio),
        ("loads.tip_force", Some(i)) => (format!("F{}", sub(i)), Dimension::Force),
        ("loads.tip_couple", Some(i)) => (format!("C{}", sub(i)), Dimension::Couple),
        ("loads.distributed_force", Some(i)) => (format!("f{}", sub(i)), Dimension::ForcePerLength),
        ("energy.stiffness", Some(i)) => (format!("B{}", sub(i)), Dimension::Stiffness),
        ("energy.intrinsic_curvature", Some(i)) => (format!("κ⁰{}", sub(i)), Dimension::Curvature),
        ("energy.shear", Some(i)) => {
            let s = ["kGA₁", "kGA₂", "EA"][i];
            (s.into(), Dimension::Force)
        }
        ("energy.quartic" | "energy.parameters.quartic", None) => {
            ("quartic stiffness C".into(), Dimension::Quartic)
        }
        ("rod.length", None) => ("L".into(), Dimension::Length),
        ("clamp.angle", None) => ("clamp angle".into(), Dimension::Radians),
        ("clamp.turn.angle", None) => ("clamp turn θ₀".into(), Dimension::Radians),
        ("support.turn.angle", None) => ("tip turn θ_L".into(), Dimension::Radians),
        ("clamp.position", Some(i)) => (format!("clamp {}", axis(i)), Dimension::Length),
        ("support.position", Some(i)) => (format!("support {}", axis(i)), Dimension::Length),
        ("arm.alpha", None) => ("reach direction α".into(), Dimension::Degrees),
        _ => return None,
    };
    Some(entry)
}

/// The label of a `--set` or continuation key (the key itself when the
/// table does not know it). `rod.length` varied is always dimensional.
pub fn key_label(key: &str, scale: Scale) -> String {
    match key_entry(key) {
        Some((symbol, dimension)) => dimension.label(&symbol, scale),
        None => key.to_string(),
    }
}

/// The label of a diagram's parameter name: a key, or a chained run's
/// `stage 1: KEY | stage 2: KEY` (as `plot::read_diagram` joins them),
/// each stage's key labelled.
pub fn parameter_label(name: &str, scale: Scale) -> String {
    name.split(" | ")
        .map(|part| match part.split_once(": ") {
            Some((stage, key)) if stage.starts_with("stage ") => {
                format!("{stage}: {}", key_label(key, scale))
            }
            _ => key_label(part, scale),
        })
        .collect::<Vec<_>>()
        .join(" | ")
}

/// Where along the rod a sampled measure is taken: s = 0, s = L, s = σL.
fn station(fraction: f64) -> String {
    if fraction == 0.0 {
        "s = 0".into()
    } else if fraction == 1.0 {
        "s = L".into()
    } else {
        format!("s = {fraction}L")
    }
}

/// The symbol and dimension of a measure (`tip_x`, `norm`, … or a name of
/// the grammar of `cosserat::continuation::Measure`), if known.
fn measure_entry(name: &str) -> Option<(String, Dimension)> {
    use cosserat::continuation::{Measure, Quantity};
    let entry = match name {
        "tip_x" | "tip_y" | "tip_z" => (format!("tip {}", &name[4..]), Dimension::Length),
        "tip_angle" => ("tip angle".into(), Dimension::Degrees),
        "norm" => ("norm of the scaled unknowns".into(), Dimension::Ratio),
        _ => match Measure::parse(name).ok()? {
            Measure::Turning => ("turning angle φ(L) − φ(0)".into(), Dimension::Radians),
            Measure::StoredEnergy => ("stored energy V".into(), Dimension::Energy),
            Measure::TotalPotentialEnergy => ("total potential Π".into(), Dimension::Energy),
            Measure::At {
                quantity,
                component: i,
                fraction,
            } => {
                let at = station(fraction);
                let (symbol, dimension) = match quantity {
                    Quantity::Position => (axis(i).to_string(), Dimension::Length),
                    Quantity::Tangent => (format!("d₃·e{}", sub(i)), Dimension::Ratio),
                    Quantity::Force => (format!("n{}", sub(i)), Dimension::Force),
                    Quantity::Moment => (format!("m{}", sub(i)), Dimension::Couple),
                    Quantity::Curvature => (format!("κ{}", sub(i)), Dimension::Curvature),
                };
                return Some((format!("{symbol}@{at}"), dimension));
            }
        },
    };
    Some(entry)
}

/// The label of a measure (the name itself when the table does not know
/// it). A sampled measure says where: "n₃ L²/B₂ at s = 0".
pub fn measure_label(name: &str, scale: Scale) -> String {
    match measure_entry(name) {
        Some((symbol, dimension)) => match symbol.split_once('@') {
            Some((symbol, at)) => format!("{} at {at}", dimension.label(symbol, scale)),
            None => dimension.label(&symbol, scale),
        },
        None => name.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const UNIT: &str = "[rod]\nlength = 1.0\n[energy]\nstiffness = [4.0, 1, 1.27]\n";

    #[test]
    fn unit_length_and_b2_make_a_problem_nondimensional() {
        assert_eq!(Scale::of_problem(UNIT, &[]), Scale::Nondimensional);
        assert_eq!(
            Scale::of_problem(UNIT, &["energy.stiffness[0]"]),
            Scale::Nondimensional
        );
        // Varying L or B₂ leaves the units they define.
        assert_eq!(Scale::of_problem(UNIT, &["rod.length"]), Scale::Dimensional);
        assert_eq!(
            Scale::of_problem(UNIT, &["energy.stiffness[1]"]),
            Scale::Dimensional
        );
        let long = UNIT.replace("length = 1.0", "length = 2.0");
        assert_eq!(Scale::of_problem(&long, &[]), Scale::Dimensional);
        let profile = UNIT.replace("1, 1.27", "{ s = [0, 1], values = [1, 2] }, 1.27");
        assert_eq!(Scale::of_problem(&profile, &[]), Scale::Dimensional);
        assert_eq!(Scale::of_problem("not toml [", &[]), Scale::Dimensional);
    }

    #[test]
    fn keys_get_their_groups_or_units() {
        let n = Scale::Nondimensional;
        let d = Scale::Dimensional;
        assert_eq!(key_label("loads.tip_force[2]", n), "F₃ L²/B₂");
        assert_eq!(key_label("loads.tip_force[2]", d), "F₃ (N)");
        assert_eq!(key_label("energy.stiffness[0]", n), "B₁/B₂");
        assert_eq!(key_label("energy.stiffness[2]", d), "B₃ (N·m²)");
        assert_eq!(key_label("loads.tip_couple[1]", n), "C₂ L/B₂");
        assert_eq!(key_label("loads.distributed_force[0]", n), "f₁ L³/B₂");
        assert_eq!(key_label("energy.intrinsic_curvature[1]", n), "κ⁰₂ L");
        assert_eq!(key_label("energy.shear[2]", d), "EA (N)");
        assert_eq!(key_label("support.position[2]", n), "support z/L");
        assert_eq!(key_label("support.turn.angle", n), "tip turn θ_L (rad)");
        assert_eq!(key_label("arm.alpha", d), "reach direction α (°)");
        assert_eq!(key_label("load_scale", d), "load factor λ");
    }

    #[test]
    fn unknown_keys_are_shown_as_they_are() {
        for key in [
            "energy.parameters.stiffening",
            "loads.tip_force[3]",
            "loads.tip_force",
            "load factor λ (× design load; κ⁰ fixed)",
            "solver.tolerance",
        ] {
            assert_eq!(key_label(key, Scale::Nondimensional), key);
        }
    }

    #[test]
    fn chained_stages_are_labelled_stage_by_stage() {
        assert_eq!(
            parameter_label(
                "stage 1: support.position[2] | stage 2: support.turn.angle",
                Scale::Nondimensional
            ),
            "stage 1: support z/L | stage 2: tip turn θ_L (rad)"
        );
        assert_eq!(
            parameter_label("energy.stiffness[0]", Scale::Dimensional),
            "B₁ (N·m²)"
        );
    }

    #[test]
    fn measures_get_their_groups_or_units() {
        let n = Scale::Nondimensional;
        let d = Scale::Dimensional;
        assert_eq!(measure_label("tip_x", n), "tip x/L");
        assert_eq!(measure_label("tip_z", d), "tip z (m)");
        assert_eq!(measure_label("tip_angle", n), "tip angle (°)");
        assert_eq!(measure_label("force[2]@0", n), "n₃ L²/B₂ at s = 0");
        assert_eq!(measure_label("moment[1]@1", d), "m₂ (N·m) at s = L");
        assert_eq!(measure_label("position[0]@0.5", n), "x/L at s = 0.5L");
        assert_eq!(measure_label("curvature[1]@0.25", n), "κ₂ L at s = 0.25L");
        assert_eq!(measure_label("tangent[0]@1", d), "d₃·e₁ at s = L");
        assert_eq!(
            measure_label("turning", n),
            "turning angle φ(L) − φ(0) (rad)"
        );
        assert_eq!(measure_label("stored_energy", n), "stored energy V L/B₂");
        assert_eq!(
            measure_label("total_potential_energy", d),
            "total potential Π (N·m)"
        );
        assert_eq!(measure_label("speed", n), "speed");
    }
}
