//! Joint compliance: each joint turns by `δq_j = c_j τ_j` under the torque it carries (the paper's
//! ref. \[15\]; `loadsim::compliance_deflection`). With measured torques (`tauN_nm`) that is one
//! parameter per joint. Without them the gravity torque is linear in the links' unknown mass
//! moments, `τ_j = Y_j(q) π + τ_payload,j(q, m)` (`loadsim::gravity_regressor`), so the deflection
//! is linear in the products `c_j π_l` and in `c_j`: one parameter per entry of `Y`'s row `j` that
//! is not zero on every row, and one for the payload; no masses needed.

use super::{LoadFrame, Regressor, rms_scales};
use crate::check::{Cursor, EffectFault, FaultKind};
use crate::term::{EffectTerm, NewEffect};
use crate::{Argument, CandidateContext, CandidateModel, EffectContext, EffectSpec, IdentifiedEffect, has_torques};

use crate::{BeyondSpan, Direction, PayloadSpan};
use errors::Error;
use crate::ErrorKind;
use measurements::{BoundSet, Measurement};
use serde::{Deserialize, Serialize};

/// Which torque drives the deflection.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ComplianceTorque {
    /// The measured joint torques of each row (`tauN_nm`), as they are.
    Measured,
    /// The measured joint torques as the gravity-torque regressors explain them: each joint's
    /// `tauN_nm` fitted on the training rows by least squares over its row of `Y(q)` and the
    /// payload's torque ([`TorqueFit`]). The torque without the sensor's noise (0.5 N·m on an
    /// iiwa-class sensor moves a 5000 N·m/rad joint by 0.1 mrad), and one that needs no torque
    /// column to predict with (eval, compensate).
    Modelled {
        /// Gravity and the nominal arm.
        load: LoadFrame,
        /// One fit per joint, in joint order.
        fits: Vec<TorqueFit>,
    },
    /// The gravity-torque regressors of the nominal arm, with the payload's torque.
    GravityRegressor(LoadFrame),
}

/// A joint's torque as a combination of its gravity-torque regressors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TorqueFit {
    /// Columns of the joint's regressor row (4 per link, `4n` the payload's).
    pub columns: Vec<usize>,
    /// Their coefficients, N·m per unit of the regressor.
    pub coefficients: Vec<f64>,
}

impl TorqueFit {
    /// Fits joint `joint`'s measured torque on the rows of `data` over the regressor columns that are not
    /// zero on every row (SVD least squares, directions below 1e-10 of the largest dropped: the
    /// regressor columns of neighbouring links are often exactly collinear).
    fn new(load: &LoadFrame, joint: usize, data: &BoundSet<'_>) -> Result<Self, Error> {
        let mut regressors = Vec::with_capacity(data.len());
        let mut measured = Vec::with_capacity(data.len());
        for (row, tool) in data.iter() {
            let all = load.regressors(row, tool)?;
            regressors.push(all.get(joint).cloned().unwrap_or_default());
            let tau = row.torques_nm.as_ref().and_then(|t| t.get(joint)).copied().ok_or_else(|| Error::new(
                ErrorKind::EffectNeedsColumn { line: row.line, effect: "joint_compliance", column: "tau1_nm" },
            ))?;
            measured.push(tau);
        }
        let width = regressors.first().map_or(0, Vec::len);
        let columns: Vec<usize> =
            (0..width).filter(|&c| regressors.iter().any(|r| r.get(c).is_some_and(|v| v.abs() > 1e-12))).collect();
        if columns.is_empty() || data.is_empty() {
            // Gravity never loads this joint (a vertical first axis): no torque to model.
            return Ok(Self { columns: Vec::new(), coefficients: Vec::new() });
        }
        let norms: Vec<f64> = columns
            .iter()
            .map(|&c| regressors.iter().map(|r| r[c] * r[c]).sum::<f64>().sqrt().max(f64::MIN_POSITIVE))
            .collect();
        let a = nalgebra::DMatrix::from_fn(data.len(), columns.len(), |i, k| regressors[i][columns[k]] / norms[k]);
        let b = nalgebra::DVector::from_vec(measured);
        let coefficients = match a.svd(true, true).solve(&b, 1e-10) {
            Ok(x) => x.iter().zip(&norms).map(|(x, n)| x / n).collect(),
            Err(_) => vec![0.0; columns.len()],
        };
        Ok(Self { columns, coefficients })
    }

    fn torque(&self, regressor_row: &[f64]) -> f64 {
        self.columns
            .iter()
            .zip(&self.coefficients)
            .map(|(&c, k)| regressor_row.get(c).copied().unwrap_or(0.0) * k)
            .sum()
    }
}

/// One parameter: one joint's deflection per unit of one torque regressor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ComplianceParameter {
    /// 0-based joint whose deflection the term drives.
    pub joint: usize,
    /// Column of the gravity regressor `Y` (4 per link), or `4n` for the payload torque; 0 for a
    /// measured torque.
    pub column: usize,
    /// The regressor is divided by this (its RMS on the training poses), so that the parameters
    /// are comparable in size: each is the joint's deflection, rad, at an RMS torque.
    pub scale: f64,
}

