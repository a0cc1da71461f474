//! The instrument's own uncertainty of each observation: a laser tracker states a
//! standard deviation for every point it measures. An observation's residual is more than its
//! measurement noise: the model's own error (what the geometry cannot explain, the GP's share)
//! scatters every row alike. Each residual component is therefore weighted by
//! `1/√(τ² + σ²)`, with `σ` the row's stated σ of that component and `τ` the scatter beyond the
//! stated noise, estimated from the residuals of the fit itself (the reweighted solves of
//! `solver.rs`), relative to the median observation's, on top of the options' sigmas: where the
//! tracker's noise dominates (`τ ≈ 0`) a point measured worse counts less; where the model's error
//! dominates (`τ ≫ σ`, the real UR10: σ ≈ 0.01 mm beside residuals of tenths of a millimetre) the
//! weights are nearly equal, as they should be. The data's overall weight against a prior stays
//! what `position_sigma_m` and `rotation_sigma_rad` make it. An observation stated far above the
//! rest is reported and kept at a weight floor, never weighted to nothing; one far below is held
//! at the same ratio, so that no few rows outweigh the rest.

use super::robust::RowError;
use super::{Observation, Target};
use serde::{Deserialize, Serialize};

/// An observation's stated standard deviations, in the reference frame: of the point along x, y,
/// z (m) and of the orientation about x, y, z (rad), each where stated. A present value is
/// finite and positive (the measurement reader refuses any other).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StatedSigma {
    /// Of the tool point, m.
    pub position_m: Option<[f64; 3]>,
    /// Of the orientation, rad.
    pub rotation_rad: Option<[f64; 3]>,
}

/// How stated uncertainties weight the observations. Validated with the identification's options.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StatedNoise {
    /// Weight observations by their stated σ where they state one.
    pub weight: bool,
    /// An observation stated more than this many times the median (the root mean square of its
    /// three axes against the median observation's) is reported by
    /// [`StatedNoiseReport::far_above`]; no component is weighted more than this many times below
    /// or above the median observation's (its weight stays within `1/ratio²` … `ratio²` of a
    /// median observation's). 10: a tracker's stated σ varies with distance and incidence over a
    /// campaign (UR10 series C: 5th to 95th percentile of its stated σ_x 0.0035 to 0.029 mm,
    /// a factor 3 either side of the median, ENGINEERING ESTIMATE of a campaign's spread); ten
    /// times the median is a reflector lost or half occluded, which a user should look at rather
    /// than have it vanish from the fit.
    pub far_above_median: f64,
}

impl Default for StatedNoise {
    fn default() -> Self {
        Self { weight: true, far_above_median: 10.0 }
    }
}

/// What the stated uncertainties did to the weights.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StatedNoiseReport {
    /// The median observation's stated σ of the point (RMS of its axes), m, where any states one.
    pub median_position_m: Option<f64>,
    /// The same of the orientation, rad.
    pub median_rotation_rad: Option<f64>,
    /// The residuals' scatter per axis beyond the stated noise (`τ`), m, at the end of the fit.
    pub excess_position_m: f64,
    /// The same of the orientation, rad (full-pose observations only).
    pub excess_rotation_rad: Option<f64>,
    /// How many observations state a σ.
    pub stated: usize,
    /// The observations stated more than [`StatedNoise::far_above_median`] times the median: their
    /// index and that ratio (the larger of point and orientation), largest first.
    pub far_above: Vec<(usize, f64)>,
    /// How many observations state a σ below `1 /` [`StatedNoise::far_above_median`] times the
    /// median in some component, weighted as if stated at that bound.
    pub far_below: usize,
    /// [`StatedNoise::far_above_median`].
    pub far_above_median: f64,
}

/// The mean of three variances.
fn mean_variance(v: &[f64; 3]) -> f64 {
    v.iter().sum::<f64>() / 3.0
}

fn median(mut values: Vec<f64>) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied()
}

/// The median of a χ² variable of 3 degrees of freedom: that of `|r|²/σ²` for a residual of three
/// independent components of variance `σ²` (Abramowitz & Stegun 26.4, `χ²₀.₅(3)`).
const CHI2_3_MEDIAN: f64 = 2.365_973_884_375_82;

/// The observations' stated σ, as the solver weights them: of the point and of the orientation
/// (kind 0, 1), each observation's stated variances (`None`: not stated, weighted as the median
/// observation) and the median observation's mean variance per axis.
#[derive(Debug, Clone)]
pub(crate) struct Stated {
    variances: Vec<[Option<[f64; 3]>; 2]>,
    median_variance: [Option<f64>; 2],
    cap: f64,
    report: StatedNoiseReport,
}

