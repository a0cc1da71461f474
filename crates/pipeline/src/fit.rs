//! The fit of a method on a measurement set, and the evaluation of a fitted model.

use crate::ErrorKind;
use crate::auto::AutoChoice;
use crate::fit_options::FitOptions;
use effects::{
    EffectContext, EffectCorrection, EffectReport, EffectSelection, EffectSpec, IdentifiedEffect, effect_reports,
};
use errors::Error;
use measurements::MeasurementSet;
use measurements::{BoundSet, OutlierLine, list_lines};
use model::geometric::{GeometricFit, fit_geometry_with_prior, observations};
use model::{
    CalibratedModel, ErrorSummary, HeldoutEstimate, HeldoutSource, Method, ResidualGp, ResidualGpReport,
    SCHEMA_VERSION, evaluate,
};
use poe::identify::{
    IdentificationOptions, IdentificationReport, KinematicPrior, Loss, ParameterMask, Scope, identify_with_prior,
    posterior_covariance,
};
use robot::RobotDescription;
use serde::Serialize;
use std::borrow::Cow;

/// What a fit reports besides the model (`calib fit --json` prints it as it is).
#[derive(Debug, Clone, Serialize)]
pub struct FitReport {
    /// The method fitted.
    pub method: Method,
    /// Number of training rows.
    pub n: usize,
    /// Whether the data had orientations.
    pub full_pose: bool,
    /// Training errors of the nominal model, registered into the tracker frame.
    pub before: ErrorSummary,
    /// Training errors of the fitted model.
    pub after: ErrorSummary,
    /// The geometric identification's report (with the effects, where there are some): errors
    /// per iteration, why it stopped (`termination`, `converged`, `final_cost`,
    /// `gradient_cosine`), rank, condition number, the unidentifiable directions in words.
    pub identification: IdentificationReport,
    /// The joints that stand for several URDF joints moved by one motor (mimic joints folded
    /// into the joint they follow): what the folding made unobservable, in addition to
    /// `identification.unidentifiable` — only the stages' summed motion is seen, not how it splits
    /// between them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub folded: Vec<robot::FoldedJoint>,
    /// The effects identified with the geometry, their parameters by name.
    pub effects: Vec<EffectReport>,
    /// The GP stage's report, for the GP methods: its hyperparameters.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_gp: Option<ResidualGpReport>,
    /// The prior toward the nominal geometry: the configuration clusters of the data,
    /// each candidate strength's error on them held out, the chosen one and why (absent for
    /// `base-tool`, which identifies no link).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal_prior: Option<crate::PriorChoice>,
    /// What `--effects auto` chose and why.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub auto: Option<AutoChoice>,
    /// What each drift or thermal growth is beyond the span of `t_s` / `temp_c` it was fitted on,
    /// held or zero, and why: chosen by leaving one session out at a time where the training rows
    /// hold several, the kind's own rule with one. Empty without such an effect.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub beyond_span: Vec<crate::SpanChoice>,
    /// What each joint compliance or link deflection is beyond the payloads it was fitted on,
    /// held, zero or extended as fitted, and why: chosen by leaving out the lightest and the
    /// heaviest payload in turn where the training rows hold several, held otherwise.
    /// Empty without such an effect.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub beyond_payload: Vec<crate::PayloadChoice>,
    /// What the plausibility checks measured (absent below 4 rows).
    pub plausibility: Option<crate::PlausibilityReport>,
    /// The rows the identification named as gross outliers (`identification.robust` has the
    /// scales and thresholds), by line of the measurement file, most sigmas first: left out of the
    /// geometric fit, the effects and the GP under the default Huber loss.
    pub outliers: Vec<OutlierLine>,
    /// What the user should know before trusting the numbers above.
    pub warnings: Vec<FitWarning>,
    /// Wall and CPU seconds per phase, where the caller recorded them ([`timings::record`]
    /// around the fit: `calib fit` and the Python package do); empty otherwise, and then left
    /// out of the JSON.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub timings: Vec<timings::PhaseTime>,
}

