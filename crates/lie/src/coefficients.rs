//! The scalar coefficients of the closed forms of exp and the Jacobians, precise at every angle.
//!
//! Each is a ratio whose numerator cancels catastrophically near θ = 0: `(θ − sin θ)/θ³` loses
//! about `log10(1/θ²)` digits to rounding in `θ − sin θ`. Below [`SERIES_ANGLE`] they are therefore
//! summed from their Taylor series (alternating, decreasing terms, truncated below 1e-17 relative),
//! above it from the closed forms, which have lost at most a few ulps there.

/// Below this angle the cancelling coefficients are summed from their Taylor series.
const SERIES_ANGLE: f64 = 1.0;

/// Below this angle the coefficients that do not cancel use a short series (only to avoid 0/0).
const TINY_ANGLE: f64 = 1e-4;

/// Horner's rule for `Σ_k c_k x^k`.
fn horner(x: f64, coefficients: &[f64]) -> f64 {
    coefficients.iter().rev().fold(0.0, |sum, c| sum * x + c)
}

/// `(sin θ / θ, (1 − cos θ) / θ²)`, the coefficients of Rodrigues' formula, from one `sin_cos` of
/// θ/2: `sin θ = 2 sin(θ/2) cos(θ/2)` and `1 − cos θ = 2 sin²(θ/2)`, which does not cancel.
pub(crate) fn rodrigues_coefficients(theta: f64) -> (f64, f64) {
    if theta < TINY_ANGLE {
        let t2 = theta * theta;
        (1.0 - t2 / 6.0 + t2 * t2 / 120.0, 0.5 - t2 / 24.0 + t2 * t2 / 720.0)
    } else {
        let (s, c) = (0.5 * theta).sin_cos();
        let s_over = s / theta;
        (2.0 * s_over * c, 2.0 * s_over * s_over)
    }
}

/// `(θ − sin θ) / θ³ = Σ_{k≥0} (−1)^k θ^{2k} / (2k + 3)!`.
pub(crate) fn angle_minus_sin_over_angle3(theta: f64) -> f64 {
    if theta < SERIES_ANGLE {
        const C: [f64; 8] = [
            1.0 / 6.0,
            -1.0 / 120.0,
            1.0 / 5040.0,
            -1.0 / 362_880.0,
            1.0 / 39_916_800.0,
            -1.0 / 6_227_020_800.0,
            1.0 / 1_307_674_368_000.0,
            -1.0 / 355_687_428_096_000.0,
        ];
        horner(theta * theta, &C)
    } else {
        (theta - theta.sin()) / (theta * theta * theta)
    }
}

/// `(θ² + 2 cos θ − 2) / (2 θ⁴) = Σ_{k≥2} (−1)^k θ^{2k−4} / (2k)!` (Barfoot Eq. 7.86, third term).
pub(crate) fn q_coefficient_2(theta: f64) -> f64 {
    if theta < SERIES_ANGLE {
        const C: [f64; 8] = [
            1.0 / 24.0,
            -1.0 / 720.0,
            1.0 / 40_320.0,
            -1.0 / 3_628_800.0,
            1.0 / 479_001_600.0,
            -1.0 / 87_178_291_200.0,
            1.0 / 20_922_789_888_000.0,
            -1.0 / 6_402_373_705_728_000.0,
        ];
        horner(theta * theta, &C)
    } else {
        let t2 = theta * theta;
        (t2 + 2.0 * theta.cos() - 2.0) / (2.0 * t2 * t2)
    }
}

/// `(2θ − 3 sin θ + θ cos θ) / (2 θ⁵) = Σ_{k≥2} (−1)^k (k − 1) θ^{2k−4} / (2k + 1)!`
/// (Barfoot Eq. 7.86, fourth term).
pub(crate) fn q_coefficient_3(theta: f64) -> f64 {
    if theta < SERIES_ANGLE {
        const C: [f64; 8] = [
            1.0 / 120.0,
            -2.0 / 5040.0,
            3.0 / 362_880.0,
            -4.0 / 39_916_800.0,
            5.0 / 6_227_020_800.0,
            -6.0 / 1_307_674_368_000.0,
            7.0 / 355_687_428_096_000.0,
            -8.0 / 121_645_100_408_832_000.0,
        ];
        horner(theta * theta, &C)
    } else {
        let (s, c) = theta.sin_cos();
        let t2 = theta * theta;
        (2.0 * theta - 3.0 * s + theta * c) / (2.0 * t2 * t2 * theta)
    }
}

/// `(1 − (θ/2) cot(θ/2)) / θ²`, the `ω^²` coefficient of `J_l⁻¹`; finite up to
/// θ = π and beyond, singular at 2π. The numerator cancels to `θ²/12`, but it multiplies `ω^²`
/// (of size θ²), so the closed form's relative error `~ε/θ²` costs only `~ε` in the Jacobian.
pub(crate) fn inverse_jacobian_coefficient(theta: f64) -> f64 {
    if theta < TINY_ANGLE {
        let t2 = theta * theta;
        1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30_240.0
    } else {
        let half = 0.5 * theta;
        let (s, c) = half.sin_cos();
        (1.0 - half * c / s) / (theta * theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series and the closed forms agree where they meet. The closed form of `q_coefficient_3`
    /// cancels from terms ~2.5 to 0.016 at θ = 1, hence the 5e-14 relative: it multiplies `ω^³`-sized
    /// terms, so this is ~1e-16 in the Jacobian.
    #[test]
    fn series_and_closed_forms_agree_at_the_switch_angles() {
        for (f, closed) in [
            (angle_minus_sin_over_angle3 as fn(f64) -> f64, (|t: f64| (t - t.sin()) / t.powi(3)) as fn(f64) -> f64),
            (q_coefficient_2, |t: f64| (t * t + 2.0 * t.cos() - 2.0) / (2.0 * t.powi(4))),
            (q_coefficient_3, |t: f64| (2.0 * t - 3.0 * t.sin() + t * t.cos()) / (2.0 * t.powi(5))),
        ] {
            for theta in [SERIES_ANGLE * (1.0 - 1e-12), SERIES_ANGLE * 0.999, SERIES_ANGLE] {
                let (a, b) = (f(theta), closed(theta));
                assert!((a - b).abs() <= 5e-14 * b.abs(), "θ = {theta}: series {a:e} vs closed form {b:e}");
            }
        }
    }

    /// Near 0 the series give the limits exactly.
    #[test]
    fn coefficients_at_zero_are_their_limits() {
        assert_eq!(rodrigues_coefficients(0.0), (1.0, 0.5));
        assert_eq!(angle_minus_sin_over_angle3(0.0), 1.0 / 6.0);
        assert_eq!(q_coefficient_2(0.0), 1.0 / 24.0);
        assert_eq!(q_coefficient_3(0.0), 1.0 / 120.0);
        assert_eq!(inverse_jacobian_coefficient(0.0), 1.0 / 12.0);
    }
}
