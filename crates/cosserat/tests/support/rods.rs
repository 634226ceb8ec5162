//! The rods several tests and benches build: uniform, linearly elastic,
//! intrinsically straight, held by the paper's clamp (d1(0) = e1 pointing
//! down, d3(0) = e3), the tip free.

use std::sync::Arc;

use cosserat::model::{Clamp, DeadLoads, LinearElastic, Rod};
use nalgebra::Vector3;

/// A rod of `length` with the uniform stiffnesses `b` = (B1, B2, B3) under
/// `loads`.
pub fn uniform(length: f64, b: [f64; 3], loads: DeadLoads) -> Rod {
    let energy = LinearElastic::uniform(b, [0.0; 3]).expect("a positive stiffness");
    Rod::new(length, Arc::new(energy), Clamp::paper(), loads, None).expect("a valid rod")
}

/// Dead loads of a tip force alone.
pub fn tip_force(x: f64, y: f64, z: f64) -> DeadLoads {
    DeadLoads {
        tip_force: Vector3::new(x, y, z),
        ..Default::default()
    }
}

/// The paper's cantilever: L = 1, B = (10, 1, 10), clamp d1 = e1 (down),
/// d3 = e3, tip force k e1.
pub fn cantilever(k: f64) -> Rod {
    uniform(1.0, [10.0, 1.0, 10.0], tip_force(k, 0.0, 0.0))
}
