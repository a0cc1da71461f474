//! Plausibility checks that `fit` runs before it fits anything: data in the wrong unit,
//! in a mirror-image frame, or with joint angles beyond the robot's limits fit without complaint
//! (metres under `_mm` columns gave "after: mean 0.0006 mm"), so they are refused here, each with
//! the numbers that show it. `force` turns the refusals into warnings.
//!
//! The scale and the handedness come from one alignment of the nominal model's tool points with
//! the measured points, `p ≈ R (o_i + R_i t) + b`: `(R_i, o_i)` the nominal flange at row `i`'s
//! joints, `t` a tool offset per tool (unknown: fitted, at most `max_tool_offset_m` from the
//! flange), `R` a rotation (or a reflection) and `b` a translation, both closed form (Kabsch,
//! Umeyama 1991, Eq. 39–41) for a given `t`, and `t` closed form for a given `R, b` (the normal
//! matrix of `R_i t` is `n I`, so the bounded solution is the unbounded one brought into the
//! ball). The two steps alternate; each lowers the sum of squares.

use crate::ErrorKind;
use errors::{Error, OptionOutOfRange, OptionValue, option};
use lie::{Matrix3, Vector3};
use measurements::{BoundSet, MeasurementSet};
use poe::JointKind;
use robot::RobotDescription;
use serde::{Deserialize, Serialize};

/// The checks' settings (`FitOptions::plausibility`, the `plausibility` block of `--options`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlausibilityOptions {
    /// Fit anyway (`calib fit --force`): every refusal becomes a warning of the report.
    pub force: bool,
    /// The accepted ratio of the measured positions' spread (RMS distance from their centroid) to
    /// the nominal model's at the same joints, with the fitted tool: 0.8 to 1.25. The tool is
    /// fitted, so what is left is the nominal geometry's error, millimetres on a metre-sized arm
    /// (the UR10's real data: 0.87 mm before calibration), a fraction of a percent of the spread;
    /// a tracker's scale error is ppm. A factor of 1.25 either way is far beyond both and far
    /// below any unit mistake (25.4 for inches).
    pub scale_band: (f64, f64),
    /// A ratio within this factor of a unit mistake's (1000: metres under `_mm`; 25.4: inches) is
    /// named as that mistake. 3: the alignment may shorten the robot's spread by pulling the tool
    /// inwards by up to `max_tool_offset_m` on data it cannot fit, so a ratio lands near, not at,
    /// the factor; the log-midpoint of 25.4 and 1000 is a factor 6.3 from each, so 3 never names
    /// the wrong one.
    pub unit_factor_tolerance: f64,
    /// Refuse as left-handed when the best reflection's RMS residual is below this fraction of the
    /// best rotation's: 0.5. Right data fit a rotation to the nominal geometry's millimetres and a
    /// reflection not at all (tens of centimetres on a metre-sized arm); planar data fit both
    /// equally, and cannot tell (ratio 1).
    pub reflection_ratio: f64,
    /// The furthest a tool point is from the flange, metres: 0.5, the bound the README states for
    /// the tool offset the registration recovers.
    pub max_tool_offset_m: f64,
    /// How far a revolute joint value may lie beyond the robot file's limits, radians: 0.035 (2°).
    /// A controller stops at its software limits; the datasheet limits a description carries are
    /// rounded to a degree, and a file's limits may be a degree or so inside the real ones.
    pub limit_margin_rad: f64,
    /// How far a prismatic joint value may lie beyond its limits, metres: 0.002, the same
    /// allowance for rounded datasheet values.
    pub limit_margin_m: f64,
    /// Iterations of the alternating alignment: 500. Alternating steps converge linearly: on the
    /// real UR10 data (series C, 2773 rows) the rotation settled to a part in 1e9 in 138
    /// iterations (0.99 mm RMS, the registered nominal's 1.00 mm), on series B it was still
    /// moving at 200 (1.09 mm against 1.09 mm). Each iteration is one pass over the rows, without
    /// forward kinematics.
    pub max_iterations: usize,
    /// For a planar chain (every revolute axis parallel, every prismatic one across them): refuse
    /// the data when the measured positions lie further from their best plane (RMS) than this
    /// fraction of their spread: 0.05. A planar arm's axes are parallel to machining tolerance,
    /// a tenth of a milliradian to a milliradian, which tilts its plane of motion by that
    /// fraction of its reach at most; 0.05 (2.9°) is far beyond that, and far below the spread of
    /// 3-D data, which leaves any plane by a third of its spread or more (the fixtures' simulated
    /// campaigns, the UR10's real series).
    pub planar_ratio: f64,
    /// After the fit: warn when the fitted model misses the training positions by more than this
    /// times the RMS of the nominal robot placed by a rigid transform (`rotation_rms_mm`). The
    /// identification holds that placement as a special case (its base and tool parameters), so at
    /// its optimum it cannot do worse; a fit that does stopped in a wrong minimum (a 7-axis arm's
    /// identification once ended over 200 times above that placement's RMS). 2: a robust fit that leaves
    /// a few gross outliers out may exceed the least-squares placement's RMS over every row
    /// somewhat, never by half again (the check is skipped when rows were left out).
    pub wrong_minimum_ratio: f64,
}