/// Joint compliance, identified with the geometry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointComplianceTerm {
    /// The torque that drives the deflection.
    pub torque: ComplianceTorque,
    /// The parameters' meaning.
    pub terms: Vec<ComplianceParameter>,
    /// Their values: radians of deflection per unit of the scaled regressor.
    pub theta: Vec<f64>,
    /// The payloads (and measured torques) of the training rows and the rule beyond them
    /// (`PayloadSpan`: held at the nearer end unless the fit chose otherwise). Absent
    /// in model files written before it was recorded: extended as fitted, as they were.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub payload_span: Option<PayloadSpan>,
}

impl JointComplianceTerm {
    /// The terms of `joints` (0-based) seen on the rows of `data` driven by `torque`: every
    /// regressor that is not zero on every row.
    pub fn new(torque: ComplianceTorque, joints: &[usize], data: &BoundSet<'_>) -> Result<Self, Error> {
        let measured = matches!(torque, ComplianceTorque::Measured);
        let mut model = Self { torque, terms: Vec::new(), theta: Vec::new(), payload_span: None };
        let raw: Vec<Vec<Vec<f64>>> =
            data.iter().map(|(row, tool)| model.torques(row, tool, None)).collect::<Result<_, _>>()?;
        for &joint in joints {
            let width = raw.first().and_then(|r| r.get(joint)).map_or(0, Vec::len);
            for column in 0..width {
                let values: Vec<Vec<f64>> = raw.iter().map(|r| vec![r[joint][column]]).collect();
                // Columns that vanish on every pose (joint 1's vertical axis, a payload of zero
                // throughout) carry nothing.
                if values.iter().any(|v| v[0].abs() > 1e-12) {
                    let scale = rms_scales(&values)[0];
                    model.terms.push(ComplianceParameter { joint, column, scale });
                }
            }
        }
        model.theta = vec![0.0; model.terms.len()];
        model.payload_span = PayloadSpan::of(data.rows(), measured);
        Ok(model)
    }

    /// Joint compliance driven by the measured torques as the gravity-torque regressors explain
    /// them ([`ComplianceTorque::Modelled`]), one parameter per joint of `joints` whose modelled
    /// torque is not zero on every row.
    pub fn modelled(load: LoadFrame, joints: &[usize], data: &BoundSet<'_>) -> Result<Self, Error> {
        let n = load.base_model.joint_count();
        let fits = (0..n).map(|j| TorqueFit::new(&load, j, data)).collect::<Result<_, _>>()?;
        Self::new(ComplianceTorque::Modelled { load, fits }, joints, data)
    }

    /// The torque regressors of one row, joint by joint (one column for a measured or modelled
    /// torque), under the rule `rule` beyond the payload span (`None` inside it): the payload, or
    /// each measured torque, held in its span for a hold.
    fn torques(&self, row: &Measurement, tool: usize, rule: Option<BeyondSpan>) -> Result<Vec<Vec<f64>>, Error> {
        let span = self.payload_span.as_ref();
        let payload_kg = span.map_or(row.payload_kg, |s| s.payload(rule, row.payload_kg));
        match &self.torque {
            ComplianceTorque::Modelled { load, fits } => {
                let regressors = load.regressors_with(&row.q, tool, payload_kg)?;
                Ok(fits.iter().zip(&regressors).map(|(fit, r)| vec![fit.torque(r)]).collect())
            }
            ComplianceTorque::Measured => match &row.torques_nm {
                Some(tau) => {
                    Ok(tau.iter().enumerate().map(|(j, t)| vec![span.map_or(*t, |s| s.torque(rule, j, *t))]).collect())
                }
                None => Err(Error::new(ErrorKind::EffectNeedsColumn {
                    line: row.line,
                    effect: "joint_compliance",
                    column: "tau1_nm",
                })),
            },
            ComplianceTorque::GravityRegressor(load) => load.regressors_with(&row.q, tool, payload_kg),
        }
    }

    /// The 0-based joints the terms act on, ascending.
    pub fn joints(&self) -> Vec<usize> {
        let mut joints: Vec<usize> = self.terms.iter().map(|t| t.joint).collect();
        joints.dedup();
        joints
    }
}

impl Regressor for JointComplianceTerm {
    fn directions(&self) -> Vec<Direction> {
        self.terms.iter().map(|t| Direction::Joint(t.joint)).collect()
    }

    fn features(&self, row: &Measurement, tool: usize) -> Result<Vec<f64>, Error> {
        let rule = self.payload_span.as_ref().and_then(|s| s.rule_at(row.payload_kg));
        let torques = self.torques(row, tool, rule)?;
        if rule == Some(BeyondSpan::Zero) {
            return Ok(vec![0.0; self.terms.len()]);
        }
        self.terms
            .iter()
            .map(|t| {
                let value = torques
                    .get(t.joint)
                    .and_then(|r| r.get(t.column))
                    .copied()
                    .ok_or_else(|| Error::new(ErrorKind::EffectJoint { joint: t.joint + 1, joint_count: torques.len() }))?;
                Ok(value / t.scale)
            })
            .collect()
    }

