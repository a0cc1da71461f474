//! The internal consistency of a calibrated model, checked once when its file is read: an edited or
//! corrupt file is refused at the field at fault, never left to panic on an index (or to be
//! silently truncated by a `zip`) in `eval` or `predict`. One function, so that each new part of a
//! model adds its checks here.

use crate::model_parts::{Part, Walk};
use crate::{CalibratedModel, Method};
use errors::ron_position::field_position;
use errors::{CommonKind, Error};
use measurements::Measurement;
use robot::{MAX_TRANSLATION_M, bad_translation};

/// Where a field is in the file's text, and the error makers that use it.
struct Located<'a> {
    text: &'a str,
    file: &'a str,
}

impl Located<'_> {
    fn at(&self, field: &str, index: usize) -> (usize, usize) {
        field_position(self.text, field, index)
    }

    fn count(&self, at: (&str, usize), field: String, what: &'static str, found: usize, expected: usize) -> Error {
        let (line, column) = self.at(at.0, at.1);
        Error::at_line(
            self.file.to_owned(),
            line as u64,
            column,
            CommonKind::ModelCount { field, what, found, expected },
        )
    }

    fn not_finite(&self, at: (&str, usize), field: String, value: f64) -> Error {
        let (line, column) = self.at(at.0, at.1);
        Error::at_line(self.file.to_owned(), line as u64, column, CommonKind::NotFinite { field, value })
    }

    /// A value that is not finite, or finite and beyond [`robot::MAX_TRANSLATION_M`].
    fn value(&self, at: (&str, usize), field: String, value: f64) -> Error {
        if !value.is_finite() {
            return self.not_finite(at, field, value);
        }
        let (line, column) = self.at(at.0, at.1);
        Error::at_line(
            self.file.to_owned(),
            line as u64,
            column,
            CommonKind::ModelValue { field, value, limit: MAX_TRANSLATION_M },
        )
    }

    fn part(&self, field: &str, message: String) -> Error {
        let (line, column) = self.at(field, 0);
        Error::at_line(self.file.to_owned(), line as u64, column, CommonKind::RonFormat { message })
    }
}

/// How many times `field:` occurs before the first `part:` (so that a field of the part can be
/// located by its occurrence within it).
fn occurrences_before(text: &str, field: &str, part: &str) -> usize {
    let start = field_position(text, part, 0);
    (0..)
        .take_while(|&k| {
            let position = field_position(text, field, k);
            position != (1, 1) && position < start
        })
        .count()
}

/// The residual GP's field as `text` spells it: `residual_gp`, or `compensation` in a file written
/// before SPEC version 4, so that a refusal names the field the file has.
fn residual_gp_field(text: &str) -> &'static str {
    if field_position(text, "residual_gp", 0) == (1, 1) && field_position(text, "compensation", 0) != (1, 1) {
        "compensation"
    } else {
        "residual_gp"
    }
}

/// The widest a GP hyperparameter of a model file may be, as a factor either way of 1: the GP
/// works on standardised inputs and normalised outputs, and its search box is far narrower (gp's
/// default bounds span 1e-9 to 1e3). Like [`robot::MAX_TRANSLATION_M`] a sanity bound on a file, not a
/// tuning constant: a signal variance of 1e200 is finite, predicts finite poses at any row, and is
/// still a corrupt file.
pub(crate) const MAX_HYPERPARAMETER_DECADES: f64 = 100.0;

/// The robot description a model carries: valid as a robot file would be (its checks, on the
/// description written out again), with the model's joints. Refused at `robot_description`.
fn check_robot(robot: &robot::RobotDescription, model: &CalibratedModel, at: &Located<'_>) -> Result<(), Error> {
    let field = "robot_description";
    // Its own text, from the field on, so that the robot's checks point into the model file.
    let (line, _) = at.at(field, 0);
    let start: usize = at.text.split_inclusive('\n').take(line - 1).map(str::len).sum();
    match robot.check_kept(&at.text[start.min(at.text.len())..], at.file) {
        Ok(()) => {}
        Err(e) => {
            if let (Some(CommonKind::RonFormat { message }), Some(place)) = (e.kind::<CommonKind>(), e.place())
                && let Some((relative, column)) = place.position()
            {
                let message = format!("robot_description is not a valid robot: {message}");
                let line = line as u64 + relative - 1;
                return Err(Error::at_line(place.file(), line, column, CommonKind::RonFormat { message }));
            }
            return Err(at.part(field, format!("robot_description is not a valid robot: {e}")));
        }
    }
    let kinds = robot.joint_kinds();
    if kinds != model.joint_kinds() {
        let (found, expected) = (kinds.len(), model.joint_count());
        if found != expected {
            return Err(at.count((field, 0), field.into(), "joints", found, expected));
        }
        return Err(
            at.part(field, "robot_description: its joint kinds are not the kinematics' (another robot?)".into())
        );
    }
    Ok(())
}

