//! A D-optimal design over candidate poses (Fedorov, *Theory of Optimal Experiments*, 1972):
//! the information `M = ρI + Σ_{i ∈ design} A_iᵀ A_i` and, for every candidate `c`, its predicted
//! variance `G_c = A_c M⁻¹ A_cᵀ` (`k × k`), kept up to date by rank-k (Woodbury) updates, so that
//! adding or removing a pose costs `O(candidates · k² r)` and not a refactorisation per
//! candidate. Adding `c` raises `log det M` by `log det(I + G_c)`, removing it lowers it by
//! `−log det(I − G_c)` (the matrix determinant lemma).

use crate::information::CandidateRows;
use rayon::prelude::*;

/// In-place Cholesky of a small SPD `k × k` matrix (lower triangle); its log-determinant, or
/// `None` where it is not positive definite.
fn cholesky(m: &mut [f64], k: usize) -> Option<f64> {
    let mut log_det = 0.0;
    for j in 0..k {
        let mut d = m[j * k + j];
        for l in 0..j {
            d -= m[j * k + l] * m[j * k + l];
        }
        if d <= 0.0 || !d.is_finite() {
            return None;
        }
        let d = d.sqrt();
        m[j * k + j] = d;
        log_det += 2.0 * d.ln();
        for i in j + 1..k {
            let mut v = m[i * k + j];
            for l in 0..j {
                v -= m[i * k + l] * m[j * k + l];
            }
            m[i * k + j] = v / d;
        }
    }
    Some(log_det)
}

/// `log det(I + sign · G)` of a `k × k` block, `-∞` where not positive definite.
fn log_det_shifted(g: &[f64], k: usize, sign: f64) -> f64 {
    let mut m = [0.0; 36];
    for i in 0..k {
        for j in 0..k {
            m[i * k + j] = sign * g[i * k + j] + if i == j { 1.0 } else { 0.0 };
        }
    }
    cholesky(&mut m[..k * k], k).unwrap_or(f64::NEG_INFINITY)
}

/// What a design maximises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Criterion {
    /// `log det M`: the volume of the parameters' confidence ellipsoid (D-optimality).
    D,
    /// The mean over the candidates of the predicted position variance `tr(P A_c M⁻¹ A_cᵀ P)`
    /// (`P` the position rows: the error a user measures), lowered
    /// (I-optimality, Atkinson, Donev & Tobias §10.6): the error the parameters leave where the
    /// robot will be used, weighted as the candidates are spread. Where the model misses effects
    /// (always, on a real robot) it keeps away from poses unlike the rest, whose systematic error
    /// a D-optimal design fits at the expense of the others (Box & Draper, 1959).
    #[default]
    I,
}

/// `tr((I + sign · G)⁻¹ F)` of `k × k` blocks, `∞` where `I + sign · G` is not positive definite.
fn trace_solve(g: &[f64], f: &[f64], k: usize, sign: f64) -> f64 {
    let mut m = [0.0; 36];
    for i in 0..k {
        for j in 0..k {
            m[i * k + j] = sign * g[i * k + j] + if i == j { 1.0 } else { 0.0 };
        }
    }
    if cholesky(&mut m[..k * k], k).is_none() {
        return f64::INFINITY;
    }
    // tr(L⁻ᵀ L⁻¹ F) = Σ_j ‖L⁻¹ f_j‖²-like terms: solve L X = F, then tr(L⁻ᵀ X) = Σ (L⁻¹)ᵀ… done
    // column by column: x = L⁻¹ f_j, y = L⁻ᵀ x, add y_j.
    let mut total = 0.0;
    for j in 0..k {
        let mut x = [0.0; 6];
        for i in 0..k {
            let mut v = f[i * k + j];
            for l in 0..i {
                v -= m[i * k + l] * x[l];
            }
            x[i] = v / m[i * k + i];
        }
        let mut y = [0.0; 6];
        for i in (0..k).rev() {
            let mut v = x[i];
            for l in i + 1..k {
                v -= m[l * k + i] * y[l];
            }
            y[i] = v / m[i * k + i];
        }
        total += y[j];
    }
    total
}

