//! `calib export`: a calibrated model's geometry as a URDF, in the robot's base frame
//! ([`robot::base_frame`]), with a fixed `tracker` link holding the base placement and a fixed link
//! per calibrated tool.
//!
//! The local POE model maps onto a URDF chain exactly: joint `i`'s origin is the local transform
//! `T_{i-1,i}(0)` (in the base frame for joint 1) and its axis is z; each tool is a fixed joint with
//! the tool transform. Written like an existing URDF (`--like`), the file is that URDF with the
//! origins of the chain's movable joints replaced (`urdf_like.rs`). What a URDF cannot hold (joint
//! compliance, the GP) is named, and the error the model makes without it measured on the training
//! data.

use crate::ErrorKind;
use crate::urdf_like::{check_joint_kinds, write_like};
use crate::urdf_text::{Written, escape, fixed_joint, origin_element};
use errors::Error;
use lie::SE3;
use measurements::MeasurementSet;
use model::{CalibratedModel, ErrorSummary};
use poe::{JointKind, LocalPoe};
use robot::{NominalTolerance, axis_changes, check_nominal, in_base_frame, tracker_from_base};
use robot::{RobotDescription, UrdfChain, UrdfDocument};
use serde::Serialize;
use std::fmt::Write;
use std::path::Path;

/// What the URDF is written like.
#[derive(Debug, Clone, Copy)]
pub enum UrdfTemplate<'a> {
    /// A URDF of our own: links `base_link`, `link_1` … `link_n`; joints `joint_1` … `joint_n`
    /// (a joint of scale ≠ 1 followed by `joint_i_stage` on its axis, a mimic joint of multiplier
    /// `scale − 1`, through a link `link_i_drive`) with the nominal description's limits, if one is given (its base frame is used; without
    /// one the base frame is the calibrated joint 1 frame and revolute joints are continuous).
    Plain {
        /// The nominal description and its file name.
        nominal: Option<(&'a RobotDescription, &'a str)>,
    },
    /// An existing URDF whose chain is the model's robot: everything in it is kept but the
    /// origins of the chain's movable joints.
    Like {
        /// The URDF.
        document: &'a UrdfDocument,
        /// Its chain.
        chain: &'a UrdfChain,
    },
}

/// The URDF text and what it holds.
#[derive(Debug, Clone)]
pub struct UrdfExport {
    /// The URDF.
    pub text: String,
    /// What was written, and what could not be.
    pub report: UrdfExportReport,
}

/// How far the calibration moved one joint axis from the nominal one, in the base frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisChange {
    /// The URDF joint's name.
    pub joint: String,
    /// Distance of the calibrated joint frame's origin from the nominal axis, mm.
    pub offset_mm: f64,
    /// Angle between the calibrated and the nominal axis, mrad.
    pub angle_mrad: f64,
}

/// The training error with and without what the URDF cannot hold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrainingErrors {
    /// The whole model.
    pub model: ErrorSummary,
    /// The geometry alone, as the URDF holds it.
    pub urdf: ErrorSummary,
    /// The whole model without each part the URDF cannot hold, in turn: what leaving that part
    /// out costs.
    pub without_each: Vec<PartError>,
}

/// The training error of a model with one of its parts left out.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartError {
    /// The part left out.
    pub part: String,
    /// The error without it.
    pub error: ErrorSummary,
}

/// What `calib export` reports (`--json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UrdfExportReport {
    /// The `<robot name>`.
    pub robot: String,
    /// The link whose frame is the robot base.
    pub base_link: String,
    /// How the base frame was placed.
    pub base_frame: String,
    /// The fixed link at the tracker frame.
    pub tracker_link: String,
    /// One fixed link per calibrated tool, in the model's tool order.
    pub tool_links: Vec<String>,
    /// Whether the tools' orientation was calibrated (full-pose data).
    pub tool_orientation_calibrated: bool,
    /// Each movable joint's change from the nominal description (empty without one).
    pub axis_changes: Vec<AxisChange>,
    /// The model's parts that a URDF cannot hold.
    pub not_in_urdf: Vec<String>,
    /// The training error with and without them, where training data were given.
    pub training_error: Option<TrainingErrors>,
}

