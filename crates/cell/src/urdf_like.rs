//! A calibrated model written into an existing URDF (`calib export --like arm.urdf`): the file is
//! kept as it is — links, inertias, visuals, limits, transmissions, comments — except the
//! `<origin>` of each movable joint on the chain, and a fixed tracker link and tool links are added.
//!
//! Each link keeps its meaning. With `P_i` the nominal POE frame of joint `i` and `W_i` the frame of
//! its child link (both at the zero configuration, base frame), `D_i = P_i⁻¹ W_i` is a constant
//! rotation that takes the URDF axis to z, so the link frame moves with the POE frame as
//! `W_i(q) = P_i(q) D_i`. The calibrated link frame is `W'_i = P'_i D_i`: visuals and inertias stay
//! on their link, the joint axis in the link frame is unchanged, and the joint origin becomes
//! `W'_parent⁻¹ W'_i`, where fixed joints on the chain keep their nominal origins.
//!
//! Mimic joints folded into their actuated joint (`urdf_mimic.rs`) keep their origins, axes and
//! `<mimic>` elements: the stages after the actuated joint's child link move with the folded
//! joint's POE frame as `W_k(q) = P_i(q) D_k`, so the correction on the actuated joint's origin
//! carries them exactly, and the multipliers stay as written. Where the actuated joint is beside
//! the chain (a column's motor moving a pseudo link), it keeps its origin too, and the correction
//! goes on the origin of its first stage on the chain, before that stage's offset: the shipped
//! shape is written back, the motor, its pseudo link and every `<mimic>` as they were.

use crate::ErrorKind;
use crate::urdf_text::{Written, escape, fixed_joint, origin_element};
use errors::Error;
use lie::SE3;
use poe::{JointKind, LocalPoe};
use robot::{StepMotion, UrdfChain, UrdfDocument};

/// `name`, or `calib_<name>` if the URDF already has a link so named.
fn free_link_name(document: &UrdfDocument, name: &str) -> String {
    let taken = |n: &str| document.robot().links.iter().any(|l| l.name == n);
    let mut candidate = name.to_owned();
    while taken(&candidate) {
        candidate = format!("calib_{candidate}");
    }
    candidate
}

/// Refuses a model whose joint kinds differ from the URDF chain's, at the first such `<joint>`:
/// the written file keeps the URDF's joint types, which would not be the model's.
pub(crate) fn check_joint_kinds(document: &UrdfDocument, chain: &UrdfChain, model: &[JointKind]) -> Result<(), Error> {
    let actuated = chain.joints.iter().map(|j| j.actuated(&chain.steps));
    for (k, (step, &model_kind)) in actuated.zip(model).enumerate() {
        let urdf_kind = match step.motion {
            StepMotion::Prismatic { .. } => JointKind::Prismatic,
            StepMotion::Revolute { .. } | StepMotion::Fixed => JointKind::Revolute,
        };
        if urdf_kind != model_kind {
            let (line, column) = document.element("joint", &step.joint).map_or((1, 1), |e| e.position);
            return Err(Error::at_line(
                document.file().to_owned(),
                line as u64,
                column,
                ErrorKind::UrdfJointKind {
                    joint: step.joint.clone(),
                    index: k + 1,
                    urdf: urdf_kind,
                    model: model_kind,
                },
            ));
        }
    }
    Ok(())
}

pub(crate) fn write_like(
    document: &UrdfDocument,
    chain: &UrdfChain,
    in_base: &LocalPoe,
    base_from_tracker: SE3,
    tool_links: &[String],
) -> Result<Written, Error> {
    let Origins { mut edits, joint_names, last } = calibrated_origins(document, chain, in_base)?;
    let Some(flange) = last else {
        return Err(document.error_at("link", &chain.tip_link, "the chain has no movable joint".into()));
    };
    let tool_links: Vec<String> = tool_links.iter().map(|t| free_link_name(document, t)).collect();
    let tracker_link = free_link_name(document, "tracker");
    let added = added_links(chain, in_base, &flange, &tool_links, &tracker_link, &base_from_tracker);
    let root = document.root();
    let text = document.text();
    let end_tag = text[..root.span.1].rfind("</").unwrap_or(root.span.1);
    edits.push((end_tag, 0, added));
    edits.push((
        root.span.0,
        0,
        format!(
            "<!-- Calibrated by calib export: the origins of the movable joints from {} to {} are the calibrated\n     geometry in the frame of {}; everything else is as in {}. -->\n",
            chain.base_link,
            chain.tip_link,
            chain.base_link,
            document.file()
        ),
    ));
    edits.sort_by_key(|e| std::cmp::Reverse(e.0));
    let mut written = text.to_owned();
    for (at, length, replacement) in edits {
        written.replace_range(at..at + length, &replacement);
    }
    Ok(Written {
        text: written,
        robot: document.robot().name.clone(),
        base_link: chain.base_link.clone(),
        tracker_link,
        tool_links,
        joint_names,
    })
}

