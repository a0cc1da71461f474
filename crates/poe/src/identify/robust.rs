//! The identification's robust loss: one row a metre off among hundreds of good ones
//! must neither spoil the model nor pass without a word.
//!
//! Each row's residual is measured by its norm, per kind (the tool point's distance in metres,
//! the orientation's angle in radians, never mixed). The scale of each kind is robust: the median
//! of the norms and `1.4826 · MAD` about it (the MAD scaled to a Gaussian standard deviation;
//! Rousseeuw & Croux, JASA 88, 1993). A row is `z` robust sigmas out when its norm is
//! `median + z · scale`: Hampel's identifier, one-sided because a norm is never negative.
//!
//! Beyond [`RobustOptions::huber_threshold`] a kind's rows are weighted by Huber's loss
//! (`w = c / r`, `c` the threshold's norm: the row pulls as if its residual were `c`, Huber 1964);
//! beyond [`RobustOptions::outlier_threshold`] the whole row is named and left out (`w = 0`).
//! Iteratively reweighted least squares (Holland & Welsch 1977) alternates the weights and the
//! solve until the weights settle. The thresholds are generous, so that data with Gaussian noise
//! stays plain least squares: the norm of three Gaussian components exceeds 6 robust sigmas with
//! probability below 1e-6, and where no row is beyond the threshold the fit is the one a plain
//! least-squares fit gives, bit for bit.

use crate::Error;
use serde::{Deserialize, Serialize};

/// The loss the identification minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Loss {
    /// Plain least squares: every row weighs the same. Rows beyond the outlier threshold are
    /// still named in the report, but kept in the fit.
    Squared,
    /// Least squares up to the Huber threshold, linear beyond it, and rows beyond the outlier
    /// threshold left out.
    #[default]
    Huber,
}

/// The robust loss's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RobustOptions {
    /// The loss.
    pub loss: Loss,
    /// Robust sigmas above the median norm beyond which a kind's residual is down-weighted
    /// (Huber's `c`). 6: the norm of three Gaussian components with the same noise exceeds it with
    /// probability below 1e-6 (median 1.54 σ, 1.4826 · MAD 0.68 σ: 5.6 σ), so clean data is plain
    /// least squares; the real UR10 series B, C and D, whose geometric residual carries
    /// compliance, reach 5.5 at most outside three rows of series B.
    pub huber_threshold: f64,
    /// Robust sigmas above the median norm beyond which a row is named as a gross outlier and
    /// left out. 10: on the real UR10 series C and D no row comes near it (5.5 at most), and on
    /// series B even rows one row passes it (line 268, 2.1 mm against a 0.36 mm median, 10.1
    /// sigmas), which a GP fitted on the odd rows still misses by 1.9 mm: an error no smooth
    /// model explains. A mistyped digit or a tracker that lost its target is hundreds.
    pub outlier_threshold: f64,
    /// At most this many reweightings after the first (plain) solve. Each solve starts where the
    /// last ended, so one usually suffices; 10 leaves room for a fit that the outliers had pulled
    /// far.
    pub max_reweightings: usize,
    /// The weights have settled when none changes by more than this. 1e-3: a row weighted 0.1 %
    /// differently moves the solution by a thousandth of that row's pull.
    pub weight_tolerance: f64,
    /// Smallest position scale, metres. 1 µm, below any tracker's noise (a laser tracker's is
    /// 10–20 µm), so that noise-free synthetic data, whose MAD is rounding, is never reweighted.
    pub scale_floor_m: f64,
    /// Smallest orientation scale, radians (1 µrad, as for the position).
    pub scale_floor_rad: f64,
}

impl Default for RobustOptions {
    fn default() -> Self {
        Self {
            loss: Loss::Huber,
            huber_threshold: 6.0,
            outlier_threshold: 10.0,
            max_reweightings: 10,
            weight_tolerance: 1e-3,
            scale_floor_m: 1e-6,
            scale_floor_rad: 1e-6,
        }
    }
}