impl CalibratedModel {
    /// Checks that the parts of the model fit together: the kinematics' joint and tool counts,
    /// the tool names, the effects' joints, indices and values, the GP's input and output
    /// dimensions. `text` is the file the model was read from, `file` its name, for positions.
    pub fn check(&self, text: &str, file: &str) -> Result<(), Error> {
        let at = Located { text, file };
        let n = self.kinematics.joint_count();
        let tool_count = self.kinematics.tool_count();
        if n == 0 {
            return Err(at.count(("joints", 0), "kinematics.joints".into(), "joints", 0, 1));
        }
        // Translations appear in the file in this order: the joints', then the tools'.
        let transforms = self.kinematics.joints().iter().map(|j| j.previous_from_joint_zero);
        if let Some((k, value)) = bad_translation(transforms.chain(self.kinematics.tools().iter().copied())) {
            let field = if k < n { format!("kinematics.joints[{k}]") } else { format!("kinematics.tools[{}]", k - n) };
            return Err(at.value(("translation", k), field, value));
        }
        // A scale is written only where it is not 1, so its occurrence counts those before it.
        let scales = self.kinematics.joints().iter().map(|j| j.scale).filter(|s| *s != 1.0);
        if let Some((k, scale)) = scales.enumerate().find(|(_, s)| !robot::scale_in_bounds(*s)) {
            let (lo, hi) = robot::SCALE_BOUNDS;
            let (line, column) = at.at("scale", k);
            let message = format!("a joint's scale is {scale:e}, expected a finite number from {lo:e} to {hi:e}");
            return Err(Error::at_line(file.to_owned(), line as u64, column, CommonKind::RonFormat { message }));
        }
        if self.tools.len() != tool_count {
            return Err(at.count(("tools", 0), "tools".into(), "tool names", self.tools.len(), tool_count));
        }
        if let Some(k) = (1..self.tools.len()).find(|&k| self.tools[..k].contains(&self.tools[k])) {
            return Err(at.part("tools", format!("tools: the name '{}' is given twice", self.tools[k])));
        }
        if self.method.uses_gp() != self.residual_gp.is_some() {
            let has = if self.residual_gp.is_some() { "has a" } else { "has no" };
            return Err(at.part("method", format!("method {} but the model {has} residual GP", self.method)));
        }
        if let Some(robot) = &self.robot_description {
            check_robot(robot, self, &at)?;
        }
        effects::check_effects(&self.effects, n, tool_count, &|field, occurrence| {
            let before = occurrences_before(text, field, "effects");
            at.at(field, before + occurrence)
        })
        .map_err(|fault| fault.into_error(file))?;
        if let Some(residual_gp) = &self.residual_gp {
            self.check_residual_gp(residual_gp, &at)?;
        }
        self.check_inputs(&at)?;
        self.check_values(&at)
    }