impl Default for PlausibilityOptions {
    fn default() -> Self {
        Self {
            force: false,
            scale_band: (0.8, 1.25),
            unit_factor_tolerance: 3.0,
            reflection_ratio: 0.5,
            max_tool_offset_m: 0.5,
            limit_margin_rad: 2f64.to_radians(),
            limit_margin_m: 0.002,
            max_iterations: 500,
            planar_ratio: 0.05,
            wrong_minimum_ratio: 2.0,
        }
    }
}

impl PlausibilityOptions {
    /// Checks every value once: the field at fault, its value and what is expected.
    pub fn validate(&self) -> Result<(), OptionOutOfRange> {
        let (lo, hi) = self.scale_band;
        let accepted = lo.is_finite() && hi.is_finite() && 0.0 < lo && lo <= 1.0 && hi >= 1.0;
        OptionOutOfRange::check(
            "scale_band",
            OptionValue::Shown(format!("({lo}, {hi})")),
            accepted,
            "0 < low ≤ 1 ≤ high",
        )?;
        option::above("unit_factor_tolerance", self.unit_factor_tolerance, 1.0)?;
        option::above("reflection_ratio", self.reflection_ratio, 0.0)?;
        option::above("max_tool_offset_m", self.max_tool_offset_m, 0.0)?;
        option::at_least("limit_margin_rad", self.limit_margin_rad, 0.0)?;
        option::at_least("limit_margin_m", self.limit_margin_m, 0.0)?;
        option::above("planar_ratio", self.planar_ratio, 0.0)?;
        option::at_least("wrong_minimum_ratio", self.wrong_minimum_ratio, 1.0)?;
        let ratio = self.reflection_ratio;
        OptionOutOfRange::check("reflection_ratio", ratio, ratio <= 1.0, "at most 1")?;
        option::at_least_one("max_iterations", self.max_iterations)
    }
}

/// What the checks measured (`FitReport::plausibility`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlausibilityReport {
    /// Spread of the measured positions, RMS distance from their centroid, mm (in the unit the
    /// columns name).
    pub measured_spread_mm: f64,
    /// Spread of the nominal model's tool points at the same joints, with the fitted tool, mm.
    pub robot_spread_mm: f64,
    /// Their ratio, measured over robot (`None` where either is zero: too few or equal poses).
    pub scale_ratio: Option<f64>,
    /// RMS residual of the best rotation of the nominal tool points onto the measured, mm.
    pub rotation_rms_mm: f64,
    /// RMS residual of the best reflection, mm.
    pub reflection_rms_mm: f64,
    /// For a planar chain only: the measured positions' RMS distance from their best plane, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub out_of_plane_mm: Option<f64>,
}

/// The checks' measurements and what they refuse, in order: joint limits, scale, handedness.
pub(crate) struct Findings {
    /// The numbers, where the alignment ran (at least 4 rows).
    pub report: Option<PlausibilityReport>,
    /// The refusals, first the one to report.
    pub refusals: Vec<Error>,
}

