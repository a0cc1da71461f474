//! The inner loops of the first-order additive term `Σₖ aₖ s((pₖ − qₖ)²)` (inputs already divided
//! by the term's own length scales), column by column over one input at a time on contiguous
//! copies of each input.
//!
//! With `d` inputs the term costs `d` exponentials per kernel entry. Profiled on the UR10 fit
//! (n = 1,387, d = 6) with the standard library's `exp`, 58 % of the whole `calib fit` was spent
//! in `exp` and 14 % more in these loops. For the squared exponential the loops therefore use
//! [`exp_nonpositive`], a branch-free exponential without library calls, and run through `pulp`'s
//! run-time dispatch, which compiles them again for AVX2 + FMA (and AVX-512) and picks the widest
//! the processor has, so that the compiler vectorises them (the Matérn shape keeps the scalar
//! library path).
//!
//! Every entry is computed by the same code whatever thread runs its column, so results stay the
//! same serial or parallel on one machine; a processor without AVX2 + FMA rounds differently in
//! the last bits.

use crate::kernel::StationaryShape;
use crate::points::Points;

/// The additive inputs as one contiguous column per input dimension (`n` values each).
pub(crate) fn columns(points: &Points) -> Vec<Vec<f64>> {
    (0..points.dim()).map(|k| (0..points.len()).map(|i| points.row(i)[k]).collect()).collect()
}

/// `eˣ` for `x ≤ 0` within `4ε` (relative) of the standard library's for `x ≥ −700` (measured:
/// 2.1ε), and a value below 1e−300 below that; branch-free and free of library calls, so that
/// loops over it vectorise.
///
/// Cody–Waite reduction `x = n ln 2 + r`, `|r| ≤ ½ ln 2` (`n` rounded by adding and subtracting
/// `1.5 · 2⁵²`, whose low mantissa bits then hold `n`), the degree-12 Taylor polynomial of `eʳ`
/// (truncation error below 2e−17 relative there) by Horner's rule, and `2ⁿ` by writing the
/// exponent bits.
#[inline(always)]
pub(crate) fn exp_nonpositive(x: f64) -> f64 {
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

/// The additive term between the rows of `columns` (`i`) and those of `query` (`j`), both
/// prepared by [`columns`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Additive<'a> {
    pub(crate) shape: StationaryShape,
    /// `aₖ`.
    pub(crate) variances: &'a [f64],
    pub(crate) columns: &'a [Vec<f64>],
    pub(crate) query: &'a [Vec<f64>],
}

/// `a e^{−r²/2}` over a slice, added to `out` (the squared exponential's kernel entries).
#[inline(always)]
fn add_squared_exponential(out: &mut [f64], col: &[f64], a: f64, q: f64) {
    for (v, p) in out.iter_mut().zip(col) {
        let t = p - q;
        *v += a * exp_nonpositive(-0.5 * t * t);
    }
}

/// [`add_squared_exponential`] that also writes each `e^{−r²/2}` to `cache` (as long as `out`),
/// for [`squared_exponential_sums_cached`] to read instead of computing it again.
#[inline(always)]
fn add_squared_exponential_caching(out: &mut [f64], cache: &mut [f64], col: &[f64], a: f64, q: f64) {
    for ((v, c), p) in out.iter_mut().zip(cache.iter_mut()).zip(col) {
        let t = p - q;
        let e = exp_nonpositive(-0.5 * t * t);
        *c = e;
        *v += a * e;
    }
}

/// [`squared_exponential_sums`] with each `e^{−rᵢ²/2}` read from `cache` (as
/// [`add_squared_exponential_caching`] wrote it): the same sums to the bit.
#[inline(always)]
fn squared_exponential_sums_cached(col: &[f64], w: &[f64], cache: &[f64], a: f64, q: f64) -> (f64, f64) {
    let mut value = [0.0; LANES];
    let mut length = [0.0; LANES];
    let (cc, wc, ec) = (col.chunks_exact(LANES), w.chunks_exact(LANES), cache.chunks_exact(LANES));
    let (c_tail, w_tail, e_tail) = (cc.remainder(), wc.remainder(), ec.remainder());
    for ((p, wi), e) in cc.zip(wc).zip(ec) {
        for l in 0..LANES {
            let t = p[l] - q;
            let r = t * t;
            let v = wi[l] * a * e[l];
            value[l] += v;
            length[l] += v * r;
        }
    }
    for ((p, wi), e) in c_tail.iter().zip(w_tail).zip(e_tail) {
        let t = p - q;
        let r = t * t;
        let v = wi * a * e;
        value[0] += v;
        length[0] += v * r;
    }
    (pairwise(&value), pairwise(&length))
}

