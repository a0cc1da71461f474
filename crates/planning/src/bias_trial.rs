//! One exchange trial of [`crate::bias::Unmodelled`] as an update, not a refactorisation.
//!
//! An exchange at one position of the design takes one pose `o` out and puts a candidate `c` in.
//! Without `o`, the sums `N₋, H₋, B₋` are shared by every candidate tried there; `c` adds its
//! `k` rows `a_c`, its `w_c` and its correlation with the rest of the design,
//! `V = Σ_{s∈S₋} κ(s, c) A_sᵀ` (`r × k`):
//!
//! ```text
//! M_c = M + Aᵀ Σ A,  A = [a_c; a_o],  Σ = diag(I, −I)      (M = ρI + N₋ + a_oᵀ a_o, the design's)
//! H_c = H₋ + a_cᵀ w_c,   B_c + N_c = G + Q,   G = B₋ + N₋,   Q = a_cᵀ(D + I)a_c + V D a_c + a_cᵀ D Vᵀ
//! ```
//!
//! Woodbury with `K = M⁻¹`, `U = K Aᵀ = [U_c, U_o]` and `T = Σ + A U` (`2k × 2k`, indefinite):
//! `M_c⁻¹ = K − U T⁻¹ Uᵀ` and `a_c M_c⁻¹ = (T⁻¹)_{c·} Uᵀ` (the first `k` rows of `T⁻¹`), so
//! that, with `Y = C K G`,
//!
//! ```text
//! tr(M_c⁻¹ H_c)          = tr(K H₋) − tr(T⁻¹ Uᵀ H₋ U) + tr(w_c U (T⁻¹)_{·c})
//! tr(M_c⁻¹ G M_c⁻¹ C)    = tr(K G K C) − 2 tr(T⁻¹ Uᵀ Y U) + tr(T⁻¹ Uᵀ C U T⁻¹ Uᵀ G U)
//! tr(a_cᵀ(D+I)a_c R)     = tr((D + I) (T⁻¹ Uᵀ C U T⁻¹)_{cc})          (R = M_c⁻¹ C M_c⁻¹)
//! 2 tr(V D a_c R)        = 2 tr(D (T⁻¹)_{c·} [Uᵀ C K V − Uᵀ C U T⁻¹ Uᵀ V])
//! ```
//!
//! `K` is the inverse of the design's own information, not of the information without `o`:
//! where `o` alone determines a direction, `(M − a_oᵀ a_o)⁻¹` is the ridge's `1/ρ` there, and
//! the terms with two such inverses (`tr(K G K C)`) would cancel ten or more digits.
//! Everything of `o` is computed once per position; a trial costs six `r × r` by `r × k`
//! products, a few `k × r` by `r × k` ones and `O(|S| k r)` for `V`, against the Cholesky factor
//! and three `r × r` solves (`O(r³)`) of a refactorisation.

use nalgebra::DMatrix;

/// What every trial at one position shares.
pub(crate) struct Position {
    /// `K = M⁻¹`, the design's (with the pose taken out still in).
    inverse: DMatrix<f64>,
    /// `[H₋; C K G; G; C]`, `4r × r`: one product with `U_c` gives the four `X U_c`.
    stacked: DMatrix<f64>,
    /// `U_o = K a_oᵀ`, `r × k`.
    u_o: DMatrix<f64>,
    /// `X U_o`, `4r × k`, and `U_oᵀ X` (`k × 4r`, one `k × r` block per `X`).
    x_u_o: DMatrix<f64>,
    u_o_x: DMatrix<f64>,
    /// `a_o U_o − I`, the lower right block of `T`.
    t_oo: DMatrix<f64>,
    /// `tr(K H₋)`.
    fit: f64,
    /// `tr(K G K C)`.
    spread: f64,
}

/// `tr(x y)` of two matrices whose product is square, without forming it.
fn trace_of_product(x: &DMatrix<f64>, y: &DMatrix<f64>) -> f64 {
    let mut total = 0.0;
    for i in 0..x.nrows() {
        for j in 0..x.ncols() {
            total += x[(i, j)] * y[(j, i)];
        }
    }
    total
}

/// The `2k × 2k` matrix of four `k × k` blocks.
fn blocks(cc: &DMatrix<f64>, co: &DMatrix<f64>, oc: &DMatrix<f64>, oo: &DMatrix<f64>) -> DMatrix<f64> {
    let k = cc.nrows();
    let mut m = DMatrix::<f64>::zeros(2 * k, 2 * k);
    m.view_mut((0, 0), (k, k)).copy_from(cc);
    m.view_mut((0, k), (k, k)).copy_from(co);
    m.view_mut((k, 0), (k, k)).copy_from(oc);
    m.view_mut((k, k), (k, k)).copy_from(oo);
    m
}

