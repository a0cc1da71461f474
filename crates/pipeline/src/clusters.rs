//! Configuration clusters: the groups of rows that lie on one inverse-kinematic
//! branch of the arm (elbow up or down, wrist flipped or not), found from the robot and the data,
//! not named for one robot. A joint separates branches where the manipulator Jacobian's
//! determinant changes sign at angles of that joint alone, whatever the other joints are (for a
//! UR or an IRB: joint 3 at the stretched elbow, joint 5 where axes 4 and 6 align; the shoulder's
//! singular surface depends on several joints and is not a joint's sign). A row's branch of such a
//! joint is the parity of the singular angles below its angle; a cluster is one pattern of
//! branches. The determinant is of the six revolute joints' columns, so an arm on a lifting
//! column or a linear track (six revolute joints and prismatic ones) has branches too; an arm with
//! another number of revolute joints (a 7-axis arm: the matrix is not square) has none.
//!
//! A prismatic joint whose values in the data span at least `min_height_span_m` (a lifting
//! column, a track) splits the rows at its median: the lower and the upper half are clusters of
//! their own, so that the prior's strength is also chosen by how a fit on one half carries to the
//! other: a column's height is a configuration as much as an arm's branch.

use errors::Error;
use measurements::Measurement;
use poe::{JointKind, LocalPoe};
use serde::Serialize;
use std::f64::consts::PI;

/// How the branches are found. Tuning constants of [`crate::NominalPriorOptions`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct ScanOptions {
    /// A prismatic joint splits the rows at its median when its values span at least this, m.
    pub min_height_span_m: f64,
    /// Angles of a joint at which the determinant is evaluated over a turn.
    pub steps: usize,
    /// Rows (spread over the data) at which a joint's singular angles must agree.
    pub probes: usize,
    /// How closely, rad.
    pub tolerance_rad: f64,
}

/// A joint whose singular angles separate branches of the arm.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BranchJoint {
    /// The joint, 1-based.
    pub joint: usize,
    /// Its singular angles in `[-180°, 180°)`, degrees, ascending.
    pub singular_deg: Vec<f64>,
}

/// A prismatic joint whose median splits the rows into a lower and an upper cluster.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeightSplit {
    /// The joint, 1-based.
    pub joint: usize,
    /// The median of its values, m: rows below it are the lower half.
    pub split_m: f64,
}

/// The prismatic joints of `model` whose values in `rows` span at least `options.min_height_span_m`.
pub(crate) fn height_splits(model: &LocalPoe, rows: &[Measurement], options: ScanOptions) -> Vec<HeightSplit> {
    if rows.is_empty() {
        return Vec::new();
    }
    (0..model.joint_count())
        .filter(|&j| model.joints()[j].kind == JointKind::Prismatic)
        .filter_map(|j| {
            let mut values: Vec<f64> = rows.iter().map(|r| r.q[j]).collect();
            values.sort_by(f64::total_cmp);
            let span = values[values.len() - 1] - values[0];
            (span >= options.min_height_span_m).then(|| {
                // The split lies strictly above the lowest value, so that neither half is empty.
                let median = values[values.len() / 2];
                HeightSplit { joint: j + 1, split_m: if median > values[0] { median } else { values[0] + 0.5 * span } }
            })
        })
        .collect()
}

/// The rows of one configuration cluster.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cluster {
    /// The branch of every branch joint, as the span of its angles between two singular ones:
    /// `joint 3 0…180°, joint 5 -180…0°`.
    pub label: String,
    /// Its rows, by index into the data.
    #[serde(skip)]
    pub rows: Vec<usize>,
    /// How many rows.
    pub n: usize,
}

fn wrap(angle: f64) -> f64 {
    (angle + PI).rem_euclid(2.0 * PI) - PI
}

/// The indices of the revolute joints, when there are six of them.
fn six_revolute(model: &LocalPoe) -> Option<Vec<usize>> {
    let revolute: Vec<usize> =
        (0..model.joint_count()).filter(|&j| model.joints()[j].kind == JointKind::Revolute).collect();
    (revolute.len() == 6).then_some(revolute)
}