impl RobustOptions {
    /// Checks the thresholds (positive, finite, the outlier one not below Huber's) and floors.
    pub fn validate(&self) -> Result<(), Error> {
        let invalid = |name: &'static str, value: f64, expected: &'static str| {
            Err(Error::InvalidOption { name, value, expected })
        };
        for (name, value) in [
            ("robust.huber_threshold", self.huber_threshold),
            ("robust.outlier_threshold", self.outlier_threshold),
            ("robust.weight_tolerance", self.weight_tolerance),
            ("robust.scale_floor_m", self.scale_floor_m),
            ("robust.scale_floor_rad", self.scale_floor_rad),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return invalid(name, value, "a finite number above 0");
            }
        }
        if self.outlier_threshold < self.huber_threshold {
            return invalid("robust.outlier_threshold", self.outlier_threshold, "at least robust.huber_threshold");
        }
        Ok(())
    }
}

/// The robust scale of one kind of residual (position or orientation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct KindScale {
    /// Median of the rows' residual norms (metres or radians).
    pub median: f64,
    /// `1.4826 · MAD` of the norms about it, at least the floor.
    pub sigma: f64,
}

impl KindScale {
    /// The scale of `norms` (not empty), `floor` at least.
    pub fn of(norms: &[f64], floor: f64) -> Self {
        let median = median(norms);
        let deviations: Vec<f64> = norms.iter().map(|v| (v - median).abs()).collect();
        // 1.4826 = 1 / Φ⁻¹(3/4): the MAD of a Gaussian is 0.6745 σ.
        Self { median, sigma: (1.4826 * self::median(&deviations)).max(floor) }
    }

    /// How many robust sigmas above the median `norm` is.
    pub fn sigmas(&self, norm: f64) -> f64 {
        (norm - self.median) / self.sigma
    }

    /// The norm `threshold` robust sigmas above the median.
    pub fn norm_at(&self, threshold: f64) -> f64 {
        self.median + threshold * self.sigma
    }
}

/// The median of `values` (the mean of the middle two for an even count; 0 for none).
pub fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    if n % 2 == 1 { sorted[n / 2] } else { 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]) }
}

/// Huber's weight `ψ(r)/r` of a residual norm `norm` with threshold norm `c`: 1 up to `c`,
/// `c / r` beyond it.
pub fn huber_weight(norm: f64, c: f64) -> f64 {
    if norm <= c { 1.0 } else { c / norm }
}

/// Huber's loss of a residual norm: `r²/2` up to `c`, `c r − c²/2` beyond (continuous with a
/// continuous derivative `ψ`, whose ratio to `r` is [`huber_weight`]).
pub fn huber_loss(norm: f64, c: f64) -> f64 {
    if norm <= c { 0.5 * norm * norm } else { c * norm - 0.5 * c * c }
}

/// One row's residual norms under the current model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RowError {
    /// The tool point's distance, metres.
    pub position_m: f64,
    /// The orientation's angle, radians (pose rows only).
    pub rotation_rad: Option<f64>,
}

/// A row named as a gross outlier.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OutlierRow {
    /// 0-based index of the observation.
    pub observation: usize,
    /// Its tool point's distance from the model, metres.
    pub position_m: f64,
    /// That distance in robust sigmas above the median.
    pub position_sigmas: f64,
    /// Its orientation's angle from the model, radians (pose rows only).
    pub rotation_rad: Option<f64>,
    /// That angle in robust sigmas above the median.
    pub rotation_sigmas: Option<f64>,
}

impl OutlierRow {
    /// The larger of its kinds' robust sigmas.
    pub fn sigmas(&self) -> f64 {
        self.position_sigmas.max(self.rotation_sigmas.unwrap_or(f64::NEG_INFINITY))
    }
}