/// Writes the model as a URDF like `template`. A model with parts a URDF cannot hold needs its
/// `training` data, to measure the error that remains without them.
pub fn export_urdf(
    model: &CalibratedModel,
    template: UrdfTemplate<'_>,
    training: Option<&MeasurementSet>,
    tolerance: &NominalTolerance,
) -> Result<UrdfExport, Error> {
    let not_in_urdf: Vec<String> = model.non_geometric_parts();
    let training_error = training_errors(model, training, &not_in_urdf)?;
    let (nominal, nominal_file) = template_nominal(template)?;
    if let UrdfTemplate::Like { document, chain } = template {
        check_joint_kinds(document, chain, &model.joint_kinds())?;
    }
    let in_base = in_base_frame(&model.kinematics, nominal.as_ref());
    if let Some(nominal) = &nominal {
        check_nominal(&in_base, nominal, model.full_pose, tolerance, &nominal_file)?;
    }
    let base_from_tracker = tracker_from_base(&model.kinematics, nominal.as_ref()).inverse();
    let tool_links = tool_link_names(&model.tools);
    let written = match template {
        UrdfTemplate::Like { document, chain } => {
            write_like(document, chain, &in_base, base_from_tracker, &tool_links)?
        }
        UrdfTemplate::Plain { nominal: description } => {
            let name = description.map_or(model.robot.clone(), |(robot, _)| robot.name.clone());
            let limits = description.map(|(robot, _)| robot.limits());
            write_plain(&name, &in_base, limits.as_deref(), base_from_tracker, &tool_links)?
        }
    };
    let axis_changes = match &nominal {
        Some(nominal) => axis_change_list(&in_base, nominal, &written.joint_names)?,
        None => Vec::new(),
    };
    let base_frame = match &nominal {
        Some(_) => {
            format!("joint 1 where {nominal_file} puts it relative to the base, as calibrated in the tracker frame")
        }
        None => "the calibrated joint 1 frame at zero (no nominal description given)".to_owned(),
    };
    let report = UrdfExportReport {
        robot: written.robot,
        base_link: written.base_link,
        base_frame,
        tracker_link: written.tracker_link,
        tool_links: written.tool_links,
        tool_orientation_calibrated: model.full_pose,
        axis_changes,
        not_in_urdf,
        training_error,
    };
    Ok(UrdfExport { text: written.text, report })
}

/// The nominal model `template` holds, if any, and the name of its file.
fn template_nominal(template: UrdfTemplate<'_>) -> Result<(Option<LocalPoe>, String), Error> {
    Ok(match template {
        UrdfTemplate::Plain { nominal: Some((robot, file)) } => (Some(robot.nominal_model()?), file.to_owned()),
        UrdfTemplate::Plain { nominal: None } => (None, String::new()),
        UrdfTemplate::Like { document, chain } => {
            (Some(chain.description().nominal_model()?), document.file().to_owned())
        }
    })
}

/// Each movable joint's change from `nominal`, named as the written URDF names it.
fn axis_change_list(in_base: &LocalPoe, nominal: &LocalPoe, joint_names: &[String]) -> Result<Vec<AxisChange>, Error> {
    Ok(axis_changes(in_base, nominal)?
        .into_iter()
        .zip(joint_names)
        .map(|((offset, angle), joint)| AxisChange {
            joint: joint.clone(),
            offset_mm: offset * 1e3,
            angle_mrad: angle * 1e3,
        })
        .collect())
}

