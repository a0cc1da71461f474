//! ISO 9283:1998 position accuracy (AP, §7.2.1) and position repeatability (RP, §7.2.2), with the
//! calibrated model's prediction as the command.
//!
//! ISO 9283 drives the robot `n` times to one commanded pose and measures where it arrives. Here
//! the "commanded" position of a row is where the calibrated model predicts the tool for its joint
//! values, and the "attained" one is the measured position. Rows whose joint values agree within
//! [`RepeatOptions::same_pose_rad`] are one pose measured several times. Per pose `j` with rows
//! `i`: `AP_j = |x̄ − x_c|` (barycentre of the attained positions against the command), and where
//! there are at least two rows, `RP_j = l̄ + 3 S_l` with `l_i = |x_i − x̄|` and
//! `S_l = √(Σ (l_i − l̄)² / (n − 1))`. A pose measured once has an AP (its error) and no RP.

use measurements::Measurement;
use serde::Serialize;

/// Which rows are one pose measured again.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RepeatOptions {
    /// Rows whose every joint value differs by less than this are one pose, rad (m for a
    /// prismatic joint). 1e-3 rad: on the real UR10 series B, 293 pairs of rows agree within
    /// 5e-4 rad on every joint (most within 1e-4: a pose the program drove to again, read back a
    /// few encoder counts apart) and no pair lies between 5e-4 and 5e-2 rad, so the threshold
    /// sits in that empty range; on series C no two rows agree within 5e-2 rad.
    /// MEASURED on /work/data/ur10_{B,C}_full.csv.
    pub same_pose_rad: f64,
}

impl Default for RepeatOptions {
    fn default() -> Self {
        Self { same_pose_rad: 1e-3 }
    }
}

/// AP and RP over a data set.
#[derive(Debug, Clone, Serialize)]
pub struct Iso9283 {
    /// The tolerance that grouped rows into poses.
    pub options: RepeatOptions,
    /// Number of distinct poses.
    pub poses: usize,
    /// Number of poses measured at least twice.
    pub repeated_poses: usize,
    /// Mean of `AP_j` over the poses, mm.
    pub ap_mean_mm: f64,
    /// Largest `AP_j`, mm.
    pub ap_max_mm: f64,
    /// Mean of `RP_j` over the repeated poses, mm (`None` without repeats).
    pub rp_mean_mm: Option<f64>,
    /// Largest `RP_j`, mm.
    pub rp_max_mm: Option<f64>,
}

impl Iso9283 {
    /// AP and RP of `rows` against `predicted` (tracker frame, m; one per row).
    pub fn new(rows: &[Measurement], predicted: &[[f64; 3]], options: RepeatOptions) -> Self {
        let groups = same_poses(rows, options.same_pose_rad);
        let mut ap = Vec::with_capacity(groups.len());
        let mut rp = Vec::new();
        for group in &groups {
            let count = group.len() as f64;
            let mean = |pick: &dyn Fn(usize) -> [f64; 3]| {
                let mut s = [0.0; 3];
                for &i in group {
                    let p = pick(i);
                    (0..3).for_each(|k| s[k] += p[k] / count);
                }
                s
            };
            let attained = mean(&|i| rows[i].position.into());
            let command = mean(&|i| predicted[i]);
            ap.push(distance(&attained, &command) * 1e3);
            if group.len() >= 2 {
                let l: Vec<f64> = group.iter().map(|&i| distance(&rows[i].position.into(), &attained) * 1e3).collect();
                let l_mean = l.iter().sum::<f64>() / count;
                let s_l = (l.iter().map(|v| (v - l_mean).powi(2)).sum::<f64>() / (count - 1.0)).sqrt();
                rp.push(l_mean + 3.0 * s_l);
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
        Self {
            options,
            poses: groups.len(),
            repeated_poses: rp.len(),
            ap_mean_mm: mean(&ap),
            ap_max_mm: max(&ap),
            rp_mean_mm: (!rp.is_empty()).then(|| mean(&rp)),
            rp_max_mm: (!rp.is_empty()).then(|| max(&rp)),
        }
    }
}

fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The rows grouped into poses: sorted by their first joint, a row joins the first earlier group
/// whose first row it matches within `tolerance` on every joint (a sweep, so `O(n log n)` on
/// distinct poses).
fn same_poses(rows: &[Measurement], tolerance: f64) -> Vec<Vec<usize>> {
    let mut order: Vec<usize> = (0..rows.len()).collect();
    let first = |i: usize| rows[i].q.first().copied().unwrap_or(0.0);
    order.sort_by(|&a, &b| first(a).total_cmp(&first(b)));
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut open = 0; // groups before this one start more than `tolerance` below the current row
    for &i in &order {
        while open < groups.len() && first(groups[open][0]) < first(i) - tolerance {
            open += 1;
        }
        let same = |g: &Vec<usize>| rows[g[0]].q.iter().zip(&rows[i].q).all(|(a, b)| (a - b).abs() < tolerance);
        match groups[open..].iter().position(same) {
            Some(k) => groups[open + k].push(i),
            None => groups.push(vec![i]),
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(q: f64, x: f64) -> Measurement {
        Measurement::at(vec![q, 0.5], nalgebra::Vector3::new(x, 0.0, 0.0))
    }

    #[test]
    fn one_pose_measured_three_times_has_the_textbook_ap_and_rp() {
        // Attained x = 1, 2, 3 mm, command 0: barycentre 2 mm, AP = 2 mm; l = 1, 0, 1 mm,
        // l̄ = 2/3, S_l = √((1/9 + 4/9 + 1/9) / 2) = √(1/3), RP = 2/3 + 3 √(1/3).
        let rows = vec![row(0.1, 1e-3), row(0.1 + 1e-4, 2e-3), row(0.1, 3e-3), row(1.0, 5e-3)];
        let predicted = vec![[0.0; 3]; 4];
        let iso = Iso9283::new(&rows, &predicted, RepeatOptions::default());
        assert_eq!((iso.poses, iso.repeated_poses), (2, 1));
        assert!((iso.ap_max_mm - 5.0).abs() < 1e-9, "the single pose misses by 5 mm: {}", iso.ap_max_mm);
        assert!((iso.ap_mean_mm - 3.5).abs() < 1e-9);
        let rp = 2.0 / 3.0 + 3.0 * (1.0f64 / 3.0).sqrt();
        assert!((iso.rp_max_mm.unwrap() - rp).abs() < 1e-9, "{:?} vs {rp}", iso.rp_max_mm);
    }

    #[test]
    fn poses_without_repeats_have_no_repeatability() {
        let rows = vec![row(0.1, 1e-3), row(0.2, 2e-3)];
        let iso = Iso9283::new(&rows, &[[0.0; 3]; 2], RepeatOptions::default());
        assert_eq!((iso.poses, iso.rp_max_mm), (2, None));
    }
}
