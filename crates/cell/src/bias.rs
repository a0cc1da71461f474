//! The expected held-out error of a design when the geometry cannot model everything (issue 26).
//!
//! The I-optimal design ([`crate::design`]) lowers the parameters' variance under white tracker
//! noise. On a real robot most of what a geometric fit leaves is not noise but a smooth function
//! of the joints (compliance, gear errors: on the UR10 of Landgraf et al. 0.44 mm, against
//! 0.02 mm of tracker noise), and a least-squares fit on a few poses bends the geometry towards
//! that function at those poses. A design of extreme, unusual poses then fits their systematic
//! error at the expense of every other pose (Box & Draper, "A basis for the selection of a
//! response surface design", JASA 1959: where bias dominates, a design should look like the
//! region it is used in).
//!
//! Here the unmodelled error is a Gaussian process over the joints, `e ~ GP(0, β κ(q, q') D)`
//! (κ a squared-exponential kernel of the chordal joint distance, `D` the position and rotation
//! rows' variances in units of the noise), and the criterion is the expected mean squared
//! position error over the candidates of the least-squares fit on the design `S`:
//!
//! ```text
//! E(S) = const − 2 tr(M⁻¹ H) + tr(M⁻¹ (B + N) M⁻¹ C)
//! N = Σ_{s∈S} A_sᵀ A_s,  M = ρI + N
//! H = Σ_{s∈S} A_sᵀ P mean_t κ(s, t) A_t        (what the fit takes of the error where it is used)
//! B = Σ_{s,s'∈S} κ(s, s') A_sᵀ D A_s'          (the error the design's poses share)
//! C = mean_t A_tᵀ P A_t                          (the I-criterion's spread)
//! ```
//!
//! `P` keeps the position rows. With `β = 0` this is the I-criterion. The design is improved by
//! exchanges from the I-optimal one, each trial evaluated exactly (`O(r³)`); the same value gives
//! the plan's predicted held-out error with the unmodelled error in it.

use crate::information::{Candidate, CandidateRows};
use nalgebra::DMatrix;
use poe::JointKind;
use rayon::prelude::*;

/// The unmodelled error's model, in the units of the candidates' rows (the noise).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BiasModel {
    /// Variance of the unmodelled position error per axis, in units of the position noise's.
    pub position_ratio: f64,
    /// The same for the rotation rows (full pose).
    pub rotation_ratio: f64,
    /// Correlation length over the joints: chordal distance of the angles, rad; a prismatic
    /// joint's travel counts in metres.
    pub length: f64,
    /// Test points (candidates, evenly strided) the mean over the candidates is taken on.
    pub test_points: usize,
    /// Candidates tried in each position of an exchange (evenly strided over those not chosen).
    pub trials: usize,
    /// Exchange passes.
    pub passes: usize,
}

struct Kernel<'a> {
    candidates: &'a [Candidate],
    kinds: &'a [JointKind],
    inverse_two_l2: f64,
}

impl Kernel<'_> {
    /// `κ(a, b) = exp(−d² / 2ℓ²)`, `d` the chordal distance of revolute joints' angles
    /// (`2 sin(Δ/2)`: a whole turn is no distance) and the plain distance of prismatic ones.
    fn at(&self, a: usize, b: usize) -> f64 {
        let (qa, qb) = (&self.candidates[a].q, &self.candidates[b].q);
        let mut d2 = 0.0;
        for (j, (x, y)) in qa.iter().zip(qb).enumerate() {
            let d = match self.kinds.get(j) {
                Some(JointKind::Prismatic) => x - y,
                _ => 2.0 * (0.5 * (x - y)).sin(),
            };
            d2 += d * d;
        }
        (-d2 * self.inverse_two_l2).exp()
    }
}

fn block(rows: &CandidateRows, c: usize) -> DMatrix<f64> {
    DMatrix::from_row_slice(rows.k, rows.r, rows.rows(c))
}

/// A design's sums `N`, `H`, `B`.
#[derive(Clone)]
struct Sums {
    n: DMatrix<f64>,
    h: DMatrix<f64>,
    b: DMatrix<f64>,
}

/// Correlations below this are taken as none (a pose's sums skip them): `e^{-27.6}`, far below
/// what changes a criterion of order one.
const NEGLIGIBLE: f64 = 1e-12;

