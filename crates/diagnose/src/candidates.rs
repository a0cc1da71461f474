//! The candidate explanations of a residual, each an effect of [`effects`] (one definition
//! per effect: the fit identifies exactly what the diagnosis scores), written as extra columns of
//! the linearised problem: compliance from the gravity-torque regressors and, where the data has
//! them, from measured torques; backlash with the sign of the stated (or stand-in) static torque,
//! of the measured torque, or of a torque learnt from the data inside each fold (module
//! `learnt_side`); a Fourier series of each moving joint's own angle; thermal growth; drift.
//!
//! Every column is a left twist per unit of one parameter, in the calibrated model's reference
//! frame (the tracker). Gravity is known only in the robot's base frame, so the scalar regressors
//! (torques, their signs) come from the nominal model in the base frame, and the twists from the
//! calibrated model.

use super::design::Design;
use effects::{
    CandidateContext, CandidateModel, ComplianceParameter, ComplianceTorque, EffectContext, EffectKind,
    IdentifiedEffect, LoadFrame, has_torques, stand_in_dynamics,
};
use errors::Error;
use measurements::BoundSet;
use poe::LocalPoe;
use rayon::prelude::*;
use robot::RobotDescription;
use serde::{Deserialize, Serialize};

/// Generates [`Effect`] from the identified kinds of `loadsim::effect_kinds!`, and `None` and
/// `Unknown`.
macro_rules! verdict_effect {
    (identified { $( $(#[$doc:meta])* $kind:ident $name:ident: $term:ident $(=> $field:ident $(| $former:literal)?: $sim:ty)?, )* }
     simulated { $( $(#[$sdoc:meta])* $skind:ident $sname:ident => $sfield:ident: $ssim:ty, )* }) => {
        /// An effect a verdict can name (the SPEC's `verdict.effect`): every kind the fit
        /// identifies, in the list's order, then `None` and `Unknown`.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[serde(rename_all = "snake_case")]
        pub enum Effect {
            $( $(#[$doc])* $kind, )*
            /// Nothing beats the noise floor.
            None,
            /// Structure remains that no candidate explains.
            Unknown,
        }

        impl Effect {
            /// The SPEC name.
            pub fn name(self) -> &'static str {
                match self {
                    $( Effect::$kind => EffectKind::$kind.name(), )*
                    Effect::None => "none",
                    Effect::Unknown => "unknown",
                }
            }

            /// The kind of effect it names (`None` for `None` and `Unknown`).
            pub fn kind(self) -> Option<EffectKind> {
                match self {
                    $( Effect::$kind => Some(EffectKind::$kind), )*
                    Effect::None | Effect::Unknown => None,
                }
            }
        }

        impl From<EffectKind> for Effect {
            /// The verdict that names `kind`; `Unknown` for a kind no candidate models.
            fn from(kind: EffectKind) -> Self {
                match kind {
                    $( EffectKind::$kind => Effect::$kind, )*
                    _ => Effect::Unknown,
                }
            }
        }
    };
}

loadsim::effect_kinds!(verdict_effect);

/// One candidate: an effect on some joints, as weighted columns of the linearised problem.
#[derive(Debug, Clone)]
pub(crate) struct Candidate {
    pub effect: Effect,
    /// 1-based joints the candidate involves (empty for thermal and drift).
    pub joints: Vec<usize>,
    /// One column per parameter: `rows_per_pose × poses` weighted values.
    pub columns: Vec<Vec<f64>>,
    /// The prior standard deviation of each parameter, if not the default (module `pool`).
    pub prior_sd: Option<f64>,
    /// For a Fourier series: the orders it may take; its columns are `cos q, sin q, cos 2q, …`.
    pub orders: Option<Vec<u32>>,
    /// The effect as the fit models it (its parameters at zero): the columns are its regressor.
    pub model: IdentifiedEffect,
}

/// What the candidates are built with.
#[derive(Debug, Clone)]
pub(crate) struct Settings<'a> {
    /// 0-based joints that move: only they get a Fourier series.
    pub moving: &'a [usize],
    /// The orders a series may take (its columns run to the largest).
    pub orders: &'a [u32],
    /// Prior standard deviation of each scaled Fourier parameter, rad.
    pub series_sd: f64,
    /// When the temperature and the time vary enough for their effects.
    pub inputs: effects::CandidateOptions,
}

/// What a learnt backlash side of one joint is learnt from (module `learnt_side`).
#[derive(Debug, Clone)]
pub(crate) struct SideSource {
    /// 0-based joint.
    pub joint: usize,
    /// Index of the joint's gravity-regressor compliance candidate.
    pub compliance: usize,
    /// Its terms (the regressors whose combination is the learnt torque).
    pub terms: Vec<ComplianceParameter>,
    /// The gravity frame, for the learnt torque's definition.
    pub load: LoadFrame,
}

/// The weighted columns of an effect's regressor at every measurement.
pub(crate) fn columns_of(
    design: &Design,
    effect: &IdentifiedEffect,
    model: &LocalPoe,
    data: &BoundSet<'_>,
) -> Result<Vec<Vec<f64>>, Error> {
    let k = design.rows_per_pose;
    let twists = effect.parameter_twists(model, data)?;
    Ok(twists
        .iter()
        .map(|per_row| {
            let mut column = vec![0.0; k * per_row.len()];
            for (i, twist) in per_row.iter().enumerate() {
                design.twist_rows(i, twist, &mut column[i * k..(i + 1) * k]);
            }
            column
        })
        .collect())
}

/// Builds every candidate the data can support, each kind's own (`effects::CandidateModel`:
/// compliance from the gravity-torque regressors and, with measured torques, from them; backlash
/// with a stated or measured side; a Fourier series per moving revolute joint; thermal growth;
/// drift; and whatever a new kind offers), per joint in joint order, then those of no joint. A
/// candidate without columns, or offered only where its columns are not all zero and zero
/// throughout, is left out. Also returns, per joint with a gravity-regressor compliance candidate,
/// what its learnt backlash side is learnt from (it is learnt inside each fold, once the pool
/// exists).
pub(crate) fn build_candidates(
    robot: &RobotDescription,
    model: &LocalPoe,
    data: &BoundSet<'_>,
    design: &Design,
    settings: &Settings<'_>,
) -> Result<(Vec<Candidate>, Vec<SideSource>), Error> {
    let n = robot.joint_count();
    // The nominal arm in the base frame, where gravity is known, with the calibrated tools placed
    // on its flange (the payload hangs from them).
    let load = EffectContext {
        robot,
        kinematics: model,
        gear: effects::GearOptions::default(),
        hold_beyond_span: effects::HOLD_BEYOND_SPAN,
    }
    .load_frame(data)?;
    let dynamics = robot.dynamics.clone().unwrap_or_else(|| stand_in_dynamics(robot));
    let context = CandidateContext {
        robot,
        data,
        load: &load,
        dynamics: &dynamics,
        measured: has_torques(data.rows()),
        moving: settings.moving,
        longest_order: settings.orders.iter().copied().max().unwrap_or(1),
        options: settings.inputs,
    };
    let keep = |offered| with_columns(design, model, data, settings, offered);
    // Each joint's candidates are independent: built in parallel, then numbered in joint order,
    // so the candidate list (and everything after it) is the same on any number of threads.
    let per_joint: Vec<Vec<Candidate>> = (0..n)
        .into_par_iter()
        .map(|j| keep(IdentifiedEffect::joint_candidates(&context, j)?))
        .collect::<Result<_, _>>()?;
    let (mut candidates, sides) = numbered(robot, per_joint, &load);
    candidates.extend(keep(IdentifiedEffect::global_candidates(&context)?)?);
    Ok((candidates, sides))
}

/// The candidates of `offered` with their columns, each kept where its columns can explain
/// something.
fn with_columns(
    design: &Design,
    model: &LocalPoe,
    data: &BoundSet<'_>,
    settings: &Settings<'_>,
    offered: Vec<CandidateModel>,
) -> Result<Vec<Candidate>, Error> {
    let nonzero = |columns: &[Vec<f64>]| columns.iter().flatten().any(|v| v.abs() > 1e-12);
    let mut kept = Vec::new();
    for offer in offered {
        let columns = columns_of(design, &offer.effect, model, data)?;
        // Columns that are all zero, or features the same on every row (a constant joint offset
        // or frame change, which the geometry holds): nothing this candidate could explain.
        if columns.is_empty()
            || (offer.only_if_nonzero && !nonzero(&columns))
            || offer.effect.features_constant(data)?
        {
            continue;
        }
        kept.push(Candidate {
            effect: Effect::from(offer.effect.effect_kind()),
            joints: offer.effect.joints(),
            columns,
            prior_sd: offer.series.then_some(settings.series_sd),
            orders: offer.series.then(|| settings.orders.to_vec()),
            model: offer.effect,
        });
    }
    Ok(kept)
}

/// Every joint's candidates in joint order, and per joint with a gravity-regressor compliance
/// candidate, what its learnt backlash side is learnt from.
fn numbered(
    robot: &RobotDescription,
    per_joint: Vec<Vec<Candidate>>,
    load: &LoadFrame,
) -> (Vec<Candidate>, Vec<SideSource>) {
    let mut candidates = Vec::new();
    let mut sides = Vec::new();
    for (j, built) in per_joint.into_iter().enumerate() {
        // A balancer or an unknown mass moves the torque's zero: the backlash side is also learnt,
        // from the joint's gravity-regressor compliance. Not on a prismatic joint whose stated
        // force keeps its sign: its force is its load's weight along the axis, `−(g·a) Σ m`, whose
        // sign no mass model changes (a balancer of the robot file is in the stated force), so a
        // learnt side would only follow the noise or the payload (a vertical column).
        let constant_force =
            robot.joints[j].kind == poe::JointKind::Prismatic && !built.iter().any(|c| c.effect == Effect::Backlash);
        let side = built.iter().position(|c| {
            matches!(&c.model, IdentifiedEffect::JointCompliance(jc)
                if matches!(jc.torque, ComplianceTorque::GravityRegressor(_)))
        });
        if let Some(at) = side.filter(|_| !constant_force)
            && let IdentifiedEffect::JointCompliance(jc) = &built[at].model
        {
            let terms = jc.terms.clone();
            sides.push(SideSource { joint: j, compliance: candidates.len() + at, terms, load: load.clone() });
        }
        candidates.extend(built);
    }
    (candidates, sides)
}
