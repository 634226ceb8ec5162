//! A fast-turning material frame does not fool the stability verdict: a
//! Greenhill shaft with a soft torsional stiffness (C = B/100) twisted by
//! M L/B = 5 spins its frame at κ3 = M/C = 500 rad per length, so the
//! second variation's modes, smooth in space, oscillate in the material
//! frame. Two coarse meshes then agree with each other and are both wrong
//! (they called P = 30 stable, against Greenhill's P_c = 24.2). The verdict
//! now starts from a mesh that keeps the turn per element within 0.5 rad
//! and matches the closed form (clamped ends: the 4 × 4 characteristic
//! determinant of `references::greenhill_clamped`) on both sides of P_c;
//! continuation on a coarse tracked mesh ends its branch naming the mesh
//! it needs instead of reporting its eigenvalues.

use cosserat::bvp::solve;
use cosserat::continuation::{continuation, BranchEnd};
use cosserat::input::Problem;
use cosserat::references::greenhill_clamped;
use cosserat::stability::{decide, Verdict};

const GREENHILL: &str = include_str!("../../../problems/greenhill.toml");

fn soft_shaft(thrust: f64) -> Problem {
    let set = [
        "energy.stiffness=[1.0, 1.0, 0.01]".to_string(),
        "loads.tip_couple=[0.0, 0.0, 5.0]".to_string(),
        format!("loads.tip_force=[0.0, 0.0, {thrust}]"),
    ];
    Problem::from_str_with(GREENHILL, &set).unwrap()
}

#[test]
fn a_soft_twisted_shaft_is_decided_on_a_resolved_mesh() {
    let critical = greenhill_clamped(5.0);
    assert!((critical - 24.18).abs() < 0.01, "{critical}");
    for (thrust, unstable) in [(0.8 * critical, false), (1.2 * critical, true)] {
        let p = soft_shaft(thrust);
        let eq = solve(&p.rod, &p.model, &p.options).unwrap();
        let d = decide(&p.rod, &eq, &p.options, &p.stability).unwrap();
        assert!(
            d.elements >= 1000,
            "the mesh resolves κ3 = 500: {} elements",
            d.elements
        );
        match (d.verdict, unstable) {
            (Verdict::Unstable { morse_index }, true) => {
                assert_eq!(morse_index, 2, "the isotropic bending pair");
            }
            (Verdict::Stable, false) => {}
            (v, _) => panic!("P = {thrust} (P_c = {critical}): {v:?}"),
        }
    }
}

#[test]
fn continuation_on_an_unresolved_mesh_ends_naming_the_mesh_it_needs() {
    let p = soft_shaft(30.0);
    let (family, opts) = p.continuation.clone().unwrap();
    match continuation(&family, &opts, &mut |_, _| true) {
        Err(e) => assert!(e.to_string().contains("continuation.elements"), "{e}"),
        Ok(d) => {
            let end = &d.branches[0].stop_reason;
            assert!(
                matches!(end, BranchEnd::Failed(why) if why.contains("continuation.elements")),
                "{end}"
            );
        }
    }
}