/// A fit that ran but deserves caution.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum FitWarning {
    /// A plausibility check refused the data and `force` fitted it anyway
    /// ([`crate::PlausibilityOptions::force`]): the refusal as it would have been given.
    Forced {
        /// The refusal's message.
        refusal: String,
    },
    /// Few residual rows per identifiable parameter: the training error understates the held-out
    /// error ([`crate::FitOptions::min_redundancy`]).
    LowRedundancy {
        /// Residual rows (3 per position, 6 per pose).
        residual_rows: usize,
        /// Identifiable parameters (the rank of the identification).
        identifiable: usize,
        /// Their ratio.
        redundancy: f64,
        /// The ratio below which this warning is given.
        min_redundancy: f64,
    },
    /// The GP's hyperparameter search stopped before a tolerance was met for some outputs: the
    /// residual GP is usable but its hyperparameters are not at the likelihood's optimum.
    GpSearchNotConverged {
        /// Output columns (0–2 position, 3–5 rotation) of the kernels concerned.
        outputs: Vec<usize>,
        /// The most L-BFGS iterations any of them ran.
        iterations: usize,
    },
    /// Rows whose residual is beyond the outlier threshold of the robust loss: a
    /// mistyped value or a tracker that lost its target, which a least-squares fit would absorb
    /// without a word.
    GrossOutliers {
        /// The rows, by line, with their residuals (as [`FitReport::outliers`]).
        rows: Vec<OutlierLine>,
        /// The threshold, robust sigmas above the median residual.
        threshold_sigmas: f64,
        /// Whether the fit left them out (the Huber loss) or kept them (plain least squares).
        left_out: bool,
    },
    /// An effect whose features have one value on every training row (a backlash of a joint whose
    /// torque or force never changes sign, such as a vertical column's weight): it is a constant
    /// the geometry already holds, so its parameters mean nothing. The diagnosis does
    /// not offer such a term; named in `--effects`, it is fitted and its split from the geometry is
    /// the priors'.
    ConstantEffect {
        /// The effect's label.
        effect: String,
    },
    /// Rows whose stated uncertainty (`std_x_mm` …) is far above the other rows': a
    /// lost or half-occluded reflector, or a mistyped σ. They are weighted as if stated at the
    /// limit, not down to nothing ([`poe::identify::StatedNoise::far_above_median`]).
    StatedUncertaintyFarAbove {
        /// The rows, by line, with their stated σ over the median row's, largest first.
        rows: Vec<(u64, f64)>,
        /// The limit, times the median.
        far_above_median: f64,
    },
    /// The fitted model misses the training positions by more than the nominal robot placed by a
    /// rigid transform ([`crate::PlausibilityOptions::wrong_minimum_ratio`]): the identification
    /// stopped in a wrong minimum, and the model is not to be used.
    WrongMinimum {
        /// The fitted model's RMS position error on the training rows, mm.
        rms_mm: f64,
        /// The rigidly placed nominal robot's, mm (`plausibility.rotation_rms_mm`).
        rigid_rms_mm: f64,
    },
}

impl std::fmt::Display for FitWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FitWarning::Forced { refusal } => write!(f, "fitted despite the plausibility check (--force): {refusal}"),
            FitWarning::LowRedundancy { residual_rows, identifiable, redundancy, min_redundancy } => write!(
                f,
                "{residual_rows} residual rows for {identifiable} identifiable parameters ({redundancy:.2} per parameter, \
                 below {min_redundancy}): the training error understates the error on new poses; measure more poses \
                 or check the model on held-out data"
            ),
            FitWarning::GpSearchNotConverged { outputs, iterations } => write!(
                f,
                "the GP's hyperparameter search for output(s) {outputs:?} stopped after {iterations} iterations \
                 without meeting its tolerance: the residual GP may be less accurate than it could be; check it on \
                 held-out data"
            ),
            FitWarning::GrossOutliers { rows, threshold_sigmas, left_out } => write!(
                f,
                "{} row(s) of the data are gross outliers, beyond {threshold_sigmas} robust sigmas of the geometric \
                 fit's residual: {}; {}; check them (a mistyped value, a tracker that lost its target)",
                rows.len(),
                list_lines(rows),
                if *left_out { "left out of the fit" } else { "KEPT in the fit (least-squares loss)" }
            ),
            FitWarning::ConstantEffect { effect } => write!(
                f,
                "effect {effect} has the same value on every training row (a torque or force that never changes \
                 sign): a constant offset the geometry already holds, so its parameters mean nothing; leave it out"
            ),
            FitWarning::StatedUncertaintyFarAbove { rows, far_above_median } => {
                let listed: Vec<String> =
                    rows.iter().take(10).map(|(line, ratio)| format!("line {line} ({ratio:.0}×)")).collect();
                let more = if rows.len() > 10 { format!(" and {} more", rows.len() - 10) } else { String::new() };
                write!(
                    f,
                    "{} row(s) state an uncertainty more than {far_above_median} times the median row's: {}{more}; \
                     weighted as if {far_above_median} times, not left out: check them (a lost or half-occluded \
                     reflector, a mistyped std column)",
                    rows.len(),
                    listed.join(", ")
                )
            }
            FitWarning::WrongMinimum { rms_mm, rigid_rms_mm } => write!(
                f,
                "the fitted model misses the training positions by {rms_mm:.3} mm RMS, more than the nominal robot \
                 placed by a rigid transform does ({rigid_rms_mm:.3} mm): the identification stopped in a wrong \
                 minimum; do NOT use this model (report the data: the fit should never do worse than that placement)"
            ),
        }
    }
}

