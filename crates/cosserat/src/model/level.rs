//! The model level a scene needs: the least model that represents it
//! exactly, since every higher level only adds equations whose solution is
//! known (zero out-of-plane bending, ν = e3). A planar scene runs the 4-ODE
//! planar model, a spatial one the 9-ODE Kirchhoff model, a shearable,
//! extensible one the Cosserat model; the choice comes with its reason.

use nalgebra::Vector3;

use super::{Freedom, Rod, TipSupport};

/// How much model the equations carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelLevel {
    /// Bending in the plane of d1(0), d3(0): x, z, φ, κ2 (4 ODEs).
    Planar,
    /// The spatial Kirchhoff rod: d1, d2, κ (9 ODEs) plus r by quadrature.
    Kirchhoff,
    /// The Cosserat rod with shear and extension (ν = e3 + S⁻¹N): the same
    /// 9 ODEs with r' = ν_i d_i and N × ν in the moment balance.
    Cosserat,
}

impl ModelLevel {
    /// The name used in problem files, reports and HDF5 attributes.
    pub fn name(self) -> &'static str {
        match self {
            ModelLevel::Planar => "planar",
            ModelLevel::Kirchhoff => "kirchhoff",
            ModelLevel::Cosserat => "cosserat",
        }
    }
}

/// The level chosen for a scene and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModelChoice {
    /// The level used.
    pub level: ModelLevel,
    /// A sentence saying why.
    pub reason: String,
}

/// Relative size below which a load component counts as zero.
const PLANE_TOLERANCE: f64 = 1e-12;

impl ModelChoice {
    /// The least level that represents the scene exactly: Cosserat when the
    /// energy can shear or extend ([`crate::model::StoredEnergy::strain_energy`]); else planar when the
    /// energy admits planar bending about d2(0) and every load keeps the rod
    /// in the plane of d1(0), d3(0); Kirchhoff otherwise.
    pub fn for_rod(rod: &Rod) -> ModelChoice {
        if rod.energy().strain_energy().is_some() {
            return ModelChoice {
                level: ModelLevel::Cosserat,
                reason: "cosserat: the energy has shear and extension strains \
                         (energy.shear, or a formula in v1, v2, v3)"
                    .into(),
            };
        }
        match planar_obstruction(rod) {
            None => ModelChoice {
                level: ModelLevel::Planar,
                reason: "planar: intrinsic curvature, forces and couple keep the rod \
                         in the plane of d1(0), d3(0)"
                    .into(),
            },
            Some(why) => ModelChoice {
                level: ModelLevel::Kirchhoff,
                reason: format!("kirchhoff: {why}"),
            },
        }
    }

    /// A level forced by the user. Forcing planar on a spatial scene is an
    /// error naming the obstruction; the Cosserat level needs shear and
    /// extension stiffnesses, and a shearable rod needs the Cosserat level
    /// (drop the shear part of the energy for the Kirchhoff limit).
    pub fn forced(rod: &Rod, level: ModelLevel) -> Result<ModelChoice, String> {
        let shearable = rod.energy().strain_energy().is_some();
        match (level, planar_obstruction(rod)) {
            (ModelLevel::Cosserat, _) if !shearable => Err(
                "the Cosserat level needs shear and extension stiffnesses (energy.shear)".into(),
            ),
            (ModelLevel::Planar | ModelLevel::Kirchhoff, _) if shearable => Err(format!(
                "the {} model is unshearable and inextensible, but the energy has \
                 shear and extension stiffnesses (energy.shear)",
                level.name()
            )),
            (ModelLevel::Planar, Some(why)) => Err(format!(
                "the planar model cannot represent this scene: {why}"
            )),
            _ => Ok(ModelChoice {
                level,
                reason: format!("{}: forced by the user", level.name()),
            }),
        }
    }
}

/// Why the scene is not planar, or None when it is.
fn planar_obstruction(rod: &Rod) -> Option<String> {
    if !rod.energy().admits_planar_bending() {
        return Some("the intrinsic curvature has κ⁰1 or κ⁰3 components".into());
    }
    let normal = rod.clamp().director(1);
    let loads = &rod.loads();
    let scale = loads
        .point_loads
        .iter()
        .map(|p| (p.force.norm() * p.s).max(p.couple.norm()))
        .fold(loads.moment_scale(rod.length()), f64::max)
        .max(f64::MIN_POSITIVE);
    for (k, p) in loads.point_loads.iter().enumerate() {
        if (p.force.dot(&normal) * p.s).abs() > PLANE_TOLERANCE * scale {
            return Some(format!("point force {k} has a component along d2(0)"));
        }
        // A couple along the plane's normal bends in the plane, as the tip
        // couple does.
        let c = p.couple - normal * p.couple.dot(&normal);
        if c.norm() > PLANE_TOLERANCE * scale {
            return Some(format!("point couple {k} is not along d2(0)"));
        }
    }
    if (loads.tip_force.dot(&normal) * rod.length()).abs() > PLANE_TOLERANCE * scale {
        return Some("the tip force has a component along d2(0)".into());
    }
    let f = loads.distributed_force.dot(&normal) * rod.length() * rod.length();
    if f.abs() > PLANE_TOLERANCE * scale {
        return Some("the distributed force has a component along d2(0)".into());
    }
    let c = loads.tip_couple - normal * loads.tip_couple.dot(&normal);
    if c.norm() > PLANE_TOLERANCE * scale {
        return Some("the tip couple is not along d2(0)".into());
    }
    rod.support()
        .as_ref()
        .and_then(|support| support_obstruction(rod, support))
}

/// Why a tip support is not planar: a target off the plane of d1(0), d3(0),
/// a sliding axis out of it, a spin axis other than d2(0), or a prescribed
/// tip frame whose d2 is not d2(0).
fn support_obstruction(rod: &Rod, support: &TipSupport) -> Option<String> {
    let normal = rod.clamp().director(1);
    let off = |v: &Vector3<f64>| v.dot(&normal).abs() > 1e-9 * v.norm().max(1.0);
    let held = support.holds_position();
    if held && off(&((support.position - rod.clamp().position) / rod.length())) {
        return Some("the tip support's position is off the plane of d1(0), d3(0)".into());
    }
    if let Freedom::Axial(a) = support.translation {
        if off(&a) {
            return Some("the tip's sliding axis is not in the plane of d1(0), d3(0)".into());
        }
    }
    match support.rotation {
        Freedom::Axial(a) if (a.cross(&normal)).norm() > 1e-9 => {
            Some("the tip's spin axis is not along d2(0)".into())
        }
        Freedom::Fixed if (support.frame.column(1) - normal).norm() > 1e-9 => {
            Some("the prescribed tip frame turns out of the plane".into())
        }
        _ => None,
    }
}