    fn theta(&self) -> &[f64] {
        &self.theta
    }

    fn theta_mut(&mut self) -> &mut Vec<f64> {
        &mut self.theta
    }

    fn parameter_names(&self) -> Vec<String> {
        let links = match &self.torque {
            ComplianceTorque::GravityRegressor(load) => Some(load.base_model.joint_count()),
            _ => None,
        };
        self.terms
            .iter()
            .map(|t| match links {
                Some(n) if t.column == 4 * n => format!("joint {} x payload torque", t.joint + 1),
                Some(_) => {
                    const MOMENT: [&str; 4] = ["m", "m c_x", "m c_y", "m c_z"];
                    format!(
                        "joint {} x gravity torque of link {} {}",
                        t.joint + 1,
                        t.column / 4 + 1,
                        MOMENT[t.column % 4]
                    )
                }
                None => format!("joint {} x torque", t.joint + 1),
            })
            .collect()
    }
}

impl EffectTerm for JointComplianceTerm {
    fn label(&self) -> String {
        match self.torque {
            ComplianceTorque::Measured => "joint_compliance (measured torques)".into(),
            ComplianceTorque::Modelled { .. } => {
                "joint_compliance (measured torques, modelled on the gravity regressors)".into()
            }
            ComplianceTorque::GravityRegressor(_) => "joint_compliance (gravity-torque regressors)".into(),
        }
    }

    fn joints(&self) -> Vec<usize> {
        JointComplianceTerm::joints(self).into_iter().map(|j| j + 1).collect()
    }

    fn check(&self, cursor: &Cursor<'_>, n: usize, tools: usize) -> Result<(), EffectFault> {
        match &self.torque {
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
        // A regressor row holds 4 columns per link and the payload's: 4n + 1; a measured or
        // modelled torque has one.
        let width = if matches!(self.torque, ComplianceTorque::GravityRegressor(_)) { 4 * n + 1 } else { 1 };
        for (k, term) in self.terms.iter().enumerate() {
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
        cursor.payload_span(self.payload_span.as_ref())?;
        cursor.count("theta", self.theta.len(), self.terms.len())
    }

    fn count_fields(&self, add: &mut dyn FnMut(&'static str, usize)) {
        add("joint", self.terms.len());
        add("column", self.terms.len());
        add("scale", self.terms.len());
        match &self.torque {
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
        Cursor::count_payload_span(self.payload_span.as_ref(), add);
    }

    fn payload_span(&self) -> Option<&PayloadSpan> {
        self.payload_span.as_ref()
    }

    fn coverage_weight(&self, row: &Measurement) -> f64 {
        self.payload_span.as_ref().map_or(1.0, |s| s.coverage(row.payload_kg))
    }

    fn set_beyond_payload(&mut self, rule: BeyondSpan) {
        if let Some(span) = &mut self.payload_span {
            span.beyond = rule;
        }
    }
}

impl NewEffect for JointComplianceTerm {
    const ARGUMENTS: &'static [Argument] = &[];

    /// Every joint, through measured torques where every row has them, the gravity-torque
    /// regressors otherwise.
    fn build(_spec: &EffectSpec, context: &EffectContext<'_>, data: &BoundSet<'_>) -> Result<Self, Error> {
        let joints: Vec<usize> = (0..context.robot.joint_count()).collect();
        let load = context.load_frame(data)?;
        if has_torques(data.rows()) {
            JointComplianceTerm::modelled(load, &joints, data)
        } else {
            JointComplianceTerm::new(ComplianceTorque::GravityRegressor(load), &joints, data)
        }
    }

    /// `δq_j = c_j τ_j`, `τ_j = Y_j(q) π + payload torque`, `π` unknown: one column per entry of
    /// `Y`'s row `j` (the products `c_j π_l`) and one for the payload (`c_j` itself), second among
    /// the joint's candidates; with measured torques also the torque as the gravity regressors
    /// explain it (the sensor's noise left out, as the fit does), third.
    fn joint_candidates(context: &CandidateContext<'_>, joint: usize) -> Result<Vec<CandidateModel>, Error> {
        let gravity = ComplianceTorque::GravityRegressor(context.load.clone());
        let mut out = vec![CandidateModel::plain(
            IdentifiedEffect::JointCompliance(JointComplianceTerm::new(gravity, &[joint], context.data)?),
            1,
        )];
        if context.measured {
            let modelled = JointComplianceTerm::modelled(context.load.clone(), &[joint], context.data)?;
            if !modelled.terms.is_empty() {
                out.push(CandidateModel::plain(IdentifiedEffect::JointCompliance(modelled), 2));
            }
        }
        Ok(out)
    }
}