/// The design and every candidate's predicted variance.
#[derive(Debug, Clone)]
pub struct Design<'a> {
    rows: &'a CandidateRows,
    prior: f64,
    criterion: Criterion,
    /// `C = mean_c A_cᵀ P A_c` (position rows), `r × r` (I-optimality only).
    spread: Vec<f64>,
    /// `F_c = A_c M⁻¹ C M⁻¹ A_cᵀ`, `candidates × k × k` (I-optimality only): what `c`'s
    /// information would take off the mean variance, before the shrinkage by `(I + G_c)⁻¹`.
    reach: Vec<f64>,
    /// `M⁻¹`, `r × r`.
    inverse: Vec<f64>,
    /// `G_c`, `candidates × k × k`.
    variance: Vec<f64>,
    chosen: Vec<usize>,
    in_design: Vec<bool>,
    log_det: f64,
    /// Updates since the last [`Design::refresh`].
    updates: usize,
}

/// Updates after which the state is recomputed: each rank-k update of `M⁻¹` subtracts terms as
/// large as `M⁻¹` itself, and while the ridge dominates (`M⁻¹ ~ 1/ρ`, the predicted variances
/// 1e6–1e12 times their final size) that cancels most digits, so every update is followed by a
/// recomputation until the poses determine every direction twice over; after that the values
/// stay of one order and 50 updates lose less than a digit.
const REFRESH_EVERY: usize = 50;

/// Candidates whose `A_c W` one matrix product gives in an update: enough rows (256 × k) for the
/// matrix kernel's blocking, few enough for rayon to share 10,000 candidates among the cores.
const UPDATE_BLOCK: usize = 256;

impl<'a> Design<'a> {
    /// An empty design with the ridge `prior · I`.
    pub fn new(rows: &'a CandidateRows, prior: f64, criterion: Criterion) -> Self {
        let (k, r) = (rows.k, rows.r);
        let spread = match criterion {
            Criterion::D => Vec::new(),
            Criterion::I => {
                let mut c = vec![0.0; r * r];
                for i in 0..rows.len() {
                    let a = rows.rows(i);
                    for x in 0..r {
                        for y in 0..r {
                            c[x * r + y] += (0..k.min(3)).map(|m| a[m * r + x] * a[m * r + y]).sum::<f64>();
                        }
                    }
                }
                let n = rows.len().max(1) as f64;
                c.iter_mut().for_each(|v| *v /= n);
                c
            }
        };
        let mut design = Self {
            rows,
            prior,
            criterion,
            spread,
            reach: Vec::new(),
            inverse: Vec::new(),
            variance: Vec::new(),
            chosen: Vec::new(),
            in_design: vec![false; rows.len()],
            log_det: 0.0,
            updates: 0,
        };
        design.refresh();
        design
    }

    /// The design of `chosen` (kept in that order), computed once rather than by one update per
    /// pose (the same state, to rounding).
    pub fn of(rows: &'a CandidateRows, prior: f64, criterion: Criterion, chosen: &[usize]) -> Self {
        let mut design = Self::new(rows, prior, criterion);
        for &c in chosen {
            design.in_design[c] = true;
        }
        design.chosen = chosen.to_vec();
        design.refresh();
        design
    }

    /// The chosen candidates, in the order they were chosen (exchanges keep the position).
    pub fn chosen(&self) -> &[usize] {
        &self.chosen
    }

    /// Whether `c` is in the design.
    #[cfg(test)]
    pub fn contains(&self, c: usize) -> bool {
        self.in_design[c]
    }

    /// `log det M`.
    pub fn log_det(&self) -> f64 {
        self.log_det
    }

    /// `G_c`.
    pub fn variance(&self, c: usize) -> &[f64] {
        let kk = self.rows.k * self.rows.k;
        &self.variance[c * kk..(c + 1) * kk]
    }

