//! The inner loops of the squared-exponential stationary term `σf² e^{−r²/2}`, one column of the
//! training matrix's strict lower triangle at a time, with `r² = ‖xᵢ‖² + ‖xⱼ‖² − 2 xᵢᵀxⱼ` from the
//! inner products a matrix product left in the column.
//!
//! As in [`crate::one_input`]: [`exp_nonpositive`] instead of the library's `exp`, and `pulp`'s
//! run-time dispatch so that the loops are compiled for AVX2 + FMA (and AVX-512) and vectorised:
//! with the library's `exp` these two loops were a sixth of a whole GP fit
//! (`docs/results/lml-floor.md` has the profile and the timings). The Matérn shape keeps the scalar
//! path in `gram.rs`.

use crate::exp::{ARCH, LANES, exp_nonpositive, pairwise};

/// `r²`, never negative (round-off can make the expansion slightly negative).
#[inline(always)]
fn squared_distance(sq_i: f64, sq_j: f64, dot: f64) -> f64 {
    (sq_i + sq_j - 2.0 * dot).max(0.0)
}

/// Off-diagonal entries of a training column: `out[i] ← σf² e^{−r²/2} + c`, where `out[i]` holds
/// the inner product `xᵢᵀxⱼ` on entry and `sq[i]` is `‖xᵢ‖²`.
#[inline(always)]
fn fill(out: &mut [f64], sq: &[f64], sq_j: f64, signal: f64, constant: f64) {
    for (v, s) in out.iter_mut().zip(sq) {
        *v = signal * exp_nonpositive(-0.5 * squared_distance(*s, sq_j, *v)) + constant;
    }
}

/// Off-diagonal entries of a gradient column: with `w` the weights `Wᵢⱼ` and `m[i]` the inner
/// product `xᵢᵀxⱼ` on entry, `m[i] ← Wᵢⱼ kᵢⱼ`; returns `(Σ Wᵢⱼ kᵢⱼ, Σ Wᵢⱼ)` in [`LANES`] partial
/// sums combined in a fixed order. Two passes (the kernel values, then the weighted sums): written
/// as one, the loop was not vectorised.
#[inline(always)]
fn weigh(m: &mut [f64], w: &[f64], sq: &[f64], sq_j: f64, signal: f64) -> (f64, f64) {
    fill(m, sq, sq_j, signal, 0.0);
    weigh_in_place(m, w)
}

/// [`fill`] that also writes each `σf² e^{−r²/2}` (without the constant) to `cache`, as
/// [`weigh`] computes it.
#[inline(always)]
fn fill_caching(out: &mut [f64], cache: &mut [f64], sq: &[f64], sq_j: f64, signal: f64, constant: f64) {
    for ((v, c), s) in out.iter_mut().zip(cache.iter_mut()).zip(sq) {
        let e = signal * exp_nonpositive(-0.5 * squared_distance(*s, sq_j, *v)) + 0.0;
        *c = e;
        *v = e + constant;
    }
}

/// [`weigh`] with the kernel values read from `cache` (as [`fill_caching`] wrote them).
#[inline(always)]
fn weigh_cached(m: &mut [f64], w: &[f64], cache: &[f64]) -> (f64, f64) {
    m.copy_from_slice(cache);
    weigh_in_place(m, w)
}

/// `m[i] ← wᵢ m[i]`; returns `(Σ wᵢ m[i], Σ wᵢ)` in [`LANES`] partial sums combined in a fixed
/// order: the second pass of [`weigh`] and [`weigh_cached`].
#[inline(always)]
fn weigh_in_place(m: &mut [f64], w: &[f64]) -> (f64, f64) {
    let mut value = [0.0; LANES];
    let mut weight = [0.0; LANES];
    let (mc, wc) = (m.chunks_exact_mut(LANES), w.chunks_exact(LANES));
    let tail = mc.len() * LANES;
    for (mi, wi) in mc.zip(wc) {
        for l in 0..LANES {
            let v = wi[l] * mi[l];
            mi[l] = v;
            value[l] += v;
            weight[l] += wi[l];
        }
    }
    for (mi, wi) in m[tail..].iter_mut().zip(&w[tail..]) {
        let v = wi * *mi;
        *mi = v;
        value[0] += v;
        weight[0] += wi;
    }
    (pairwise(&value), pairwise(&weight))
}

