//! The squared exponential of one input at a time, `a e^{−(p − q)²/2}` for a column of points `p`
//! against one query `q` (the first-order additive kernel term, inputs already divided by their
//! length scales).
//!
//! With `d` inputs the additive term costs `d` exponentials per kernel entry. Profiled on the UR10
//! fit (n = 1,387, d = 6) with the standard library's `exp`, 58 % of the whole `calib fit` was
//! spent in `exp` and 14 % more in these loops. They therefore use [`exp_nonpositive`], and run
//! through `pulp`'s run-time dispatch, which compiles them again for AVX2 + FMA (and AVX-512) and
//! picks the widest the processor has, so that the compiler vectorises them.

use crate::exp::{ARCH, LANES, exp_nonpositive, pairwise};

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

/// `out[i] += a e^{−(col[i] − q)²/2}` on the widest instruction set of this processor.
pub fn add_column(out: &mut [f64], col: &[f64], a: f64, q: f64) {
    ARCH.with(|arch| arch.dispatch(AddSquaredExponential { out, col, a, q }))
}

/// [`add_column`] that also writes each `e^{−(col[i] − q)²/2}` to `cache` (as long as `out`).
pub fn add_column_caching(out: &mut [f64], cache: &mut [f64], col: &[f64], a: f64, q: f64) {
    ARCH.with(|arch| arch.dispatch(AddSquaredExponentialCaching { out, cache, col, a, q }))
}

/// `(Σᵢ wᵢ a e^{−rᵢ²/2}, Σᵢ wᵢ a e^{−rᵢ²/2} rᵢ²)`, `rᵢ = col[i] − q`, on the widest instruction set.
pub fn sums(col: &[f64], w: &[f64], a: f64, q: f64) -> (f64, f64) {
    ARCH.with(|arch| arch.dispatch(SquaredExponentialSums { col, w, a, q }))
}

/// [`sums`] with the exponentials read from `cache` as [`add_column_caching`] wrote them: the same
/// sums to the bit.
pub fn sums_cached(col: &[f64], w: &[f64], cache: &[f64], a: f64, q: f64) -> (f64, f64) {
    ARCH.with(|arch| arch.dispatch(SquaredExponentialSumsCached { col, w, cache, a, q }))
}

#[cfg(test)]
mod tests {
    use super::*;

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
