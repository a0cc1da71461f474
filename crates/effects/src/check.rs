//! The effects of a model file checked once, on reading: every index within the robot, every
//! count consistent, every value finite. A fault names the field and its occurrence within the
//! `effects` list, so that the caller can place it in the file.

use super::{Backlash, ComplianceTorque, IdentifiedEffect, LoadFrame, MAX_HARMONICS, TorqueSign};
use errors::Error;

/// What is wrong, where.
#[derive(Debug)]
pub struct EffectFault {
    /// The field path, e.g. `effects[1].theta`.
    pub path: String,
    /// The line and column of the field in the file.
    pub position: (usize, usize),
    /// What is wrong.
    pub kind: FaultKind,
}

/// The kinds of [`EffectFault`]; each becomes the [`Error`] variant of the same name.
#[derive(Debug)]
#[allow(missing_docs)] // the fields are those of the `Error` variants they become
pub enum FaultKind {
    /// A list of the wrong length.
    Count { what: &'static str, found: usize, expected: usize },
    /// An index beyond the robot's joints or tools.
    Index { index: usize, limit: usize },
    /// A value that is not finite.
    NotFinite { value: f64 },
    /// A value beyond a sanity bound.
    Value { value: f64, limit: f64 },
    /// Two ends of a range in the wrong order.
    Order { low: f64, high: f64 },
}

impl EffectFault {
    /// The error of this fault in file `file`.
    pub fn into_error(self, file: &str) -> Error {
        let (line, column) = self.position;
        let file = file.to_owned();
        let field = self.path;
        match self.kind {
            FaultKind::Count { what, found, expected } => {
                Error::ModelCount { file, line, column, field, what, found, expected }
            }
            FaultKind::Index { index, limit } => Error::ModelIndex { file, line, column, field, index, limit },
            FaultKind::NotFinite { value } => Error::NotFinite { file, line, column, field, value },
            FaultKind::Value { value, limit } => Error::ModelValue { file, line, column, field, value, limit },
            FaultKind::Order { low, high } => Error::RonFormat {
                file,
                line,
                column,
                message: format!("{field} is [{low}, {high}]: its first value must not exceed its second"),
            },
        }
    }
}

/// Counts occurrences of field names within the effects list, effect by effect, so that a fault
/// is placed at its own occurrence.
struct Cursor<'a> {
    effect: usize,
    seen: std::collections::HashMap<&'static str, usize>,
    locate: &'a dyn Fn(&str, usize) -> (usize, usize),
}

