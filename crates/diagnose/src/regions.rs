//! Where the model misses: the held-out error broken down by component and by region of the
//! workspace, the payload, the temperature and the time.

use super::statistics::mean;
use serde::{Deserialize, Serialize};

/// One measured pose as the diagnosis sees it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseDiagnosis {
    /// Line in the data file.
    pub line: u64,
    /// Joint values, rad.
    pub q: Vec<f64>,
    /// Payload, kg.
    pub payload_kg: f64,
    /// Temperature, °C.
    pub temp_c: Option<f64>,
    /// Time, s.
    pub t_s: Option<f64>,
    /// Horizontal distance of the tool point from the base z axis, m.
    pub reach_m: f64,
    /// Height of the tool point above the base, m.
    pub height_m: f64,
    /// Held-out position residual of the geometric model, base-frame axes, mm.
    pub before_mm: [f64; 3],
    /// Held-out position residual once the verdict's effects are modelled, base-frame axes, mm.
    pub after_mm: [f64; 3],
    /// Held-out orientation error before and after, mrad (full-pose data).
    pub rotation_mrad: Option<[f64; 2]>,
}

impl PoseDiagnosis {
    /// Held-out position error of the geometric model, mm.
    pub fn before_error_mm(&self) -> f64 {
        norm(&self.before_mm)
    }

    /// Held-out position error with the verdict's effects, mm.
    pub fn after_error_mm(&self) -> f64 {
        norm(&self.after_mm)
    }
}

fn norm(v: &[f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The held-out error of one group of poses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Region {
    /// What the poses are grouped by: `component`, `payload`, `joint 3`, `reach`, `height`,
    /// `temperature`, `time`.
    pub dimension: String,
    /// Which group: a component name or a range.
    pub bin: String,
    /// Number of poses.
    pub n: usize,
    /// Mean held-out error of the geometric model, mm (RMS for a component).
    pub before_mm: f64,
    /// The same with the verdict's effects, mm.
    pub after_mm: f64,
}

fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let v: Vec<f64> = values.collect();
    (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// Equal-count bins of `key` (at most `bins`, at least 15 poses each).
fn quantile_regions(
    poses: &[PoseDiagnosis],
    dimension: &str,
    unit: &str,
    bins: usize,
    key: &dyn Fn(&PoseDiagnosis) -> f64,
) -> Vec<Region> {
    let mut order: Vec<usize> = (0..poses.len()).collect();
    order.sort_by(|&a, &b| key(&poses[a]).total_cmp(&key(&poses[b])));
    let bins = bins.min(poses.len() / 15).max(1);
    (0..bins)
        .map(|b| {
            let members = &order[b * poses.len() / bins..(b + 1) * poses.len() / bins];
            let (low, high) = (key(&poses[members[0]]), key(&poses[members[members.len() - 1]]));
            Region {
                dimension: dimension.to_owned(),
                bin: format!("{low:.3} … {high:.3} {unit}"),
                n: members.len(),
                before_mm: mean(&members.iter().map(|&i| poses[i].before_error_mm()).collect::<Vec<_>>()),
                after_mm: mean(&members.iter().map(|&i| poses[i].after_error_mm()).collect::<Vec<_>>()),
            }
        })
        .collect()
}

/// Every breakdown the data supports; joint bins only over the joints that move (`moving`,
/// 0-based): a bin of a joint held still splits encoder jitter, not the workspace.
pub(crate) fn regions(poses: &[PoseDiagnosis], moving: &[usize], prismatic: &[usize]) -> Vec<Region> {
    let mut out = Vec::new();
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        out.push(Region {
            dimension: "component".into(),
            bin: format!("{name} (base frame, RMS)"),
            n: poses.len(),
            before_mm: rms(poses.iter().map(|p| p.before_mm[axis])),
            after_mm: rms(poses.iter().map(|p| p.after_mm[axis])),
        });
    }
    if poses.iter().all(|p| p.rotation_mrad.is_some()) && !poses.is_empty() {
        let rotation = |k: usize| mean(&poses.iter().filter_map(|p| p.rotation_mrad.map(|r| r[k])).collect::<Vec<_>>());
        out.push(Region {
            dimension: "component".into(),
            bin: "rotation (mean, mrad)".into(),
            n: poses.len(),
            before_mm: rotation(0),
            after_mm: rotation(1),
        });
    }
    let mut payloads: Vec<f64> = poses.iter().map(|p| p.payload_kg).collect();
    payloads.sort_by(f64::total_cmp);
    payloads.dedup();
    if payloads.len() > 1 && payloads.len() <= 12 {
        for m in payloads {
            let members: Vec<&PoseDiagnosis> = poses.iter().filter(|p| p.payload_kg == m).collect();
            out.push(Region {
                dimension: "payload".into(),
                bin: format!("{m} kg"),
                n: members.len(),
                before_mm: mean(&members.iter().map(|p| p.before_error_mm()).collect::<Vec<_>>()),
                after_mm: mean(&members.iter().map(|p| p.after_error_mm()).collect::<Vec<_>>()),
            });
        }
    } else if payloads.len() > 12 {
        out.extend(quantile_regions(poses, "payload", "kg", 5, &|p| p.payload_kg));
    }
    for &j in moving {
        // A prismatic joint in millimetres, a revolute one in degrees.
        if prismatic.contains(&(j + 1)) {
            out.extend(quantile_regions(poses, &format!("joint {}", j + 1), "mm", 6, &|p| p.q[j] * 1e3));
        } else {
            out.extend(quantile_regions(poses, &format!("joint {}", j + 1), "deg", 6, &|p| p.q[j].to_degrees()));
        }
    }
    out.extend(quantile_regions(poses, "reach", "m", 5, &|p| p.reach_m));
    out.extend(quantile_regions(poses, "height", "m", 5, &|p| p.height_m));
    if poses.iter().all(|p| p.temp_c.is_some()) {
        out.extend(quantile_regions(poses, "temperature", "°C", 5, &|p| p.temp_c.unwrap_or(0.0)));
    }
    if poses.iter().all(|p| p.t_s.is_some()) {
        out.extend(quantile_regions(poses, "time", "s", 5, &|p| p.t_s.unwrap_or(0.0)));
    }
    out
}
