//! The options of a fit, and the options file (`calib fit --options FIT.ron`) that sets any of
//! them: unknown fields are refused at their line and column, values checked once.

use diagnose::DiagnoseOptions;
use effects::EffectSelection;
use errors::{CommonKind, Error, OptionOutOfRange, option};
use model::ResidualGpOptions;
use poe::identify::{IdentificationOptions, Solver};
use serde::{Deserialize, Serialize};
use std::path::Path;

mod selection_text {
    use effects::EffectSelection;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(selection: &EffectSelection, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&selection.to_string())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<EffectSelection, D::Error> {
        let text = String::deserialize(deserializer)?;
        if text == "none" {
            return Ok(EffectSelection::None);
        }
        text.parse().map_err(serde::de::Error::custom)
    }
}

/// How the non-geometric effects are identified with the geometry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EffectOptions {
    /// Which effects (`--effects`; none by default: the paper's methods).
    #[serde(with = "selection_text")]
    pub selection: EffectSelection,
    /// Prior standard deviation of every effect parameter about zero, in the unit of its scaled
    /// feature: radians of joint deflection (gear, compliance, backlash), metres or radians of
    /// drift, strain of thermal growth, each at the feature's RMS over the training rows. A ridge
    /// that holds what the data does not determine at zero. 1 mrad is the size one term of a
    /// joint-angle error reaches on an industrial arm (compliance at the RMS torque 0.1–1 mrad on
    /// the simulated IRB 4400 and iiwa; gear error tens of µrad); a well-excited parameter is
    /// determined 1e4 to 1e6 times more precisely by the data, so the prior barely moves it. On the
    /// real UR10 (train on series C, 32 harmonics on joints 1–3) a prior of 5 mrad let the series
    /// run off outside the angles C covers (11.6 mm on series B, whose joint 1 spans other angles),
    /// 1 mrad keeps it at 1.20 mm there (poe: 1.24 mm) with the same held-out error on C (0.137 mm).
    pub prior_sigma: f64,
    /// The solver of the joint identification. Levenberg–Marquardt with the prior: the paper's
    /// pseudo-inverse cannot hold unexcited effect directions at their prior.
    pub solver: Solver,
    /// Iteration limit of the joint identification (the geometry alone keeps
    /// `identification.max_iterations`). Effects whose regressors are nearly collinear with the
    /// geometry converge slowly: on the 7-axis campaign with joints 3–7 fixed, joint compliance
    /// through the gravity-torque regressors (81 parameters, condition number 1e9) took 64 to 98
    /// Levenberg–Marquardt iterations to meet the cost or gradient criterion.
    pub max_iterations: usize,
    /// How gear series are held and faded outside the angles they were fitted on.
    pub gear: effects::GearOptions,
    /// Thermal growth and drift are applied as fitted up to this fraction of their fitted span
    /// of `temp_c` / `t_s` beyond either end; further out the growth is held at that value (a
    /// function of the temperature) and the drift falls back to zero (a drift
    /// fitted within a 73-minute session was carried on as a straight line eight days later). 1:
    /// a linear term is trusted as far beyond its data as the data reaches (the simulated warm-up
    /// and drift campaigns of `tests/effects.rs` are tested 0.6 of their span past the training
    /// rows, where the simulated physics is linear); a day later it is held.
    pub hold_beyond_span: f64,
    /// The measuring sessions of the training rows (split by gaps in `t_s`), from which the fit
    /// chooses whether a drift or a thermal growth is held or zero beyond the span above.
    pub sessions: SessionOptions,
    /// The payload groups of the training rows, from which the fit chooses whether a term driven
    /// by the payload's load (joint compliance, link deflection) is held, zero or extended beyond
    /// the payloads it was fitted on.
    pub payloads: PayloadOptions,
    /// Where the posterior σ of the geometry-and-effects model at a row (the tool point's
    /// position) exceeds this multiple of the largest σ over the training rows, the model falls
    /// back to the geometry fitted alone, fully from twice it (`model::EffectUncertainty`).
    /// Such a row excites a combination of the effects' parameters that no training row did (the
    /// home pose of UR10 series D, fitted on D's even rows: σ 26 mm against at most 0.21 mm on the
    /// training rows, and the effects miss it by 28 mm where the geometry misses by 0.3). The σ
    /// is a linear posterior: where an effect has absorbed some of what the geometry could not
    /// reach in the training band, it is confident and wrong off the band (the simulated IRB 4400
    /// trained on `|q2 + q3| < 0.15`, `tests/effects.rs`: errors of 0.2–1 mm where σ is 3–10×
    /// the training rows'), so the limit is low: 2 keeps the geometry's error off that band within
    /// a quarter of the noise on both seeds, where 4 left seed 62 at 2.5× the geometry's. A
    /// payload up to twice the heaviest trained (a compliance term's σ grows with the load) is
    /// still applied in full. `inf`: never fall back by σ.
    pub fallback_sigma_ratio: f64,
    /// The diagnosis that `auto` runs on the training data.
    pub diagnose: DiagnoseOptions,
}