/// The posterior uncertainty of the geometry and effects ([`model::EffectUncertainty`]) from the
/// identification's covariance, its σ at the training rows, and the σ beyond which the model falls
/// back to the geometry (`None` where the covariance is not definite).
fn effect_uncertainty(
    kinematics: &poe::LocalPoe,
    effects: &[IdentifiedEffect],
    free: Vec<usize>,
    covariance: &[f64],
    data: &BoundSet<'_>,
    options: &crate::EffectOptions,
) -> Result<Option<model::EffectUncertainty>, Error> {
    let p = free.len() + effects.iter().map(IdentifiedEffect::parameter_count).sum::<usize>();
    let Some(factor) = model::EffectUncertainty::factor_of(covariance, p) else { return Ok(None) };
    let mut uncertainty =
        model::EffectUncertainty { free, factor, training_sigma_m: [0.0; 2], fallback_sigma_m: f64::MAX / 2.0 };
    let mut sigmas = Vec::with_capacity(data.len());
    for (row, tool) in data.iter() {
        let sigma = uncertainty.sigma(kinematics, effects, row, tool)?;
        sigmas.push(model::EffectUncertainty::position(&sigma));
    }
    sigmas.sort_by(f64::total_cmp);
    let median = sigmas.get(sigmas.len() / 2).copied().unwrap_or(0.0);
    let largest = sigmas.last().copied().unwrap_or(0.0);
    uncertainty.training_sigma_m = [median, largest];
    // inf (never), and training rows without any σ to compare with, keep a limit no row reaches.
    let limit = options.fallback_sigma_ratio * largest;
    uncertainty.fallback_sigma_m = if limit.is_finite() && limit > 0.0 { limit } else { f64::MAX / 2.0 };
    Ok(Some(uncertainty))
}

/// The geometry's own uncertainty ([`model::GeometryUncertainty`]) of `kinematics` fitted on
/// `data`: the kinematic block of the posterior covariance at the fit under the prior of `widths`
/// (translation m, rotation rad) about the placed nominal `placed`, with the effects' correction
/// at its fitted parameters where there is one. `None` where the covariance cannot be had.
#[allow(clippy::too_many_arguments)]
fn geometry_uncertainty(
    kinematics: &poe::LocalPoe,
    placed: &poe::LocalPoe,
    widths: (f64, f64),
    mask: &ParameterMask,
    correction: Option<(&dyn poe::identify::PoseCorrection, &[f64])>,
    data: &MeasurementSet,
    bound: &BoundSet<'_>,
    options: &IdentificationOptions,
) -> Result<Option<model::GeometryUncertainty>, Error> {
    let prior = KinematicPrior::on_links(placed.clone(), widths.0, widths.1);
    let covariance = posterior_covariance(kinematics, &observations(data), mask, correction, &prior, options)
        .map_err(Error::kinematics)?;
    let free = mask.free_indices();
    let dim = free.len() + correction.map_or(0, |(_, theta)| theta.len());
    model::GeometryUncertainty::of(kinematics, free, &covariance, dim, bound)
}

/// The effects a list names, built on the training rows.
fn build_effects(
    specs: &[EffectSpec],
    robot: &RobotDescription,
    kinematics: &poe::LocalPoe,
    data: &BoundSet<'_>,
    options: &crate::EffectOptions,
) -> Result<Vec<IdentifiedEffect>, Error> {
    let context = EffectContext { robot, kinematics, gear: options.gear, hold_beyond_span: options.hold_beyond_span };
    specs.iter().map(|spec| IdentifiedEffect::new(spec, &context, data)).collect()
}