/// `(Σᵢ wᵢ a e^{−rᵢ²/2}, Σᵢ wᵢ a e^{−rᵢ²/2} rᵢ²)` in [`LANES`] interleaved partial sums combined
/// in a fixed order (so that the loop vectorises and the result does not depend on the thread).
#[inline(always)]
fn squared_exponential_sums(col: &[f64], w: &[f64], a: f64, q: f64) -> (f64, f64) {
    let mut value = [0.0; LANES];
    let mut length = [0.0; LANES];
    let (cc, wc) = (col.chunks_exact(LANES), w.chunks_exact(LANES));
    let (c_tail, w_tail) = (cc.remainder(), wc.remainder());
    for (p, wi) in cc.zip(wc) {
        for l in 0..LANES {
            let t = p[l] - q;
            let r = t * t;
            let v = wi[l] * a * exp_nonpositive(-0.5 * r);
            value[l] += v;
            length[l] += v * r;
        }
    }
    for (p, wi) in c_tail.iter().zip(w_tail) {
        let t = p - q;
        let r = t * t;
        let v = wi * a * exp_nonpositive(-0.5 * r);
        value[0] += v;
        length[0] += v * r;
    }
    (pairwise(&value), pairwise(&length))
}

/// Partial sums per loop lane: eight, one AVX-512 register of `f64` (two AVX2 registers).
pub(crate) const LANES: usize = 8;

/// `Σ v` of the lanes in a fixed pairwise order.
#[inline(always)]
pub(crate) fn pairwise(v: &[f64; LANES]) -> f64 {
    ((v[0] + v[1]) + (v[2] + v[3])) + ((v[4] + v[5]) + (v[6] + v[7]))
}

/// [`add_squared_exponential`] for `pulp`'s dispatch: `with_simd` is inlined into a function
/// compiled for the detected instruction set, and the loop with it (a closure is not inlined there
/// and stays scalar).
struct AddSquaredExponential<'a> {
    out: &'a mut [f64],
    col: &'a [f64],
    a: f64,
    q: f64,
}

impl pulp::WithSimd for AddSquaredExponential<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        add_squared_exponential(self.out, self.col, self.a, self.q)
    }
}

/// [`squared_exponential_sums`] for `pulp`'s dispatch, as [`AddSquaredExponential`].
struct SquaredExponentialSums<'a> {
    col: &'a [f64],
    w: &'a [f64],
    a: f64,
    q: f64,
}

impl pulp::WithSimd for SquaredExponentialSums<'_> {
    type Output = (f64, f64);
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> (f64, f64) {
        squared_exponential_sums(self.col, self.w, self.a, self.q)
    }
}

/// [`add_squared_exponential_caching`] for `pulp`'s dispatch.
struct AddSquaredExponentialCaching<'a> {
    out: &'a mut [f64],
    cache: &'a mut [f64],
    col: &'a [f64],
    a: f64,
    q: f64,
}

impl pulp::WithSimd for AddSquaredExponentialCaching<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        add_squared_exponential_caching(self.out, self.cache, self.col, self.a, self.q)
    }
}

/// [`squared_exponential_sums_cached`] for `pulp`'s dispatch.
struct SquaredExponentialSumsCached<'a> {
    col: &'a [f64],
    w: &'a [f64],
    cache: &'a [f64],
    a: f64,
    q: f64,
}

impl pulp::WithSimd for SquaredExponentialSumsCached<'_> {
    type Output = (f64, f64);
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> (f64, f64) {
        squared_exponential_sums_cached(self.col, self.w, self.cache, self.a, self.q)
    }
}