    /// What adding `c` adds to the criterion: `log det(I + G_c)` (D), or what it takes off the
    /// mean variance, `tr((I + G_c)⁻¹ F_c)` (I).
    pub fn gain(&self, c: usize) -> f64 {
        match self.criterion {
            Criterion::D => log_det_shifted(self.variance(c), self.rows.k, 1.0),
            Criterion::I => trace_solve(self.variance(c), self.reach(c), self.rows.k, 1.0),
        }
    }

    /// What removing `c` (in the design) takes from the criterion: `−log det(I − G_c)` (D), or
    /// what it adds to the mean variance, `tr((I − G_c)⁻¹ F_c)` (I).
    pub fn loss(&self, c: usize) -> f64 {
        match self.criterion {
            Criterion::D => -log_det_shifted(self.variance(c), self.rows.k, -1.0),
            Criterion::I => trace_solve(self.variance(c), self.reach(c), self.rows.k, -1.0),
        }
    }

    fn reach(&self, c: usize) -> &[f64] {
        let kk = self.rows.k * self.rows.k;
        &self.reach[c * kk..(c + 1) * kk]
    }

    /// The mean over the candidates of the predicted position variance (the trace of `G_c`'s first three rows).
    #[cfg(test)]
    pub fn mean_variance(&self) -> f64 {
        let k = self.rows.k;
        (0..self.rows.len()).map(|c| (0..k.min(3)).map(|i| self.variance(c)[i * k + i]).sum::<f64>()).sum::<f64>()
            / self.rows.len().max(1) as f64
    }

    /// The candidate outside the design with the largest gain among those `allowed` (lowest
    /// index on ties).
    pub fn best(&self, allowed: impl Fn(usize) -> bool + Sync) -> Option<(usize, f64)> {
        (0..self.rows.len())
            .into_par_iter()
            .filter(|&c| !self.in_design[c] && allowed(c))
            .map(|c| (c, self.gain(c)))
            .reduce_with(|a, b| if b.1 > a.1 || (b.1 == a.1 && b.0 < a.0) { b } else { a })
    }

    /// Adds `c` at the end of the design.
    pub fn add(&mut self, c: usize) {
        self.update(c, 1.0);
        self.chosen.push(c);
        self.in_design[c] = true;
        self.keep_accurate();
    }

    /// Recomputes the state where the updates since the last recomputation may have cost digits.
    fn keep_accurate(&mut self) {
        let determined = 2 * self.rows.r.div_ceil(self.rows.k);
        if self.chosen.len() <= determined || self.updates >= REFRESH_EVERY {
            self.refresh();
        }
    }

    /// Replaces the pose at `position` of the design by `c`.
    pub fn replace(&mut self, position: usize, c: usize) {
        let old = self.chosen[position];
        self.update(old, -1.0);
        self.in_design[old] = false;
        self.update(c, 1.0);
        self.in_design[c] = true;
        self.chosen[position] = c;
        self.keep_accurate();
    }

    /// Removes the pose at `position` (for an exchange; [`Design::put_back`] restores it).
    fn take_out(&mut self, position: usize) -> usize {
        let old = self.chosen[position];
        self.update(old, -1.0);
        self.in_design[old] = false;
        old
    }

    fn put_back(&mut self, position: usize, c: usize) {
        self.update(c, 1.0);
        self.in_design[c] = true;
        self.chosen[position] = c;
        self.keep_accurate();
    }

    /// Greedy additions up to `n` poses; `checkpoint(n, design)` after each.
    pub fn greedy(&mut self, n: usize, mut checkpoint: impl FnMut(&Self)) {
        while self.chosen.len() < n.min(self.rows.len()) {
            let Some((c, _)) = self.best(|_| true) else { break };
            self.add(c);
            checkpoint(self);
        }
    }