    /// The residual GP against the model: its payload input and pose kind as the method's and
    /// the model's, its input and output dimensions, its hyperparameters within their bounds.
    fn check_residual_gp(&self, residual_gp: &crate::ResidualGp, at: &Located<'_>) -> Result<(), Error> {
        let n = self.kinematics.joint_count();
        let gp_field = residual_gp_field(at.text);
        if residual_gp.with_payload != (self.method == Method::PoeGpLoad) {
            let message = format!("{gp_field}.with_payload is {} for method {}", residual_gp.with_payload, self.method);
            return Err(at.part("with_payload", message));
        }
        if residual_gp.full_pose != self.full_pose {
            let message =
                format!("{gp_field}.full_pose is {}, the model's full_pose {}", residual_gp.full_pose, self.full_pose);
            return Err(at.part(gp_field, message));
        }
        let inputs = n + usize::from(residual_gp.with_payload) + residual_gp.inputs.len();
        if residual_gp.gp.input_dim() != inputs {
            let found = residual_gp.gp.input_dim();
            return Err(at.count(("gp", 0), format!("{gp_field}.gp"), "inputs", found, inputs));
        }
        let bound = 10f64.powf(MAX_HYPERPARAMETER_DECADES);
        let hyperparameters = residual_gp.gp.kernels().into_iter().flat_map(|k| k.parameters());
        if let Some(value) = hyperparameters.into_iter().find(|p| !(p.abs() <= bound && p.abs() >= 1.0 / bound)) {
            let message = format!(
                "{gp_field}.gp: a kernel hyperparameter is {value:e}, outside 1e-{MAX_HYPERPARAMETER_DECADES} to \
                 1e{MAX_HYPERPARAMETER_DECADES} (the GP works on standardised data; an edited or corrupt file)"
            );
            return Err(at.part("kernel", message));
        }
        let outputs = if self.full_pose { 6 } else { 3 };
        if residual_gp.gp.output_count() != outputs {
            let found = residual_gp.gp.output_count();
            return Err(at.count(("gp", 0), format!("{gp_field}.gp"), "outputs", found, outputs));
        }
        Ok(())
    }

    /// The measured signals the model takes: named once each, and each with its span in the
    /// training range where the file keeps one (the check walks the model there, and `eval`
    /// counts the rows outside it).
    fn check_inputs(&self, at: &Located<'_>) -> Result<(), Error> {
        let names = self.input_names();
        if let Some(k) = (1..names.len()).find(|&k| names[..k].contains(&names[k])) {
            let gp_field = residual_gp_field(at.text);
            return Err(at.part("inputs", format!("{gp_field}.inputs: the input '{}' is named twice", names[k])));
        }
        if let Some(range) = &self.training_range
            && let Some(name) = names.iter().find(|name| range.input(name).is_none())
        {
            let message =
                format!("training_range.inputs: no span of the input '{name}', which the model takes (an edited file)");
            return Err(at.part("training_range", message));
        }
        Ok(())
    }

    /// The rows the walk probes, and how to say where they are: inside the ranges the model was
    /// fitted on (the centre and both corners); for a file without them, the GP's training mean
    /// where there is a GP, otherwise every joint at 0 and at 1 rad or 1 m (payload, torques,
    /// temperature and time at 0 where not recorded).
    fn probe_rows(&self) -> (Vec<Measurement>, &'static str) {
        if let Some(range) = &self.training_range {
            return (range.probe_rows(), "at the centre or a corner of the ranges it was fitted on");
        }
        let n = self.kinematics.joint_count();
        let row = |q: Vec<f64>, payload_kg: f64| Measurement {
            payload_kg,
            temp_c: Some(0.0),
            t_s: Some(0.0),
            torques_nm: Some(vec![0.0; n]),
            ..Measurement::at(q, lie::Vector3::zeros())
        };
        match &self.residual_gp {
            Some(residual_gp) => {
                let mean = residual_gp.gp.input_mean();
                let payload = if residual_gp.with_payload { mean.get(n).copied().unwrap_or(0.0) } else { 0.0 };
                let p = n + usize::from(residual_gp.with_payload);
                let signals =
                    residual_gp.inputs.iter().enumerate().map(|(k, _)| mean.get(p + k).copied().unwrap_or(0.0));
                let names: std::sync::Arc<[String]> = residual_gp.inputs.clone().into();
                let inputs = measurements::Inputs::new(names, signals.collect());
                let probe = Measurement { inputs, ..row(mean[..n.min(mean.len())].to_vec(), payload) };
                (vec![probe], "at the mean of the GP's training inputs")
            }
            None => (vec![row(vec![0.0; n], 0.0), row(vec![1.0; n], 0.0)], "with every joint at 0 or 1"),
        }
    }