/// The training error of the model, of its geometry alone and without each part a URDF cannot
/// hold (`not_in_urdf`); without training data, none, and refused when there are such parts.
fn training_errors(
    model: &CalibratedModel,
    training: Option<&MeasurementSet>,
    not_in_urdf: &[String],
) -> Result<Option<TrainingErrors>, Error> {
    match training {
        Some(data) => {
            // Every model below is this one with parts left out: the same joints and tools.
            let data = &model.bind(data)?;
            let parts = model.parts();
            let without_each = (0..parts.len())
                .filter(|&k| !parts[k].in_urdf())
                .map(|k| {
                    let error = model::evaluate(&model.without_part(k), data)?.summary;
                    Ok(PartError { part: parts[k].name(), error })
                })
                .collect::<Result<_, Error>>()?;
            Ok(Some(TrainingErrors {
                model: model::evaluate(model, data)?.summary,
                urdf: model::evaluate(&model.geometry_only(), data)?.summary,
                without_each,
            }))
        }
        None if !not_in_urdf.is_empty() => Err(Error::new(ErrorKind::ExportNeedsData { parts: not_in_urdf.to_vec() })),
        None => Ok(None),
    }
}

/// Writes the URDF text to `path`, atomically ([`measurements::write_file`]).
pub fn write_urdf(path: &Path, export: &UrdfExport) -> Result<(), Error> {
    measurements::write_file(path, export.text.as_bytes())
}

/// `tool` for the default tool, `tool_<name>` for the others (characters a link name should not
/// have become `_`), made unique.
fn tool_link_names(tools: &[String]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for tool in tools {
        let clean: String =
            tool.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
        let base = if tool.is_empty() { "tool".to_owned() } else { format!("tool_{clean}") };
        let mut name = base.clone();
        let mut k = 2;
        while names.contains(&name) {
            name = format!("{base}_{k}");
            k += 1;
        }
        names.push(name);
    }
    names
}

fn write_plain(
    name: &str,
    in_base: &LocalPoe,
    limits: Option<&[(f64, f64)]>,
    base_from_tracker: SE3,
    tool_links: &[String],
) -> Result<Written, Error> {
    let n = in_base.joint_count();
    let mut text = String::from("<?xml version=\"1.0\"?>\n");
    let _ = writeln!(
        text,
        "<!-- Calibrated geometry written by calib export. Base frame: {}; `tracker` is the tracker frame.\n     Each joint turns about (or slides along) the z axis of its child link. Effort and velocity\n     limits are not known to calib (written as 0). -->",
        if limits.is_some() { "joint 1 as the nominal description places it" } else { "the calibrated joint 1 frame" }
    );
    let _ = writeln!(text, "<robot name=\"{}\">", escape(name));
    for i in 0..=n {
        let _ = writeln!(text, "  <link name=\"{}\"/>", plain_link(i));
        if i < n && in_base.joints()[i].scale != 1.0 {
            let _ = writeln!(text, "  <link name=\"{}\"/>", drive_link(i));
        }
    }
    for tool in tool_links.iter().map(String::as_str).chain(["tracker"]) {
        let _ = writeln!(text, "  <link name=\"{}\"/>", escape(tool));
    }
    for (i, joint) in in_base.joints().iter().enumerate() {
        let bounds = limits.and_then(|l| l.get(i)).copied().filter(|(lo, hi)| lo.is_finite() && hi.is_finite());
        write_plain_joint(&mut text, i, joint, bounds)?;
    }
    for (tool, link_name) in in_base.tools().iter().zip(tool_links) {
        fixed_joint(&mut text, "  ", &plain_link(n), link_name, tool);
    }
    fixed_joint(&mut text, "  ", "base_link", "tracker", &base_from_tracker);
    let _ = writeln!(text, "</robot>");
    Ok(Written {
        text,
        robot: name.to_owned(),
        base_link: "base_link".into(),
        tracker_link: "tracker".into(),
        tool_links: tool_links.to_vec(),
        joint_names: (1..=n).map(|i| format!("joint_{i}")).collect(),
    })
}

/// The link after joint `i` (0-based) in a plain URDF: `base_link` before the first joint.
fn plain_link(i: usize) -> String {
    if i == 0 { "base_link".to_owned() } else { format!("link_{i}") }
}

/// The intermediate link of joint `i` (0-based) when it moves `scale` ≠ 1 per unit of its value.
fn drive_link(i: usize) -> String {
    format!("link_{}_drive", i + 1)
}