/// What the robust loss did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobustReport {
    /// The loss.
    pub loss: Loss,
    /// Reweighted solves after the first, plain one (0: no row was beyond the Huber threshold).
    pub reweightings: usize,
    /// Whether the weights settled within [`RobustOptions::max_reweightings`].
    pub settled: bool,
    /// The position residuals' robust scale at the end, metres (where observations state their
    /// σ, of residuals taken relative to it: a median observation's, module `stated_noise`).
    pub position: KindScale,
    /// The orientation residuals' robust scale at the end, radians (full-pose data only).
    pub rotation: Option<KindScale>,
    /// The Huber threshold, robust sigmas.
    pub huber_threshold: f64,
    /// The outlier threshold, robust sigmas.
    pub outlier_threshold: f64,
    /// Rows down-weighted but kept (Huber's linear part).
    pub downweighted: usize,
    /// The rows beyond the outlier threshold, most sigmas first: left out of the fit under
    /// [`Loss::Huber`], kept under [`Loss::Squared`].
    pub outliers: Vec<OutlierRow>,
}

/// The weights the residuals of one state call for, and the report of them.
pub(crate) struct Assessment {
    /// Per observation: the weight of its position rows and of its orientation rows.
    pub weights: Vec<[f64; 2]>,
    pub report: RobustReport,
}

/// Weighs rows by their residual norms ([`RobustOptions`]).
pub(crate) fn assess(errors: &[RowError], options: &RobustOptions) -> Assessment {
    let positions: Vec<f64> = errors.iter().map(|e| e.position_m).collect();
    let rotations: Vec<f64> = errors.iter().filter_map(|e| e.rotation_rad).collect();
    let position = KindScale::of(&positions, options.scale_floor_m);
    let rotation = (!rotations.is_empty()).then(|| KindScale::of(&rotations, options.scale_floor_rad));
    let huber = options.loss == Loss::Huber;
    let mut weights = Vec::with_capacity(errors.len());
    let mut outliers = Vec::new();
    let mut downweighted = 0;
    for (observation, error) in errors.iter().enumerate() {
        let position_sigmas = position.sigmas(error.position_m);
        let rotation_sigmas = rotation.zip(error.rotation_rad).map(|(s, r)| s.sigmas(r));
        let outlier = position_sigmas > options.outlier_threshold
            || rotation_sigmas.is_some_and(|z| z > options.outlier_threshold);
        if outlier {
            outliers.push(OutlierRow {
                observation,
                position_m: error.position_m,
                position_sigmas,
                rotation_rad: error.rotation_rad,
                rotation_sigmas,
            });
        }
        let weight = if !huber {
            [1.0, 1.0]
        } else if outlier {
            [0.0, 0.0]
        } else {
            let wp = huber_weight(error.position_m, position.norm_at(options.huber_threshold));
            let wr = match (rotation, error.rotation_rad) {
                (Some(s), Some(r)) => huber_weight(r, s.norm_at(options.huber_threshold)),
                _ => 1.0,
            };
            if wp < 1.0 || wr < 1.0 {
                downweighted += 1;
            }
            [wp, wr]
        };
        weights.push(weight);
    }
    outliers.sort_by(|a, b| b.sigmas().total_cmp(&a.sigmas()));
    Assessment {
        weights,
        report: RobustReport {
            loss: options.loss,
            reweightings: 0,
            settled: true,
            position,
            rotation,
            huber_threshold: options.huber_threshold,
            outlier_threshold: options.outlier_threshold,
            downweighted,
            outliers,
        },
    }
}