/// Runs the checks on `bound`, the data bound to `robot`. An `Err` is a failure to compute (a kinematics error),
/// not a refusal: those are in [`Findings::refusals`].
pub(crate) fn check(
    robot: &RobotDescription,
    bound: &BoundSet<'_>,
    options: &PlausibilityOptions,
) -> Result<Findings, Error> {
    let data = bound.set();
    let mut refusals = Vec::new();
    if let Some(refusal) = joint_limits(robot, data, options) {
        refusals.push(refusal);
    }
    if data.rows.len() < 4 || !data.positions_measured {
        return Ok(Findings { report: None, refusals });
    }
    let (start, flanges) = nominal_flanges(robot, data)?;
    let measured: Vec<Vector3> = data.rows.iter().map(|r| r.position).collect();
    // A planar chain's tool moves in a plane: data that leave every plane are another robot's,
    // and fit it with the axes tilted to reach them (refused first: it explains the rest).
    let planar = robot.planar_direction().map(|direction| (direction, out_of_plane(&measured)));
    refusals.extend(planar.and_then(|planar| planar_refusal(robot, data, planar, &measured, options)));
    let problem = Alignment::new(bound, &flanges, &measured, options);
    let (report, rotation_rms, reflection_rms) = alignment_report(&problem, start, planar.map(|(_, d)| d));
    refusals.extend(scale_or_handedness(data, &report, rotation_rms, reflection_rms, options));
    Ok(Findings { report: Some(report), refusals })
}

/// The start of the fitted tool offset (the description's tool, where it has one) and, per row,
/// the nominal model's flange at its joints: rotation and position.
fn nominal_flanges(
    robot: &RobotDescription,
    data: &MeasurementSet,
) -> Result<(Vector3, Vec<(Matrix3, Vector3)>), Error> {
    // The nominal model's flange: its tool, where the description has one, is only the start of
    // the fitted tool offset.
    let mut nominal = robot.nominal_model()?;
    let start = Vector3::from(robot.tool.unwrap_or([0.0; 3]));
    nominal.set_tools(vec![nominal.tools()[0] * lie::SE3::from_translation(-start)]);
    let mut flanges = Vec::with_capacity(data.rows.len());
    for row in &data.rows {
        let pose = nominal.forward(&row.q, 0).map_err(Error::kinematics)?;
        flanges.push((pose.rotation().matrix(), pose.translation()));
    }
    Ok((start, flanges))
}

/// A planar chain's refusal of data further from their best plane (`out_of_plane`, m, with the
/// chain's axis `direction`) than `planar_ratio` of their spread.
fn planar_refusal(
    robot: &RobotDescription,
    data: &MeasurementSet,
    (direction, out_of_plane): ([f64; 3], f64),
    measured: &[Vector3],
    options: &PlausibilityOptions,
) -> Option<Error> {
    let spread = spread(measured);
    (out_of_plane > options.planar_ratio * spread).then(|| {
        Error::in_file(
            data.source.clone(),
            ErrorKind::PlanarChainData {
                robot: robot.name.clone(),
                direction,
                joints: robot.joint_count(),
                out_of_plane_mm: out_of_plane * 1e3,
                spread_mm: spread * 1e3,
                ratio: options.planar_ratio,
            },
        )
    })
}

/// The best rotation and the best reflection of the nominal tool points onto the measured
/// points: the report (`out_of_plane`: a planar chain's distance of the data from their plane,
/// m), and the RMS residual of each, m.
fn alignment_report(
    problem: &Alignment<'_>,
    start: Vector3,
    out_of_plane: Option<f64>,
) -> (PlausibilityReport, f64, f64) {
    let rotation = problem.fit(start, 1.0);
    let reflection = problem.fit(start, -1.0);
    let measured_spread = spread(problem.measured);
    let robot_spread = spread(&rotation.points);
    let scale_ratio = (measured_spread > 0.0 && robot_spread > 0.0).then(|| measured_spread / robot_spread);
    let report = PlausibilityReport {
        measured_spread_mm: measured_spread * 1e3,
        robot_spread_mm: robot_spread * 1e3,
        scale_ratio,
        rotation_rms_mm: rotation.rms * 1e3,
        reflection_rms_mm: reflection.rms * 1e3,
        out_of_plane_mm: out_of_plane.map(|distance| distance * 1e3),
    };
    (report, rotation.rms, reflection.rms)
}

