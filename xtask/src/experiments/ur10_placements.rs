//! How many tracker placements one series of the IPA UR10 dataset holds. Every row
//! has the commanded goal (the T-Mac's point in the robot's base frame, planned) beside the
//! measured point (tracker frame): within one placement a single rigid transform maps the goals
//! onto the measured points to the robot's uncalibrated accuracy (millimetres); a tracker moved
//! between rows breaks that by its move (metres). A series is one placement, two (split at the
//! row where the second begins, each part one rigid transform), or refused.

use lie::Vector3;

/// When the rows of a series are one placement, two, or neither.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlacementOptions {
    /// The largest distance, mm, between a measured point and its goal under the placement's rigid
    /// transform. One transform for all rows of a UR10 series leaves at most 10.8 mm (A), 4.9 (B),
    /// 12.3 (C) and 2.3 (D): the robot's uncalibrated error and the T-Mac's offset from the planned
    /// point. A moved tracker leaves its move, metres; 50 mm is far from both.
    pub max_residual_mm: f64,
    /// The fewest rows a placement may have: fewer do not determine its transform against noise.
    pub min_rows: usize,
}

impl Default for PlacementOptions {
    fn default() -> Self {
        Self { max_residual_mm: 50.0, min_rows: 10 }
    }
}

/// One placement's fit: its rows, the residual of its rigid transform.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlacementFit {
    /// Its first row (0-based) and the row after its last.
    pub rows: (usize, usize),
    /// RMS and largest distance of the measured points from the transformed goals, mm.
    pub rms_mm: f64,
    pub max_mm: f64,
    /// The row (0-based) of the largest.
    pub max_row: usize,
}

/// What the rows are.
#[derive(Debug, Clone, PartialEq)]
pub enum Placements {
    /// One placement: every row under one rigid transform.
    One(PlacementFit),
    /// Two, the second from `second.rows.0` on; `together` is the one-transform fit they fail.
    Two { first: PlacementFit, second: PlacementFit, together: PlacementFit },
}

/// Why a series is neither one placement nor two.
#[derive(Debug, Clone, PartialEq)]
pub struct NotPlacements {
    /// The one-transform fit of all rows.
    pub together: PlacementFit,
    /// The best split's two fits, where there were rows enough to try one.
    pub best_split: Option<(PlacementFit, PlacementFit)>,
}

/// The rigid fit of `goals[a..b]` onto `measured[a..b]` (mm).
fn fit(goals: &[Vector3], measured: &[Vector3], (a, b): (usize, usize)) -> PlacementFit {
    let transform = poe::identify::kabsch(&goals[a..b], &measured[a..b]);
    let residuals: Vec<f64> = (a..b).map(|i| (transform.transform_point(&goals[i]) - measured[i]).norm()).collect();
    let (max_row, max_mm) =
        residuals.iter().enumerate().fold((a, 0.0), |(r, m), (i, &d)| if d > m { (a + i, d) } else { (r, m) });
    let rms_mm = (residuals.iter().map(|d| d * d).sum::<f64>() / residuals.len().max(1) as f64).sqrt();
    PlacementFit { rows: (a, b), rms_mm, max_mm, max_row }
}

/// The placements of rows whose commanded goals (base frame, mm) are `goals` and whose measured
/// points (tracker frame, mm) are `measured`, in measuring order.
pub fn placements(
    goals: &[Vector3],
    measured: &[Vector3],
    options: &PlacementOptions,
) -> Result<Placements, Box<NotPlacements>> {
    let n = goals.len().min(measured.len());
    let together = fit(goals, measured, (0, n));
    if together.max_mm <= options.max_residual_mm {
        return Ok(Placements::One(together));
    }
    // The split whose two transforms leave the least squared residual.
    let best = (options.min_rows..=n.saturating_sub(options.min_rows))
        .map(|k| (fit(goals, measured, (0, k)), fit(goals, measured, (k, n))))
        .min_by(|(a1, b1), (a2, b2)| {
            let cost = |a: &PlacementFit, b: &PlacementFit| {
                a.rms_mm.powi(2) * (a.rows.1 - a.rows.0) as f64 + b.rms_mm.powi(2) * (b.rows.1 - b.rows.0) as f64
            };
            cost(a1, b1).total_cmp(&cost(a2, b2))
        });
    match best {
        Some((first, second))
            if first.max_mm <= options.max_residual_mm && second.max_mm <= options.max_residual_mm =>
        {
            Ok(Placements::Two { first, second, together })
        }
        best_split => Err(Box::new(NotPlacements { together, best_split })),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lie::{SE3, SO3};

    /// Goals on a 3-D spiral, measured through `placement` with millimetre noise; from row
    /// `moved_from` on through `moved` instead.
    fn rows(n: usize, moved_from: usize, moved: SE3) -> (Vec<Vector3>, Vec<Vector3>) {
        let placement = SE3::new(SO3::exp(&Vector3::new(0.1, -0.2, 2.1)), Vector3::new(2900.0, -1100.0, -1200.0));
        let goals: Vec<Vector3> = (0..n)
            .map(|i| {
                let t = i as f64 * 0.37;
                Vector3::new(400.0 * t.cos(), 400.0 * t.sin(), 300.0 + 2.0 * i as f64)
            })
            .collect();
        let measured = goals
            .iter()
            .enumerate()
            .map(|(i, g)| {
                let noise = Vector3::new((i as f64 * 1.7).sin(), (i as f64 * 2.3).cos(), (i as f64 * 0.9).sin());
                let transform = if i < moved_from { placement } else { moved * placement };
                transform.transform_point(g) + noise
            })
            .collect();
        (goals, measured)
    }

    #[test]
    fn one_placement_is_one_and_a_moved_tracker_splits_where_it_moved() {
        let options = PlacementOptions::default();
        let (goals, measured) = rows(300, 300, SE3::identity());
        let Ok(Placements::One(fit)) = placements(&goals, &measured, &options) else { panic!("one placement") };
        assert!(fit.max_mm < 2.0, "{fit:?}");
        // The tracker moved 1.2 m (and turned) before row 199.
        let moved = SE3::new(SO3::exp(&Vector3::new(0.0, 0.0, 0.3)), Vector3::new(1200.0, 0.0, 0.0));
        let (goals, measured) = rows(300, 199, moved);
        let Ok(Placements::Two { first, second, together }) = placements(&goals, &measured, &options) else {
            panic!("two placements")
        };
        assert_eq!((first.rows, second.rows), ((0, 199), (199, 300)));
        assert!(first.max_mm < 2.0 && second.max_mm < 2.0 && together.max_mm > 100.0, "{first:?} {second:?}");
    }

    #[test]
    fn rows_no_two_placements_explain_are_refused() {
        let options = PlacementOptions::default();
        let (goals, mut measured) = rows(300, 300, SE3::identity());
        // Three placements: two moves.
        for (i, point) in measured.iter_mut().enumerate() {
            if i >= 100 {
                *point += Vector3::new(800.0, 0.0, 0.0);
            }
            if i >= 200 {
                *point += Vector3::new(0.0, 900.0, 0.0);
            }
        }
        let refused = placements(&goals, &measured, &options).expect_err("three placements");
        let (first, second) = refused.best_split.unwrap();
        assert!(first.max_mm.max(second.max_mm) > options.max_residual_mm, "{first:?} {second:?}");
    }
}
