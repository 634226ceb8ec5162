//! Quadrature independent of the library's integrators.

/// ∫_a^b f by composite Simpson on 2000 panels.
pub fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let n = 2000;
    let h = (b - a) / f64::from(n);
    (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * f(a + h * f64::from(i))
        })
        .sum::<f64>()
        * h
        / 3.0
}