/// The expected held-out error of designs over one set of candidates under one [`BiasModel`].
pub struct Unmodelled<'a> {
    rows: &'a CandidateRows,
    kernel: Kernel<'a>,
    model: BiasModel,
    /// `D`'s diagonal.
    d: Vec<f64>,
    /// `β_pos · mean_t κ(c, t) P A_t` per candidate (`k × r`, rotation rows zero).
    w: Vec<DMatrix<f64>>,
    c: DMatrix<f64>,
    ridge: f64,
}

impl<'a> Unmodelled<'a> {
    /// The criterion's fixed parts: the test points' spread and every candidate's correlation
    /// with them (`O(candidates · test_points · k r)`).
    pub fn new(
        rows: &'a CandidateRows,
        candidates: &'a [Candidate],
        kinds: &'a [JointKind],
        ridge: f64,
        model: BiasModel,
    ) -> Self {
        let (k, r) = (rows.k, rows.r);
        let stride = candidates.len().div_ceil(model.test_points.max(1)).max(1);
        let tests: Vec<usize> = (0..candidates.len()).step_by(stride).collect();
        let kernel = Kernel { candidates, kinds, inverse_two_l2: 1.0 / (2.0 * model.length * model.length) };
        let positions = k.min(3);
        let mut c = DMatrix::<f64>::zeros(r, r);
        for &t in &tests {
            let a = block(rows, t).rows(0, positions).into_owned();
            c += a.transpose() * a;
        }
        c /= tests.len() as f64;
        let w: Vec<DMatrix<f64>> = (0..candidates.len())
            .into_par_iter()
            .map(|s| {
                let mut w = DMatrix::<f64>::zeros(k, r);
                for &t in &tests {
                    let kappa = kernel.at(s, t);
                    if kappa < NEGLIGIBLE {
                        continue;
                    }
                    let a = rows.rows(t);
                    for i in 0..positions {
                        for j in 0..r {
                            w[(i, j)] += kappa * a[i * r + j];
                        }
                    }
                }
                w * (model.position_ratio / tests.len() as f64)
            })
            .collect();
        let d = (0..k).map(|i| if i < 3 { model.position_ratio } else { model.rotation_ratio }).collect();
        Self { rows, kernel, model, d, w, c, ridge }
    }

    fn sums(&self, design: &[usize]) -> Sums {
        let r = self.rows.r;
        let mut sums = Sums { n: DMatrix::zeros(r, r), h: DMatrix::zeros(r, r), b: DMatrix::zeros(r, r) };
        for (position, &s) in design.iter().enumerate() {
            self.add(&mut sums, &design[..position], s, 1.0, None);
        }
        sums
    }

    /// Adds (`sign` 1) or removes (−1) `c` to the sums of `others` (`skip`: a position of
    /// `others` that is not in the design).
    fn add(&self, sums: &mut Sums, others: &[usize], c: usize, sign: f64, skip: Option<usize>) {
        let a = block(self.rows, c);
        let at = a.transpose();
        sums.n += sign * (&at * &a);
        sums.h += sign * (&at * &self.w[c]);
        let da = DMatrix::from_fn(self.rows.k, self.rows.r, |i, j| self.d[i] * a[(i, j)]);
        sums.b += sign * (&at * &da);
        let mut v = DMatrix::<f64>::zeros(self.rows.r, self.rows.k);
        for (i, &s) in others.iter().enumerate() {
            if s == c || Some(i) == skip {
                continue;
            }
            let kappa = self.kernel.at(s, c);
            if kappa >= NEGLIGIBLE {
                v += kappa * block(self.rows, s).transpose();
            }
        }
        let cross = &v * &da;
        sums.b += sign * (&cross + cross.transpose());
    }

    /// `−2 tr(M⁻¹ H) + tr(M⁻¹ (B + N) M⁻¹ C)` of the sums; `∞` where `M` is not positive definite.
    fn criterion(&self, sums: &Sums) -> f64 {
        let m = &sums.n + DMatrix::<f64>::identity(self.rows.r, self.rows.r) * self.ridge;
        let Some(cholesky) = nalgebra::Cholesky::new(m) else { return f64::INFINITY };
        let fit = cholesky.solve(&sums.h).trace();
        let x = cholesky.solve(&(&sums.b + &sums.n));
        let y = cholesky.solve(&self.c);
        let mut spread = 0.0;
        for i in 0..x.nrows() {
            for j in 0..x.ncols() {
                spread += x[(i, j)] * y[(j, i)];
            }
        }
        -2.0 * fit + spread
    }