    /// Walks the parts at rows where the model was fitted ([`Self::probe_rows`]) and refuses the
    /// first part that makes a number non-finite or puts the tool beyond [`robot::MAX_TRANSLATION_M`].
    /// The checks above bound what they can name; this catches any finite but absurd value they
    /// leave (1e308 in the GP's training outputs, a feature scale of 1e-320) that would make
    /// predictions NaN or kilometres off, and names the part. A sound model passes: the rows are
    /// inside what it was fitted on (at every joint 1 rad, a GP fitted with the wrist
    /// within 2 mrad of zero extrapolated beyond a kilometre and a sound model was refused).
    fn check_values(&self, at: &Located<'_>) -> Result<(), Error> {
        if let Some(range) = &self.training_range
            && let Some((name, index, value)) = range.fault(self.kinematics.joint_count(), MAX_TRANSLATION_M)
        {
            let message = format!(
                "training_range.{name}[{index}]: {value:e} is not a range of finite values, smallest first, one per \
                 joint, joint values within ±{MAX_TRANSLATION_M:e} (an edited or corrupt file)"
            );
            return Err(at.part("training_range", message));
        }
        if let Some((index, value)) =
            crate::joint_limits::limits_fault(&self.joint_limits, self.kinematics.joint_count())
        {
            let message = format!(
                "joint_limits[{index}]: {value:e} is not a range of finite values, smallest first, one per joint \
                 (an edited or corrupt file)"
            );
            return Err(at.part("joint_limits", message));
        }
        if let Some(uncertainty) = &self.effect_uncertainty
            && let Some(message) = uncertainty_fault(uncertainty, &self.effects, self.kinematics.layout().len())
        {
            return Err(at.part("effect_uncertainty", message));
        }
        if let Some(message) = self.geometry_uncertainty.as_ref().and_then(|u| u.fault(self.kinematics.layout().len()))
        {
            return Err(at.part("geometry_uncertainty", message));
        }
        let (rows, where_) = self.probe_rows();
        // Made here from the model, every row on its first tool.
        let probe = measurements::BoundSet::made_for_model("the model check", rows);
        let mut walk = Walk::new(&probe, self.uncertainty());
        for (k, part) in self.parts().iter().enumerate() {
            let applied = part.apply(&mut walk);
            if applied.is_ok() && walk.is_bounded(MAX_TRANSLATION_M) {
                continue;
            }
            let field = match part {
                Part::Geometry(_) => "kinematics",
                Part::Effect(_) => "effects",
                Part::Fallback(_) => "fallback_kinematics",
                Part::GaussianProcess(_) => residual_gp_field(at.text),
            };
            let why = applied
                .err()
                .map_or("a pose that is not finite or beyond a kilometre".to_owned(), |e| format!("'{e}'"));
            let message = format!(
                "{field}: part {k} ({}) gives {why} {where_}: a value in it is out of range \
                 (an edited or corrupt file)",
                part.name()
            );
            return Err(at.part(field, message));
        }
        Ok(())
    }
}

/// What is wrong with an effect uncertainty read from a file, if anything: a free index inside
/// the layout, a factor of the size the free and effect parameters make, finite numbers, a
/// positive fallback σ.
fn uncertainty_fault(
    uncertainty: &crate::EffectUncertainty,
    effects: &[effects::IdentifiedEffect],
    layout: usize,
) -> Option<String> {
    if let Some(index) = uncertainty.free.iter().find(|&&i| i >= layout) {
        return Some(format!(
            "effect_uncertainty.free: {index} is not a parameter of the kinematics ({layout} parameters; an edited or corrupt file)"
        ));
    }
    let p = uncertainty.free.len() + effects.iter().map(effects::IdentifiedEffect::parameter_count).sum::<usize>();
    if uncertainty.factor.len() != p * (p + 1) / 2 {
        return Some(format!(
            "effect_uncertainty.factor: {} numbers, {} expected for {p} parameters (an edited or corrupt file)",
            uncertainty.factor.len(),
            p * (p + 1) / 2,
        ));
    }
    if let Some(value) = uncertainty.factor.iter().find(|v| !v.is_finite()) {
        return Some(format!("effect_uncertainty.factor: {value} is not finite (an edited or corrupt file)"));
    }
    let [median, largest] = uncertainty.training_sigma_m;
    let limit = uncertainty.fallback_sigma_m;
    let ordered = median.is_finite() && largest.is_finite() && 0.0 <= median && median <= largest;
    if !(ordered && limit.is_finite() && limit > 0.0) {
        return Some(format!(
            "effect_uncertainty: training_sigma_m ({median:e}, {largest:e}) and fallback_sigma_m {limit:e} must be \
             finite, the first two ordered and at least 0, the last above 0 (an edited or corrupt file)"
        ));
    }
    None
}