impl Default for EffectOptions {
    fn default() -> Self {
        Self {
            selection: EffectSelection::None,
            prior_sigma: 1e-3,
            solver: Solver::LevenbergMarquardt,
            max_iterations: 300,
            gear: effects::GearOptions::default(),
            hold_beyond_span: effects::HOLD_BEYOND_SPAN,
            sessions: SessionOptions::default(),
            payloads: PayloadOptions::default(),
            fallback_sigma_ratio: 2.0,
            diagnose: DiagnoseOptions::default(),
        }
    }
}

/// Options of a fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitOptions {
    /// The geometric identification.
    pub identification: IdentificationOptions,
    /// The GP on the residual, step 2 (methods `poe-gp`, `poe-gp-load`). Options files written
    /// before SPEC version 5 call the section `compensation`, which still reads.
    #[serde(alias = "compensation")]
    pub residual_gp: ResidualGpOptions,
    /// Non-geometric effects identified with the geometry, before any GP. Beyond the paper.
    pub effects: EffectOptions,
    /// Warn when the residual rows per identifiable parameter fall below this. 3, from the
    /// expected squared residuals of a linear least-squares fit of `p` parameters to `r` rows of
    /// noise σ: `σ²(1 − p/r)` on the training rows, about `σ²(1 + p/r)` held out; at `r/p = 3` the
    /// held-out RMS is already √2 times the training RMS, so the training error a user reads
    /// flatters the model by more than 40 %.
    pub min_redundancy: f64,
    /// The checks run on the data before anything is fitted (units, handedness, joint limits),
    /// and `force`, which turns their refusals into warnings.
    #[serde(default)]
    pub plausibility: crate::PlausibilityOptions,
    /// The prior toward the nominal geometry and how its strength is chosen.
    pub nominal_prior: crate::NominalPriorOptions,
    /// How the held-out estimate kept in the model treats repeated configurations.
    pub heldout: model::HeldoutOptions,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            identification: IdentificationOptions::default(),
            residual_gp: ResidualGpOptions::default(),
            effects: EffectOptions::default(),
            min_redundancy: 3.0,
            plausibility: crate::PlausibilityOptions::default(),
            nominal_prior: crate::NominalPriorOptions::default(),
            heldout: model::HeldoutOptions::default(),
        }
    }
}

impl FitOptions {
    /// The options with `effects` identified with the geometry.
    pub fn with_effects(mut self, selection: EffectSelection) -> Self {
        self.effects.selection = selection;
        self
    }
}