impl Additive<'_> {
    /// [`Additive::add_column`] for the squared-exponential shape that also keeps each input's
    /// exponentials: `cache[k · out.len() ..][.. out.len()]` for input `k`.
    pub(crate) fn add_column_caching(&self, out: &mut [f64], cache: &mut [f64], j: usize, from: usize) {
        let len = out.len();
        let rows = from..from + len;
        for (((a, col), qcol), cache) in
            self.variances.iter().zip(self.columns).zip(self.query).zip(cache.chunks_exact_mut(len.max(1)))
        {
            let (a, q, col) = (*a, qcol[j], &col[rows.clone()]);
            ARCH.with(|arch| arch.dispatch(AddSquaredExponentialCaching { out: &mut *out, cache, col, a, q }))
        }
    }

    /// [`Additive::gradient_sums`] for the squared-exponential shape with the exponentials read
    /// from `cache`, laid out as [`Additive::add_column_caching`] wrote them for rows
    /// `from − skip ..` (`skip` leading rows of each input's block are not summed).
    pub(crate) fn gradient_sums_cached(
        &self,
        sums: &mut [f64],
        w: &[f64],
        cache: &[f64],
        skip: usize,
        j: usize,
        from: usize,
    ) {
        let d = self.variances.len();
        let block = w.len() + skip;
        for (k, ((a, col), qcol)) in self.variances.iter().zip(self.columns).zip(self.query).enumerate() {
            let (a, q, col) = (*a, qcol[j], &col[from..from + w.len()]);
            let cache = &cache[k * block + skip..(k + 1) * block];
            let (value, length) = ARCH.with(|arch| arch.dispatch(SquaredExponentialSumsCached { col, w, cache, a, q }));
            sums[k] += value;
            sums[d + k] += length;
        }
    }

    /// `Σₖ aₖ s((cₖ[i] − qₖ[j])²)` added to `out[i − from]` for `i` in `from..from + out.len()`:
    /// part of column `j` of the kernel matrix.
    pub(crate) fn add_column(&self, out: &mut [f64], j: usize, from: usize) {
        let rows = from..from + out.len();
        for ((a, col), qcol) in self.variances.iter().zip(self.columns).zip(self.query) {
            let (a, q, col) = (*a, qcol[j], &col[rows.clone()]);
            match self.shape {
                StationaryShape::SquaredExponential => {
                    ARCH.with(|arch| arch.dispatch(AddSquaredExponential { out: &mut *out, col, a, q }))
                }
                StationaryShape::Matern52 => {
                    for (v, p) in out.iter_mut().zip(col) {
                        *v += self.shape.value(a, (p - q) * (p - q));
                    }
                }
            }
        }
    }

    /// For each input `k`: `Σᵢ wᵢ aₖ s(rᵢₖ²)` and `Σᵢ wᵢ mᵢₖ rᵢₖ²` (the variance's and the length
    /// scale's share of `Σᵢ wᵢ ∂Kᵢⱼ/∂θ`, `m` the shape's length-scale weight) over `i` in
    /// `from..from + w.len()` against column `j`, added to `sums[k]` and `sums[d + k]`.
    pub(crate) fn gradient_sums(&self, sums: &mut [f64], w: &[f64], j: usize, from: usize) {
        let d = self.variances.len();
        for (k, ((a, col), qcol)) in self.variances.iter().zip(self.columns).zip(self.query).enumerate() {
            let (a, q, col) = (*a, qcol[j], &col[from..from + w.len()]);
            let (value, length) = match self.shape {
                StationaryShape::SquaredExponential => {
                    ARCH.with(|arch| arch.dispatch(SquaredExponentialSums { col, w, a, q }))
                }
                StationaryShape::Matern52 => {
                    let (mut value, mut length) = (0.0, 0.0);
                    for (p, wi) in col.iter().zip(w) {
                        let r = (p - q) * (p - q);
                        let (v, m) = self.shape.value_and_weight(a, r);
                        value += wi * v;
                        length += wi * m * r;
                    }
                    (value, length)
                }
            };
            sums[k] += value;
            sums[d + k] += length;
        }
    }
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

    #[test]
    fn the_dispatched_and_the_plain_loops_agree() {
        let col: Vec<f64> = (0..37).map(|i| (i as f64 * 0.37).sin() * 3.0).collect();
        let w: Vec<f64> = (0..37).map(|i| (i as f64 * 0.11).cos()).collect();
        let (a, q) = (0.7, 0.4);
        let exact: f64 = col.iter().zip(&w).map(|(p, wi)| wi * a * (-0.5 * (p - q) * (p - q)).exp()).sum();
        let plain = squared_exponential_sums(&col, &w, a, q);
        let fast = pulp::Arch::new().dispatch(SquaredExponentialSums { col: &col, w: &w, a, q });
        assert!((plain.0 - exact).abs() <= 1e-14, "{} vs {exact}", plain.0);
        assert!((fast.0 - plain.0).abs() <= 1e-14 && (fast.1 - plain.1).abs() <= 1e-14);
        let mut out_plain = vec![1.0; 37];
        add_squared_exponential(&mut out_plain, &col, a, q);
        let mut out_fast = vec![1.0; 37];
        pulp::Arch::new().dispatch(AddSquaredExponential { out: &mut out_fast, col: &col, a, q });
        for ((x, y), p) in out_fast.iter().zip(&out_plain).zip(&col) {
            assert!((x - y).abs() <= 1e-15);
            assert!((y - 1.0 - a * (-0.5 * (p - q) * (p - q)).exp()).abs() <= 1e-15);
        }
    }
}
