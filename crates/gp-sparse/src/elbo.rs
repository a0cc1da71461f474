//! Titsias' collapsed variational bound (VFE, Titsias 2009, Eq. 9) for `m` inducing inputs and its
//! analytic gradient in the kernel's log-parameters, in `O(n m²)` flops and `O(m² + chunk·m)`
//! memory: the training rows are visited in chunks, twice (the bound, then the gradient), and no
//! `m × n` matrix is ever stored.
//!
//! For `p` outputs sharing the kernel, with `L Lᵀ = K_uu`, `A = L⁻¹ K_uf / σ`, `B = I + A Aᵀ`,
//! `a = A Y / σ`, `w = B⁻¹ a`:
//! `F = −(np/2) ln 2πσ² − (p/2) ln|B| − ½ (‖Y‖²/σ² − tr(aᵀ w)) − p (tr K_ff − σ² ‖A‖²) / (2σ²)`.
//!
//! Gradient (derived from the Woodbury form with `Σ = K_uu + K_uf K_fu / σ²`; the finite-difference
//! tests check it): `dF = tr(M_uu dK_uu) + Σ M_uf ∘ dK_uf − (p / 2σ²) Σ dk_ii`, with
//! `M_uu = L⁻ᵀ [(p/2)(I − B⁻¹ − A Aᵀ) − ½ w wᵀ] L⁻¹`,
//! `M_uf = (L⁻ᵀ [p (I − B⁻¹) − w wᵀ] L⁻¹ K_uf + L⁻ᵀ w Yᵀ) / σ²`, and for the noise
//! `σ² ∂F/∂σ² = −np/2 + (p/2)(m − tr B⁻¹) + ‖Y‖²/(2σ²) − tr(aᵀ w) + ½ tr(wᵀ A Aᵀ w)
//! + (p/2)(tr K_ff / σ² − ‖A‖²)`.

use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::{Accum, Mat, MatRef};

use dense::product;
use gp::blocks::{
    Evaluator, Expanded, Factor, Points, Prepared, check_finite_outputs, contract_cross, cross_covariance,
    prior_variances, training_covariance,
};
use gp::{Error, JitterConfig, JitterOutcome, Kernel, LogMarginalLikelihood, Parallelism};

/// Rows per chunk: a `m × 2048` block is 8 MB at `m = 500`, small beside `K_uu`'s factors yet
/// wide enough for faer's products to run at full speed.
pub(crate) const CHUNK_ROWS: usize = 2048;

/// The pieces of the posterior that prediction needs, and the bound.
#[derive(Debug, Clone)]
pub(crate) struct Posterior {
    pub(crate) evaluator: Evaluator,
    /// Inducing inputs prepared for `evaluator`.
    pub(crate) inducing: Prepared,
    pub(crate) l_uu: Factor,
    pub(crate) jitter: JitterOutcome,
    pub(crate) l_b: Factor,
    /// `w = B⁻¹ A Y / σ`, `m × p`: the mean at `x*` is `(L⁻¹ K_u*)ᵀ w`.
    pub(crate) w: Mat<f64>,
    /// The bound `F`.
    pub(crate) bound: f64,
}

/// What pass 1 leaves for the gradient.
struct Sums {
    /// `A Aᵀ` in full.
    aat: Mat<f64>,
    /// `A Y / σ`.
    ay: Mat<f64>,
    trace_k: f64,
    yy: f64,
}

fn chunks(n: usize) -> impl Iterator<Item = std::ops::Range<usize>> {
    (0..n).step_by(CHUNK_ROWS).map(move |s| s..(s + CHUNK_ROWS).min(n))
}

fn rows_of<'a>(y: MatRef<'a, f64>, r: &std::ops::Range<usize>) -> MatRef<'a, f64> {
    y.subrows(r.start, r.len())
}