/// The determinant of the 6 × 6 spatial Jacobian of the six revolute joints at `q`.
fn determinant(model: &LocalPoe, q: &[f64]) -> Result<f64, Error> {
    let twists = model.spatial_twists(q).map_err(Error::kinematics)?;
    let columns: Vec<nalgebra::Vector6<f64>> =
        six_revolute(model).unwrap_or_default().into_iter().map(|j| twists[j].to_vector()).collect();
    if columns.len() != 6 {
        return Ok(0.0);
    }
    Ok(nalgebra::Matrix6::from_columns(&columns).determinant())
}

/// The angles in `[-π, π)` at which the determinant changes sign as joint `j` turns, the others
/// held at `q`. The grid is offset by half a step, so that no singular angle at a round value
/// (0, ±π) falls on it, and closes over the turn.
fn sign_changes(model: &LocalPoe, q: &[f64], j: usize, steps: usize) -> Result<Vec<f64>, Error> {
    let angle = |k: usize| -PI + 2.0 * PI * (k as f64 + 0.5) / steps as f64;
    let mut at = q.to_vec();
    let mut values = Vec::with_capacity(steps);
    for k in 0..steps {
        at[j] = angle(k);
        values.push(determinant(model, &at)?);
    }
    let mut zeros = Vec::new();
    for k in 0..steps {
        let (a, b) = (values[k], values[(k + 1) % steps]);
        if (a > 0.0 && b < 0.0) || (a < 0.0 && b > 0.0) {
            zeros.push(wrap(angle(k) + (2.0 * PI / steps as f64) * a / (a - b)));
        }
    }
    zeros.sort_by(f64::total_cmp);
    Ok(zeros)
}

/// The joints with singular angles that are the same at every probe row, and those angles.
pub(crate) fn branch_joints(
    model: &LocalPoe,
    rows: &[Measurement],
    options: ScanOptions,
) -> Result<Vec<BranchJoint>, Error> {
    let n = model.joint_count();
    if six_revolute(model).is_none() || rows.is_empty() {
        return Ok(Vec::new());
    }
    // One probe from each of `probes` consecutive stretches of the rows: the one farthest from
    // a singular pose (largest |det|), so that no other factor's zero, nor rounding, hides the
    // sign changes (a pose at a wrist singularity has a determinant of rounding noise).
    let mut probes: Vec<&[f64]> = Vec::with_capacity(options.probes);
    for p in 0..options.probes.min(rows.len()) {
        let stretch = &rows[p * rows.len() / options.probes..((p + 1) * rows.len() / options.probes).max(p + 1)];
        let mut best: Option<(f64, &[f64])> = None;
        for row in stretch {
            let size = determinant(model, &row.q)?.abs();
            if best.is_none_or(|(b, _)| size > b) {
                best = Some((size, row.q.as_slice()));
            }
        }
        probes.extend(best.map(|(_, q)| q));
    }
    let mut joints = Vec::new();
    for j in 0..n {
        if model.joints()[j].kind != JointKind::Revolute {
            continue;
        }
        // The singular angles every probe shares: the zeros of a factor of the determinant that
        // depends on this joint alone (the others move with the other joints).
        let mut common = sign_changes(model, probes[0], j, options.steps)?;
        for q in &probes[1..] {
            if common.is_empty() {
                break;
            }
            let other = sign_changes(model, q, j, options.steps)?;
            common.retain(|a| other.iter().any(|b| wrap(a - b).abs() <= options.tolerance_rad));
        }
        // Around a turn a factor changes sign an even number of times; an odd count is no
        // branch this scan can tell.
        if !common.is_empty() && common.len() % 2 == 0 {
            joints.push(BranchJoint { joint: j + 1, singular_deg: common.iter().map(|a| a.to_degrees()).collect() });
        }
    }
    Ok(joints)
}

/// The branch of joint angle `q`: `true` where an even number of singular angles lie at or below
/// it.
fn branch(joint: &BranchJoint, q: f64) -> bool {
    let q = wrap(q).to_degrees();
    joint.singular_deg.iter().filter(|&&s| s <= q).count() % 2 == 0
}