    /// Fedorov exchanges: each pose in turn is taken out and the best candidate put in its
    /// place where that gains more than `tolerance` times what the pose itself gains; up to `passes` passes, fewer
    /// where one changes nothing. Returns the exchanges made.
    pub fn exchange(&mut self, passes: usize, tolerance: f64) -> usize {
        let mut made = 0;
        for _ in 0..passes {
            let mut changed = false;
            for position in 0..self.chosen.len() {
                let old = self.take_out(position);
                let kept = self.gain(old);
                match self.best(|_| true) {
                    Some((c, gain)) if c != old && gain - kept > tolerance * kept.abs().max(1e-300) => {
                        self.put_back(position, c);
                        made += 1;
                        changed = true;
                    }
                    _ => self.put_back(position, old),
                }
            }
            if !changed {
                break;
            }
        }
        self.refresh();
        made
    }

    /// Adds (`sign` = 1) or removes (−1) candidate `s`: `M⁻¹ ← M⁻¹ ∓ W Wᵀ`, `G_c ← G_c ∓ (A_c W)(A_c W)ᵀ`
    /// with `W = M⁻¹ A_sᵀ L⁻ᵀ`, `L Lᵀ = I ± G_s`.
    fn update(&mut self, s: usize, sign: f64) {
        self.updates += 1;
        let k = self.rows.k;
        let u = self.inverse_times_rows(s);
        let mut l = self.capacitance(s, sign);
        let Some(log_det) = cholesky(&mut l[..k * k], k) else {
            // Only a removal of a pose that alone determines a direction gets here, which the
            // ridge forbids; recompute rather than corrupt the state.
            self.refresh_with(s, sign);
            return;
        };
        self.log_det += log_det;
        let w = self.solve_factor(&u, &l);
        self.downdate_inverse(&w, sign);
        let (z, t) =
            if self.criterion == Criterion::I { self.reach_factors(&w, sign) } else { (Vec::new(), [0.0; 36]) };
        self.update_candidates(&w, &z, &t, sign);
    }

    /// `U = M⁻¹ A_sᵀ`, r × k.
    fn inverse_times_rows(&self, s: usize) -> Vec<f64> {
        let (k, r) = (self.rows.k, self.rows.r);
        let a_s = self.rows.rows(s);
        let mut u = vec![0.0; r * k];
        for i in 0..r {
            for j in 0..k {
                u[i * k + j] = (0..r).map(|l| self.inverse[i * r + l] * a_s[j * r + l]).sum();
            }
        }
        u
    }

    /// `I ± G_s`, k × k, the matrix whose Cholesky factor is `L`.
    fn capacitance(&self, s: usize, sign: f64) -> [f64; 36] {
        let k = self.rows.k;
        let mut l = [0.0; 36];
        let g_s = self.variance(s).to_vec();
        for i in 0..k {
            for j in 0..k {
                l[i * k + j] = sign * g_s[i * k + j] + if i == j { 1.0 } else { 0.0 };
            }
        }
        l
    }

    /// `W = U L⁻ᵀ`: each row w of W solved from `L wᵀ = uᵀ`.
    fn solve_factor(&self, u: &[f64], l: &[f64; 36]) -> Vec<f64> {
        let (k, r) = (self.rows.k, self.rows.r);
        let mut w = vec![0.0; r * k];
        for i in 0..r {
            for j in 0..k {
                let mut v = u[i * k + j];
                for m in 0..j {
                    v -= l[j * k + m] * w[i * k + m];
                }
                w[i * k + j] = v / l[j * k + j];
            }
        }
        w
    }

    /// `M⁻¹ ← M⁻¹ ∓ W Wᵀ`.
    fn downdate_inverse(&mut self, w: &[f64], sign: f64) {
        let (k, r) = (self.rows.k, self.rows.r);
        for i in 0..r {
            for j in 0..r {
                let ww: f64 = (0..k).map(|m| w[i * k + m] * w[j * k + m]).sum();
                self.inverse[i * r + j] -= sign * ww;
            }
        }
    }