/// Joint `i` (0-based) of a plain URDF, with its limits `bounds` where finite. A joint that moves
/// `scale` ≠ 1 per unit of its value (folded mimic stages) is written as a joint to an
/// intermediate link and a mimic stage on the same axis with multiplier `scale − 1`: the motions
/// about (along) one line add, so the pair moves as the model's joint.
fn write_plain_joint(text: &mut String, i: usize, joint: &poe::Joint, bounds: Option<(f64, f64)>) -> Result<(), Error> {
    let kind = match (joint.kind, bounds) {
        (JointKind::Revolute, Some(_)) => "revolute",
        (JointKind::Revolute, None) => "continuous",
        (JointKind::Prismatic, Some(_)) => "prismatic",
        (JointKind::Prismatic, None) => return Err(Error::new(ErrorKind::PrismaticWithoutLimits { joint: i + 1 })),
    };
    let staged = joint.scale != 1.0;
    let _ = writeln!(
        text,
        "  <joint name=\"joint_{}\" type=\"{kind}\">\n    <parent link=\"{}\"/>\n    <child link=\"{}\"/>\n    {}\n    <axis xyz=\"0 0 1\"/>",
        i + 1,
        plain_link(i),
        if staged { drive_link(i) } else { plain_link(i + 1) },
        origin_element(&joint.previous_from_joint_zero)
    );
    if let Some((lower, upper)) = bounds {
        let _ = writeln!(text, "    <limit lower=\"{lower:?}\" upper=\"{upper:?}\" effort=\"0\" velocity=\"0\"/>");
    }
    let _ = writeln!(text, "  </joint>");
    if !staged {
        return Ok(());
    }
    let multiplier = joint.scale - 1.0;
    let _ = writeln!(
        text,
        "  <joint name=\"joint_{}_stage\" type=\"{kind}\">\n    <parent link=\"{}\"/>\n    <child link=\"{}\"/>\n    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n    <axis xyz=\"0 0 1\"/>",
        i + 1,
        drive_link(i),
        plain_link(i + 1)
    );
    if let Some((lower, upper)) = bounds {
        let (a, b) = (lower * multiplier, upper * multiplier);
        let _ = writeln!(
            text,
            "    <limit lower=\"{:?}\" upper=\"{:?}\" effort=\"0\" velocity=\"0\"/>",
            a.min(b),
            a.max(b)
        );
    }
    let _ =
        writeln!(text, "    <mimic joint=\"joint_{}\" multiplier=\"{multiplier:?}\" offset=\"0\"/>\n  </joint>", i + 1);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use lie::Vector3;

    #[test]
    fn tool_links_are_named_cleanly_and_uniquely() {
        let tools: Vec<String> = ["", "smr 1", "smr_1", "a&b"].iter().map(|s| s.to_string()).collect();
        assert_eq!(tool_link_names(&tools), ["tool", "tool_smr_1", "tool_smr_1_2", "tool_a_b"]);
    }

    #[test]
    fn origins_read_back_to_the_same_transform_even_at_gimbal_lock() {
        let poses = [
            SE3::new(lie::SO3::from_rpy(0.3, std::f64::consts::FRAC_PI_2, -1.2), Vector3::new(0.1, -2.0, 1e-17)),
            SE3::new(
                lie::SO3::from_rpy(1.0, -std::f64::consts::FRAC_PI_2 + 1e-9, 2.0),
                Vector3::new(1.0 / 3.0, 0.0, 0.5),
            ),
        ];
        for pose in poses {
            let text = origin_element(&pose);
            let numbers: Vec<f64> = text
                .split('"')
                .skip(1)
                .step_by(2)
                .flat_map(|v| v.split(' ').map(|x| x.parse::<f64>().unwrap()).collect::<Vec<_>>())
                .collect();
            let back = SE3::new(
                lie::SO3::from_rpy(numbers[3], numbers[4], numbers[5]),
                Vector3::new(numbers[0], numbers[1], numbers[2]),
            );
            assert!((back.to_matrix() - pose.to_matrix()).norm() < 1e-15, "{text}");
        }
    }
}