struct FillCaching<'a> {
    out: &'a mut [f64],
    cache: &'a mut [f64],
    sq: &'a [f64],
    sq_j: f64,
    signal: f64,
    constant: f64,
}

impl pulp::WithSimd for FillCaching<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        fill_caching(self.out, self.cache, self.sq, self.sq_j, self.signal, self.constant)
    }
}

struct WeighCached<'a> {
    m: &'a mut [f64],
    w: &'a [f64],
    cache: &'a [f64],
}

impl pulp::WithSimd for WeighCached<'_> {
    type Output = (f64, f64);
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> (f64, f64) {
        weigh_cached(self.m, self.w, self.cache)
    }
}

/// [`fill_caching`] on the widest instruction set of this processor.
pub fn fill_column_caching(out: &mut [f64], cache: &mut [f64], sq: &[f64], sq_j: f64, signal: f64, constant: f64) {
    ARCH.with(|arch| arch.dispatch(FillCaching { out, cache, sq, sq_j, signal, constant }))
}

/// [`weigh_cached`] on the widest instruction set of this processor.
pub fn weigh_column_cached(m: &mut [f64], w: &[f64], cache: &[f64]) -> (f64, f64) {
    ARCH.with(|arch| arch.dispatch(WeighCached { m, w, cache }))
}

struct Fill<'a> {
    out: &'a mut [f64],
    sq: &'a [f64],
    sq_j: f64,
    signal: f64,
    constant: f64,
}

impl pulp::WithSimd for Fill<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        fill(self.out, self.sq, self.sq_j, self.signal, self.constant)
    }
}

struct Weigh<'a> {
    m: &'a mut [f64],
    w: &'a [f64],
    sq: &'a [f64],
    sq_j: f64,
    signal: f64,
}

impl pulp::WithSimd for Weigh<'_> {
    type Output = (f64, f64);
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> (f64, f64) {
        weigh(self.m, self.w, self.sq, self.sq_j, self.signal)
    }
}

/// [`fill`] on the widest instruction set of this processor.
pub fn fill_column(out: &mut [f64], sq: &[f64], sq_j: f64, signal: f64, constant: f64) {
    ARCH.with(|arch| arch.dispatch(Fill { out, sq, sq_j, signal, constant }))
}

/// [`weigh`] on the widest instruction set of this processor.
pub fn weigh_column(m: &mut [f64], w: &[f64], sq: &[f64], sq_j: f64, signal: f64) -> (f64, f64) {
    ARCH.with(|arch| arch.dispatch(Weigh { m, w, sq, sq_j, signal }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dispatched_loops_agree_with_the_library_exponential() {
        let n = 37;
        let sq: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.3).sin().abs()).collect();
        let dots: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).cos()).collect();
        let w: Vec<f64> = (0..n).map(|i| (i as f64 * 0.11).sin()).collect();
        let (sq_j, signal, constant) = (1.3, 0.8, 0.05);
        let exact = |i: usize| signal * (-0.5 * (sq[i] + sq_j - 2.0 * dots[i]).max(0.0)).exp();
        let mut out = dots.clone();
        fill_column(&mut out, &sq, sq_j, signal, constant);
        for (i, v) in out.iter().enumerate() {
            assert!((v - exact(i) - constant).abs() <= 1e-15, "entry {i}: {v} vs {}", exact(i) + constant);
        }
        let mut m = dots.clone();
        let (value, weight) = weigh_column(&mut m, &w, &sq, sq_j, signal);
        let expected_value: f64 = (0..n).map(|i| w[i] * exact(i)).sum();
        let expected_weight: f64 = w.iter().sum();
        assert!((value - expected_value).abs() <= 1e-14, "{value} vs {expected_value}");
        assert!((weight - expected_weight).abs() <= 1e-14, "{weight} vs {expected_weight}");
        for (i, v) in m.iter().enumerate() {
            assert!((v - w[i] * exact(i)).abs() <= 1e-15, "entry {i}");
        }
    }
}
