//! Where a plan's unmodelled error comes from: the options, or a calibrated model's own
//! held-out error (`calib plan --model`).
//!
//! The plan's criterion ([`crate::bias`]) needs the RMS per axis of the error the geometry
//! cannot model. A calibrated model keeps its fit's estimate of its mean 3-D position error on
//! poses it was not fitted on ([`model::HeldoutEstimate`]); for an isotropic Gaussian error of
//! `σ` per axis the norm has a Maxwell distribution of mean `2√2/√π · σ ≈ 1.596 σ`, so
//! `σ = mean · √(π/8) ≈ 0.627 · mean`. The model keeps no held-out orientation error: the
//! orientation's is taken as the position's at the 1 m lever, as the defaults assume
//! ([`crate::PlanOptions::unmodelled_mrad`]).

use errors::Error;
use model::{HeldoutSource, Method};
use serde::{Deserialize, Serialize};

/// Where one of the plan's unmodelled errors came from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "from")]
pub enum UnmodelledFrom {
    /// [`crate::PlanOptions`]' default.
    Default,
    /// Set in the options.
    Options,
    /// The model's held-out mean position error ([`per_axis_from_mean`]); for the orientation,
    /// that per-axis value in mrad (mm at the 1 m lever).
    Model {
        /// The model's held-out mean 3-D position error, mm.
        heldout_mm: f64,
        /// How the fit estimated it.
        heldout_source: HeldoutSource,
        /// The model's method: with effects or a GP it is what they leave, below what the
        /// geometry alone leaves.
        method: Method,
        /// Whether the model has effects or a GP beside its geometry.
        beyond_geometry: bool,
    },
}

impl std::fmt::Display for UnmodelledFrom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Default => {
                f.write_str("the default; `--model` with a fitted model sets it from the model's held-out error")
            }
            Self::Options => f.write_str("set in the options"),
            Self::Model { heldout_mm, heldout_source, method, beyond_geometry } => {
                write!(
                    f,
                    "from the {method} model's held-out error, {heldout_mm:.3} mm mean ({heldout_source}) × √(π/8)"
                )?;
                if *beyond_geometry {
                    f.write_str("; its effects or GP take part of the error: the geometry alone leaves more")?;
                }
                Ok(())
            }
        }
    }
}

/// The RMS per axis `σ` of an isotropic 3-D Gaussian error whose norm has mean `mean`:
/// `mean · √(π/8)` (the Maxwell distribution's mean is `2σ √(2/π)`).
pub fn per_axis_from_mean(mean: f64) -> f64 {
    mean * (std::f64::consts::PI / 8.0).sqrt()
}

/// Which unmodelled errors a RON options text sets (the others are [`crate::PlanOptions`]' defaults).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UnmodelledGiven {
    /// `unmodelled_mm` is set.
    pub position: bool,
    /// `unmodelled_mrad` is set.
    pub rotation: bool,
}

/// The two fields as the text has them (every other field ignored: [`crate::PlanOptions::parse`]
/// checks them).
#[derive(Deserialize)]
#[serde(rename = "PlanOptions")]
struct Given {
    unmodelled_mm: Option<ron::Value>,
    unmodelled_mrad: Option<ron::Value>,
}

impl UnmodelledGiven {
    /// What the text of an options file sets; errors name the file, line and column.
    pub fn of_text(text: &str, file: &str) -> Result<Self, Error> {
        let given: Given = errors::ron_position::ron_options().from_str(text).map_err(|e| Error::ron(file, &e))?;
        Ok(Self { position: given.unmodelled_mm.is_some(), rotation: given.unmodelled_mrad.is_some() })
    }
}