impl FitOptions {
    /// Reads an options file (RON; every field optional, unknown fields refused).
    pub fn read(path: &Path) -> Result<Self, Error> {
        let text = errors::ron_position::read_text(path)?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Parses options from RON text and checks them; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Self, Error> {
        let options: FitOptions =
            errors::ron_position::ron_options().from_str(text).map_err(|e| Error::ron(file, &e))?;
        options.validate().map_err(|(field, message)| {
            let (line, column) = errors::ron_position::field_position(text, field, 0);
            Error::at_line(file.to_owned(), line as u64, column, CommonKind::RonFormat { message })
        })?;
        Ok(options)
    }

    /// Checks every value once: the identification's, and the effects' prior.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        // poe and gp know no `errors`: their refusal of an option has its shape, carried over whole.
        self.identification.validate().map_err(|error| match error {
            poe::Error::InvalidOption { name, value, expected } => {
                OptionOutOfRange::new(name, value, expected).in_file("identification")
            }
            other => ("identification", format!("identification: {other}")),
        })?;
        option::at_least_one("max_iterations", self.effects.max_iterations).map_err(|e| e.in_file("effects"))?;
        let redundancy = self.min_redundancy;
        let accepted = redundancy.is_finite() && redundancy >= 1.0;
        OptionOutOfRange::check("min_redundancy", redundancy, accepted, "a finite number of at least 1")
            .map_err(|e| e.in_file(""))?;
        self.residual_gp.validate_fade().map_err(|e| e.in_file("residual_gp"))?;
        self.residual_gp.validate_inputs()?;
        self.residual_gp.gp.validate().map_err(|error| match error {
            gp::Error::InvalidOption { field, value, expected } => {
                OptionOutOfRange::new(field, value, expected).in_file("residual_gp.gp")
            }
            other => ("gp", format!("residual_gp.gp: {other}")),
        })?;
        self.effects.gear.validate().map_err(|e| e.in_file("effects.gear"))?;
        let hold = self.effects.hold_beyond_span;
        let accepted = hold.is_finite() && hold >= 0.0;
        OptionOutOfRange::check("hold_beyond_span", hold, accepted, "a number of at least 0")
            .map_err(|e| e.in_file("effects"))?;
        self.effects.sessions.validate().map_err(|e| e.in_file("effects.sessions"))?;
        self.effects.payloads.validate().map_err(|e| e.in_file("effects.payloads"))?;
        let ratio = self.effects.fallback_sigma_ratio;
        let accepted = !ratio.is_nan() && ratio >= 1.0;
        OptionOutOfRange::check("fallback_sigma_ratio", ratio, accepted, "a number of at least 1 (inf for never)")
            .map_err(|e| e.in_file("effects"))?;
        self.plausibility.validate().map_err(|e| e.in_file("plausibility"))?;
        self.nominal_prior.validate().map_err(|e| e.in_file("nominal_prior"))?;
        self.heldout.validate().map_err(|e| e.in_file("heldout"))?;
        let prior = self.effects.prior_sigma;
        OptionOutOfRange::check(
            "prior_sigma",
            prior,
            !prior.is_nan() && prior > 0.0,
            "a number above 0 (inf for none)",
        )
        .map_err(|e| e.in_file("effects"))?;
        Ok(())
    }
}

/// How the training rows are split into sessions, and whether the rule beyond the span is chosen
/// from them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SessionOptions {
    /// Choose the rule by leaving one session out at a time where there are several; `false`:
    /// each kind's own rule (drift: zero; growth: held), as for one session.
    pub choose: bool,
    /// A gap in `t_s` between rows consecutive in time longer than this many times the median
    /// gap starts a new session. 20: within a session a robot moves to a pose and settles in
    /// seconds to a minute, and pauses for a tool change or a re-sighting of the tracker last a
    /// few times that (the generator's 30 s per pose; a real campaign, 444 poses in 73
    /// minutes, ~10 s apart); a new session starts hours to days later, a thousand times the
    /// spacing and more. Any ratio between the two splits the same way.
    pub gap_ratio: f64,
}

impl Default for SessionOptions {
    fn default() -> Self {
        Self { choose: true, gap_ratio: 20.0 }
    }
}

impl SessionOptions {
    /// Refuses a ratio that is not a finite number above 1 (every gap would split).
    pub fn validate(&self) -> Result<(), OptionOutOfRange> {
        let r = self.gap_ratio;
        OptionOutOfRange::check("gap_ratio", r, r.is_finite() && r > 1.0, "a finite number above 1")
    }
}

/// Whether the rule of a payload-driven term beyond its payloads is chosen from the training rows'
/// payload groups (rows of one `payload_kg` value).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PayloadOptions {
    /// Choose the rule by leaving out the lightest and the heaviest payload group in turn where
    /// there are `min_groups` or more; `false`: held (the kinds' own rule), as with fewer groups.
    pub choose: bool,
    /// The fewest distinct payloads that allow the choice. 3: leaving out the lightest or the
    /// heaviest of two leaves one payload to fit on, and at one payload its share of a joint's
    /// torque is a point mass at the tool, the same columns as the last link's own mass moments
    /// (`loadsim::gravity_regressor`), so the fold's term has not seen the load change while the
    /// full fit's has; with three the fold keeps two, the fewest that can be called several.
    pub min_groups: usize,
}

impl Default for PayloadOptions {
    fn default() -> Self {
        Self { choose: true, min_groups: 3 }
    }
}