/// The refusal of a spread ratio outside `scale_band` (a unit mistake, named where it is near
/// one's factor) or, only where the scale is right, of data a reflection fits far better than a
/// rotation (a left-handed frame).
fn scale_or_handedness(
    data: &MeasurementSet,
    report: &PlausibilityReport,
    rotation_rms: f64,
    reflection_rms: f64,
    options: &PlausibilityOptions,
) -> Option<Error> {
    let (lo, hi) = options.scale_band;
    if let Some(ratio) = report.scale_ratio
        && !(lo..=hi).contains(&ratio)
    {
        let column_unit = data.position_unit.unwrap_or("mm");
        Some(Error::in_file(
            data.source.clone(),
            ErrorKind::PositionScale {
                measured_spread_mm: report.measured_spread_mm,
                robot_spread_mm: report.robot_spread_mm,
                ratio,
                column_unit,
                likely_unit: likely_unit(ratio, column_unit, options.unit_factor_tolerance),
                band: options.scale_band,
            },
        ))
    } else if rotation_rms > 0.0 && reflection_rms < options.reflection_ratio * rotation_rms {
        // Only where the scale is right: a scaled point cloud fits neither, and says nothing.
        Some(Error::in_file(
            data.source.clone(),
            ErrorKind::LeftHandedFrame {
                rotation_rms_mm: report.rotation_rms_mm,
                reflection_rms_mm: report.reflection_rms_mm,
                reflection_ratio: options.reflection_ratio,
            },
        ))
    } else {
        None
    }
}

/// The first joint value beyond its limits by more than the margin, in file order.
fn joint_limits(robot: &RobotDescription, data: &MeasurementSet, options: &PlausibilityOptions) -> Option<Error> {
    let limits = robot.limits();
    let kinds = robot.joint_kinds();
    let margin = |k: usize| match kinds[k] {
        JointKind::Revolute => options.limit_margin_rad,
        JointKind::Prismatic => options.limit_margin_m,
    };
    let within = |k: usize, value: f64| {
        let (lo, hi) = limits[k];
        lo - margin(k) <= value && value <= hi + margin(k)
    };
    for row in &data.rows {
        for (k, &value) in row.q.iter().enumerate().take(limits.len()) {
            if within(k, value) {
                continue;
            }
            let column = data.joint_columns.get(k);
            // Degrees written under `_rad`: every value of the column, read as degrees, fits.
            let degrees_under_rad = column.is_some_and(|c| c.unit == "rad")
                && data.rows.iter().all(|r| r.q.get(k).is_none_or(|&v| within(k, v.to_radians())));
            return Some(Error::at_line(
                data.source.clone(),
                row.line,
                column.map_or(k + 1, |c| c.column),
                ErrorKind::JointBeyondLimits {
                    joint: k + 1,
                    kind: kinds[k],
                    value,
                    limits: limits[k],
                    margin: margin(k),
                    degrees_under_rad,
                },
            ));
        }
    }
    None
}

/// The unit the positions were likely written in, where the ratio is within `tolerance` of what
/// that unit under the column's name gives.
fn likely_unit(ratio: f64, column_unit: &str, tolerance: f64) -> Option<&'static str> {
    let column_m = if column_unit == "m" { 1.0 } else { 1e-3 };
    [("metres", 1.0), ("millimetres", 1e-3), ("inches", 0.0254)]
        .into_iter()
        .filter(|&(_, unit_m)| unit_m != column_m)
        .map(|(name, unit_m)| (name, (ratio / (column_m / unit_m)).ln().abs()))
        .filter(|&(_, distance)| distance <= tolerance.ln())
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(name, _)| name)
}

/// RMS distance of the points from their centroid.
fn spread(points: &[Vector3]) -> f64 {
    let n = points.len() as f64;
    let centroid = points.iter().sum::<Vector3>() / n;
    (points.iter().map(|p| (p - centroid).norm_squared()).sum::<f64>() / n).sqrt()
}

/// RMS distance of the points from their best plane (least squares: the square root of the
/// smallest eigenvalue of their covariance).
fn out_of_plane(points: &[Vector3]) -> f64 {
    let n = points.len() as f64;
    let centroid = points.iter().sum::<Vector3>() / n;
    let covariance = points.iter().map(|p| (p - centroid) * (p - centroid).transpose()).sum::<Matrix3>() / n;
    let smallest = covariance.symmetric_eigenvalues().min();
    smallest.max(0.0).sqrt()
}

