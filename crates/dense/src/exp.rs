//! A branch-free exponential for the kernels' inner loops, the instruction set they run on, and
//! the fixed-order sums that keep their results independent of the thread.

/// `eˣ` for `x ≤ 0` within `4ε` (relative) of the standard library's for `x ≥ −700` (measured:
/// 2.1ε), and a value below 1e−300 below that; branch-free and free of library calls, so that
/// loops over it vectorise.
///
/// Cody–Waite reduction `x = n ln 2 + r`, `|r| ≤ ½ ln 2` (`n` rounded by adding and subtracting
/// `1.5 · 2⁵²`, whose low mantissa bits then hold `n`), the degree-12 Taylor polynomial of `eʳ`
/// (truncation error below 2e−17 relative there) by Horner's rule, and `2ⁿ` by writing the
/// exponent bits.
#[inline(always)]
pub fn exp_nonpositive(x: f64) -> f64 {
    const LN2_HI: f64 = 6.931_471_803_691_238e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    const SHIFTER: f64 = 6_755_399_441_055_744.0; // 1.5 · 2⁵²
    // 1/k! for k = 12 … 2.
    const C: [f64; 11] = [
        1.0 / 479_001_600.0,
        1.0 / 39_916_800.0,
        1.0 / 3_628_800.0,
        1.0 / 362_880.0,
        1.0 / 40_320.0,
        1.0 / 5_040.0,
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
    ];
    let x = if x < -700.0 { -700.0 } else { x };
    let x = if x > 0.0 { 0.0 } else { x };
    let shifted = x * std::f64::consts::LOG2_E + SHIFTER;
    let n = shifted - SHIFTER;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let mut p = C[0];
    for c in &C[1..] {
        p = p * r + c;
    }
    let e = 1.0 + r + r * r * p;
    // The low 52 bits of `shifted` are 2⁵¹ + n, n ∈ [−1010, 0]: 2ⁿ has exponent field n + 1023.
    let n_bits = (shifted.to_bits() & ((1 << 52) - 1)).wrapping_sub(1 << 51);
    e * f64::from_bits(n_bits.wrapping_add(1023) << 52)
}

thread_local! {
    /// The widest instruction set of this processor, detected once per thread.
    pub(crate) static ARCH: pulp::Arch = pulp::Arch::new();
}

/// Partial sums per loop lane: eight, one AVX-512 register of `f64` (two AVX2 registers).
pub const LANES: usize = 8;

/// `Σ v` of the lanes in a fixed pairwise order.
#[inline(always)]
pub fn pairwise(v: &[f64; LANES]) -> f64 {
    ((v[0] + v[1]) + (v[2] + v[3])) + ((v[4] + v[5]) + (v[6] + v[7]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_nonpositive_is_within_four_epsilon_of_the_standard_library() {
        let mut worst: f64 = 0.0;
        for i in 0..=200_000 {
            let x = (-(i as f64) * 700.0 / 200_000.0 - 1e-9 * (i % 7) as f64).max(-700.0);
            let (fast, exact) = (exp_nonpositive(x), x.exp());
            worst = worst.max(((fast - exact) / exact).abs());
        }
        assert!(worst <= 4.0 * f64::EPSILON, "largest relative error {worst:e}");
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert!(exp_nonpositive(-800.0) < 1e-300);
    }
}
