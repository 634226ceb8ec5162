//! The methods the tests run a scene with, and a solve by one of them on a
//! forced model level.

use cosserat::bvp::{solve, Equilibrium, Method, SolverOptions};
use cosserat::model::{ModelChoice, ModelLevel, Rod};

/// Single shooting, multiple shooting on `segments` segments, and adaptive
/// collocation of order 6.
pub const fn methods(segments: usize) -> [Method; 3] {
    [
        Method::Shooting,
        Method::MultipleShooting { segments },
        Method::Collocation { stages: 3 },
    ]
}

/// Every method: single and multiple shooting (8 segments), and adaptive
/// collocation of orders 4 and 6 (to its default tolerance 1e-10).
pub const EVERY_METHOD: [Method; 4] = [
    Method::Shooting,
    Method::MultipleShooting { segments: 8 },
    Method::Collocation { stages: 2 },
    Method::Collocation { stages: 3 },
];

/// The two unshearable levels a planar scene can be solved on.
pub const UNSHEARABLE_LEVELS: [ModelLevel; 2] = [ModelLevel::Planar, ModelLevel::Kirchhoff];

/// The default options with `method`.
pub fn options(method: Method) -> SolverOptions {
    SolverOptions {
        method,
        ..Default::default()
    }
}

/// `rod` solved on `level` by `method` with the default options; a failure
/// panics with the level and the method.
pub fn solve_with(rod: &Rod, level: ModelLevel, method: Method) -> Equilibrium {
    let choice = ModelChoice::forced(rod, level).unwrap();
    solve(rod, &choice, &options(method)).unwrap_or_else(|e| panic!("{level:?} {method:?}: {e}"))
}