impl PayloadOptions {
    /// Refuses fewer than 2 groups (a fold would leave nothing to fit on).
    pub fn validate(&self) -> Result<(), OptionOutOfRange> {
        let n = self.min_groups;
        OptionOutOfRange::check("min_groups", n as f64, n >= 2, "at least 2")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gp_field_given_alone_keeps_the_stages_kernel_and_search() {
        let options = FitOptions::parse("(residual_gp: (gp: (optimiser: (max_iterations: 100))))", "fit.ron").unwrap();
        let default = ResidualGpOptions::default().gp;
        let gp = &options.residual_gp.gp;
        assert_eq!(gp.optimiser.max_iterations, 100);
        assert_eq!(gp.kernel, default.kernel);
        assert_eq!((gp.optimiser.restarts, gp.optimiser.warm_start_rows), (0, 500));
        assert_eq!(gp.optimiser.function_tolerance, default.optimiser.function_tolerance);
        assert_ne!(default.kernel, gp::GpConfig::default().kernel, "the trap this guards against exists");
    }

    #[test]
    fn every_gp_field_can_be_given_and_reads_back() {
        // A field added to gp::GpConfig or OptimiserConfig without a patch field fails here.
        let mut options = FitOptions::default();
        options.residual_gp.gp.optimiser.seed = 9;
        options.residual_gp.gp.kernel = gp::KernelChoice::Matern52Ard;
        options.residual_gp.gp.bounds = Some(gp::Kernel::start(gp::KernelChoice::Matern52Ard, 3).default_bounds());
        let text = ron::ser::to_string(&options).unwrap();
        assert_eq!(FitOptions::parse(&text, "fit.ron").unwrap(), options, "{text}");
    }

    #[test]
    fn the_plausibility_block_can_be_given_and_a_bad_value_is_refused_at_its_field() {
        let options = FitOptions::parse("(plausibility: (force: true, scale_band: (0.9, 1.1)))", "fit.ron").unwrap();
        assert!(options.plausibility.force);
        assert_eq!(options.plausibility.scale_band, (0.9, 1.1));
        assert_eq!(options.plausibility.reflection_ratio, crate::PlausibilityOptions::default().reflection_ratio);
        let error = FitOptions::parse("(plausibility: (\n  reflection_ratio: 2.0))", "fit.ron").unwrap_err();
        let message = error.to_string();
        assert!(message.contains("fit.ron:2:3") && message.contains("reflection_ratio is 2"), "{message}");
    }

    #[test]
    fn the_nominal_prior_block_can_be_given_and_a_bad_value_is_refused_at_its_field() {
        let options =
            FitOptions::parse("(nominal_prior: (choose: false, tolerance_translation_m: 5e-4))", "fit.ron").unwrap();
        assert!(!options.nominal_prior.choose);
        assert_eq!(options.nominal_prior.tolerance_translation_m, 5e-4);
        let default = crate::NominalPriorOptions::default();
        assert_eq!(options.nominal_prior.tolerance_rotation_rad, default.tolerance_rotation_rad);
        let error = FitOptions::parse("(nominal_prior: (\n  min_cluster_share: 0.9))", "fit.ron").unwrap_err();
        let message = error.to_string();
        assert!(message.contains("fit.ron:2:3") && message.contains("min_cluster_share is 0.9"), "{message}");
        let error = FitOptions::parse("(nominal_prior: (translations_m: [0.0]))", "fit.ron").unwrap_err();
        assert!(error.to_string().contains("translations_m"), "{error}");
        for bad in ["0.0", "inf", "-1e-3"] {
            let text = format!("(nominal_prior: (\n  tolerance_rotation_rad: {bad}))");
            let message = FitOptions::parse(&text, "fit.ron").unwrap_err().to_string();
            assert!(message.contains("fit.ron:2:3") && message.contains("tolerance_rotation_rad is"), "{message}");
        }
    }

    #[test]
    fn the_gp_fade_can_be_given_or_turned_off_and_a_ratio_outside_zero_to_one_is_refused_at_its_field() {
        let options = FitOptions::parse("(residual_gp: (fade_above_variance_ratio: Some(0.25)))", "fit.ron").unwrap();
        assert_eq!(options.residual_gp.fade_above_variance_ratio, Some(0.25));
        let options = FitOptions::parse("(residual_gp: (fade_above_variance_ratio: None))", "fit.ron").unwrap();
        assert_eq!(options.residual_gp.fade_above_variance_ratio, None);
        for (bad, shown) in [("1.0", "1"), ("-0.1", "-0.1"), ("NaN", "NaN")] {
            let text = format!("(residual_gp: (\n  fade_above_variance_ratio: Some({bad})))");
            let message = FitOptions::parse(&text, "fit.ron").unwrap_err().to_string();
            let expected = format!(
                "fit.ron:2:3: residual_gp.fade_above_variance_ratio is {shown}, expected a number in [0, 1) or None"
            );
            assert_eq!(message, expected);
        }
        let rows = ResidualGpOptions { fade_share_rows: 0, ..ResidualGpOptions::default() };
        let refused = rows.validate_fade().unwrap_err();
        assert_eq!(refused.to_string(), "option fade_share_rows = 0: expected at least 1");
        let text = "(residual_gp: (\n  fade_share_rows: 0))";
        let message = FitOptions::parse(text, "fit.ron").unwrap_err().to_string();
        assert_eq!(message, "fit.ron:2:3: residual_gp.fade_share_rows is 0, expected at least 1");
    }

    /// poe's and gp's refusals of an option carry field, value and range over whole, placed at
    /// the field's last part in the file (`huber_threshold:` for `robust.huber_threshold`).
    #[test]
    fn a_refusal_of_an_identification_or_gp_option_names_its_field_value_and_range_at_its_place() {
        let cases = [
            ("(identification: (\n  rcond: 2.0))", "fit.ron:2:3: identification.rcond is 2, expected below 1"),
            (
                "(identification: (robust: (\n    huber_threshold: -1.0)))",
                "fit.ron:2:5: identification.robust.huber_threshold is -1, expected a finite number above 0",
            ),
            (
                "(residual_gp: (gp: (optimiser: (\n    memory: 0))))",
                "fit.ron:2:5: residual_gp.gp.optimiser.memory is 0, expected at least 1",
            ),
            (
                "(residual_gp: (gp: (jitter: (\n    initial_relative: 0.0))))",
                "fit.ron:2:5: residual_gp.gp.jitter.initial_relative is 0, expected a finite number above 0",
            ),
            (
                "(residual_gp: (gp: (jitter: (\n    growth: 1.0))))",
                "fit.ron:2:5: residual_gp.gp.jitter.growth is 1, expected a finite number above 1",
            ),
        ];
        for (text, expected) in cases {
            assert_eq!(FitOptions::parse(text, "fit.ron").unwrap_err().to_string(), expected, "{text}");
        }
    }

    #[test]
    fn bad_gp_fields_are_refused_with_file_line_and_column() {
        let error =
            FitOptions::parse("(residual_gp: (gp: (\n  optimiser: (max_iteration: 1))))", "fit.ron").unwrap_err();
        let message = error.to_string();
        assert!(message.contains("fit.ron:2:") && message.contains("max_iteration"), "{message}");
        let error = FitOptions::parse("(residual_gp: (gp: (optimiser: (\n    function_tolerance: -1.0))))", "fit.ron")
            .unwrap_err();
        let message = error.to_string();
        assert!(message.contains("fit.ron:2:5") && message.contains("function_tolerance is -1"), "{message}");
        let error = FitOptions::parse("(residual_gp: (gp: (jitter: (growth: 0.5))))", "fit.ron").unwrap_err();
        let message = error.to_string();
        assert!(message.contains("fit.ron:1:30") && message.contains("jitter.growth is 0.5"), "{message}");
    }

    #[test]
    fn an_options_file_that_calls_the_section_compensation_reads_as_the_same_options() {
        let new = "(residual_gp: (fade_above_variance_ratio: None, fade_share_rows: 50, gp: (optimiser: (seed: 4))))";
        let options = FitOptions::parse(new, "fit.ron").unwrap();
        assert_ne!(options, FitOptions::default(), "the section was read");
        let old = new.replacen("residual_gp", "compensation", 1);
        assert_eq!(FitOptions::parse(&old, "old.ron").unwrap(), options, "{old}");
        let both = "(residual_gp: (fade_share_rows: 50), compensation: (fade_share_rows: 50))";
        assert!(FitOptions::parse(both, "both.ron").is_err(), "the section given twice is refused");
        let message = FitOptions::parse(
            "(compensation: (
  fade_share_rows: 0))",
            "old.ron",
        )
        .unwrap_err()
        .to_string();
        assert!(message.contains("old.ron:2:3") && message.contains("fade_share_rows is 0"), "{message}");
    }
}