/// Pass 1: `A Aᵀ`, `A Y / σ`, `tr K_ff`, `‖Y‖²`, chunk by chunk in row order (the sums are the same
/// serial or parallel: each chunk's products are faer's, added in a fixed order).
fn pass_one(
    evaluator: &Evaluator,
    zp: &Prepared,
    xp: &Prepared,
    y: MatRef<'_, f64>,
    l_uu: &Factor,
    sigma: f64,
    parallelism: Parallelism,
) -> Sums {
    let par = parallelism.faer();
    let (m, p) = (zp.len(), y.ncols());
    let mut aat = Mat::zeros(m, m);
    let mut ay = Mat::zeros(m, p);
    let mut trace_k = 0.0;
    let mut yy = 0.0;
    for r in chunks(xp.len()) {
        let xc = xp.rows(r.clone());
        let mut a = cross_covariance(evaluator, zp, &xc, parallelism);
        l_uu.solve_lower_in_place(a.as_mut(), par);
        let yc = rows_of(y, &r);
        triangular::matmul(
            aat.as_mut(),
            BlockStructure::TriangularLower,
            Accum::Add,
            a.as_ref(),
            BlockStructure::Rectangular,
            a.transpose(),
            BlockStructure::Rectangular,
            1.0 / (sigma * sigma),
            par,
        );
        // Narrow outputs (m × p, long inner dimension) serially: a parallel split of the inner
        // dimension would change the order of the sums (results must not depend on threads).
        matmul(ay.as_mut(), Accum::Add, a.as_ref(), yc, 1.0 / (sigma * sigma), faer::Par::Seq);
        trace_k += prior_variances(evaluator, &xc).iter().sum::<f64>();
        yy += (0..yc.ncols()).map(|j| yc.col(j).iter().map(|v| v * v).sum::<f64>()).sum::<f64>();
    }
    for j in 0..m {
        for i in 0..j {
            aat[(i, j)] = aat[(j, i)];
        }
    }
    Sums { aat, ay, trace_k, yy }
}

/// The bound and the posterior for `kernel` with inducing inputs `z` (jitter on `K_uu` escalated as
/// `jitter` says, or exactly `fixed_jitter`), and, when `with_gradient`, `∂F/∂ ln θ` in the
/// kernel's log-parameter order.
pub(crate) fn evidence_lower_bound(
    kernel: &Kernel,
    x: &Points,
    y: MatRef<'_, f64>,
    z: &Points,
    jitter: (&JitterConfig, Option<f64>),
    with_gradient: bool,
    parallelism: Parallelism,
) -> Result<(Posterior, Vec<f64>), Error> {
    let par = parallelism.faer();
    let (evaluator, xp) = kernel.prepare(x);
    let (_, zp) = kernel.prepare(z);
    let (n, m, p) = (x.len(), z.len(), y.ncols());
    let kuu = training_covariance(&evaluator, &zp, 0.0, parallelism);
    let (l_uu, jitter) = match jitter {
        (config, None) => Factor::with_jitter(&kuu, config, par)?,
        (_, Some(j)) => (Factor::with_fixed_jitter(&kuu, j, par)?, JitterOutcome { added: j, failed_attempts: 0 }),
    };
    let s = kernel.noise_variance();
    let sigma = s.sqrt();
    let Sums { aat, ay, trace_k, yy } = pass_one(&evaluator, &zp, &xp, y, &l_uu, sigma, parallelism);
    let mut b = aat.clone();
    for i in 0..m {
        b[(i, i)] += 1.0;
    }
    // B ⪰ I: only non-finite input can make this fail.
    let (l_b, _) = Factor::with_jitter(&b, &JitterConfig::default(), par)?;
    let mut c = ay.clone();
    l_b.solve_lower_in_place(c.as_mut(), par);
    let mut w = ay.clone();
    l_b.solve_in_place(w.as_mut(), par);
    let cc: f64 = (0..p).map(|k| c.col(k).iter().map(|v| v * v).sum::<f64>()).sum();
    let trace_aat: f64 = (0..m).map(|i| aat[(i, i)]).sum();
    let (nf, pf, mf) = (n as f64, p as f64, m as f64);
    let bound = -0.5 * nf * pf * (2.0 * std::f64::consts::PI * s).ln()
        - 0.5 * pf * l_b.log_determinant()
        - 0.5 * (yy / s - cc)
        - pf * (trace_k - s * trace_aat) / (2.0 * s);
    let posterior = Posterior { evaluator, inducing: zp, l_uu, jitter, l_b, w, bound };
    if !with_gradient {
        return Ok((posterior, Vec::new()));
    }
    let Posterior { evaluator, inducing: zp, l_uu, l_b, w, .. } = &posterior;
    // B⁻¹, then E = p (I − B⁻¹) − w wᵀ and C = (p/2)(I − B⁻¹ − A Aᵀ) − ½ w wᵀ.
    let mut b_inv = Mat::<f64>::identity(m, m);
    l_b.solve_in_place(b_inv.as_mut(), par);
    let mut wwt = Mat::zeros(m, m);
    product(wwt.as_mut(), Accum::Replace, w.as_ref(), w.transpose(), 1.0, par);
    let identity = |i: usize, j: usize| if i == j { 1.0 } else { 0.0 };
    let mut e = Mat::from_fn(m, m, |i, j| pf * (identity(i, j) - b_inv[(i, j)]) - wwt[(i, j)]);
    let mut cz =
        Mat::from_fn(m, m, |i, j| 0.5 * pf * (identity(i, j) - b_inv[(i, j)] - aat[(i, j)]) - 0.5 * wwt[(i, j)]);
    // F = L⁻ᵀ E L⁻¹ and M_uu = L⁻ᵀ C L⁻¹: solve from the left, transpose, solve again.
    let sandwich = |mat: &mut Mat<f64>| {
        l_uu.solve_upper_transposed_in_place(mat.as_mut(), par);
        *mat = mat.transpose().to_owned();
        l_uu.solve_upper_transposed_in_place(mat.as_mut(), par);
    };
    sandwich(&mut e);
    sandwich(&mut cz);
    let mut u = w.clone();
    l_uu.solve_upper_transposed_in_place(u.as_mut(), par);
    let layout = Expanded { dim: x.dim() };
    let mut g = contract_cross(evaluator, zp, zp, cz.as_ref(), true, parallelism);
    for r in chunks(n) {
        let xc = xp.rows(r.clone());
        let kc = cross_covariance(evaluator, zp, &xc, parallelism);
        let mut mc = Mat::zeros(m, r.len());
        product(mc.as_mut(), Accum::Replace, e.as_ref(), kc.as_ref(), 1.0 / s, par);
        product(mc.as_mut(), Accum::Add, u.as_ref(), rows_of(y, &r).transpose(), 1.0 / s, par);
        let gc = contract_cross(evaluator, zp, &xc, mc.as_ref(), false, parallelism);
        for (a, b) in g.iter_mut().zip(&gc) {
            *a += b;
        }
        // −(p / 2σ²) Σ ∂k_ii: k_ii = σf² + σc² + Σ_d l_id² + Σ_d a_d.
        let scale = -pf / (2.0 * s);
        g[Expanded::SIGNAL] += scale * evaluator.signal_variance * r.len() as f64;
        g[layout.constant()] += scale * evaluator.constant * r.len() as f64;
        for (k, a) in evaluator.additive_variances.iter().enumerate() {
            g[layout.additive_variance(k)] += scale * a * r.len() as f64;
        }
        if let Some(l) = &xc.linear {
            for i in 0..l.len() {
                for (d, v) in l.row(i).iter().enumerate() {
                    g[layout.linear(d)] += scale * v * v;
                }
            }
        }
    }
    let tr_b_inv: f64 = (0..m).map(|i| b_inv[(i, i)]).sum();
    let aw: f64 = (0..p).map(|k| (0..m).map(|i| ay[(i, k)] * w[(i, k)]).sum::<f64>()).sum();
    let mut aat_w = Mat::zeros(m, p);
    product(aat_w.as_mut(), Accum::Replace, aat.as_ref(), w.as_ref(), 1.0, par);
    let waaw: f64 = (0..p).map(|k| (0..m).map(|i| w[(i, k)] * aat_w[(i, k)]).sum::<f64>()).sum();
    g[layout.noise()] = -0.5 * nf * pf + 0.5 * pf * (mf - tr_b_inv) + 0.5 * yy / s - aw
        + 0.5 * waaw
        + 0.5 * pf * (trace_k / s - trace_aat);
    let gradient = kernel.fold_gradient(&g, x.dim());
    Ok((posterior, gradient))
}