    /// I-optimality: with Y = C W, Z = M⁻¹ Y (the old M⁻¹) and T = Wᵀ Y,
    /// Q' = Q − σ(W Zᵀ + Z Wᵀ) + W T Wᵀ, so F_c' = F_c − σ(H Eᵀ + E Hᵀ) + H T Hᵀ, E = A_c Z.
    /// Returns `(Z, T)`; called after [`Self::downdate_inverse`].
    fn reach_factors(&self, w: &[f64], sign: f64) -> (Vec<f64>, [f64; 36]) {
        let (k, r) = (self.rows.k, self.rows.r);
        let mut y = vec![0.0; r * k];
        for i in 0..r {
            for j in 0..k {
                y[i * k + j] = (0..r).map(|m| self.spread[i * r + m] * w[m * k + j]).sum();
            }
        }
        let mut z = vec![0.0; r * k];
        for i in 0..r {
            for j in 0..k {
                // M⁻¹ before this update: the new one plus σ W Wᵀ.
                z[i * k + j] = (0..r)
                    .map(|m| {
                        let ww: f64 = (0..k).map(|n| w[i * k + n] * w[m * k + n]).sum();
                        (self.inverse[i * r + m] + sign * ww) * y[m * k + j]
                    })
                    .sum();
            }
        }
        let mut t = [0.0; 36];
        for i in 0..k {
            for j in 0..k {
                t[i * k + j] = (0..r).map(|m| w[m * k + i] * y[m * k + j]).sum();
            }
        }
        (z, t)
    }

    /// Every candidate's `G_c` (and, for I-optimality, `F_c`) updated with `H = A_c W` and
    /// `E = A_c Z`, a block of candidates at a time.
    fn update_candidates(&mut self, w: &[f64], z: &[f64], t: &[f64; 36], sign: f64) {
        let (k, r) = (self.rows.k, self.rows.r);
        let rows = self.rows;
        let with_reach = self.criterion == Criterion::I;
        // [W | Z]ᵀ (k or 2k rows × r): one product with a block of candidates' rows gives every
        // candidate's `A_c W` and `A_c Z` in a matrix kernel, not k² dot products each.
        let width = if with_reach { 2 * k } else { k };
        let factors = nalgebra::DMatrix::from_fn(width, r, |j, l| if j < k { w[l * k + j] } else { z[l * k + j - k] });
        let kk = k * k;
        let update_block = |block: usize, g: &mut [f64], mut f: Option<&mut [f64]>| {
            let count = g.len() / kk;
            let first = block * UPDATE_BLOCK;
            // The block's rows, row-major `count·k × r`: column-major `r × count·k`.
            let a = nalgebra::DMatrixView::from_slice(&rows.a[first * k * r..(first + count) * k * r], r, count * k);
            let products = &factors * a;
            for c in 0..count {
                let (mut h, mut e) = ([0.0; 36], [0.0; 36]);
                for i in 0..k {
                    for j in 0..k {
                        h[i * k + j] = products[(j, c * k + i)];
                        if with_reach {
                            e[i * k + j] = products[(k + j, c * k + i)];
                        }
                    }
                }
                let reach = f.as_deref_mut().map(|f| &mut f[c * kk..(c + 1) * kk]);
                update_candidate(&mut g[c * kk..(c + 1) * kk], reach, (&h, &e, t), k, sign);
            }
        };
        if with_reach {
            self.variance
                .par_chunks_mut(UPDATE_BLOCK * kk)
                .zip(self.reach.par_chunks_mut(UPDATE_BLOCK * kk))
                .enumerate()
                .for_each(|(block, (g, f))| update_block(block, g, Some(f)));
        } else {
            self.variance
                .par_chunks_mut(UPDATE_BLOCK * kk)
                .enumerate()
                .for_each(|(block, g)| update_block(block, g, None));
        }
    }

    fn refresh_with(&mut self, s: usize, sign: f64) {
        self.in_design[s] = sign > 0.0;
        self.refresh();
    }

