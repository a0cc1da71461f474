//! Gross outliers before anything is attributed.
//!
//! A row a metre off is not the structure of any effect, yet it dominates every held-out error
//! and every selection, and a GP finds "structure" in the joints it happens to sit at. So the
//! geometry is fitted first with the identification's robust loss, and the rows it names as
//! gross outliers (`poe::identify::RobustOptions::outlier_threshold` robust sigmas beyond the
//! median residual) are named by line and left out of the diagnosis, which says so.
//!
//! A few such rows are errors of the data. Many are not: a share of the rows far beyond the
//! rest is a large effect (a backlash puts the rows on one side of its band a band's width off
//! the geometry fitted to the others: the blind check's strong backlash cases name 10 % of their
//! rows) or a second population (a tool or frame changed during the campaign, a collision), and
//! leaving it out would hide the very thing to be found. Beyond
//! [`OutlierOptions::max_left_out_fraction`] of the rows the diagnosis keeps them and runs as
//! usual; if the effects it selects bring all but that share of them back within the threshold,
//! they were the effect and the verdict stands; otherwise nothing is attributed: the verdict is
//! `unknown`, for that reason.

use super::Verdict;
use super::candidates::Effect;
use errors::Error;
use measurements::{BoundSet, OutlierLine, list_lines};
use model::geometric::fit_geometry;
use poe::LocalPoe;
use poe::identify::{IdentificationOptions, Scope};
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

/// When gross outliers stop the diagnosis from attributing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OutlierOptions {
    /// Up to this share of the rows, gross outliers are left out as errors of the data and the
    /// diagnosis goes on; beyond it they are kept, and the verdict is `unknown` unless the
    /// selected effects bring all but this share of the rows back. 2 %: a tracker that loses its
    /// target now and then, or a mistyped value, spoils a row or two in a few hundred; six rows
    /// in three hundred, each ten robust sigmas out, are a pattern.
    pub max_left_out_fraction: f64,
}

impl Default for OutlierOptions {
    fn default() -> Self {
        Self { max_left_out_fraction: 0.02 }
    }
}

/// The gross outliers of a diagnosed data set (the JSON's `gross_outliers`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct GrossOutliers {
    /// The rows, by line, most sigmas first; left out of every number of the diagnosis.
    pub rows: Vec<OutlierLine>,
    /// The threshold they are beyond, robust sigmas above the median residual of the geometry.
    pub threshold_sigmas: f64,
    /// Whether they are too many to be errors of the data, and kept in the diagnosis.
    #[serde(default)]
    pub kept: bool,
    /// Of the rows kept, how many the selected effects leave beyond the threshold (held out).
    #[serde(default)]
    pub unexplained: usize,
    /// Whether they are too many to be errors of the data and the selected effects do not
    /// explain them, so that no effect is attributed.
    pub attribution_refused: bool,
}

impl GrossOutliers {
    /// The verdict, `unknown` without joints where the outliers refuse attribution; the result
    /// of the verdict's effect goes with an attributed effect only.
    pub(crate) fn verdict(&self, verdict: Verdict, result: Option<f64>) -> (Verdict, Option<f64>) {
        if self.attribution_refused {
            (Verdict { effect: Effect::Unknown, joints: Vec::new() }, None)
        } else {
            (verdict, result)
        }
    }

    /// The reason of an `unknown` verdict they force, if they do.
    pub fn verdict_reason(&self) -> Option<String> {
        self.attribution_refused.then(|| {
            format!(
                "unknown: gross outliers at {} ({} rows, too many to be errors of the data, and the selected effects do not explain them): no effect is \
                 attributed; check those rows, or the campaign for a change of tool or frame",
                list_lines(&self.rows),
                self.rows.len()
            )
        })
    }

    /// The summary's line about them, if there are any.
    pub fn summary_line(&self) -> Option<String> {
        (!self.rows.is_empty()).then(|| {
            let fate = match (self.kept, self.attribution_refused) {
                (false, _) => "left out of the diagnosis".to_owned(),
                (true, false) => format!(
                    "too many to be errors of the data, kept: the selected effects bring all but {} of them back",
                    self.unexplained
                ),
                (true, true) => format!(
                    "too many to be errors of the data, kept: the selected effects leave {} of them beyond it",
                    self.unexplained
                ),
            };
            format!(
                "  gross outliers: {} row(s) beyond {} robust sigmas of the geometric fit, {fate}: {}\n",
                self.rows.len(),
                self.threshold_sigmas,
                list_lines(&self.rows)
            )
        })
    }
}

/// The data the diagnosis works on and the gross outliers left out of it (or kept).
pub(crate) struct Screened<'a> {
    /// The rows kept, bound as the diagnosis's data is.
    pub data: Cow<'a, BoundSet<'a>>,
    pub outliers: GrossOutliers,
    /// Where they are kept: their 0-based rows and the position distance beyond which a row is
    /// one, m (median plus the threshold in robust sigmas).
    kept: Option<(Vec<usize>, f64)>,
    max_fraction: f64,
}

/// Fits the geometry to every row with the robust loss and leaves out the rows it names.
pub(crate) fn screen<'a>(
    nominal: &LocalPoe,
    bound: &'a BoundSet<'a>,
    options: &OutlierOptions,
) -> Result<Screened<'a>, Error> {
    let data = bound.set();
    let identification = IdentificationOptions::default();
    let robust = fit_geometry(nominal, data, Scope::Full, &identification)?.report.robust;
    let rows = OutlierLine::of(&robust, data);
    let many = rows.len() as f64 > options.max_left_out_fraction * data.rows.len() as f64;
    let outliers = GrossOutliers {
        kept: many,
        unexplained: 0,
        attribution_refused: false,
        threshold_sigmas: robust.outlier_threshold,
        rows,
    };
    let kept = many.then(|| {
        let rows: Vec<usize> = robust.outliers.iter().map(|o| o.observation).collect();
        (rows, robust.position.median + robust.outlier_threshold * robust.position.sigma)
    });
    let data = if outliers.rows.is_empty() || many {
        Cow::Borrowed(bound)
    } else {
        Cow::Owned(bound.without(&robust.outliers))
    };
    Ok(Screened { data, outliers, kept, max_fraction: options.max_left_out_fraction })
}

impl Screened<'_> {
    /// Where the outliers were kept: counts those the selected effects leave beyond the
    /// threshold (`heldout_m`: every row's held-out position error with them, m) and refuses
    /// attribution when more than the allowed share of the rows is left.
    pub(crate) fn judged(&self, heldout_m: &[f64]) -> GrossOutliers {
        let mut outliers = self.outliers.clone();
        if let Some((rows, threshold_m)) = &self.kept {
            let left = rows.iter().filter(|&&i| heldout_m.get(i).is_none_or(|&e| e > *threshold_m)).count();
            outliers.unexplained = left;
            outliers.attribution_refused = left as f64 > self.max_fraction * heldout_m.len() as f64;
        }
        outliers
    }
}