/// The alternating alignment of the nominal tool points with the measured points.
struct Alignment<'a> {
    flanges: &'a [(Matrix3, Vector3)],
    tools: &'a [usize],
    measured: &'a [Vector3],
    tool_count: usize,
    options: &'a PlausibilityOptions,
}

/// An alignment's result: the nominal tool points with the fitted tools, and the RMS residual.
struct Aligned {
    points: Vec<Vector3>,
    rms: f64,
}

impl<'a> Alignment<'a> {
    /// The alignment of `bound`'s rows: their nominal flanges, their tools (one per tool of the
    /// data, or per index the rows use, whichever is more) and their measured positions.
    fn new(
        bound: &'a BoundSet<'_>,
        flanges: &'a [(Matrix3, Vector3)],
        measured: &'a [Vector3],
        options: &'a PlausibilityOptions,
    ) -> Self {
        let tools = bound.tools();
        let tool_count = bound.set().tools.len().max(1 + tools.iter().copied().max().unwrap_or(0));
        Self { flanges, tools, measured, tool_count, options }
    }

    /// The best alignment with `det R = determinant` (1 a rotation, −1 a reflection), every tool
    /// started at `start`.
    fn fit(&self, start: Vector3, determinant: f64) -> Aligned {
        let bound = self.options.max_tool_offset_m;
        let into_ball = |t: Vector3| if t.norm() > bound { t * (bound / t.norm()) } else { t };
        let mut tools = vec![into_ball(start); self.tool_count];
        let mut previous = f64::INFINITY;
        let mut points = self.points(&tools);
        let mut rms = f64::INFINITY;
        for _ in 0..self.options.max_iterations {
            let (rotation, translation) = kabsch(&points, self.measured, determinant);
            rms = (points
                .iter()
                .zip(self.measured)
                .map(|(n, p)| (rotation * n + translation - p).norm_squared())
                .sum::<f64>()
                / points.len() as f64)
                .sqrt();
            // Each step lowers the sum of squares; stop where it no longer does by a part in 1e9.
            if previous.is_finite() && previous - rms <= 1e-9 * previous {
                break;
            }
            previous = rms;
            // t = mean over the tool's rows of R_iᵀ (Rᵀ (p_i − b) − o_i), then into the ball.
            let mut sums = vec![(Vector3::zeros(), 0usize); self.tool_count];
            for ((&(r_i, o_i), p), &k) in self.flanges.iter().zip(self.measured).zip(self.tools) {
                sums[k].0 += r_i.transpose() * (rotation.transpose() * (p - translation) - o_i);
                sums[k].1 += 1;
            }
            for (tool, (sum, count)) in tools.iter_mut().zip(sums) {
                if count > 0 {
                    *tool = into_ball(sum / count as f64);
                }
            }
            points = self.points(&tools);
        }
        Aligned { points, rms }
    }

    fn points(&self, tools: &[Vector3]) -> Vec<Vector3> {
        self.flanges.iter().zip(self.tools).map(|((r, o), &k)| o + r * tools[k]).collect()
    }
}