/// Fits `method` to `data` for `robot` (paper Section III: step 1, then step 2 for the GP
/// methods, trained on the error the identified model leaves on the same rows, Eq. 8). Effects
/// named in `options.effects` are identified jointly with the geometry, after it has been fitted
/// alone, and before the GP.
pub fn fit(
    robot: &RobotDescription,
    data: &MeasurementSet,
    method: Method,
    options: &FitOptions,
) -> Result<(CalibratedModel, FitReport), Error> {
    // The one binding of the fit: the joints checked, each row's tool its own index, since the
    // model takes the data's tools in their order.
    let bound = BoundSet::to_robot(data, &robot.joint_kinds())?;
    let inputs = Inputs { robot, data, bound: &bound, options };
    let (findings, mut warnings) = plausibility(&inputs)?;
    let scope = if method == Method::BaseTool { Scope::BaseTool } else { Scope::Full };
    let (mut model, mut geometry) = fit_geometry_alone(&inputs, method, scope)?;
    let mut auto = None;
    let specs = effect_specs(&inputs, &mut auto)?;
    let (identification, effects) = if specs.is_empty() {
        (geometry.report, EffectsFit::default())
    } else {
        let on = EffectsBasis { scope, registered: &geometry.registered, prior: &mut geometry.prior };
        fit_effects(&inputs, &specs, on, &mut model, &mut warnings)?
    };
    let outliers = OutlierLine::of(&identification.robust, data);
    let left_out = identification.robust.loss == Loss::Huber && !outliers.is_empty();
    let residual_gp = if method.uses_gp() {
        Some(fit_residual_gp(&inputs, method, &identification, left_out, &mut model, &mut auto)?)
    } else {
        None
    };
    let (before, after) = checked_training_errors(&model, geometry.registered, &bound, method)?;
    let distinct = model::RepeatGroups::of(&data.rows, options.heldout.repeat_tolerance).groups.len();
    model.heldout = heldout_estimate(&after, &identification, residual_gp.as_ref(), (distinct, data.rows.len()));
    let judged = Judged { identification: &identification, outliers: &outliers, left_out, after: &after };
    warnings.extend(quality_warnings(&inputs, &judged, findings.report.as_ref(), residual_gp.as_ref()));
    model.fit_warnings = Some(warnings.iter().map(ToString::to_string).collect());
    let report = FitReport {
        method,
        n: data.rows.len(),
        full_pose: data.full_pose,
        before,
        after,
        identification,
        folded: robot.folded.clone(),
        effects: effects.reports,
        residual_gp,
        nominal_prior: geometry.prior,
        auto,
        beyond_span: effects.beyond_span,
        beyond_payload: effects.beyond_payload,
        plausibility: findings.report,
        outliers,
        warnings,
        timings: Vec::new(),
    };
    Ok((model, report))
}

/// What every phase of one fit reads.
struct Inputs<'a> {
    robot: &'a RobotDescription,
    data: &'a MeasurementSet,
    /// `data` bound to `robot`.
    bound: &'a BoundSet<'a>,
    options: &'a FitOptions,
}

/// Before anything is fitted: a unit mistake or a mirrored frame fits as well as the right data,
/// so it is refused here, or with `force` reported as a warning.
fn plausibility(inputs: &Inputs<'_>) -> Result<(crate::plausibility::Findings, Vec<FitWarning>), Error> {
    let options = &inputs.options.plausibility;
    let mut findings =
        timings::phase("plausibility", || crate::plausibility::check(inputs.robot, inputs.bound, options))?;
    let mut warnings = Vec::new();
    for refusal in std::mem::take(&mut findings.refusals) {
        if !options.force {
            return Err(refusal);
        }
        warnings.push(FitWarning::Forced { refusal: refusal.to_string() });
    }
    Ok((findings, warnings))
}