impl Stated {
    /// `None` where no observation states a σ or weighting is off.
    pub(crate) fn new(observations: &[Observation], options: &StatedNoise) -> Option<Self> {
        if !options.weight || observations.iter().all(|o| o.stated_sigma.is_none()) {
            return None;
        }
        let squared = |v: [f64; 3]| v.map(|x| x * x);
        let variances: Vec<[Option<[f64; 3]>; 2]> = observations
            .iter()
            .map(|o| {
                let s = o.stated_sigma;
                let rotation = matches!(o.target, Target::Pose(_)).then(|| s.and_then(|s| s.rotation_rad)).flatten();
                [s.and_then(|s| s.position_m).map(squared), rotation.map(squared)]
            })
            .collect();
        let median_variance: [Option<f64>; 2] = std::array::from_fn(|k| {
            median(variances.iter().filter_map(|v| v[k].as_ref().map(mean_variance)).collect())
        });
        let cap = options.far_above_median;
        let mut far_above = Vec::new();
        for (index, v) in variances.iter().enumerate() {
            let ratio = (0..2)
                .filter_map(|k| Some((mean_variance(v[k].as_ref()?) / median_variance[k]?).sqrt()))
                .fold(0.0, f64::max);
            if ratio > cap {
                far_above.push((index, ratio));
            }
        }
        far_above.sort_by(|a, b| b.1.total_cmp(&a.1));
        let stated = observations.iter().filter(|o| o.stated_sigma.is_some()).count();
        let report = StatedNoiseReport {
            median_position_m: median_variance[0].map(f64::sqrt),
            median_rotation_rad: median_variance[1].map(f64::sqrt),
            excess_position_m: 0.0,
            excess_rotation_rad: median_variance[1].map(|_| 0.0),
            stated,
            far_above,
            far_below: 0,
            far_above_median: cap,
        };
        Some(Self { variances, median_variance, cap, report })
    }

    /// Each observation's residual components' noise relative to the median observation's,
    /// `(point x, y, z, orientation x, y, z)`, given the scatter beyond the stated noise
    /// (`excess`, per axis, of the point and of the orientation): `√((τ² + σ²) / (τ² + m²))`,
    /// held within `1/cap … cap`; 1 where not stated.
    pub(crate) fn factors(&self, excess: [f64; 2]) -> Vec<[f64; 6]> {
        let cap = self.cap;
        self.variances
            .iter()
            .map(|v| {
                let mut f = [1.0; 6];
                for k in 0..2 {
                    if let (Some(stated), Some(m)) = (v[k], self.median_variance[k]) {
                        let t = excess[k] * excess[k];
                        for c in 0..3 {
                            f[3 * k + c] = ((t + stated[c]) / (t + m)).sqrt().clamp(1.0 / cap, cap);
                        }
                    }
                }
                f
            })
            .collect()
    }

    /// The scatter per axis beyond the stated noise, of the point and of the orientation: the
    /// `τ ≥ 0` at which the median over observations of `|r|² / (τ² + σ̄²)` is the median of χ²
    /// with 3 degrees of freedom (`σ̄²`: the observation's mean stated variance per axis, the
    /// median observation's where it states none). A median, so that neither gross outliers nor
    /// a minority of noisy rows move it. `inflation` (≥ 1) corrects the residuals of a fit for
    /// the degrees of freedom it took (`rows / (rows − parameters)`).
    pub(crate) fn excess(&self, errors: &[RowError], inflation: f64) -> [f64; 2] {
        std::array::from_fn(|k| {
            let Some(m) = self.median_variance[k] else { return 0.0 };
            let pairs: Vec<(f64, f64)> = errors
                .iter()
                .zip(&self.variances)
                .filter_map(|(e, v)| {
                    let r = if k == 0 { Some(e.position_m) } else { e.rotation_rad }?;
                    Some((r * r * inflation, v[k].as_ref().map_or(m, mean_variance)))
                })
                .collect();
            let g = |t: f64| median(pairs.iter().map(|(r2, s2)| r2 / (t + s2)).collect()).unwrap_or(0.0);
            if pairs.is_empty() || g(0.0) <= CHI2_3_MEDIAN {
                return 0.0;
            }
            // g falls with τ²; at the upper end `median(|r|²) / CHI2_3_MEDIAN` it is at most the
            // target, since every σ̄² > 0.
            let (mut low, mut high) = (0.0, median(pairs.iter().map(|p| p.0).collect()).unwrap_or(0.0) / CHI2_3_MEDIAN);
            for _ in 0..100 {
                let mid = 0.5 * (low + high);
                if g(mid) > CHI2_3_MEDIAN { low = mid } else { high = mid }
            }
            (0.5 * (low + high)).sqrt()
        })
    }