    /// Recomputes `M⁻¹`, `log det M` and every `G_c` from the design (rounding gathered by the
    /// updates is dropped).
    pub fn refresh(&mut self) {
        self.updates = 0;
        let (k, r) = (self.rows.k, self.rows.r);
        let mut m = nalgebra::DMatrix::<f64>::identity(r, r) * self.prior;
        for (c, _) in self.in_design.iter().enumerate().filter(|(_, d)| **d) {
            let a = nalgebra::DMatrix::from_row_slice(k, r, self.rows.rows(c));
            m += a.transpose() * a;
        }
        let cholesky = nalgebra::Cholesky::new(m).expect("a ridge plus a sum of squares is positive definite");
        self.log_det = cholesky.l().diagonal().iter().map(|d| 2.0 * d.ln()).sum();
        let inverse = cholesky.inverse();
        self.inverse = (0..r * r).map(|i| inverse[(i / r, i % r)]).collect();
        let rows = self.rows;
        let mut variance = vec![0.0; rows.len() * k * k];
        variance.par_chunks_mut(k * k).enumerate().for_each(|(c, g)| {
            let a = nalgebra::DMatrix::from_row_slice(k, r, rows.rows(c));
            let v = &a * &inverse * a.transpose();
            for i in 0..k {
                for j in 0..k {
                    g[i * k + j] = v[(i, j)];
                }
            }
        });
        self.variance = variance;
        if self.criterion == Criterion::I {
            let spread = nalgebra::DMatrix::from_row_slice(r, r, &self.spread);
            let q = &inverse * spread * &inverse;
            let mut reach = vec![0.0; rows.len() * k * k];
            reach.par_chunks_mut(k * k).enumerate().for_each(|(c, f)| {
                let a = nalgebra::DMatrix::from_row_slice(k, r, rows.rows(c));
                let v = &a * &q * a.transpose();
                for i in 0..k {
                    for j in 0..k {
                        f[i * k + j] = v[(i, j)];
                    }
                }
            });
            self.reach = reach;
        }
    }

    /// The mean over all candidates of the trace of `G_c`'s first `rows` rows (the position rows),
    /// and its largest value.
    pub fn predicted_variance(&self, rows: usize) -> (f64, f64) {
        let k = self.rows.k;
        let traces: Vec<f64> =
            (0..self.rows.len()).map(|c| (0..rows).map(|i| self.variance(c)[i * k + i]).sum()).collect();
        let mean = traces.iter().sum::<f64>() / traces.len().max(1) as f64;
        (mean, traces.iter().copied().fold(0.0, f64::max))
    }

    /// The same for the rotation rows (3..6) where there are some.
    pub fn predicted_rotation_variance(&self) -> Option<(f64, f64)> {
        let k = self.rows.k;
        (k == 6).then(|| {
            let traces: Vec<f64> =
                (0..self.rows.len()).map(|c| (3..6).map(|i| self.variance(c)[i * k + i]).sum()).collect();
            (traces.iter().sum::<f64>() / traces.len().max(1) as f64, traces.iter().copied().fold(0.0, f64::max))
        })
    }
}