impl Cursor<'_> {
    fn fault(&self, field: &'static str, within: usize, path: String, kind: FaultKind) -> EffectFault {
        let occurrence = self.seen.get(field).copied().unwrap_or(0) + within;
        EffectFault {
            path: format!("effects[{}].{path}", self.effect),
            position: (self.locate)(field, occurrence),
            kind,
        }
    }

    fn finite(&self, field: &'static str, values: &[f64], positive: bool) -> Result<(), EffectFault> {
        match values.iter().position(|v| !v.is_finite() || (positive && *v <= 0.0)) {
            Some(k) => Err(self.fault(field, 0, format!("{field}[{k}]"), FaultKind::NotFinite { value: values[k] })),
            None => Ok(()),
        }
    }

    fn count(&self, field: &'static str, found: usize, expected: usize) -> Result<(), EffectFault> {
        if found == expected {
            Ok(())
        } else {
            Err(self.fault(field, 0, field.to_owned(), FaultKind::Count { what: "values", found, expected }))
        }
    }

    fn joint(
        &self,
        field: &'static str,
        within: usize,
        path: String,
        joint: usize,
        n: usize,
    ) -> Result<(), EffectFault> {
        if joint < n {
            Ok(())
        } else {
            Err(self.fault(field, within, path, FaultKind::Index { index: joint, limit: n }))
        }
    }

    fn load(&self, load: &LoadFrame, n: usize, tools: usize) -> Result<(), EffectFault> {
        let base = &load.base_model;
        if base.joint_count() != n {
            let kind = FaultKind::Count { what: "joints", found: base.joint_count(), expected: n };
            return Err(self.fault("base_model", 0, "base_model".into(), kind));
        }
        if base.tool_count() != tools {
            let kind = FaultKind::Count { what: "tools", found: base.tool_count(), expected: tools };
            return Err(self.fault("base_model", 0, "base_model".into(), kind));
        }
        let moved = base.joints().iter().map(|j| j.previous_from_joint_zero).chain(base.tools().iter().copied());
        if let Some((_, value)) = robot::bad_translation(moved) {
            let kind = if value.is_finite() {
                FaultKind::Value { value, limit: robot::MAX_TRANSLATION_M }
            } else {
                FaultKind::NotFinite { value }
            };
            return Err(self.fault("base_model", 0, "base_model".into(), kind));
        }
        self.finite("gravity_m_per_s2", &load.gravity_m_per_s2, false)
    }

    /// Counts the fields of one effect, so that the next effect's occurrences start after them.
    fn advance(&mut self, effect: &IdentifiedEffect) {
        let mut add = |field: &'static str, count: usize| *self.seen.entry(field).or_insert(0) += count;
        add("theta", 1);
        match effect {
            IdentifiedEffect::JointCompliance(c) => {
                add("joint", c.terms.len());
                add("column", c.terms.len());
                add("scale", c.terms.len());
                match &c.torque {
                    ComplianceTorque::Measured => {}
                    ComplianceTorque::GravityRegressor(_) => {
                        add("base_model", 1);
                        add("gravity_m_per_s2", 1);
                    }
                    ComplianceTorque::Modelled { fits, .. } => {
                        add("base_model", 1);
                        add("gravity_m_per_s2", 1);
                        add("fits", 1);
                        add("columns", fits.len());
                        add("coefficients", fits.len());
                    }
                }
            }
            IdentifiedEffect::GearPeriodic(g) => {
                add("joint", 1);
                add("orders", 1);
                add("scale", 1);
                add("fitted_range", usize::from(g.fitted_range.is_some()));
                add("fitted_gaps", usize::from(!g.fitted_gaps.is_empty()));
                add("turn_gaps", usize::from(!g.turn_gaps.is_empty()));
                add("taper_rad", usize::from(g.taper_rad.is_some()));
                add("mean", usize::from(!g.mean.is_empty()));
                add("fitted_rms_rad", usize::from(g.fitted_rms_rad.is_some()));
                add("roughness_order", 1);
            }
            IdentifiedEffect::Backlash(b) => {
                add("joint", 1);
                add("scale", 1);
                match &b.sign {
                    TorqueSign::Measured => {}
                    TorqueSign::Stated { .. } => {
                        add("base_model", 1);
                        add("gravity_m_per_s2", 1);
                    }
                    TorqueSign::Learnt { .. } => {
                        add("base_model", 1);
                        add("gravity_m_per_s2", 1);
                        add("columns", 1);
                        add("coefficients", 1);
                    }
                }
            }
            IdentifiedEffect::Thermal(_) => {
                add("reference_c", 1);
                add("scale", 1);
            }
            IdentifiedEffect::TimeDrift(_) => {
                add("reference_s", 1);
                add("scale", 1);
            }
        }
        self.effect += 1;
    }

    fn backlash(&self, b: &Backlash, n: usize, tools: usize) -> Result<(), EffectFault> {
        self.joint("joint", 0, "joint".into(), b.joint, n)?;
        self.count("scale", b.scale.len(), 1)?;
        self.count("theta", b.theta.len(), 1)?;
        match &b.sign {
            TorqueSign::Measured => Ok(()),
            TorqueSign::Stated { load, dynamics } => {
                self.load(load, n, tools)?;
                dynamics.validate(n).map_err(|_| {
                    let kind = FaultKind::Count { what: "links", found: dynamics.links.len(), expected: n };
                    self.fault("dynamics", 0, "sign.dynamics".into(), kind)
                })
            }
            TorqueSign::Learnt { load, columns, coefficients } => {
                self.load(load, n, tools)?;
                if let Some(k) = columns.iter().position(|&c| c > 4 * n) {
                    let kind = FaultKind::Index { index: columns[k], limit: 4 * n + 1 };
                    return Err(self.fault("columns", 0, format!("columns[{k}]"), kind));
                }
                self.count("coefficients", coefficients.len(), columns.len())?;
                self.finite("coefficients", coefficients, false)
            }
        }
    }
}