    /// The report, with the final scatter and the count of observations held at the lower bound.
    pub(crate) fn report(&self, excess: [f64; 2]) -> StatedNoiseReport {
        let floor = 1.0 / self.cap;
        let far_below = self
            .variances
            .iter()
            .filter(|v| {
                (0..2).any(|k| match (v[k], self.median_variance[k]) {
                    (Some(s), Some(m)) => s.iter().any(|x| (x / m).sqrt() < floor),
                    _ => false,
                })
            })
            .count();
        StatedNoiseReport {
            excess_position_m: excess[0],
            excess_rotation_rad: self.median_variance[1].map(|_| excess[1]),
            far_below,
            ..self.report.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lie::Vector3;

    fn observation(sigma_m: f64) -> Observation {
        Observation {
            q: vec![0.0],
            tool: 0,
            target: Target::Point(Vector3::zeros()),
            stated_sigma: Some(StatedSigma { position_m: Some([sigma_m, sigma_m, 2.0 * sigma_m]), rotation_rad: None }),
        }
    }

    fn stated(observations: &[Observation]) -> Stated {
        Stated::new(observations, &StatedNoise::default()).expect("stated")
    }

    #[test]
    fn observations_are_weighted_relative_to_the_median_and_one_far_above_the_rest_is_reported_at_the_floor() {
        let mut observations: Vec<Observation> = (0..9).map(|i| observation(1e-5 * (1.0 + 0.1 * i as f64))).collect();
        observations.push(observation(1e-3));
        observations.push(observation(1e-8));
        let stated = stated(&observations);
        let factors = stated.factors([0.0, 0.0]);
        let report = stated.report([0.0, 0.0]);
        let m = report.median_position_m.unwrap();
        // The sixth of eleven: 1.4e-5 m on x and y, twice on z.
        assert!((m - 1.4e-5 * 2f64.sqrt()).abs() < 1e-18, "{m}");
        assert_eq!((report.stated, report.median_rotation_rad), (11, None));
        // The median observation: its axes relative to it; no orientation: 1.
        let f = factors[5];
        assert!((f[2] / f[0] - 2.0).abs() < 1e-12 && f[3..] == [1.0; 3], "{f:?}");
        // The tenth is stated about 67 times the median: reported, and weighted as if ten times.
        assert_eq!(report.far_above.len(), 1);
        assert_eq!(report.far_above[0].0, 9);
        assert!(report.far_above[0].1 > 60.0, "{:?}", report.far_above);
        assert!(factors[9][..3].iter().all(|x| *x == 10.0), "{:?}", factors[9]);
        // The last, 2000 times below: held at a tenth, counted.
        assert!(factors[10][..3].iter().all(|x| *x == 0.1), "{:?}", factors[10]);
        assert_eq!(report.far_below, 1);
        // Off, or nothing stated: none.
        assert!(Stated::new(&observations, &StatedNoise { weight: false, ..Default::default() }).is_none());
        let bare = Observation { stated_sigma: None, ..observation(1.0) };
        assert!(Stated::new(&[bare], &StatedNoise::default()).is_none());
    }

    /// A scatter far above the stated noise flattens the weights: the stated σ then explains little
    /// of a row's residual.
    #[test]
    fn a_scatter_beyond_the_stated_noise_evens_the_weights_out() {
        let observations: Vec<Observation> = (0..9).map(|i| observation(1e-5 * (1.0 + 0.5 * i as f64))).collect();
        let stated = stated(&observations);
        let spread = |excess: f64| {
            let f = stated.factors([excess, 0.0]);
            f[8][0] / f[0][0]
        };
        assert!((spread(0.0) - 5.0).abs() < 1e-12, "{}", spread(0.0));
        assert!(spread(1e-5) > 1.5 && spread(1e-5) < 5.0, "{}", spread(1e-5));
        assert!((spread(1e-2) - 1.0).abs() < 1e-4, "{}", spread(1e-2));
    }

    /// The scatter beyond the stated noise is found where it is (the residuals' median against
    /// χ² of 3 degrees of freedom), and is zero where the stated noise explains the residuals.
    #[test]
    fn the_scatter_beyond_the_stated_noise_is_estimated_from_the_residuals() {
        let observations: Vec<Observation> = (0..401).map(|i| observation(1e-5 * (1.0 + (i % 7) as f64))).collect();
        let stated = stated(&observations);
        // Residual norms whose squares over (τ² + σ̄²) are exactly χ²₃'s median for τ = 0.2 mm.
        let tau = 2e-4;
        let errors = |tau: f64| -> Vec<RowError> {
            stated
                .variances
                .iter()
                .map(|v| {
                    let s2 = mean_variance(v[0].as_ref().unwrap());
                    RowError { position_m: (CHI2_3_MEDIAN * (tau * tau + s2)).sqrt(), rotation_rad: None }
                })
                .collect()
        };
        let [found, rotation] = stated.excess(&errors(tau), 1.0);
        assert!((found - tau).abs() < 1e-9 * tau && rotation == 0.0, "{found}");
        // Inflated by the degrees of freedom the fit took.
        let [inflated, _] = stated.excess(&errors(tau), 1.5);
        assert!(inflated > tau, "{inflated}");
        // Residuals the stated noise explains: none beyond it.
        let [none, _] = stated.excess(&errors(0.0), 1.0);
        assert!(none < 1e-9 * tau, "{none}");
        let smaller: Vec<RowError> =
            errors(0.0).iter().map(|e| RowError { position_m: 0.5 * e.position_m, rotation_rad: None }).collect();
        assert_eq!(stated.excess(&smaller, 1.0), [0.0, 0.0]);
    }
}