/// Titsias' collapsed bound on the log marginal likelihood of `y` (n × p, one GP per column, all
/// with `kernel`) at inputs `x` (n × d) with inducing inputs `inducing` (m × d), used as given: no
/// standardisation, no jitter; and, if asked for, its gradient in the kernel's log-parameters
/// (inducing inputs held fixed).
pub fn sparse_evidence_lower_bound(
    kernel: &Kernel,
    x: MatRef<'_, f64>,
    y: MatRef<'_, f64>,
    inducing: MatRef<'_, f64>,
    with_gradient: bool,
    parallelism: Parallelism,
) -> Result<LogMarginalLikelihood, Error> {
    if x.nrows() != y.nrows() {
        return Err(Error::RowCountMismatch { input_rows: x.nrows(), output_rows: y.nrows() });
    }
    if inducing.ncols() != x.ncols() {
        return Err(Error::InputDimensionMismatch { expected: x.ncols(), found: inducing.ncols() });
    }
    kernel.validate(x.ncols())?;
    let points = Points::from_rows(x)?;
    let z = Points::from_rows(inducing)?;
    check_finite_outputs(y)?;
    let no_jitter = JitterConfig { max_attempts: 0, ..JitterConfig::default() };
    let (posterior, gradient) =
        evidence_lower_bound(kernel, &points, y, &z, (&no_jitter, None), with_gradient, parallelism)?;
    Ok(LogMarginalLikelihood { value: posterior.bound, gradient })
}
