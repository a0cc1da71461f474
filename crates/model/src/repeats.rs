//! Repeated configurations: rows whose joint vectors agree within a tolerance, a pose measured
//! more than once. A held-out estimate that leaves one row out keeps its twin, and what a GP or
//! an effect learns from the twin is the row's own value; leaving the whole group out is the
//! estimate of a pose the fit has not seen (284 of UR10 series B's 748 even rows repeat
//! a configuration to 1e-4 rad, and its GP's leave-one-out error said 0.107 mm where the odd rows
//! measure 0.272).

use measurements::Measurement;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// How the fit estimates its held-out error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HeldoutOptions {
    /// Rows whose joint values all agree within this (rad for a revolute joint, m for a prismatic
    /// one; the largest difference over the joints) are one configuration measured again, and
    /// are left out together. 1e-3: on the UR10 data the repeats of series B agree to 1e-4 rad
    /// (the controller's repeatability), and no two distinct configurations of B or C lie within
    /// 1e-2 (the nearest, on C, 1.2e-2 … 5e-2 apart); 1 mrad of a joint moves the UR10's tool
    /// by at most 1.3 mm, where the GP's length scales are tenths of a radian.
    pub repeat_tolerance: f64,
}

impl Default for HeldoutOptions {
    fn default() -> Self {
        Self { repeat_tolerance: 1e-3 }
    }
}

impl HeldoutOptions {
    /// The tolerance is finite and not negative (0: only identical joint vectors repeat).
    pub fn validate(&self) -> Result<(), errors::OptionOutOfRange> {
        let t = self.repeat_tolerance;
        errors::OptionOutOfRange::check("repeat_tolerance", t, t.is_finite() && t >= 0.0, "a number of at least 0")
    }
}

/// The rows grouped by configuration: a partition of the rows, each group in row order, groups in
/// the order of their first row; rows joined where their joint vectors differ by at most
/// `tolerance` in every joint (and joined through a chain of such rows).
#[derive(Debug, Clone, PartialEq)]
pub struct RepeatGroups {
    /// Every row in exactly one group.
    pub groups: Vec<Vec<usize>>,
}

impl RepeatGroups {
    /// Groups `rows` by configuration. Rows are binned on a grid of `10 · tolerance` cells, and a
    /// row is compared only with the rows of its cell and of the neighbouring cells on the sides
    /// it lies within `tolerance` of, so the cost stays near linear in the rows.
    pub fn of(rows: &[Measurement], tolerance: f64) -> Self {
        let n = rows.len();
        let mut parent: Vec<usize> = (0..n).collect();
        // Any cell size holds identical vectors together, where only those repeat.
        let cell_size = if tolerance > 0.0 { 10.0 * tolerance } else { 1.0 };
        let cell = |q: &[f64]| -> Vec<i64> { q.iter().map(|v| (v / cell_size).floor() as i64).collect() };
        let mut bins: HashMap<Vec<i64>, Vec<usize>> = HashMap::new();
        for (i, row) in rows.iter().enumerate() {
            bins.entry(cell(&row.q)).or_default().push(i);
        }
        for (i, row) in rows.iter().enumerate() {
            let home = cell(&row.q);
            let offsets = twin_offsets(&row.q, &home, cell_size, tolerance);
            let mut index = vec![0usize; offsets.len()];
            loop {
                let key: Vec<i64> = home.iter().zip(&index).zip(&offsets).map(|((c, &k), o)| c + o[k]).collect();
                for &j in bins.get(&key).map_or(&[][..], Vec::as_slice) {
                    if j < i && same_configuration(&row.q, &rows[j].q, tolerance) {
                        union(&mut parent, i, j);
                    }
                }
                // The next combination of offsets, odometer-wise.
                let mut d = 0;
                while d < index.len() {
                    index[d] += 1;
                    if index[d] < offsets[d].len() {
                        break;
                    }
                    index[d] = 0;
                    d += 1;
                }
                if d == index.len() {
                    break;
                }
            }
        }
        Self { groups: groups_by_root(&mut parent) }
    }

    /// Rows that share their configuration with another row.
    pub fn repeated_rows(&self) -> usize {
        self.groups.iter().filter(|g| g.len() > 1).map(Vec::len).sum()
    }

    /// Whether any configuration is repeated.
    pub fn any(&self) -> bool {
        self.groups.iter().any(|g| g.len() > 1)
    }
}

fn same_configuration(a: &[f64], b: &[f64], tolerance: f64) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tolerance)
}

/// Per joint, the cell offsets a twin of `q` (in cell `home`) can be in: 0, and -1 / +1 where
/// `q` lies within `tolerance` of the cell's edge.
fn twin_offsets(q: &[f64], home: &[i64], cell_size: f64, tolerance: f64) -> Vec<Vec<i64>> {
    q.iter()
        .zip(home)
        .map(|(v, c)| {
            let low = v - *c as f64 * cell_size;
            let mut o = vec![0];
            if low <= tolerance {
                o.push(-1);
            }
            if cell_size - low <= tolerance {
                o.push(1);
            }
            o
        })
        .collect()
}

/// The rows of each union-find root, groups in the order of their first row.
fn groups_by_root(parent: &mut [usize]) -> Vec<Vec<usize>> {
    let mut by_root: HashMap<usize, usize> = HashMap::new();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in 0..parent.len() {
        let root = find(parent, i);
        let g = *by_root.entry(root).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(i);
    }
    groups
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

fn union(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb)] = ra.min(rb);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lie::Vector3;

    fn row(q: &[f64]) -> Measurement {
        Measurement::at(q.to_vec(), Vector3::zeros())
    }

    /// The grid finds every pair a brute-force comparison finds, across cell edges and chains.
    #[test]
    fn groups_match_brute_force_across_cell_edges() {
        let t = 1e-3;
        // Twins straddling a cell edge (10 t = 0.01), a chain of three, a near miss, negatives.
        let qs: Vec<Vec<f64>> = vec![
            vec![0.0099, 1.0],
            vec![0.0101, 1.0],
            vec![0.5, -0.3],
            vec![0.5008, -0.3],
            vec![0.5016, -0.3],
            vec![0.7, 0.2],
            vec![0.7012, 0.2],
            vec![-0.02, -0.0005],
            vec![-0.0195, 0.0004],
            vec![0.0099, 1.0011],
        ];
        let rows: Vec<Measurement> = qs.iter().map(|q| row(q)).collect();
        let groups = RepeatGroups::of(&rows, t);
        assert_eq!(groups.groups, vec![vec![0, 1], vec![2, 3, 4], vec![5], vec![6], vec![7, 8], vec![9]]);
        assert_eq!(groups.repeated_rows(), 7);
        assert!(groups.any());
        let alone = RepeatGroups::of(&rows[..3], t);
        assert_eq!(alone.groups, vec![vec![0, 1], vec![2]]);
        assert_eq!(RepeatGroups::of(&rows, 0.0).groups.len(), rows.len());
        assert!(!RepeatGroups::of(&[], t).any());
    }

    #[test]
    fn a_negative_or_infinite_tolerance_is_refused() {
        for t in [-1e-3, f64::NAN, f64::INFINITY] {
            let options = HeldoutOptions { repeat_tolerance: t };
            assert_eq!(options.validate().unwrap_err().field, "repeat_tolerance");
        }
        assert!(HeldoutOptions::default().validate().is_ok());
    }
}