/// The orthogonal `R` with `det R = determinant` and the `b` that minimise `Σ |R n_i + b − p_i|²`
/// (Kabsch; Umeyama 1991, Eq. 39–41, with the sign of the smallest singular direction chosen).
fn kabsch(from: &[Vector3], to: &[Vector3], determinant: f64) -> (Matrix3, Vector3) {
    let n = from.len() as f64;
    let (from_mean, to_mean) = (from.iter().sum::<Vector3>() / n, to.iter().sum::<Vector3>() / n);
    let covariance: Matrix3 =
        from.iter().zip(to).map(|(a, b)| (b - to_mean) * (a - from_mean).transpose()).sum::<Matrix3>() / n;
    let svd = covariance.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return (Matrix3::identity(), to_mean - from_mean);
    };
    let smallest = svd.singular_values.imin();
    let mut d = Matrix3::identity();
    d[(smallest, smallest)] = determinant * (u * v_t).determinant().signum();
    let rotation = u * d * v_t;
    (rotation, to_mean - rotation * from_mean)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud() -> Vec<Vector3> {
        (0..20)
            .map(|i| Vector3::new((i as f64 * 0.7).sin(), (i as f64 * 1.3).cos(), (i as f64 * 0.37).sin() * 0.5))
            .collect()
    }

    #[test]
    fn kabsch_recovers_a_rotation_and_a_reflection_with_the_determinant_asked_for() {
        let rotation = lie::SO3::exp(&Vector3::new(0.3, -1.1, 0.7)).matrix();
        let shift = Vector3::new(1.0, 2.0, -0.5);
        let from = cloud();
        let to: Vec<Vector3> = from.iter().map(|p| rotation * p + shift).collect();
        let (r, b) = kabsch(&from, &to, 1.0);
        assert!((r - rotation).norm() < 1e-9 && (b - shift).norm() < 1e-9);
        let mirror = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0));
        let mirrored: Vec<Vector3> = to.iter().map(|p| mirror * p).collect();
        let (r, b) = kabsch(&from, &mirrored, -1.0);
        assert!((r.determinant() + 1.0).abs() < 1e-9);
        let worst = from.iter().zip(&mirrored).map(|(p, q)| (r * p + b - q).norm()).fold(0.0, f64::max);
        assert!(worst < 1e-9, "{worst}");
    }

    #[test]
    fn a_unit_mistake_is_named_only_near_its_factor() {
        assert_eq!(likely_unit(1e-3, "mm", 3.0), Some("metres"));
        assert_eq!(likely_unit(1.0 / 25.4, "mm", 3.0), Some("inches"));
        assert_eq!(likely_unit(1e3, "m", 3.0), Some("millimetres"));
        assert_eq!(likely_unit(0.5, "mm", 3.0), None);
    }

    #[test]
    fn the_default_options_validate_and_a_bad_value_is_refused_with_its_field_value_and_range() {
        assert_eq!(PlausibilityOptions::default().validate(), Ok(()));
        let refused = |options: PlausibilityOptions| options.validate().unwrap_err().in_file("plausibility");
        let band = refused(PlausibilityOptions { scale_band: (1.1, 1.3), ..PlausibilityOptions::default() });
        assert_eq!(band, ("scale_band", "plausibility.scale_band is (1.1, 1.3), expected 0 < low ≤ 1 ≤ high".into()));
        let cases = [
            (
                PlausibilityOptions { unit_factor_tolerance: 1.0, ..Default::default() },
                "unit_factor_tolerance is 1, expected a finite number above 1",
            ),
            (
                PlausibilityOptions { reflection_ratio: 0.0, ..Default::default() },
                "reflection_ratio is 0, expected a finite number above 0",
            ),
            (
                PlausibilityOptions { reflection_ratio: 2.0, ..Default::default() },
                "reflection_ratio is 2, expected at most 1",
            ),
            (
                PlausibilityOptions { max_tool_offset_m: f64::INFINITY, ..Default::default() },
                "max_tool_offset_m is inf, expected a finite number above 0",
            ),
            (
                PlausibilityOptions { limit_margin_rad: -0.1, ..Default::default() },
                "limit_margin_rad is -0.1, expected a finite number of at least 0",
            ),
            (
                PlausibilityOptions { limit_margin_m: f64::NAN, ..Default::default() },
                "limit_margin_m is NaN, expected a finite number of at least 0",
            ),
            (
                PlausibilityOptions { planar_ratio: 0.0, ..Default::default() },
                "planar_ratio is 0, expected a finite number above 0",
            ),
            (
                PlausibilityOptions { wrong_minimum_ratio: 0.5, ..Default::default() },
                "wrong_minimum_ratio is 0.5, expected a finite number of at least 1",
            ),
            (
                PlausibilityOptions { max_iterations: 0, ..Default::default() },
                "max_iterations is 0, expected at least 1",
            ),
        ];
        for (options, message) in cases {
            let (field, text) = refused(options);
            assert_eq!(text, format!("plausibility.{message}"));
            assert!(message.starts_with(field), "{field}: {message}");
        }
        // Limits themselves are accepted where the range includes them.
        let at_limits = PlausibilityOptions {
            limit_margin_rad: 0.0,
            limit_margin_m: 0.0,
            wrong_minimum_ratio: 1.0,
            reflection_ratio: 1.0,
            scale_band: (1.0, 1.0),
            ..Default::default()
        };
        assert_eq!(at_limits.validate(), Ok(()));
    }
}