/// An edit of the URDF's text: byte offset, bytes replaced, new text (applied from the end).
type Edit = (usize, usize, String);

/// The calibrated origins of the chain's movable joints, as edits of the text.
struct Origins {
    edits: Vec<Edit>,
    /// The name of each description joint given a calibrated origin, in chain order.
    joint_names: Vec<String>,
    /// The last movable step's child link and its frame in its POE joint's frame: the tools hang
    /// from it. `None` when the chain has no movable joint.
    last: Option<(String, SE3)>,
}

/// Walks the chain from the base: each joint's first step on the chain gets the origin that puts
/// its child link at `W'_i = P'_i D_i`; fixed joints and later stages keep theirs.
fn calibrated_origins(document: &UrdfDocument, chain: &UrdfChain, in_base: &LocalPoe) -> Result<Origins, Error> {
    let nominal = chain.description().nominal_model()?;
    let zero = vec![0.0; nominal.joint_count()];
    let (nominal_frames, calibrated_frames) =
        (nominal.frames(&zero).map_err(Error::kinematics)?, in_base.frames(&zero).map_err(Error::kinematics)?);
    let link_frames = chain.link_frames();
    let mut origins = Origins { edits: Vec::new(), joint_names: Vec::new(), last: None };
    let mut calibrated_link = SE3::identity();
    for ((step, nominal_link), joint) in chain.steps.iter().zip(&link_frames).zip(&joint_of_steps(chain)) {
        if step.motion == StepMotion::Fixed {
            calibrated_link = calibrated_link * step.from_to;
            continue;
        }
        let Some((i, first)) = *joint else {
            return Err(document.error_at("joint", &step.joint, format!("joint '{}' is not folded", step.joint)));
        };
        let link_in_poe = nominal_frames[i].inverse() * *nominal_link;
        if !first {
            // A stage keeps its origin; the tools hang from the last one the chain reaches.
            calibrated_link = calibrated_link * step.from_to * step.zero_motion();
            origins.last = Some((step.to_link.clone(), link_in_poe));
            continue;
        }
        // The joint's first step on the chain (its actuated joint, or the first stage of a driver
        // beside the chain, at its offset at zero) carries the calibrated frame.
        let new_link = calibrated_frames[i] * link_in_poe;
        let origin = calibrated_link.inverse() * new_link * step.zero_motion().inverse();
        calibrated_link = new_link;
        origins.edits.push(origin_edit(document, &step.joint, &origin)?);
        origins.joint_names.push(chain.joints[i].actuated(&chain.steps).joint.clone());
        origins.last = Some((step.to_link.clone(), link_in_poe));
    }
    Ok(origins)
}

/// The description's joint of each step (its actuated joint's, or that of the joint it follows),
/// and whether the step starts that joint on the chain.
fn joint_of_steps(chain: &UrdfChain) -> Vec<Option<(usize, bool)>> {
    let mut joint_of: Vec<Option<(usize, bool)>> = vec![None; chain.steps.len()];
    for (i, joint) in chain.joints.iter().enumerate() {
        for &k in std::iter::once(&joint.first).chain(&joint.stages) {
            if let Some(slot) = joint_of.get_mut(k) {
                *slot = Some((i, k == joint.first));
            }
        }
    }
    joint_of
}

/// The edit that gives the `<joint>` named `joint` the origin `origin`: its `<origin>` replaced,
/// or one put before its first child.
fn origin_edit(document: &UrdfDocument, joint: &str, origin: &SE3) -> Result<Edit, Error> {
    let Some(element) = document.element("joint", joint) else {
        return Err(document.error_at("joint", joint, format!("joint '{joint}' is not a top-level element")));
    };
    let replacement = origin_element(origin);
    Ok(match element.child("origin") {
        Some(old) => (old.span.0, old.span.1 - old.span.0, replacement),
        None => {
            let at = element.children.first().map_or(element.span.1, |c| c.span.0);
            (at, 0, format!("{replacement}\n    "))
        }
    })
}

/// The links and fixed joints added at the end of the robot: each tool hanging from the flange
/// link (`flange`: its name and its frame in its POE joint's frame), and the tracker from the base.
fn added_links(
    chain: &UrdfChain,
    in_base: &LocalPoe,
    (flange_link, flange_in_poe): &(String, SE3),
    tool_links: &[String],
    tracker_link: &str,
    base_from_tracker: &SE3,
) -> String {
    let mut added = String::from("\n  <!-- Added by calib export: the calibrated tools and the tracker frame. -->\n");
    for (tool, name) in in_base.tools().iter().zip(tool_links) {
        let _ = std::fmt::Write::write_fmt(&mut added, format_args!("  <link name=\"{}\"/>\n", escape(name)));
        fixed_joint(&mut added, "  ", flange_link, name, &(flange_in_poe.inverse() * *tool));
    }
    let _ = std::fmt::Write::write_fmt(&mut added, format_args!("  <link name=\"{}\"/>\n", escape(tracker_link)));
    fixed_joint(&mut added, "  ", &chain.base_link, tracker_link, base_from_tracker);
    added
}
