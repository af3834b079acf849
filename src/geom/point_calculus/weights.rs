//! The weight functions of paper 003's point equations and their
//! derivatives. Each set sums to 1 for every parameter value.

/// The conic arc A (u = 0) → B (u = 1) with tangent point C and discriminant
/// k: weights of (A, B, C) and their derivatives. This is the rational
/// quadratic Bezier A, C, B with middle weight (1 − k)/k, multiplied through
/// by k: numerators k·ū², k·u², 2(1 − k)·u·ū over k(1 − 2u)² + 2uū.
pub fn conic_weights(k: f64, u: f64) -> ([f64; 3], [f64; 3]) {
    let ub = 1.0 - u;
    let na = k * ub * ub;
    let nb = k * u * u;
    let nc = 2.0 * (1.0 - k) * u * ub;
    let da = -2.0 * k * ub;
    let db = 2.0 * k * u;
    let dc = 2.0 * (1.0 - k) * (1.0 - 2.0 * u);
    let s = 1.0 - 2.0 * u;
    let den = k * s * s + 2.0 * u * ub;
    let dden = -4.0 * k * s + 2.0 * s;
    let inv = 1.0 / den;
    let w = [na * inv, nb * inv, nc * inv];
    let d = [
        (da * den - na * dden) * inv * inv,
        (db * den - nb * dden) * inv * inv,
        (dc * den - nc * dden) * inv * inv,
    ];
    (w, d)
}

/// The Desargues cubic arc: weights of (A, B, C, D) — ū³, u²ū, ū²u, u³ over
/// 2u² − 2u + 1 (= ū² + u², their sum) — and their derivatives.
pub fn desargues_weights(u: f64) -> ([f64; 4], [f64; 4]) {
    let ub = 1.0 - u;
    let n = [ub * ub * ub, u * u * ub, ub * ub * u, u * u * u];
    let dn = [
        -3.0 * ub * ub,
        2.0 * u * ub - u * u,
        ub * ub - 2.0 * u * ub,
        3.0 * u * u,
    ];
    let den = 2.0 * u * u - 2.0 * u + 1.0;
    let dden = 4.0 * u - 2.0;
    let inv = 1.0 / den;
    let w = n.map(|ni| ni * inv);
    let mut d = [0.0; 4];
    for i in 0..4 {
        d[i] = (dn[i] * den - n[i] * dden) * inv * inv;
    }
    (w, d)
}

/// The parabola through three points at u = 0, ½, 1: ū(1 − 2u), 4uū, u(2u − 1).
pub fn parabola_weights(u: f64) -> ([f64; 3], [f64; 3]) {
    let ub = 1.0 - u;
    (
        [ub * (1.0 - 2.0 * u), 4.0 * u * ub, u * (2.0 * u - 1.0)],
        [4.0 * u - 3.0, 4.0 - 8.0 * u, 4.0 * u - 1.0],
    )
}