/// The effects `options.effects` names, or those the diagnosis chooses (`--effects auto`, its
/// choice set in `auto`).
fn effect_specs(inputs: &Inputs<'_>, auto: &mut Option<AutoChoice>) -> Result<Vec<EffectSpec>, Error> {
    let effects = &inputs.options.effects;
    Ok(match &effects.selection {
        EffectSelection::None => Vec::new(),
        EffectSelection::List(list) => list.clone(),
        EffectSelection::Auto => {
            let choice =
                timings::phase("diagnosis", || crate::auto::choose(inputs.robot, inputs.bound, &effects.diagnose))?;
            let chosen = choice.chosen.clone();
            *auto = Some(choice);
            chosen
        }
    })
}

/// The check `read_model` runs, on the text `write_model` writes: a fit never hands over a model
/// that its own file would be refused for, and the cause shows here. Then the training errors of
/// the nominal model placed by `registered` and of the fitted `model`.
fn checked_training_errors(
    model: &CalibratedModel,
    registered: poe::LocalPoe,
    bound: &BoundSet<'_>,
    method: Method,
) -> Result<(ErrorSummary, ErrorSummary), Error> {
    timings::phase("model file check", || {
        let text = model::model_text(model, "the fitted model")?;
        model.check(&text, "the fitted model").map_err(|source| {
            Error::new(ErrorKind::FittedModelRefused { method: method.to_string(), source: Box::new(source) })
        })
    })?;
    let registered = CalibratedModel {
        kinematics: registered,
        effects: Vec::new(),
        fallback_kinematics: None,
        residual_gp: None,
        ..model.clone()
    };
    // `registered` and `model` share the data's tools, so the one binding serves both.
    timings::phase("training errors", || {
        Ok::<_, Error>((evaluate(&registered, bound)?.summary, evaluate(model, bound)?.summary))
    })
}

/// The geometry fitted alone.
struct Geometry {
    /// The nominal model placed in the tracker frame (the "before" of the report).
    registered: poe::LocalPoe,
    report: IdentificationReport,
    /// The prior toward the nominal geometry, its strength chosen on held-out configuration
    /// clusters (none for `base-tool`, which identifies no link).
    prior: Option<crate::PriorChoice>,
}

/// The geometry fitted alone under the prior toward the nominal geometry, and the model that
/// holds it with its uncertainty.
fn fit_geometry_alone(inputs: &Inputs<'_>, method: Method, scope: Scope) -> Result<(CalibratedModel, Geometry), Error> {
    let (robot, data, options) = (inputs.robot, inputs.data, inputs.options);
    let nominal = robot.nominal_model()?;
    let nominal_prior = match scope {
        Scope::Full => Some(timings::phase("prior choice", || {
            crate::choose_prior(&nominal, data, &options.identification, &options.nominal_prior)
        })?),
        Scope::BaseTool => None,
    };
    let prior_sigmas = nominal_prior.as_ref().and_then(crate::PriorChoice::chosen);
    let GeometricFit { model: kinematics, registered, report } = timings::phase("identification", || {
        fit_geometry_with_prior(&nominal, data, scope, prior_sigmas, &options.identification)
    })?;
    let mut model = CalibratedModel {
        schema_version: SCHEMA_VERSION,
        robot: robot.name.clone(),
        method,
        full_pose: data.full_pose,
        tools: data.tools.clone(),
        kinematics,
        effects: Vec::new(),
        fallback_kinematics: None,
        effect_uncertainty: None,
        geometry_uncertainty: None,
        residual_gp: None,
        training_range: model::TrainingRange::of(&data.rows),
        joint_limits: model::stored_limits(&robot.limits()),
        heldout: None,
        fit_warnings: Some(Vec::new()),
        robot_description: Some(robot.clone()),
    };
    // The geometry's own uncertainty: its posterior under the nominal's tolerance, whatever
    // strength the held-out clusters chose for the fit (a stronger one says how to fit, not how
    // far the geometry may be off where the data does not reach). Without a prior the directions
    // no training pose sees have no variance, and a σ would say nothing.
    if let Some(widths) = nominal_prior.as_ref().and_then(crate::PriorChoice::posterior) {
        let mask = ParameterMask::all(model.kinematics.layout());
        model.geometry_uncertainty = timings::phase("geometry uncertainty", || {
            geometry_uncertainty(
                &model.kinematics,
                &registered,
                widths,
                &mask,
                None,
                data,
                inputs.bound,
                &options.identification,
            )
        })?;
    }
    Ok((model, Geometry { registered, report, prior: nominal_prior }))
}

