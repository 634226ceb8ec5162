//! A check of spatial arm designs independent of the fixed-shape pencil
//! (docs/extensions.md, "Spatial arms", the points of the paper's Fig. 6):
//! the vertical spatial optima at P = (B̄1, B̄3) = (7.5, 5.0) and
//! R = (7.5, 4.3), looped shapes whose R* (2.2129, 2.1744) exceed the
//! fast-pretwist column limit (π/2)√(2B̄1/(1+B̄1)) = 2.0867.
//!
//! The designed rod (κ̄⁰ of the design held, the design load) is solved by
//! multiple shooting from the design's clamp curvature, and the second
//! variation of that equilibrium is assembled from the solved equilibrium
//! (`stability::analyze`, not the fixed-shape pencil K0 + λK1) on 50 to 400
//! quadratic elements. The equilibrium must be the design (its tip where
//! the fixed shape's κ̄ puts it), and its lowest eigenvalues zero to the
//! mesh error with no negative one beyond it: critical at the design load.
//! That is the whole claim of γ_crit, since K0 (the unloaded rod) is
//! positive definite, so K0 + λK1 = (1 − λ)K0 + λ(K0 + K1) is positive
//! definite for every λ < 1 once K0 + K1 is semidefinite.
//!
//! Last, P's design (held, not optimized again) at other stiffness ratios:
//! its reach rises with the torsional stiffness B̄3 (the loop carries the
//! load largely in torsion, as a coil spring does).
//!
//!   cargo run --release -p cosserat --example spatial_design_check

use std::f64::consts::PI;

use cosserat::bvp::{solve, Method, SolverOptions, Strategy};
use cosserat::model::{ModelChoice, ModelLevel};
use cosserat::stability::{analyze, StabilityOptions};
use cosserat::study::arm::{ArmProblem, ArmScene, SpatialArm};
use nalgebra::Vector3;

/// A design to check: its name, B̄1, B̄3 and design vector (c2..c8,
/// a1..a3, t1..t3, ψ) as `cosserat optimize` found it (the long box of
/// docs/extensions.md, `--set arm.alpha=90 --set 'energy.stiffness=[B̄1,
/// 1.0, B̄3]'`).
struct Point {
    name: &'static str,
    b1: f64,
    b3: f64,
    design: [f64; 14],
}

const POINTS: [Point; 2] = [
    Point {
        name: "P",
        b1: 7.5,
        b3: 5.0,
        design: [
            -4.0,
            1.404_661_936_659_905_6,
            0.195_706_924_430_353_17,
            -0.160_226_872_172_741_1,
            -0.480_314_445_270_645_65,
            -0.212_956_641_218_565_06,
            -0.307_635_495_015_435_1,
            1.012_211_295_746_607_2,
            1.999_999_357_352_140_8,
            -0.180_947_055_107_907_26,
            3.664_139_241_515_569_4,
            -1.524_541_657_723_972_5,
            -1.281_226_602_583_363_6,
            1.572_048_589_550_299_8,
        ],
    },
    Point {
        name: "R",
        b1: 7.5,
        b3: 4.3,
        design: [
            -4.0,
            1.395_042_220_570_751_1,
            0.282_902_110_780_222_4,
            -0.206_738_294_286_069_96,
            -0.407_682_485_090_695_5,
            -0.092_968_936_998_835_38,
            -0.305_849_689_639_179_36,
            1.068_779_877_214_765,
            1.999_999_980_734_100_5,
            -0.242_384_644_445_746_1,
            3.701_418_485_966_058,
            -1.393_480_562_924_767_5,
            -1.421_213_637_737_528_2,
            0.912_361_619_042_341_8,
        ],
    },
];

/// The long box of docs/extensions.md, vertical, at (B̄1, B̄3).
fn vertical_arm(b1: f64, b3: f64) -> SpatialArm {
    let half = (-0.5, 0.5);
    SpatialArm {
        planar: ArmProblem {
            b1,
            b3,
            alpha: PI / 2.0,
            bounds: vec![(-4.0, 4.0), (-2.0, 2.0), half, half, half, half, half],
            stability: StabilityOptions::new(50, 2, 1).expect("a mesh"),
        },
        bend_bounds: vec![(-2.0, 2.0), (-2.0, 2.0), (-1.0, 1.0)],
        twist_bounds: vec![(-8.0, 8.0), (-4.0, 4.0), (-2.0, 2.0)],
        roll_bounds: Some((-PI, PI)),
        directions: vec![],
    }
}

fn check(point: &Point) {
    let arm = vertical_arm(point.b1, point.b3);
    let scene = ArmScene::default();
    let design = arm.design_in(&scene, &point.design).expect("a design");
    println!(
        "{} (B̄1 = {}, B̄3 = {}): R* = {:.6}, γ_crit = {:.6} on 50 elements",
        point.name, point.b1, point.b3, design.reach, design.gamma
    );
    let resolution = arm.mesh_check(&scene, &design);
    let optimum = arm
        .finish(&scene, design, resolution, 1)
        .expect("the design's shapes");
    let scale = scene.length(optimum.design.gamma);
    let tip = optimum.loaded_shape.last().expect("a loaded shape");
    let design_tip = Vector3::new(tip[0], tip[1], tip[2]) / scale;
    let rod = arm
        .designed_rod(&scene, &optimum.design)
        .expect("the designed rod");
    let opts = SolverOptions {
        strategy: Strategy::Direct,
        method: Method::MultipleShooting { segments: 32 },
        initial_guess: Some(
            optimum
                .design
                .curvature_coefficients
                .iter()
                .map(|c| c[0])
                .collect(),
        ),
        ..Default::default()
    };
    let model = ModelChoice {
        level: ModelLevel::Kirchhoff,
        reason: String::new(),
    };
    let eq = solve(&rod, &model, &opts).expect("the design's equilibrium");
    println!(
        "  design load: residual {:.1e}, tip {:.1e} L from the design's",
        eq.residual,
        (eq.tip().position - design_tip).norm()
    );
    for elements in [50, 100, 200, 400] {
        let so = StabilityOptions::new(elements, 2, 4).expect("a mesh");
        match analyze(&rod, &eq, &opts, &so) {
            Ok(st) => {
                let e: Vec<String> = st.blocks[0]
                    .eigenvalues
                    .iter()
                    .map(|v| format!("{v:+.3e}"))
                    .collect();
                println!(
                    "  N = {elements}: lowest eigenvalues {} (Morse index {})",
                    e.join(", "),
                    st.morse_index
                );
            }
            Err(e) => println!("  N = {elements}: {e}"),
        }
    }
}

/// R* of P's design at other (B̄1, B̄3), on 50 elements.
fn scan_stiffness() {
    let scene = ArmScene::default();
    println!("P's design at other stiffness ratios (50 elements):");
    for (b1, b3) in [
        (7.5, 1.0),
        (7.5, 2.0),
        (7.5, 3.0),
        (7.5, 4.3),
        (7.5, 5.0),
        (4.0, 1.27),
        (16.0, 2.0 / 3.0),
    ] {
        let reach = vertical_arm(b1, b3)
            .design_in(&scene, &POINTS[0].design)
            .map_or(f64::NAN, |d| d.reach);
        let column = PI / 2.0 * (2.0 * b1 / (1.0 + b1)).sqrt();
        println!(
            "  B̄1 = {b1}, B̄3 = {b3:.3}: R = {reach:.6} (fast-pretwist column limit {column:.4})"
        );
    }
}

fn main() {
    for point in &POINTS {
        check(point);
    }
    scan_stiffness();
}
