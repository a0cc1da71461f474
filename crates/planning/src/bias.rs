//! The expected held-out error of a design when the geometry cannot model everything.
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
//! exchanges from the I-optimal one, each trial a rank-2k update ([`crate::bias_trial`],
//! `O(r² k)`), the one taken evaluated afresh (`O(r³)`); the same value gives the plan's
//! predicted held-out error with the unmodelled error in it.

use crate::bias_trial::Position;
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

/// `κ(a, b) = exp(−d² / 2ℓ²)`, `d` the chordal distance of revolute joints' angles
/// (`2 sin(Δ/2)`, the distance of the points `(cos q, sin q)`: a whole turn is no distance) and
/// the plain distance of prismatic ones. Each candidate is mapped to those points once, so that a
/// pair costs no trigonometry.
struct Kernel {
    /// Per candidate: `(cos q, sin q)` of a revolute joint, `q` of a prismatic one.
    points: Vec<Vec<f64>>,
    inverse_two_l2: f64,
}

impl Kernel {
    fn new(candidates: &[Candidate], kinds: &[JointKind], length: f64) -> Self {
        let points = candidates
            .iter()
            .map(|c| {
                let mut p = Vec::with_capacity(2 * c.q.len());
                for (j, &q) in c.q.iter().enumerate() {
                    match kinds.get(j) {
                        Some(JointKind::Prismatic) => p.push(q),
                        _ => p.extend([q.cos(), q.sin()]),
                    }
                }
                p
            })
            .collect();
        Self { points, inverse_two_l2: 1.0 / (2.0 * length * length) }
    }

