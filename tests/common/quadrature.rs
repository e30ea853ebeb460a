//! Quadrature for tests.

/// ∫ f over [a, b] by Simpson's rule on `n` intervals (`n` even).
pub fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    assert!(
        n.is_multiple_of(2),
        "Simpson's rule needs an even number of intervals"
    );
    let h = (b - a) / n as f64;
    let s: f64 = (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * f(a + i as f64 * h)
        })
        .sum();
    s * h / 3.0
}