/// Where the effects' fit starts from: the geometry fitted alone.
struct EffectsBasis<'a> {
    scope: Scope,
    /// The nominal model placed in the tracker frame.
    registered: &'a poe::LocalPoe,
    /// The prior toward the nominal geometry; the effects' fit sets its strength with the effects.
    prior: &'a mut Option<crate::PriorChoice>,
}

/// What the effects' fit with the geometry adds to the report.
#[derive(Default)]
struct EffectsFit {
    reports: Vec<EffectReport>,
    beyond_span: Vec<crate::SpanChoice>,
    beyond_payload: Vec<crate::PayloadChoice>,
}

/// The effects `specs` name, identified jointly with the geometry: `model`'s kinematics become
/// the joint fit's (the geometry alone its fallback), its effects and their uncertainties are set.
/// Returns the joint fit's identification report.
fn fit_effects(
    inputs: &Inputs<'_>,
    specs: &[EffectSpec],
    on: EffectsBasis<'_>,
    model: &mut CalibratedModel,
    warnings: &mut Vec<FitWarning>,
) -> Result<(IdentificationReport, EffectsFit), Error> {
    let (robot, data, bound, options) = (inputs.robot, inputs.data, inputs.bound, inputs.options);
    let mut effects = build_effects(specs, robot, &model.kinematics, bound, &options.effects)?;
    for effect in &effects {
        if effect.features_constant(bound)? {
            warnings.push(FitWarning::ConstantEffect { effect: effect.label() });
        }
    }
    let correction = EffectCorrection::new(&effects, bound, options.effects.prior_sigma)?;
    let layout = model.kinematics.layout();
    let mask = if on.scope == Scope::BaseTool { ParameterMask::base_tool(layout) } else { ParameterMask::all(layout) };
    let id_options = IdentificationOptions {
        solver: options.effects.solver,
        max_iterations: options.effects.max_iterations,
        ..options.identification.clone()
    };
    let identify = |prior: Option<&KinematicPrior>| {
        identify_with_prior(&model.kinematics, &observations(data), &mask, Some(&correction), prior, &id_options)
    };
    // The effects are fitted under the same prior, about the same placed nominal model, as the
    // geometry alone (otherwise they would free what it held), weighed against the residual the
    // geometry with its effects leaves: one fit without the prior more.
    let prior_sigmas = on.prior.as_ref().and_then(crate::PriorChoice::chosen);
    let sigmas = match on.prior.as_mut().filter(|_| prior_sigmas.is_some()) {
        Some(choice) => {
            let plain = timings::phase("effects identification without the prior", || identify(None))
                .map_err(Error::kinematics)?;
            choice.for_effects(&plain.report)
        }
        None => None,
    };
    let prior = sigmas.map(|(t, r)| KinematicPrior::on_links(on.registered.clone(), t, r));
    let fitted = timings::phase("effects identification", || identify(prior.as_ref())).map_err(Error::kinematics)?;
    EffectCorrection::distribute(&mut effects, &fitted.correction);
    for effect in &mut effects {
        effect.after_fit(&data.rows);
    }
    let reports = effect_reports(&effects, &fitted.report.held_at_prior, &robot.joint_kinds());
    model.fallback_kinematics = Some(std::mem::replace(&mut model.kinematics, fitted.model));
    if let Some(widths) = on.prior.as_ref().and_then(crate::PriorChoice::posterior_with_effects) {
        // The kinematics' marginal of the fit with the effects: the model's kinematics now.
        let with = Some((&correction as &dyn poe::identify::PoseCorrection, fitted.correction.as_slice()));
        model.geometry_uncertainty = timings::phase("geometry uncertainty", || {
            geometry_uncertainty(&model.kinematics, on.registered, widths, &mask, with, data, bound, &id_options)
        })?;
    }
    model.effect_uncertainty = timings::phase("effects uncertainty", || {
        effect_uncertainty(
            &model.kinematics,
            &effects,
            mask.free_indices(),
            &fitted.covariance,
            bound,
            &options.effects,
        )
    })?;
    let (beyond_span, beyond_payload) = beyond_fitted(inputs, specs, &mut effects)?;
    model.effects = effects;
    Ok((fitted.report, EffectsFit { reports, beyond_span, beyond_payload }))
}