/// Whether two weightings differ by at most `tolerance` in every entry.
pub(crate) fn settled(old: &[[f64; 2]], new: &[[f64; 2]], tolerance: f64) -> bool {
    old.len() == new.len()
        && old.iter().zip(new).all(|(a, b)| (a[0] - b[0]).abs() <= tolerance && (a[1] - b[1]).abs() <= tolerance)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_takes_the_middle_and_the_mean_of_the_middle_two() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&[]), 0.0);
    }

    #[test]
    fn mad_scale_is_a_gaussian_sigma_and_ignores_one_gross_value() {
        // Symmetric values about 10 with MAD 1: the scale is 1.4826, whatever the largest is.
        let mut values = vec![8.0, 9.0, 9.0, 10.0, 11.0, 11.0, 12.0];
        let clean = KindScale::of(&values, 1e-9);
        assert_eq!(clean.median, 10.0);
        assert!((clean.sigma - 1.4826).abs() < 1e-12, "{clean:?}");
        *values.last_mut().unwrap() = 1e6;
        assert_eq!(KindScale::of(&values, 1e-9), clean);
        // The floor holds for identical values.
        assert_eq!(KindScale::of(&[2.0; 5], 0.5).sigma, 0.5);
        assert!((clean.sigmas(clean.norm_at(6.0)) - 6.0).abs() < 1e-12);
    }

    /// Huber's weight is its loss's derivative over the norm: checked by central differences.
    #[test]
    fn huber_weight_is_the_derivative_of_the_loss_over_the_norm() {
        let c = 1.7;
        for r in [0.1, 1.0, 1.69, 1.71, 3.0, 40.0] {
            let h = 1e-6;
            let psi = (huber_loss(r + h, c) - huber_loss(r - h, c)) / (2.0 * h);
            assert!((psi / r - huber_weight(r, c)).abs() < 1e-8, "r {r}: {} vs {}", psi / r, huber_weight(r, c));
        }
        assert_eq!(huber_weight(c, c), 1.0);
        assert!((huber_weight(2.0 * c, c) - 0.5).abs() < 1e-15);
    }

    fn rows(norms: &[f64]) -> Vec<RowError> {
        norms.iter().map(|&p| RowError { position_m: p, rotation_rad: Some(p * 2.0) }).collect()
    }

    #[test]
    fn a_gross_row_is_named_and_left_out_and_clean_rows_keep_weight_one() {
        let mut norms: Vec<f64> = (0..300).map(|i| 1e-4 * (1.0 + 0.5 * ((i as f64) * 0.37).sin())).collect();
        let clean = assess(&rows(&norms), &RobustOptions::default());
        assert!(clean.report.outliers.is_empty());
        assert_eq!(clean.report.downweighted, 0);
        assert!(clean.weights.iter().all(|w| *w == [1.0, 1.0]));
        norms[17] = 1.0;
        let dirty = assess(&rows(&norms), &RobustOptions::default());
        assert_eq!(dirty.report.outliers.len(), 1);
        assert_eq!(dirty.report.outliers[0].observation, 17);
        assert!(dirty.report.outliers[0].position_sigmas > 1e3);
        assert_eq!(dirty.weights[17], [0.0, 0.0]);
        assert_eq!(dirty.weights.iter().filter(|w| **w == [1.0, 1.0]).count(), 299);
        // Least squares names it but keeps it.
        let squared = RobustOptions { loss: Loss::Squared, ..RobustOptions::default() };
        let kept = assess(&rows(&norms), &squared);
        assert_eq!(kept.report.outliers.len(), 1);
        assert_eq!(kept.weights[17], [1.0, 1.0]);
    }

    #[test]
    fn a_row_between_the_thresholds_is_down_weighted_by_huber() {
        let mut norms: Vec<f64> = (0..100).map(|i| 1e-4 * (1.0 + 0.5 * ((i as f64) * 0.37).sin())).collect();
        let scale = KindScale::of(&norms, 1e-9);
        norms[3] = scale.norm_at(8.0);
        let options = RobustOptions::default();
        let assessed = assess(&rows(&norms), &options);
        assert!(assessed.report.outliers.is_empty());
        assert_eq!(assessed.report.downweighted, 1);
        let scale = KindScale::of(&norms, 1e-9);
        let expected = scale.norm_at(options.huber_threshold) / norms[3];
        assert!((assessed.weights[3][0] - expected).abs() < 1e-12 && expected < 1.0);
    }

    #[test]
    fn refused_options_name_their_field() {
        let bad = RobustOptions { outlier_threshold: 3.0, ..RobustOptions::default() };
        assert!(matches!(bad.validate(), Err(Error::InvalidOption { name: "robust.outlier_threshold", .. })));
        let bad = RobustOptions { huber_threshold: f64::NAN, ..RobustOptions::default() };
        assert!(matches!(bad.validate(), Err(Error::InvalidOption { name: "robust.huber_threshold", .. })));
        assert!(RobustOptions::default().validate().is_ok());
    }
}