impl Position {
    /// The shared parts: the design's `n` (`N`, with the pose `o` taken out still in), the sums
    /// without `o` (`n_without`, `h`, `b`: `N₋`, `H₋`, `B₋`), `o`'s rows `a_o` (`k × r`), the test
    /// points' spread `c` and the ridge; `None` where `ρI + N` is not positive definite (the
    /// caller then evaluates every trial afresh).
    pub(crate) fn new(
        n: &DMatrix<f64>,
        n_without: &DMatrix<f64>,
        h: &DMatrix<f64>,
        b: &DMatrix<f64>,
        a_o: &DMatrix<f64>,
        c: &DMatrix<f64>,
        ridge: f64,
    ) -> Option<Self> {
        let (k, r) = (a_o.nrows(), n.nrows());
        let m = n + DMatrix::<f64>::identity(r, r) * ridge;
        let inverse = nalgebra::Cholesky::new(m)?.inverse();
        let g = b + n_without;
        let kg = &inverse * &g;
        let kc = &inverse * c;
        let y = c * &kg;
        let mut stacked = DMatrix::<f64>::zeros(4 * r, r);
        stacked.rows_mut(0, r).copy_from(h);
        stacked.rows_mut(r, r).copy_from(&y);
        stacked.rows_mut(2 * r, r).copy_from(&g);
        stacked.rows_mut(3 * r, r).copy_from(c);
        let u_o = &inverse * a_o.transpose();
        let x_u_o = &stacked * &u_o;
        let u_o_t = u_o.transpose();
        let mut u_o_x = DMatrix::<f64>::zeros(k, 4 * r);
        for x in 0..4 {
            u_o_x.columns_mut(x * r, r).copy_from(&(&u_o_t * stacked.rows(x * r, r)));
        }
        let t_oo = a_o * &u_o - DMatrix::<f64>::identity(k, k);
        let fit = trace_of_product(&inverse, h);
        let spread = trace_of_product(&kg, &kc);
        Some(Self { inverse, stacked, u_o, x_u_o, u_o_x, t_oo, fit, spread })
    }

    /// The criterion `−2 tr(M⁻¹ H) + tr(M⁻¹ (B + N) M⁻¹ C)` with candidate `c` put in place of
    /// `o`: its rows `a` (`k × r`), its `w` (`k × r`), its correlation with the rest of the
    /// design `v` (`r × k`) and `D`'s diagonal `d`; `∞` where `T` is singular (the exchange
    /// leaves a direction undetermined).
    pub(crate) fn trial(&self, a: &DMatrix<f64>, w: &DMatrix<f64>, v: &DMatrix<f64>, d: &[f64]) -> f64 {
        let (k, r) = (a.nrows(), a.ncols());
        let mut right = DMatrix::<f64>::zeros(r, 2 * k);
        right.columns_mut(0, k).copy_from(&a.transpose());
        right.columns_mut(k, k).copy_from(v);
        let solved = &self.inverse * right;
        let u_c = solved.columns(0, k).into_owned();
        let kv = solved.columns(k, k).into_owned();
        let u_c_t = u_c.transpose();
        let a_u_o = a * &self.u_o;
        let t = blocks(&(DMatrix::<f64>::identity(k, k) + a * &u_c), &a_u_o, &a_u_o.transpose(), &self.t_oo);
        let Some(t_inverse) = t.lu().try_inverse() else { return f64::INFINITY };
        let x_u_c = &self.stacked * &u_c;
        // Uᵀ X U for X = H₋, Y, G, C, from the blocks of c and o.
        let quadratic = |x: usize| {
            let x_c = x_u_c.rows(x * r, r);
            blocks(
                &(&u_c_t * x_c),
                &(&u_c_t * self.x_u_o.rows(x * r, r)),
                &(self.u_o_x.columns(x * r, r) * &u_c),
                &(self.u_o_x.columns(x * r, r) * &self.u_o),
            )
        };
        let (uhu, uyu, ugu, ucu) = (quadratic(0), quadratic(1), quadratic(2), quadratic(3));
        let mut w_u = DMatrix::<f64>::zeros(k, 2 * k);
        w_u.columns_mut(0, k).copy_from(&(w * &u_c));
        w_u.columns_mut(k, k).copy_from(&(w * &self.u_o));
        let t_c = t_inverse.columns(0, k).into_owned();
        let fit = self.fit - trace_of_product(&t_inverse, &uhu) + trace_of_product(&w_u, &t_c);
        let scaled = &t_inverse * &ucu;
        let spread_g =
            self.spread - 2.0 * trace_of_product(&t_inverse, &uyu) + trace_of_product(&scaled, &(&t_inverse * &ugu));
        let own = &scaled * &t_inverse;
        // Uᵀ C K V and Uᵀ V, 2k × k.
        let mut u_c_k_v = DMatrix::<f64>::zeros(2 * k, k);
        u_c_k_v.rows_mut(0, k).copy_from(&(x_u_c.rows(3 * r, r).transpose() * &kv));
        u_c_k_v.rows_mut(k, k).copy_from(&(self.x_u_o.rows(3 * r, r).transpose() * &kv));
        let mut u_v = DMatrix::<f64>::zeros(2 * k, k);
        u_v.rows_mut(0, k).copy_from(&(&u_c_t * v));
        u_v.rows_mut(k, k).copy_from(&(self.u_o.transpose() * v));
        let inner = u_c_k_v - &ucu * (&t_inverse * u_v);
        let cross = t_inverse.rows(0, k) * inner;
        let mut added = 0.0;
        for i in 0..k {
            added += (d[i] + 1.0) * own[(i, i)] + 2.0 * d[i] * cross[(i, i)];
        }
        -2.0 * fit + spread_g + added
    }
}
