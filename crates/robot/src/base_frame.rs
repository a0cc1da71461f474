//! Where the robot's base frame is in a calibrated model, which lives in the tracker frame.
//!
//! A tracker sees the arm, not its base: the base placement and joint 1's zero cannot be told apart
//! from the data, so the base frame is a convention. Ours, as in the diagnosis: the base frame is
//! where the nominal model puts it relative to joint 1, with joint 1 where the calibration found it,
//!
//! `tracker_from_base = T'_{0,1}(0) · T_{0,1}(0)⁻¹`,
//!
//! the calibrated first local transform (which holds the base placement) times the inverse of the
//! nominal one. In the base frame the calibrated joint 1 is then exactly the nominal joint 1 and
//! every calibration change sits in the later transforms. Without a nominal model the base frame
//! is the calibrated joint 1 frame at zero (`T_{0,1}(0) = I`), which is the nominal base frame for
//! descriptions whose joint 1 turns about the base z axis through the origin (all RON fixtures).

use crate::ErrorKind;
use errors::Error;
use lie::SE3;
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// How far a nominal description may be from a calibrated model and still be the one the model was
/// fitted with.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct NominalTolerance {
    /// Largest distance of a calibrated joint frame's origin from the nominal axis, m.
    pub offset_m: f64,
    /// Largest angle between a calibrated and a nominal joint axis, rad.
    pub angle_rad: f64,
}

impl Default for NominalTolerance {
    /// 20 mm and 20 mrad: ten times what calibrations move an arm's axes (a millimetre and a
    /// milliradian, see `simulated::Perturbation`), and far less than a different description's
    /// choice of frames moves them (the UR10 URDF's base is 127 mm and half a turn from its DH base).
    fn default() -> Self {
        Self { offset_m: 0.02, angle_rad: 0.02 }
    }
}

/// `tracker_from_base` of a calibrated model (reference frame: tracker) by the convention above;
/// `nominal` is the base-frame model it was fitted from, if known.
pub fn tracker_from_base(calibrated: &LocalPoe, nominal: Option<&LocalPoe>) -> SE3 {
    let first = |model: &LocalPoe| model.joints().first().map_or_else(SE3::identity, |j| j.previous_from_joint_zero);
    match nominal {
        Some(nominal) => first(calibrated) * first(nominal).inverse(),
        None => first(calibrated),
    }
}

/// The calibrated kinematics in the base frame.
pub fn in_base_frame(calibrated: &LocalPoe, nominal: Option<&LocalPoe>) -> LocalPoe {
    let mut model = calibrated.clone();
    model.change_reference(tracker_from_base(calibrated, nominal).inverse());
    model
}

/// How far each calibrated joint axis (of `in_base`, a calibrated model in the base frame) is from
/// the nominal one at the zero configuration: the distance of the calibrated joint frame's origin
/// from the nominal axis line (m) and the angle between the axes (rad). Both models must have the
/// same number of joints.
pub fn axis_changes(in_base: &LocalPoe, nominal: &LocalPoe) -> Result<Vec<(f64, f64)>, Error> {
    let zero = vec![0.0; nominal.joint_count()];
    let (calibrated, described) =
        (in_base.frames(&zero).map_err(Error::kinematics)?, nominal.frames(&zero).map_err(Error::kinematics)?);
    Ok(calibrated
        .iter()
        .zip(&described)
        .map(|(c, d)| {
            let (zc, zd) = (c.rotation().matrix().column(2).into_owned(), d.rotation().matrix().column(2).into_owned());
            let gap = c.translation() - d.translation();
            ((gap - zd * zd.dot(&gap)).norm(), zc.cross(&zd).norm().atan2(zc.dot(&zd)))
        })
        .collect())
}

/// Refuses a nominal model that is not the one `in_base` (a calibrated model in the base frame) was
/// fitted from: each joint axis at the zero configuration must lie within `tolerance` of the nominal
/// one ([`axis_changes`]). Another description of the same robot with other frames (another base,
/// another point on axis 1) moves every later axis rigidly, so this catches it.
///
/// With position-only data (`full_pose` false) the last joint is left out: a tool point on its
/// axis (a probe along the flange's z) does not tell which way the axis points, and the fit may
/// leave it tens of milliradians off without any error in the measured point. `file` names the
/// description in the message.
pub fn check_nominal(
    in_base: &LocalPoe,
    nominal: &LocalPoe,
    full_pose: bool,
    tolerance: &NominalTolerance,
    file: &str,
) -> Result<(), Error> {
    if in_base.joint_count() != nominal.joint_count() {
        return Err(Error::in_file(
            file.to_owned(),
            ErrorKind::RobotJointCount { robot: nominal.joint_count(), model: in_base.joint_count() },
        ));
    }
    let excess = |(offset, angle): (f64, f64)| (offset / tolerance.offset_m).max(angle / tolerance.angle_rad);
    let mut changes = axis_changes(in_base, nominal)?;
    if !full_pose {
        changes.pop();
    }
    let worst = (0..changes.len()).max_by(|&a, &b| excess(changes[a]).total_cmp(&excess(changes[b])));
    match worst {
        Some(joint) if excess(changes[joint]) > 1.0 => Err(Error::in_file(
            file.to_owned(),
            ErrorKind::NominalMismatch {
                joint: joint + 1,
                offset_mm: changes[joint].0 * 1e3,
                angle_mrad: changes[joint].1 * 1e3,
                limit_mm: tolerance.offset_m * 1e3,
                limit_mrad: tolerance.angle_rad * 1e3,
            },
        )),
        _ => Ok(()),
    }
}