    /// The expected mean squared position error over the test points of a fit on `design`, in
    /// units of the position noise's variance: the tracker noise (3), the unmodelled error
    /// (`3β`) and what the fit on the design adds to or takes from it.
    pub fn expected(&self, design: &[usize]) -> f64 {
        3.0 + 3.0 * self.model.position_ratio + self.criterion(&self.sums(design))
    }

    /// Exchanges in `design` that lower [`Unmodelled::expected`]: each position in turn, the
    /// best of `trials` candidates outside the design put in its place where that lowers it;
    /// up to `passes` passes. Returns the exchanges made.
    pub fn exchange(&self, design: &mut [usize]) -> usize {
        let mut current = self.criterion(&self.sums(design));
        let mut made = 0;
        for _ in 0..self.model.passes {
            let mut changed = false;
            for position in 0..design.len() {
                let old = design[position];
                let mut without = self.sums(design);
                self.add(&mut without, design, old, -1.0, Some(position));
                let outside: Vec<usize> = (0..self.rows.len()).filter(|c| !design.contains(c)).collect();
                let step = outside.len().div_ceil(self.model.trials.max(1)).max(1);
                let trials: Vec<usize> = outside.iter().copied().step_by(step).collect();
                let best = trials
                    .par_iter()
                    .map(|&c| {
                        let mut sums = without.clone();
                        self.add(&mut sums, design, c, 1.0, Some(position));
                        (c, self.criterion(&sums))
                    })
                    .reduce_with(|a, b| if b.1 < a.1 || (b.1 == a.1 && b.0 < a.0) { b } else { a });
                if let Some((c, value)) = best
                    && value < current - EXCHANGE_TOLERANCE * current.abs().max(1.0)
                {
                    design[position] = c;
                    current = value;
                    made += 1;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        made
    }
}

/// Smallest relative drop of the criterion an exchange must bring (rounding of a refactorised
/// `r × r` system is far below it).
const EXCHANGE_TOLERANCE: f64 = 1e-9;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::{Criterion, Design};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A standard normal draw (Box–Muller).
    fn normal(rng: &mut ChaCha8Rng) -> f64 {
        let u: f64 = rng.random_range(f64::EPSILON..1.0);
        let v: f64 = rng.random_range(0.0..1.0);
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    /// `count` candidates on two revolute joints in [−1.5, 1.5] rad and random `k × r` rows.
    fn problem(count: usize, k: usize, r: usize, seed: u64) -> (Vec<Candidate>, CandidateRows) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let candidates = (0..count)
            .map(|_| Candidate {
                q: vec![rng.random_range(-1.5..1.5), rng.random_range(-1.5..1.5)],
                tool: 0,
                payload_kg: 0.0,
            })
            .collect();
        let a = (0..count * k * r).map(|_| normal(&mut rng)).collect();
        (candidates, CandidateRows { k, r, p: r, a })
    }

    fn model(position_ratio: f64, rotation_ratio: f64, length: f64) -> BiasModel {
        BiasModel { position_ratio, rotation_ratio, length, test_points: 10_000, trials: 10_000, passes: 3 }
    }

    #[test]
    fn without_an_unmodelled_error_the_expected_error_is_the_i_criterions() {
        let (candidates, rows) = problem(60, 6, 5, 1);
        let kinds = [JointKind::Revolute; 2];
        let ridge = 1e-9;
        let unmodelled = Unmodelled::new(&rows, &candidates, &kinds, ridge, model(0.0, 0.0, 0.3));
        let mut design = Design::new(&rows, ridge, Criterion::I);
        for c in [3, 7, 11, 19, 23, 31, 40, 52] {
            design.add(c);
        }
        design.refresh();
        let (mean, _) = design.predicted_variance(3);
        let expected = unmodelled.expected(design.chosen());
        assert!((expected - (3.0 + mean)).abs() < 1e-9 * expected, "{expected} against {}", 3.0 + mean);
    }

    /// The expected error is what a least-squares fit on the design leaves, averaged over draws of
    /// the unmodelled error (a Gaussian process with the model's kernel) and the noise. Compared
    /// is what the fit adds to the error the test poses carry anyway (the draws' common part
    /// cancels), so that each of the criterion's terms shows; a test pose is measured anew (its
    /// noise is not the design's).
    #[test]
    fn the_expected_error_is_the_mean_of_simulated_fits() {
        let (k, r) = (6, 8);
        let (candidates, rows) = problem(40, k, r, 2);
        let kinds = [JointKind::Revolute; 2];
        let length = 1.0;
        let bias = model(9.0, 4.0, length);
        let unmodelled = Unmodelled::new(&rows, &candidates, &kinds, 0.0, bias);
        let design = [0, 3, 5, 8, 13, 21, 22, 30, 34, 39];
        let sums = unmodelled.sums(&design);
        let excess = unmodelled.criterion(&sums);
        // Covariance of every candidate's k bias rows: κ(c, c') D.
        let n = candidates.len();
        let kernel = Kernel { candidates: &candidates, kinds: &kinds, inverse_two_l2: 1.0 / (2.0 * length * length) };
        let d = [9.0, 9.0, 9.0, 4.0, 4.0, 4.0];
        let covariance = DMatrix::from_fn(n * k, n * k, |i, j| {
            if i % k == j % k { kernel.at(i / k, j / k) * d[i % k] + if i == j { 1e-10 } else { 0.0 } } else { 0.0 }
        });
        let factor = nalgebra::Cholesky::new(covariance).expect("a kernel matrix is positive definite").l();
        let mut m = DMatrix::<f64>::zeros(r, r);
        for &s in &design {
            let a = block(&rows, s);
            m += a.transpose() * a;
        }
        let m_inverse = m.try_inverse().expect("ten poses determine eight directions");
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let draws = 20_000;
        let mut total = 0.0;
        for _ in 0..draws {
            let z = nalgebra::DVector::from_fn(n * k, |_, _| normal(&mut rng));
            let bias = &factor * z;
            let measured: Vec<nalgebra::DVector<f64>> =
                (0..n).map(|c| nalgebra::DVector::from_fn(k, |i, _| bias[c * k + i] + normal(&mut rng))).collect();
            let mut rhs = nalgebra::DVector::<f64>::zeros(r);
            for &s in &design {
                rhs += block(&rows, s).transpose() * &measured[s];
            }
            let theta = &m_inverse * rhs;
            // A held-out measurement of a pose carries its unmodelled error and noise of its own.
            let mut added = 0.0;
            for t in 0..n {
                let y = nalgebra::DVector::from_fn(k, |i, _| bias[t * k + i] + normal(&mut rng));
                let error = &y - block(&rows, t) * &theta;
                added += (0..3).map(|i| error[i] * error[i] - y[i] * y[i]).sum::<f64>();
            }
            total += added / n as f64;
        }
        let simulated = total / draws as f64;
        let fit = -2.0 * nalgebra::Cholesky::new(sums.n.clone()).unwrap().solve(&sums.h).trace();
        assert!(
            (simulated - excess).abs() < 0.05 * fit.abs(),
            "simulated {simulated:.4}, expected {excess:.4}, of which the fit's take of the unmodelled error {fit:.4}"
        );
    }

    #[test]
    fn exchanges_lower_the_expected_error_and_leave_a_local_optimum() {
        let (candidates, rows) = problem(80, 3, 5, 4);
        let kinds = [JointKind::Revolute; 2];
        let converged = BiasModel { passes: 100, ..model(16.0, 16.0, 0.3) };
        let unmodelled = Unmodelled::new(&rows, &candidates, &kinds, 1e-9, converged);
        let mut design: Vec<usize> = (0..12).collect();
        let before = unmodelled.expected(&design);
        let made = unmodelled.exchange(&mut design);
        let after = unmodelled.expected(&design);
        assert!(made > 0 && after < before, "{made} exchanges: {before} → {after}");
        let mut sorted = design.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), design.len(), "a pose chosen twice");
        // No single exchange lowers it further (the passes ran out before changes did not).
        for position in 0..design.len() {
            for c in (0..candidates.len()).filter(|c| !design.contains(c)) {
                let mut other = design.clone();
                other[position] = c;
                assert!(unmodelled.expected(&other) >= after - 1e-9 * after.abs(), "{position} ← {c}");
            }
        }
    }
}
