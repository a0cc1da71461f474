//! The geometry's own posterior uncertainty, carried to the rows a model is applied at: for rows
//! outside every fitted configuration, `eval` and `predict` give the error the geometry's own
//! uncertainty predicts there beside the warning. The fit under the prior toward the
//! nominal geometry keeps the covariance of the kinematic parameters (directions the training
//! poses determine poorly keep about the prior's width, the nominal's tolerance; the others what
//! the data gives); at a row, `σ = ‖Lᵀ g‖` of the tool point's position, `g` the identification
//! Jacobian's columns. Where a row puts a joint outside the range the model was fitted on, that
//! σ says how far the geometry may be off there, which the fit's own residuals cannot.

use crate::EffectUncertainty;
use crate::effect_sigma::{factor_sigma, kinematic_changes, packed_numbers};
use errors::Error;
use measurements::{BoundSet, Measurement};
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// The posterior uncertainty of a model's kinematic parameters, as a model file keeps it: kept by
/// fits under the prior toward the nominal geometry (without a prior, the directions no training
/// pose sees have no variance, and a σ from it would say nothing where it matters).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeometryUncertainty {
    /// The free kinematic parameters, as indices into the kinematics' parameter layout (their left
    /// perturbations, `poe::LocalPoe::identification_jacobian`), in the factor's order.
    pub free: Vec<usize>,
    /// The lower Cholesky factor `L` of their posterior covariance `Σ = L Lᵀ`, packed by rows as
    /// [`EffectUncertainty::factor`] is.
    #[serde(with = "packed_numbers")]
    pub factor: Vec<f64>,
    /// The σ of the tool point's position (m) over the training rows: their RMS and the largest.
    pub training_sigma_m: [f64; 2],
}

impl GeometryUncertainty {
    /// The uncertainty of the parameters `free` of `kinematics`, the first `free.len()` of the
    /// covariance `covariance` (row-major, `dim × dim`: the kinematic block of a fit with
    /// effects is their marginal), with its σ over the rows of `data`; `None` where the
    /// covariance is not of that size or not definite.
    pub fn of(
        kinematics: &LocalPoe,
        free: Vec<usize>,
        covariance: &[f64],
        dim: usize,
        data: &BoundSet<'_>,
    ) -> Result<Option<Self>, Error> {
        let p = free.len();
        if p == 0 || p > dim || covariance.len() != dim * dim {
            return Ok(None);
        }
        let block: Vec<f64> = (0..p).flat_map(|i| covariance[i * dim..i * dim + p].iter().copied()).collect();
        let Some(factor) = EffectUncertainty::factor_of(&block, p) else { return Ok(None) };
        let mut uncertainty = Self { free, factor, training_sigma_m: [0.0; 2] };
        let sigmas: Vec<f64> =
            data.iter().map(|(row, tool)| uncertainty.sigma_m(kinematics, row, tool)).collect::<Result<_, _>>()?;
        uncertainty.training_sigma_m = [rms(&sigmas), sigmas.iter().copied().fold(0.0, f64::max)];
        Ok(Some(uncertainty))
    }

    /// The σ of the tool point's position (m) that `kinematics` predict at `row` (model tool
    /// `tool`).
    pub fn sigma_m(&self, kinematics: &LocalPoe, row: &Measurement, tool: usize) -> Result<f64, Error> {
        let (changes, _) = kinematic_changes(kinematics, &self.free, row, tool)?;
        Ok(EffectUncertainty::position(&factor_sigma(&self.factor, &changes)))
    }

    /// What is wrong with it as read from a file for kinematics of `layout` parameters, if
    /// anything.
    pub(crate) fn fault(&self, layout: usize) -> Option<String> {
        if let Some(index) = self.free.iter().find(|&&i| i >= layout) {
            return Some(format!(
                "geometry_uncertainty.free: {index} is not a parameter of the kinematics ({layout} parameters; an \
                 edited or corrupt file)"
            ));
        }
        let p = self.free.len();
        if self.factor.len() != p * (p + 1) / 2 {
            return Some(format!(
                "geometry_uncertainty.factor: {} numbers, {} expected for {p} parameters (an edited or corrupt file)",
                self.factor.len(),
                p * (p + 1) / 2
            ));
        }
        if let Some(value) = self.factor.iter().find(|v| !v.is_finite()) {
            return Some(format!("geometry_uncertainty.factor: {value} is not finite (an edited or corrupt file)"));
        }
        let [typical, largest] = self.training_sigma_m;
        if !(typical.is_finite() && largest.is_finite() && 0.0 <= typical && typical <= largest) {
            return Some(format!(
                "geometry_uncertainty.training_sigma_m ({typical:e}, {largest:e}) must be finite, ordered and at least \
                 0 (an edited or corrupt file)"
            ));
        }
        None
    }
}

fn rms(values: &[f64]) -> f64 {
    if values.is_empty() { 0.0 } else { (values.iter().map(|v| v * v).sum::<f64>() / values.len() as f64).sqrt() }
}

/// The error the geometry's own uncertainty predicts on the rows that put a joint outside the
/// range the model was fitted on (`calib eval --json`: `geometry_sigma`), beside the warning that
/// names them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GeometrySigma {
    /// The rows that put some joint outside the range the model was fitted on.
    pub rows: usize,
    /// How many rows there are.
    pub of_rows: usize,
    /// The file line of the first of them.
    pub first_line: u64,
    /// The RMS over them of the σ of the tool point's position, mm.
    pub rms_mm: f64,
    /// The largest, mm.
    pub max_mm: f64,
    /// The RMS over the training rows, mm: what the fitted configurations have.
    pub training_rms_mm: f64,
}

impl GeometrySigma {
    /// Over the rows of `data` for which `outside` holds, the σ that `uncertainty` gives with
    /// `kinematics`; `None` where no row is outside.
    pub(crate) fn of(
        uncertainty: &GeometryUncertainty,
        kinematics: &LocalPoe,
        data: &BoundSet<'_>,
        outside: impl Fn(&Measurement) -> bool,
    ) -> Result<Option<Self>, Error> {
        let mut sigmas = Vec::new();
        let mut first_line = None;
        for (row, tool) in data.iter().filter(|(row, _)| outside(row)) {
            first_line.get_or_insert(row.line);
            sigmas.push(uncertainty.sigma_m(kinematics, row, tool)?);
        }
        let Some(first_line) = first_line else { return Ok(None) };
        Ok(Some(Self {
            rows: sigmas.len(),
            of_rows: data.len(),
            first_line,
            rms_mm: rms(&sigmas) * 1e3,
            max_mm: sigmas.iter().copied().fold(0.0, f64::max) * 1e3,
            training_rms_mm: uncertainty.training_sigma_m[0] * 1e3,
        }))
    }
}

impl std::fmt::Display for GeometrySigma {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} of {} rows (the first at line {}) put a joint outside the range the model was fitted on: there the \
             geometry's own uncertainty (its posterior under the nominal's tolerance) is σ {:.4} mm RMS, up to {:.4} mm \
             ({:.4} mm RMS on its training rows); that is the geometry's part alone, a lower bound: what the model \
             leaves beyond the geometry is not in it, and outside the fitted configurations it can be several times more",
            self.rows, self.of_rows, self.first_line, self.rms_mm, self.max_mm, self.training_rms_mm
        )
    }
}