/// What each effect is beyond the sessions and the payloads it was fitted on, chosen by fits
/// (`poe`, with the same options) that hold some of them out.
fn beyond_fitted(
    inputs: &Inputs<'_>,
    specs: &[EffectSpec],
    effects: &mut [IdentifiedEffect],
) -> Result<(Vec<crate::SpanChoice>, Vec<crate::PayloadChoice>), Error> {
    let (robot, data, options) = (inputs.robot, inputs.data, inputs.options);
    let beyond_span = timings::phase("beyond span (sessions held out)", || {
        crate::sessions::choose(data, specs, effects, options, |train, fold_options| {
            fit(robot, train, Method::Poe, fold_options).map(|(model, _)| model)
        })
    })?;
    let beyond_payload = timings::phase("beyond payload (payloads held out)", || {
        crate::payloads::choose(data, specs, effects, options, |train, fold_options| {
            fit(robot, train, Method::Poe, fold_options).map(|(model, _)| model)
        })
    })?;
    Ok((beyond_span, beyond_payload))
}

/// The residual GP on what the model leaves on the training rows (the rows the identification
/// left out as gross outliers aside), with its fallback GP for the geometry alone where there are
/// effects; `--effects auto`'s prediction with it on top is set in `auto`.
fn fit_residual_gp(
    inputs: &Inputs<'_>,
    method: Method,
    identification: &IdentificationReport,
    left_out: bool,
    model: &mut CalibratedModel,
    auto: &mut Option<AutoChoice>,
) -> Result<ResidualGpReport, Error> {
    let (bound, options) = (inputs.bound, inputs.options);
    let with_payload = method == Method::PoeGpLoad;
    // The GP learns what the geometry leaves on the rows the geometry was fitted to: an
    // outlier's metre would otherwise be its largest "structure".
    let kept = if left_out { Cow::Owned(bound.without(&identification.robust.outliers)) } else { Cow::Borrowed(bound) };
    let poses = model.geometric_poses(&kept)?;
    let repeats = model::RepeatGroups::of(kept.rows(), options.heldout.repeat_tolerance);
    let (mut fitted, report) =
        timings::phase("GP", || ResidualGp::fit(&poses, kept.set(), with_payload, &options.residual_gp, &repeats))?;
    if let (Some(alone), false) = (&model.fallback_kinematics, model.effects.is_empty()) {
        let alone_poses = kept
            .rows()
            .iter()
            .zip(kept.tools())
            .map(|(row, &tool)| alone.forward(&row.q, tool))
            .collect::<Result<Vec<_>, _>>()
            .map_err(Error::kinematics)?;
        timings::phase("fallback GP", || fitted.fit_fallback(&alone_poses, kept.set(), &options.residual_gp))?;
    }
    // `--effects auto`'s prediction with this GP on top, its hyperparameters held fixed.
    if let Some(choice) = auto {
        choice.predicted_with_gp = timings::phase("held-out prediction with the GP", || {
            crate::gp_folds::predicted_with_gp(
                &fitted,
                &choice.folds,
                &options.residual_gp.gp,
                options.heldout.repeat_tolerance,
            )
        })?;
        if choice.predicted_with_gp.as_ref().and_then(|p| p.fallback_gp).is_some_and(|c| !c.kept) {
            fitted.fallback = None;
        }
    }
    model.residual_gp = Some(fitted);
    Ok(report)
}

/// What the finished fit is judged on.
struct Judged<'a> {
    identification: &'a IdentificationReport,
    outliers: &'a [OutlierLine],
    /// Whether the fit left the outliers out.
    left_out: bool,
    /// The fitted model's training errors.
    after: &'a ErrorSummary,
}