/// A branch in words: with two singular angles `a < b`, `a…b°` or `b…a+360°`; with more, the
/// parity of the singular angles below the joint's angle.
fn side(joint: &BranchJoint, even: bool) -> String {
    match joint.singular_deg[..] {
        [a, b] if even => format!("{:.0}…{:.0}°", b, a + 360.0),
        [a, b] => format!("{a:.0}…{b:.0}°"),
        _ => (if even { "even" } else { "odd" }).to_owned(),
    }
}

/// The rows grouped by their pattern of branches and column halves, largest cluster first (ties
/// by label).
pub(crate) fn clusters(joints: &[BranchJoint], heights: &[HeightSplit], rows: &[Measurement]) -> Vec<Cluster> {
    let mut groups: std::collections::BTreeMap<Vec<bool>, Vec<usize>> = std::collections::BTreeMap::new();
    for (i, row) in rows.iter().enumerate() {
        let key: Vec<bool> = joints
            .iter()
            .map(|j| branch(j, row.q[j.joint - 1]))
            .chain(heights.iter().map(|h| row.q[h.joint - 1] >= h.split_m))
            .collect();
        groups.entry(key).or_default().push(i);
    }
    let mut clusters: Vec<Cluster> = groups
        .into_iter()
        .map(|(key, rows)| {
            let label = if joints.is_empty() && heights.is_empty() {
                "all rows".to_owned()
            } else {
                let parts: Vec<String> = joints
                    .iter()
                    .zip(&key)
                    .map(|(j, &even)| format!("joint {} {}", j.joint, side(j, even)))
                    .chain(heights.iter().zip(&key[joints.len()..]).map(|(h, &upper)| {
                        let relation = if upper { "at or above" } else { "below" };
                        format!("joint {} {relation} {:.1} mm", h.joint, h.split_m * 1e3)
                    }))
                    .collect();
                parts.join(", ")
            };
            Cluster { label, n: rows.len(), rows }
        })
        .collect();
    clusters.sort_by(|a, b| b.n.cmp(&a.n).then_with(|| a.label.cmp(&b.label)));
    clusters
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ur10() -> LocalPoe {
        let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots/ur10.ron");
        robot::RobotDescription::read(&path).unwrap().nominal_model().unwrap()
    }

    fn row(q: [f64; 6]) -> Measurement {
        Measurement::at(q.to_vec(), lie::Vector3::zeros())
    }

    #[test]
    fn a_ur10s_branches_are_the_elbow_and_the_wrist_at_zero_and_half_a_turn() {
        // The first row at the wrist's singularity: its determinant is rounding noise, with
        // hundreds of sign changes of joint 3 (as row 0 of the UR10's series B, even rows); the
        // scan probes the other row of its stretch.
        let rows: Vec<Measurement> = std::iter::once(row([0.2, -0.6, -1.0, -1.5, 0.0, 0.3]))
            .chain((1..16).map(|k| {
                let t = 0.5 * k as f64;
                row([0.3 * t - 1.0, -0.2 * t - 0.5, 0.25 * t - 1.1, 0.4 * t - 2.0, 0.3 * t - 1.3, 0.1 * t])
            }))
            .collect();
        let options = ScanOptions { steps: 720, probes: 8, tolerance_rad: 1e-2, min_height_span_m: 0.1 };
        let joints = branch_joints(&ur10(), &rows, options).unwrap();
        let named: Vec<usize> = joints.iter().map(|j| j.joint).collect();
        assert_eq!(named, [3, 5], "{joints:?}");
        for joint in &joints {
            assert_eq!(joint.singular_deg.len(), 2, "{joint:?}");
            assert!(joint.singular_deg.iter().any(|s| s.abs() < 0.5), "{joint:?}");
            assert!(joint.singular_deg.iter().any(|s| (s.abs() - 180.0).abs() < 0.5), "{joint:?}");
        }
        let found =
            clusters(&joints, &[], &[row([0.0, -1.0, 1.0, 0.0, 1.0, 0.0]), row([0.0, -1.0, -1.0, 0.0, 1.0, 0.0])]);
        assert_eq!(found.len(), 2, "{found:?}");
        assert_ne!(found[0].label, found[1].label);
    }
}
