//! The methods the tests run a scene with.

use cosserat::bvp::Method;

/// Single shooting, multiple shooting on `segments` segments, and adaptive
/// collocation of order 6.
pub const fn methods(segments: usize) -> [Method; 3] {
    [
        Method::Shooting,
        Method::MultipleShooting { segments },
        Method::Collocation { stages: 3 },
    ]
}