/// The warnings the finished fit deserves, in the order the report lists them.
fn quality_warnings(
    inputs: &Inputs<'_>,
    judged: &Judged<'_>,
    plausible: Option<&crate::PlausibilityReport>,
    residual_gp: Option<&ResidualGpReport>,
) -> Vec<FitWarning> {
    let (identification, outliers, options) = (judged.identification, judged.outliers, inputs.options);
    let mut warnings = Vec::new();
    if identification.redundancy() < options.min_redundancy {
        warnings.push(FitWarning::LowRedundancy {
            residual_rows: identification.residual_rows,
            identifiable: identification.rank,
            redundancy: identification.redundancy(),
            min_redundancy: options.min_redundancy,
        });
    }
    if outliers.is_empty() {
        let ratio = options.plausibility.wrong_minimum_ratio;
        warnings.extend(wrong_minimum(judged.after.rms_position_error_mm, plausible, ratio));
    }
    if !outliers.is_empty() {
        warnings.push(FitWarning::GrossOutliers {
            rows: outliers.to_vec(),
            threshold_sigmas: identification.robust.outlier_threshold,
            left_out: judged.left_out,
        });
    }
    if let Some(stated) = identification.stated_noise.as_ref().filter(|s| !s.far_above.is_empty()) {
        let data = inputs.data;
        let rows = stated.far_above.iter().map(|&(i, ratio)| (data.rows.get(i).map_or(0, |r| r.line), ratio));
        warnings.push(FitWarning::StatedUncertaintyFarAbove {
            rows: rows.collect(),
            far_above_median: stated.far_above_median,
        });
    }
    if let Some(report) = residual_gp {
        let unconverged = report.gp.unconverged();
        if !unconverged.is_empty() {
            warnings.push(FitWarning::GpSearchNotConverged {
                outputs: unconverged.iter().flat_map(|(o, _)| o.iter().copied()).collect(),
                iterations: unconverged.iter().map(|(_, i)| *i).max().unwrap_or(0),
            });
        }
    }
    warnings
}

/// The warning for a fit whose training RMS (`rms_mm`) is above `ratio` times that of the rigidly
/// placed nominal robot (`None` without a plausibility report: too few rows, no positions).
fn wrong_minimum(rms_mm: f64, plausible: Option<&crate::PlausibilityReport>, ratio: f64) -> Option<FitWarning> {
    let rigid_rms_mm = plausible?.rotation_rms_mm;
    (rms_mm > ratio * rigid_rms_mm).then_some(FitWarning::WrongMinimum { rms_mm, rigid_rms_mm })
}

/// The fit's estimate of its held-out error, kept in the model (`calib register` judges against
/// it): the exact GP's leave-one-out error where there is a GP (`None` for the sparse GP, whose
/// training error says nothing of new poses), else the training error corrected for the
/// identifiable parameters, the effects' among them. Both count a configuration measured more
/// than once as one (`distinct` configurations of the rows): the GP's error leaves the repeats of
/// a configuration out together, the correction counts the residual rows of distinct
/// configurations. (For `--effects auto` the diagnosis's cross-validated error was the other
/// candidate; `docs/results/off-training.md` has both against the UR10's other half.)
fn heldout_estimate(
    after: &ErrorSummary,
    identification: &IdentificationReport,
    residual_gp: Option<&ResidualGpReport>,
    distinct: (usize, usize),
) -> Option<HeldoutEstimate> {
    if let Some(gp) = residual_gp {
        if let Some(grouped) = &gp.leave_group_out {
            return HeldoutEstimate::new(grouped.mean_position_error_mm, HeldoutSource::GpLeaveGroupOut);
        }
        let loo = gp.leave_one_out.as_ref()?;
        return HeldoutEstimate::new(loo.mean_position_error_mm, HeldoutSource::GpLeaveOneOut);
    }
    HeldoutEstimate::degrees_of_freedom(
        after.mean_position_error_mm,
        identification.residual_rows,
        identification.rank,
        distinct,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plausible(rigid_rms_mm: f64) -> crate::PlausibilityReport {
        crate::PlausibilityReport {
            measured_spread_mm: 1000.0,
            robot_spread_mm: 1000.0,
            scale_ratio: Some(1.0),
            rotation_rms_mm: rigid_rms_mm,
            reflection_rms_mm: 800.0,
            out_of_plane_mm: None,
        }
    }

    #[test]
    fn a_fit_worse_than_the_rigid_placement_is_named_a_wrong_minimum() {
        // A 7-axis campaign's fit stopped in a wrong minimum: 894.5 mm RMS against the placement's 4.0.
        let warning = wrong_minimum(894.5, Some(&plausible(4.01)), 2.0).expect("a wrong minimum");
        assert!(warning.to_string().contains("894.500 mm RMS") && warning.to_string().contains("do NOT use"));
        // A fit at or below the placement, or within the ratio of it, is not.
        assert_eq!(wrong_minimum(3.79, Some(&plausible(4.01)), 2.0), None);
        assert_eq!(wrong_minimum(7.9, Some(&plausible(4.01)), 2.0), None);
        assert_eq!(wrong_minimum(894.5, None, 2.0), None);
    }
}