/// Checks every effect of a model with `n` joints and `tools` tools; `locate` gives the line and
/// column of the `occurrence`-th (0-based, counted from the start of the effects list) `field:`.
pub fn check_effects(
    effects: &[IdentifiedEffect],
    n: usize,
    tools: usize,
    locate: &dyn Fn(&str, usize) -> (usize, usize),
) -> Result<(), EffectFault> {
    let mut cursor = Cursor { effect: 0, seen: std::collections::HashMap::new(), locate };
    for effect in effects {
        match effect {
            IdentifiedEffect::JointCompliance(c) => {
                match &c.torque {
                    ComplianceTorque::Measured => {}
                    ComplianceTorque::GravityRegressor(load) => cursor.load(load, n, tools)?,
                    ComplianceTorque::Modelled { load, fits } => {
                        cursor.load(load, n, tools)?;
                        cursor.count("fits", fits.len(), n)?;
                        for (k, fit) in fits.iter().enumerate() {
                            if let Some(m) = fit.columns.iter().position(|&c| c > 4 * n) {
                                let kind = FaultKind::Index { index: fit.columns[m], limit: 4 * n + 1 };
                                return Err(cursor.fault("columns", k, format!("fits[{k}].columns[{m}]"), kind));
                            }
                            if fit.coefficients.len() != fit.columns.len() {
                                let kind = FaultKind::Count {
                                    what: "values",
                                    found: fit.coefficients.len(),
                                    expected: fit.columns.len(),
                                };
                                return Err(cursor.fault("coefficients", k, format!("fits[{k}].coefficients"), kind));
                            }
                            if let Some(&value) = fit.coefficients.iter().find(|v| !v.is_finite()) {
                                let kind = FaultKind::NotFinite { value };
                                return Err(cursor.fault("coefficients", k, format!("fits[{k}].coefficients"), kind));
                            }
                        }
                    }
                }
                // A regressor row holds 4 columns per link and the payload's: 4n + 1; a measured
                // or modelled torque has one.
                let width = if matches!(c.torque, ComplianceTorque::GravityRegressor(_)) { 4 * n + 1 } else { 1 };
                for (k, term) in c.terms.iter().enumerate() {
                    cursor.joint("joint", k, format!("terms[{k}].joint"), term.joint, n)?;
                    if term.column >= width {
                        let kind = FaultKind::Index { index: term.column, limit: width };
                        return Err(cursor.fault("column", k, format!("terms[{k}].column"), kind));
                    }
                    if !(term.scale.is_finite() && term.scale > 0.0) {
                        let kind = FaultKind::NotFinite { value: term.scale };
                        return Err(cursor.fault("scale", k, format!("terms[{k}].scale"), kind));
                    }
                }
                cursor.count("theta", c.theta.len(), c.terms.len())?;
            }
            IdentifiedEffect::GearPeriodic(g) => {
                cursor.joint("joint", 0, "joint".into(), g.joint, n)?;
                if let Some(k) = g.orders.iter().position(|&h| h > MAX_HARMONICS) {
                    let kind = FaultKind::Index { index: g.orders[k] as usize, limit: MAX_HARMONICS as usize + 1 };
                    return Err(cursor.fault("orders", 0, format!("orders[{k}]"), kind));
                }
                cursor.count("scale", g.scale.len(), 2 * g.orders.len())?;
                cursor.count("theta", g.theta.len(), 2 * g.orders.len())?;
                cursor.finite("scale", &g.scale, true)?;
                if let Some([low, high]) = g.fitted_range {
                    cursor.finite("fitted_range", &[low, high], false)?;
                    if low > high {
                        let kind = FaultKind::Order { low, high };
                        return Err(cursor.fault("fitted_range", 0, "fitted_range".into(), kind));
                    }
                }
                for (k, &[a, b]) in g.fitted_gaps.iter().enumerate() {
                    cursor.finite("fitted_gaps", &[a, b], false)?;
                    if a > b {
                        let kind = FaultKind::Order { low: a, high: b };
                        return Err(cursor.fault("fitted_gaps", 0, format!("fitted_gaps[{k}]"), kind));
                    }
                }
                // The turn's gaps lie within [0, 4π): a gap starts inside the turn and the one
                // across 2π ends within the next.
                for (k, &[a, b]) in g.turn_gaps.iter().enumerate() {
                    cursor.finite("turn_gaps", &[a, b], false)?;
                    if a > b || a < 0.0 || b > 2.0 * std::f64::consts::TAU {
                        let kind = FaultKind::Order { low: a, high: b };
                        return Err(cursor.fault("turn_gaps", 0, format!("turn_gaps[{k}]"), kind));
                    }
                }
                if let Some(taper) = g.taper_rad {
                    cursor.finite("taper_rad", &[taper], true)?;
                }
                if !g.mean.is_empty() {
                    cursor.count("mean", g.mean.len(), 2 * g.orders.len())?;
                    cursor.finite("mean", &g.mean, false)?;
                }
                if let Some(rms) = g.fitted_rms_rad {
                    cursor.finite("fitted_rms_rad", &[rms], false)?;
                    if rms < 0.0 {
                        let kind = FaultKind::Order { low: 0.0, high: rms };
                        return Err(cursor.fault("fitted_rms_rad", 0, "fitted_rms_rad".into(), kind));
                    }
                }
                if !(0.0..=4.0).contains(&g.roughness_order) {
                    let kind = FaultKind::Value { value: g.roughness_order, limit: 4.0 };
                    return Err(cursor.fault("roughness_order", 0, "roughness_order".into(), kind));
                }
            }
            IdentifiedEffect::Backlash(b) => {
                cursor.backlash(b, n, tools)?;
                cursor.finite("scale", &b.scale, true)?;
            }
            IdentifiedEffect::Thermal(t) => {
                cursor.finite("reference_c", &[t.reference_c], false)?;
                cursor.count("scale", t.scale.len(), 1)?;
                cursor.count("theta", t.theta.len(), 1)?;
                cursor.finite("scale", &t.scale, true)?;
            }
            IdentifiedEffect::TimeDrift(d) => {
                cursor.finite("reference_s", &[d.reference_s], false)?;
                cursor.count("scale", d.scale.len(), 6)?;
                cursor.count("theta", d.theta.len(), 6)?;
                cursor.finite("scale", &d.scale, true)?;
            }
        }
        cursor.finite("theta", effect.theta(), false)?;
        // The features are scaled to RMS 1 on the training poses, so a coefficient is the effect's
        // RMS size in rad or m: beyond a kilometre it is a corrupt file, not a robot.
        let limit = robot::MAX_TRANSLATION_M;
        if let Some(k) = effect.theta().iter().position(|v| v.abs() > limit) {
            let kind = FaultKind::Value { value: effect.theta()[k], limit };
            return Err(cursor.fault("theta", 0, format!("theta[{k}]"), kind));
        }
        cursor.advance(effect);
    }
    Ok(())
}