/// One candidate's `G_c ← G_c ∓ H Hᵀ` and, where `f` is given, `F_c ← F_c ∓ (H Eᵀ + E Hᵀ) + H T Hᵀ`.
fn update_candidate(
    g: &mut [f64],
    f: Option<&mut [f64]>,
    (h, e, t): (&[f64; 36], &[f64; 36], &[f64; 36]),
    k: usize,
    sign: f64,
) {
    for i in 0..k {
        for j in 0..k {
            let hh: f64 = (0..k).map(|m| h[i * k + m] * h[j * k + m]).sum();
            g[i * k + j] -= sign * hh;
        }
    }
    if let Some(f) = f {
        let mut ht = [0.0; 36];
        for i in 0..k {
            for j in 0..k {
                ht[i * k + j] = (0..k).map(|m| h[i * k + m] * t[m * k + j]).sum();
            }
        }
        for i in 0..k {
            for j in 0..k {
                let cross: f64 = (0..k).map(|m| h[i * k + m] * e[j * k + m] + e[i * k + m] * h[j * k + m]).sum();
                let quad: f64 = (0..k).map(|m| ht[i * k + m] * h[j * k + m]).sum();
                f[i * k + j] += -sign * cross + quad;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_rows(candidates: usize, k: usize, r: usize, seed: u64) -> CandidateRows {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        CandidateRows { k, r, p: r, a: (0..candidates * k * r).map(|_| rng.random_range(-1.0..1.0)).collect() }
    }

    #[test]
    fn updates_match_a_recomputation() {
        for criterion in [Criterion::D, Criterion::I] {
            updates_match_a_recomputation_for(criterion);
        }
    }

    fn updates_match_a_recomputation_for(criterion: Criterion) {
        // More candidates than one block of the update (UPDATE_BLOCK), poses in three of them;
        // more poses than `keep_accurate` recomputes after each (2⌈r/k⌉ = 6), so that the last
        // additions and the replacement are updates.
        let rows = random_rows(600, 3, 7, 1);
        let mut design = Design::new(&rows, 1e-3, criterion);
        let poses = [3, 9, 317, 4, 530, 41, 260, 599, 100, 12];
        for c in poses {
            design.add(c);
        }
        assert!(design.updates > 0, "the last additions were not updates");
        design.replace(1, 22);
        let (log_det, variance, reach) = (design.log_det(), design.variance.clone(), design.reach.clone());
        let mut replaced = poses;
        replaced[1] = 22;
        let at_once = Design::of(&rows, 1e-3, criterion, &replaced);
        assert_eq!(at_once.chosen(), design.chosen());
        design.refresh();
        assert_eq!(at_once.log_det().to_bits(), design.log_det().to_bits());
        assert!((log_det - design.log_det()).abs() < 1e-8 * log_det.abs().max(1.0));
        for (a, b) in variance.iter().zip(&design.variance).chain(reach.iter().zip(&design.reach)) {
            assert!((a - b).abs() < 1e-8 * b.abs().max(1.0), "{criterion:?}: {a} {b}");
        }
    }

    #[test]
    fn a_gain_is_the_change_of_log_det() {
        let rows = random_rows(20, 6, 5, 2);
        let mut design = Design::new(&rows, 1e-2, Criterion::D);
        design.add(0);
        let before = design.log_det();
        let gain = design.gain(7);
        design.add(7);
        design.refresh();
        assert!((design.log_det() - before - gain).abs() < 1e-10);
        let loss = design.loss(7);
        assert!((loss - gain).abs() < 1e-10);
    }

    #[test]
    fn exchanges_lower_the_mean_variance() {
        let rows = random_rows(300, 6, 12, 6);
        let mut design = Design::new(&rows, 1e-6, Criterion::I);
        design.greedy(20, |_| {});
        design.refresh();
        let greedy = design.mean_variance();
        let made = design.exchange(3, 1e-9);
        let exchanged = design.mean_variance();
        assert!(exchanged <= greedy, "{made} exchanges: {greedy} -> {exchanged}");
    }

    #[test]
    fn an_i_gain_is_the_drop_of_the_mean_variance() {
        let rows = random_rows(30, 6, 5, 5);
        let mut design = Design::new(&rows, 1e-2, Criterion::I);
        design.add(3);
        let before = design.mean_variance();
        let gain = design.gain(11);
        design.add(11);
        design.refresh();
        assert!((before - design.mean_variance() - gain).abs() < 1e-9 * before, "{before} {gain}");
        let loss = design.loss(11);
        assert!((loss - gain).abs() < 1e-9 * gain);
    }

    #[test]
    fn greedy_and_exchange_beat_random_designs_on_log_det() {
        let rows = random_rows(300, 3, 12, 3);
        let mut design = Design::new(&rows, 1e-6, Criterion::D);
        design.greedy(10, |_| {});
        design.exchange(3, 1e-9);
        let planned = design.log_det();
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..20 {
            let mut random = Design::new(&rows, 1e-6, Criterion::D);
            while random.chosen().len() < 10 {
                let c = rng.random_range(0..rows.len());
                if !random.contains(c) {
                    random.add(c);
                }
            }
            assert!(planned > random.log_det(), "{planned} vs {}", random.log_det());
        }
    }
}
