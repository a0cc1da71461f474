//! A calibrated model as a sequence of parts: the geometry, then the named effects, then the GP.
//! Each part applies itself to the poses of a set of rows ([`Part::apply`]); prediction, the fit's
//! "after" report, export (what a URDF cannot hold) and joint-target compensation all walk the same sequence, so
//! a new kind of part is one new variant here.
//!
//! The effects move a pose by one left exponential of the sum of their twists, exactly as the
//! identification models them (`poe::identify::PoseCorrection`): each effect adds its twist to the
//! rows' pending twist, and the pending twist is applied before the GP reads the poses and at the
//! end.

use crate::ErrorKind;
use crate::ResidualGp;
use crate::effect_sigma::EffectUncertainty;
use effects::IdentifiedEffect;
use errors::Error;
use lie::{SE3, Twist, Vector6};
use measurements::BoundSet;
use poe::LocalPoe;

/// One part of a calibrated model, in the order the parts apply.
#[derive(Debug, Clone, Copy)]
pub enum Part<'a> {
    /// The identified local POE kinematics (reference frame: the tracker).
    Geometry(&'a LocalPoe),
    /// A non-geometric effect identified with the geometry.
    Effect(&'a IdentifiedEffect),
    /// The geometry fitted alone, before the effects: where an effect fades out (outside the
    /// joint angles it was fitted on) the pose blends from the geometry-and-effects fit to this
    /// one, so that far from the training angles the model is the plain geometric fit.
    Fallback(&'a LocalPoe),
    /// The residual GP: what is left, step 2.
    GaussianProcess(&'a ResidualGp),
}

impl<'a> Part<'a> {
    /// The part's name in reports: `geometry`, the effect's label, `gaussian_process`.
    pub fn name(&self) -> String {
        match self {
            Part::Geometry(_) => "geometry".into(),
            Part::Effect(effect) => effect.label(),
            Part::Fallback(_) => "geometry_fallback".into(),
            Part::GaussianProcess(_) => "gaussian_process".into(),
        }
    }

    /// Whether a URDF can hold the part: the geometry, and the fallback geometry, which changes
    /// nothing on the joint angles the effects were fitted on (a URDF holds one geometry; the
    /// exported one is the geometry fitted with the effects).
    pub fn in_urdf(&self) -> bool {
        matches!(self, Part::Geometry(_) | Part::Fallback(_))
    }

    /// Applies the part to the state of a walk over `rows`.
    pub(crate) fn apply(&self, walk: &mut Walk<'a>) -> Result<(), Error> {
        match *self {
            Part::Geometry(kinematics) => walk.set_geometry(kinematics),
            Part::Effect(effect) => walk.add_effect(effect),
            Part::Fallback(fallback) => walk.fall_back(fallback),
            Part::GaussianProcess(residual_gp) => walk.correct_with_gp(residual_gp),
        }
    }
}

/// What each part does to the self's state ([`Part::apply`]).
impl<'a> Walk<'a> {
    /// The geometry's poses, nothing pending, every row covered.
    fn set_geometry(&mut self, kinematics: &'a LocalPoe) -> Result<(), Error> {
        self.kinematics = Some(kinematics);
        self.poses = self
            .data
            .iter()
            .map(|(row, tool)| kinematics.forward(&row.q, tool))
            .collect::<Result<_, _>>()
            .map_err(Error::kinematics)?;
        self.pending = vec![Vector6::zeros(); self.data.len()];
        self.coverage = vec![1.0; self.data.len()];
        self.posterior_variance = None;
        self.faded = None;
        Ok(())
    }

    /// The effect's twist added to each row's pending twist, its coverage and σ to the rows'.
    fn add_effect(&mut self, effect: &'a IdentifiedEffect) -> Result<(), Error> {
        let kinematics = self.kinematics.ok_or(Error::new(ErrorKind::PartOrder { part: "effect" }))?;
        for (((pending, coverage), row), &tool) in
            self.pending.iter_mut().zip(&mut self.coverage).zip(self.data.rows()).zip(self.data.tools())
        {
            *pending += effect.twist(kinematics, row, tool)?;
            *coverage *= effect.coverage_weight(row);
        }
        if effect.has_sigma() {
            let variance = self.effect_variance.get_or_insert_with(|| vec![[0.0; 6]; self.data.len()]);
            for (((variance, pose), row), &tool) in
                variance.iter_mut().zip(&self.poses).zip(self.data.rows()).zip(self.data.tools())
            {
                let sigma = effect.sigma(kinematics, row, tool, &pose.translation())?;
                for (v, s) in variance.iter_mut().zip(sigma.iter()) {
                    *v += s * s;
                }
            }
        }
        Ok(())
    }

    /// The pending twists applied; where the effects fade, the poses blend to `fallback`'s.
    fn fall_back(&mut self, fallback: &'a LocalPoe) -> Result<(), Error> {
        self.flush();
        // Where the effects' own σ says they were fitted on nothing like the row, the
        // model falls back to the geometry fitted alone, as outside a gear series' angles;
        // the σ of what is still applied shrinks with it.
        if let Some((uncertainty, effects)) = self.uncertainty {
            let kinematics = self.kinematics.ok_or(Error::new(ErrorKind::PartOrder { part: "fallback" }))?;
            let mut variances = Vec::with_capacity(self.data.len());
            for ((coverage, row), &tool) in self.coverage.iter_mut().zip(self.data.rows()).zip(self.data.tools()) {
                let sigma = uncertainty.sigma(kinematics, effects, row, tool)?;
                *coverage *= uncertainty.weight(EffectUncertainty::position(&sigma));
                variances.push(sigma.map(|s| s * s * *coverage * *coverage));
            }
            self.posterior_variance = Some(variances);
        }
        if self.coverage.iter().all(|&w| w >= 1.0) {
            return Ok(());
        }
        let mut faded = FadedPoses { unblended: self.poses.clone(), alone: self.poses.clone() };
        for ((((pose, alone_pose), coverage), row), &tool) in
            self.poses.iter_mut().zip(&mut faded.alone).zip(&self.coverage).zip(self.data.rows()).zip(self.data.tools())
        {
            if *coverage < 1.0 {
                // T = exp(w · log(T_e T_g⁻¹)) T_g: the geometry alone at w = 0.
                let alone = fallback.forward(&row.q, tool).map_err(Error::kinematics)?;
                *pose = blend(pose, &alone, *coverage);
                *alone_pose = alone;
            }
        }
        self.faded = Some(faded);
        Ok(())
    }

    /// The pending twists applied, then the GP's correction (blended with the fallback GP's where
    /// the effects fade) and its σ.
    fn correct_with_gp(&mut self, residual_gp: &'a ResidualGp) -> Result<(), Error> {
        self.flush();
        let fallback = match &self.faded {
            Some(faded) => residual_gp.predict_fallback(self.data, &faded.alone).transpose()?,
            None => None,
        };
        let mut std = Vec::with_capacity(self.poses.len());
        match (fallback, &self.faded) {
            (Some(fallback), Some(faded)) => {
                // Where the effects fade, the pose blends from the effects' pose with
                // this GP's correction to the geometry alone with the fallback GP's.
                let corrections = residual_gp.predict(self.data, &faded.unblended)?;
                for (i, ((g, s), (g0, s0))) in corrections.into_iter().zip(fallback).enumerate() {
                    let w = self.coverage[i];
                    self.poses[i] = if w < 1.0 {
                        blend(&(g * faded.unblended[i]), &(g0 * faded.alone[i]), w)
                    } else {
                        g * faded.unblended[i]
                    };
                    std.push(std::array::from_fn(|k| (w * s[k] * s[k] + (1.0 - w) * s0[k] * s0[k]).sqrt()));
                }
            }
            _ => {
                let corrections = residual_gp.predict(self.data, &self.poses)?;
                for (pose, (g, s)) in self.poses.iter_mut().zip(corrections) {
                    *pose = g * *pose;
                    std.push(s);
                }
            }
        }
        self.std = Some(std);
        Ok(())
    }
}

/// `exp(w · log(T_e T_g⁻¹)) T_g`: `geometry` at `w = 0`, `effects` at `w = 1`.
fn blend(effects: &SE3, geometry: &SE3, w: f64) -> SE3 {
    let towards = (*effects * geometry.inverse()).log().to_vector() * w;
    Twist::from_vector(&towards).exp() * *geometry
}

/// Where some row's effects fade ([`Part::Fallback`]): every row's pose before the blend, and the
/// geometry fitted alone's (the pose before the blend where a row does not fade).
#[derive(Debug)]
pub(crate) struct FadedPoses {
    unblended: Vec<SE3>,
    alone: Vec<SE3>,
}

/// The state of a walk over the parts: the poses so far, the effects' pending twist, the GP's
/// standard deviations.
#[derive(Debug)]
pub(crate) struct Walk<'a> {
    /// The rows with their model tools.
    data: &'a BoundSet<'a>,
    kinematics: Option<&'a LocalPoe>,
    pub(crate) poses: Vec<SE3>,
    pending: Vec<Vector6>,
    /// How far each row lies within the angles every effect so far was fitted on: the product
    /// of their [`IdentifiedEffect::coverage_weight`]s.
    coverage: Vec<f64>,
    /// The variance each row's effects leave uncorrected where they fade out, per component
    /// (`None` when no effect reports one).
    pub(crate) effect_variance: Option<Vec<[f64; 6]>>,
    /// The posterior uncertainty of the geometry and effects, where the model keeps it, and the
    /// effects it is of.
    uncertainty: Option<(&'a EffectUncertainty, &'a [IdentifiedEffect])>,
    /// The variance of the effects' correction at each row from their parameters' posterior,
    /// per component (`None` without [`Walk::uncertainty`]).
    pub(crate) posterior_variance: Option<Vec<[f64; 6]>>,
    pub(crate) std: Option<Vec<[f64; 6]>>,
    /// Set by [`Part::Fallback`] where some row fades: the poses the GP part blends between.
    faded: Option<FadedPoses>,
}

impl<'a> Walk<'a> {
    pub(crate) fn new(
        data: &'a BoundSet<'a>,
        uncertainty: Option<(&'a EffectUncertainty, &'a [IdentifiedEffect])>,
    ) -> Self {
        Self {
            data,
            kinematics: None,
            poses: Vec::new(),
            pending: Vec::new(),
            coverage: Vec::new(),
            effect_variance: None,
            uncertainty,
            posterior_variance: None,
            std: None,
            faded: None,
        }
    }

    /// Whether every number of the walk so far (poses, pending twists, GP deviations) is finite,
    /// and every pose within `reach` metres of the reference frame.
    pub(crate) fn is_bounded(&self, reach: f64) -> bool {
        let pose = |p: &SE3| {
            p.translation().iter().all(|v| v.abs() <= reach) && p.rotation().matrix().iter().all(|v| v.is_finite())
        };
        self.poses.iter().all(pose)
            && self.pending.iter().all(|t| t.iter().all(|v| v.is_finite()))
            && self.std.iter().flatten().all(|s| s.iter().all(|v| v.is_finite()))
    }

    /// The standard deviation of each row's pose: the GP's and the faded effects', in
    /// quadrature (independent sources); `None` when neither is part of the model.
    pub(crate) fn standard_deviations(&self) -> Option<Vec<[f64; 6]>> {
        if self.std.is_none() && self.effect_variance.is_none() && self.posterior_variance.is_none() {
            return None;
        }
        let at = |v: &Option<Vec<[f64; 6]>>, i: usize| v.as_ref().map_or([0.0; 6], |v| v[i]);
        Some(
            (0..self.data.len())
                .map(|i| {
                    let (gp, faded, posterior) =
                        (at(&self.std, i), at(&self.effect_variance, i), at(&self.posterior_variance, i));
                    std::array::from_fn(|k| (gp[k] * gp[k] + faded[k] + posterior[k]).sqrt())
                })
                .collect(),
        )
    }

    /// Applies the effects' pending twists: `exp(Σ twists) · pose`.
    pub(crate) fn flush(&mut self) {
        for (pose, pending) in self.poses.iter_mut().zip(&mut self.pending) {
            if *pending != Vector6::zeros() {
                *pose = Twist::from_vector(pending).exp() * *pose;
                *pending = Vector6::zeros();
            }
        }
    }
}