    /// `κ(a, b)`; 0 where it is below [`NEGLIGIBLE`] (no exponential taken).
    fn at(&self, a: usize, b: usize) -> f64 {
        let d2: f64 = self.points[a].iter().zip(&self.points[b]).map(|(x, y)| (x - y) * (x - y)).sum();
        let exponent = d2 * self.inverse_two_l2;
        if exponent > -NEGLIGIBLE.ln() { 0.0 } else { (-exponent).exp() }
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
    kernel: Kernel,
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
        let kernel = Kernel::new(candidates, kinds, model.length);
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

    /// `V = Σ κ(s, c) A_sᵀ` over the poses `s` of `others` (`r × k`), leaving out `c` itself
    /// and the position `skip` of `others` (a pose not in the design).
    fn correlation(&self, others: &[usize], c: usize, skip: Option<usize>) -> DMatrix<f64> {
        let (k, r) = (self.rows.k, self.rows.r);
        let mut v = DMatrix::<f64>::zeros(r, k);
        for (i, &s) in others.iter().enumerate() {
            if s == c || Some(i) == skip {
                continue;
            }
            let kappa = self.kernel.at(s, c);
            if kappa >= NEGLIGIBLE {
                let a = self.rows.rows(s);
                for row in 0..k {
                    for column in 0..r {
                        v[(column, row)] += kappa * a[row * r + column];
                    }
                }
            }
        }
        v
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
        let cross = self.correlation(others, c, skip) * &da;
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
    ///
    /// A trial is a rank-k update of the sums without the pose taken out ([`Position`]); the
    /// best trial is evaluated afresh before it is taken, so that rounding in the update can
    /// only choose among near-equal candidates, never accept a change that does not lower the
    /// criterion.
    pub fn exchange(&self, design: &mut [usize]) -> usize {
        let mut made = 0;
        let mut in_design = vec![false; self.rows.len()];
        design.iter().for_each(|&s| in_design[s] = true);
        let outside = self.rows.len() - design.len();
        let step = outside.div_ceil(self.model.trials.max(1)).max(1);
        for _ in 0..self.model.passes {
            // The sums afresh each pass: the exchanges' additions and removals gather rounding.
            let mut sums = self.sums(design);
            let mut current = self.criterion(&sums);
            let mut changed = false;
            for position in 0..design.len() {
                let old = design[position];
                let mut without = sums.clone();
                self.add(&mut without, design, old, -1.0, Some(position));
                let trials: Vec<usize> = (0..self.rows.len()).filter(|&c| !in_design[c]).step_by(step).collect();
                let shared = Position::new(
                    &sums.n,
                    &without.n,
                    &without.h,
                    &without.b,
                    &block(self.rows, old),
                    &self.c,
                    self.ridge,
                );
                let best = trials
                    .par_iter()
                    .map(|&c| {
                        let value = match &shared {
                            Some(shared) => shared.trial(
                                &block(self.rows, c),
                                &self.w[c],
                                &self.correlation(design, c, Some(position)),
                                &self.d,
                            ),
                            None => self.criterion(&self.with(&without, design, c, position)),
                        };
                        (c, value)
                    })
                    .reduce_with(|a, b| if b.1 < a.1 || (b.1 == a.1 && b.0 < a.0) { b } else { a });
                let Some((c, _)) = best else { continue };
                let candidate = self.with(&without, design, c, position);
                let value = self.criterion(&candidate);
                if value < current - EXCHANGE_TOLERANCE * current.abs().max(1.0) {
                    design[position] = c;
                    in_design[old] = false;
                    in_design[c] = true;
                    sums = candidate;
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

    /// The sums `without` the pose at `position` of `design`, with `c` put there.
    fn with(&self, without: &Sums, design: &[usize], c: usize, position: usize) -> Sums {
        let mut sums = without.clone();
        self.add(&mut sums, design, c, 1.0, Some(position));
        sums
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
        let kernel = Kernel::new(&candidates, &kinds, length);
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
    fn the_kernel_is_of_the_chordal_distance_and_of_a_prismatic_joints_travel() {
        let candidates: Vec<Candidate> = [[0.3, -2.9, 0.05], [-2.8, 3.1, 0.3], [0.31, -2.9, 0.05]]
            .iter()
            .map(|q| Candidate { q: q.to_vec(), tool: 0, payload_kg: 0.0 })
            .collect();
        let kinds = [JointKind::Revolute, JointKind::Revolute, JointKind::Prismatic];
        let length = 1.3;
        let kernel = Kernel::new(&candidates, &kinds, length);
        for (a, b) in [(0, 1), (0, 2), (1, 2), (1, 1)] {
            let (qa, qb) = (&candidates[a].q, &candidates[b].q);
            let d2 = (2.0 * (0.5 * (qa[0] - qb[0])).sin()).powi(2)
                + (2.0 * (0.5 * (qa[1] - qb[1])).sin()).powi(2)
                + (qa[2] - qb[2]).powi(2);
            let expected = (-d2 / (2.0 * length * length)).exp();
            assert!((kernel.at(a, b) - expected).abs() < 1e-14, "{a} {b}: {} against {expected}", kernel.at(a, b));
        }
        // Far apart on a short length: below NEGLIGIBLE, taken as none.
        assert_eq!(Kernel::new(&candidates, &kinds, 0.1).at(0, 1), 0.0);
    }

    /// The rank-k update of a trial ([`Position::trial`]) against the criterion of the design
    /// with the candidate put in, evaluated afresh, on random designs: small ones (the pose
    /// taken out leaves directions to the ridge) and larger ones, position and full-pose rows.
    #[test]
    fn a_trials_update_equals_a_fresh_evaluation() {
        for (k, r, size, seed) in [(3, 5, 3, 10), (3, 8, 4, 11), (6, 9, 12, 12), (6, 7, 2, 13), (3, 6, 20, 14)] {
            let (candidates, rows) = problem(50, k, r, seed);
            let kinds = [JointKind::Revolute; 2];
            let unmodelled = Unmodelled::new(&rows, &candidates, &kinds, 1e-6, model(9.0, 4.0, 0.7));
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let mut design: Vec<usize> = Vec::new();
            while design.len() < size {
                let c = rng.random_range(0..candidates.len());
                if !design.contains(&c) {
                    design.push(c);
                }
            }
            let sums = unmodelled.sums(&design);
            for position in 0..design.len() {
                let mut without = sums.clone();
                unmodelled.add(&mut without, &design, design[position], -1.0, Some(position));
                let shared = Position::new(
                    &sums.n,
                    &without.n,
                    &without.h,
                    &without.b,
                    &block(&rows, design[position]),
                    &unmodelled.c,
                    unmodelled.ridge,
                )
                .expect("a ridge makes M positive definite");
                for c in (0..candidates.len()).filter(|c| !design.contains(c)) {
                    let updated = shared.trial(
                        &block(&rows, c),
                        &unmodelled.w[c],
                        &unmodelled.correlation(&design, c, Some(position)),
                        &unmodelled.d,
                    );
                    let mut other = design.clone();
                    other[position] = c;
                    let fresh = unmodelled.criterion(&unmodelled.sums(&other));
                    assert!(
                        (updated - fresh).abs() < 1e-8 * fresh.abs().max(1.0),
                        "k {k}, r {r}, {size} poses, position {position} ← {c}: updated {updated}, afresh {fresh}"
                    );
                }
            }
        }
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