/// Where a plan's unmodelled position and orientation errors came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnmodelledSetting {
    /// The position's ([`crate::PlanOptions::unmodelled_mm`]).
    pub position: UnmodelledFrom,
    /// The orientation's ([`crate::PlanOptions::unmodelled_mrad`]).
    pub rotation: UnmodelledFrom,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PlanOptions;
    use model::CalibratedModel;

    /// The mean norm of draws of an isotropic Gaussian of σ 1 per axis is `1 / √(π/8)`.
    #[test]
    fn the_per_axis_error_is_the_mean_norm_over_the_maxwell_mean() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut normal = || {
            let u: f64 = rng.random_range(f64::EPSILON..1.0);
            let v: f64 = rng.random_range(0.0..1.0);
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        let draws = 200_000;
        let mean = (0..draws).map(|_| (0..3).map(|_| normal().powi(2)).sum::<f64>().sqrt()).sum::<f64>() / draws as f64;
        assert!((per_axis_from_mean(mean) - 1.0).abs() < 0.005, "{mean}");
        assert!((per_axis_from_mean(1.596) - 1.0).abs() < 1e-3);
    }

    fn fitted(heldout: Option<model::HeldoutEstimate>) -> CalibratedModel {
        let row = |a, alpha, d| poe::DhRow { kind: poe::JointKind::Revolute, a, alpha, d, theta: 0.0 };
        CalibratedModel {
            schema_version: model::SCHEMA_VERSION,
            robot: "two links".into(),
            method: Method::Poe,
            full_pose: true,
            tools: vec![String::new()],
            kinematics: poe::LocalPoe::from_dh(&[row(0.5, 0.0, 0.0), row(0.4, 0.0, 0.0)], poe::DhConvention::Standard),
            effects: Vec::new(),
            fallback_kinematics: None,
            effect_uncertainty: None,
            geometry_uncertainty: None,
            residual_gp: None,
            training_range: None,
            joint_limits: Vec::new(),
            heldout,
            fit_warnings: None,
            robot_description: None,
        }
    }

    #[test]
    fn a_models_heldout_error_sets_what_the_options_leave() {
        let heldout = model::HeldoutEstimate::new(0.444, HeldoutSource::DegreesOfFreedom);
        let model = fitted(heldout);
        let sigma = 0.444 * (std::f64::consts::PI / 8.0).sqrt();
        let mut options = PlanOptions::default();
        let setting = options.set_unmodelled_from(Some(&model), UnmodelledGiven::default());
        assert_eq!((options.unmodelled_mm, options.unmodelled_mrad), (sigma, sigma));
        let from = UnmodelledFrom::Model {
            heldout_mm: 0.444,
            heldout_source: HeldoutSource::DegreesOfFreedom,
            method: Method::Poe,
            beyond_geometry: false,
        };
        assert_eq!(setting, UnmodelledSetting { position: from, rotation: from });
        // What the options set stays.
        let mut options = PlanOptions { unmodelled_mm: 0.3, ..PlanOptions::default() };
        let setting = options.set_unmodelled_from(Some(&model), UnmodelledGiven { position: true, rotation: false });
        assert_eq!((options.unmodelled_mm, options.unmodelled_mrad), (0.3, sigma));
        assert_eq!(setting.position, UnmodelledFrom::Options);
        // No model, or one without an estimate: the defaults, said so.
        for model in [None, Some(fitted(None))] {
            let mut options = PlanOptions::default();
            let setting = options.set_unmodelled_from(model.as_ref(), UnmodelledGiven::default());
            assert_eq!(options, PlanOptions::default());
            assert_eq!(
                setting,
                UnmodelledSetting { position: UnmodelledFrom::Default, rotation: UnmodelledFrom::Default }
            );
        }
    }

    #[test]
    fn the_text_says_which_unmodelled_errors_it_sets() {
        let both =
            UnmodelledGiven::of_text("(unmodelled_mm: 0.3, unmodelled_mrad: 0.0, unmodelled_passes: 1)", "o.ron");
        assert_eq!(both.unwrap(), UnmodelledGiven { position: true, rotation: true });
        let named = UnmodelledGiven::of_text("PlanOptions(criterion: d, unmodelled_mrad: 0.5)", "o.ron");
        assert_eq!(named.unwrap(), UnmodelledGiven { position: false, rotation: true });
        assert_eq!(UnmodelledGiven::of_text("()", "o.ron").unwrap(), UnmodelledGiven::default());
        let err = UnmodelledGiven::of_text("(unmodelled_mm: 0.3,\n unmodelled_mrad: )", "o.ron").unwrap_err();
        assert!(err.to_string().contains("o.ron:2"), "{err}");
    }
}
