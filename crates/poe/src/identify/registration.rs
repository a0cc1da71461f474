//! A closed-form first guess of the tracker placement and the tool offsets, so that the
//! identification needs no initial guess from the user.

use super::{Observation, Target};
use crate::{Error, LocalPoe};
use lie::{Matrix3, SE3, SO3, Vector3};

/// Nearest rotation to a 3×3 matrix (polar decomposition), keeping a right-handed result.
pub fn nearest_rotation(m: &Matrix3) -> SO3 {
    let svd = m.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return SO3::identity();
    };
    let mut correction = Matrix3::identity();
    if (u * v_t).determinant() < 0.0 {
        correction[(2, 2)] = -1.0;
    }
    SO3::from_matrix_unchecked(u * correction * v_t)
}

/// Registers the nominal model into the measurement frame and estimates each tool's
/// `flange_from_tool` transform, by linear least squares.
///
/// With `tracker_from_base = (R, t)`, flange poses `(R_f, p_f)` from the nominal model and a tool
/// offset `u` in the flange frame, a measured point is `p = R p_f + R R_f u + t`. Writing
/// `W_jk = u_k R e_j`, the term `R R_f u = Σ_jk (R_f)_jk W_jk` is linear, so each coordinate of `p`
/// is linear in `[p_f, vec(R_f), 1]` with 3 + 9 + 1 unknowns (9 more per extra tool). `R` is the
/// rotation nearest to the fitted `p_f` coefficients; `u_k = ⅓ Σ_j (R e_j)·W_jk`. Full-pose data
/// also gives the tool orientation, as the chordal mean of `R_fᵀ Rᵀ R_measured`.
///
/// `nominal` must have the flange as its only tool. The returned model has the measurement frame
/// as reference and one tool per tool index seen in `observations`.
pub fn register(nominal: &LocalPoe, observations: &[Observation]) -> Result<LocalPoe, Error> {
    let tool_count = observations.iter().map(|o| o.tool + 1).max().unwrap_or(1);
    let unknowns = 4 + 9 * tool_count;
    if observations.len() < unknowns {
        return Err(Error::TooFewForRegistration { observations: observations.len(), needed: unknowns });
    }
    let flanges: Vec<SE3> = observations.iter().map(|o| nominal.forward(&o.q, 0)).collect::<Result<_, _>>()?;
    let points: Vec<Vector3> = observations
        .iter()
        .map(|o| match o.target {
            Target::Pose(pose) => pose.translation(),
            Target::Point(point) => point,
        })
        .collect();
    let closed = closed_form(observations, &flanges, &points, tool_count)?;
    // The linear solve above splits its coefficients between the flange positions and the flange
    // rotations, which are nearly dependent when few joints move (a point fixed to the flange
    // moves with both): its rotation can then be far off. Alternating rigid fits from zero tool
    // offsets do not share that weakness; the start with the smaller residual is kept.
    let alternating = alternating_fit(observations, &flanges, &points, tool_count);
    let residual = |(placement, offsets): &(SE3, Vec<Vector3>)| -> f64 {
        observations
            .iter()
            .zip(&flanges)
            .zip(&points)
            .map(|((o, f), p)| (p - placement.transform_point(&f.transform_point(&offsets[o.tool]))).norm_squared())
            .sum()
    };
    let (tracker_from_base, offsets) = if residual(&alternating) < residual(&closed) { alternating } else { closed };
    let mut orientation_sums = vec![Matrix3::zeros(); tool_count];
    for ((observation, flange), _) in observations.iter().zip(&flanges).zip(&points) {
        if let Target::Pose(measured) = observation.target {
            orientation_sums[observation.tool] +=
                (tracker_from_base * *flange).rotation().inverse().matrix() * measured.rotation().matrix();
        }
    }
    let flange_tool = nominal.tools()[0];
    let tools = offsets
        .iter()
        .zip(&orientation_sums)
        .map(|(offset, sum)| {
            let orientation = if sum.norm() > 0.0 { nearest_rotation(sum) } else { SO3::identity() };
            flange_tool * SE3::new(orientation, *offset)
        })
        .collect();
    let mut model = nominal.clone();
    model.set_tools(tools);
    model.change_reference(tracker_from_base);
    Ok(model)
}

/// The linear least-squares placement and tool offsets (the derivation on [`register`]): `R`
/// nearest the fitted `p_f` coefficients, `u_k = ⅓ Σ_j (R e_j)·W_jk`, then `t` from the residual mean.
fn closed_form(
    observations: &[Observation],
    flanges: &[SE3],
    points: &[Vector3],
    tool_count: usize,
) -> Result<(SE3, Vec<Vector3>), Error> {
    let count = observations.len() as f64;
    let x = linear_coefficients(observations, flanges, points, tool_count)?;
    let m = Matrix3::from_fn(|c, j| x[(j, c)]);
    let rotation = nearest_rotation(&m);
    let r = rotation.matrix();
    let mut offsets = vec![Vector3::zeros(); tool_count];
    for (tool, offset) in offsets.iter_mut().enumerate() {
        for k in 0..3 {
            offset[k] =
                (0..3).map(|j| (0..3).map(|c| r[(c, j)] * x[(3 + 9 * tool + 3 * j + k, c)]).sum::<f64>()).sum::<f64>()
                    / 3.0;
        }
    }
    // The translation from the residual mean, now that R and the offsets are fixed.
    let translation = observations
        .iter()
        .zip(flanges)
        .zip(points)
        .map(|((o, f), p)| p - rotation.act(&f.transform_point(&offsets[o.tool])))
        .sum::<Vector3>()
        / count;
    Ok((SE3::new(rotation, translation), offsets))
}

/// The coefficients of `[p_f, vec(R_f) per tool, 1]` for each coordinate of the measured point
/// (`unknowns × 3`), on centred data, by a truncated SVD solve; refused below the rank the
/// tools' offsets need.
fn linear_coefficients(
    observations: &[Observation],
    flanges: &[SE3],
    points: &[Vector3],
    tool_count: usize,
) -> Result<faer::Mat<f64>, Error> {
    let unknowns = 4 + 9 * tool_count;
    // Centre the data so that the columns are comparable in scale.
    let count = observations.len() as f64;
    let mean_flange = flanges.iter().map(|f| f.translation()).sum::<Vector3>() / count;
    let mean_point = points.iter().sum::<Vector3>() / count;
    let mut a = faer::Mat::<f64>::zeros(observations.len(), unknowns);
    let mut b = faer::Mat::<f64>::zeros(observations.len(), 3);
    for (row, ((observation, flange), point)) in observations.iter().zip(flanges).zip(points).enumerate() {
        let p = flange.translation() - mean_flange;
        let r = flange.rotation().matrix();
        for j in 0..3 {
            a[(row, j)] = p[j];
        }
        for j in 0..3 {
            for k in 0..3 {
                a[(row, 3 + 9 * observation.tool + 3 * j + k)] = r[(j, k)];
            }
        }
        a[(row, unknowns - 1)] = 1.0;
        let centred = point - mean_point;
        for c in 0..3 {
            b[(row, c)] = centred[c];
        }
    }
    let svd = a.thin_svd().map_err(|_| Error::DegenerateRegistration { rank: 0, needed: unknowns })?;
    let s = svd.S().column_vector();
    let smax = s[0];
    let rank = (0..s.nrows()).filter(|&i| s[i] > 1e-10 * smax).count();
    if rank < unknowns - 3 * tool_count {
        return Err(Error::DegenerateRegistration { rank, needed: unknowns });
    }
    let (u, v) = (svd.U(), svd.V());
    let mut x = faer::Mat::<f64>::zeros(unknowns, 3);
    for k in 0..unknowns {
        if s[k] <= 1e-10 * smax {
            continue;
        }
        for c in 0..3 {
            let utb: f64 = (0..observations.len()).map(|i| u[(i, k)] * b[(i, c)]).sum();
            for j in 0..unknowns {
                x[(j, c)] += v[(j, k)] * utb / s[k];
            }
        }
    }
    Ok(x)
}

/// The rigid transform `(R, t)` minimising `Σ |R a_i + t − b_i|²` (Kabsch 1976, the SVD solution,
/// a proper rotation).
pub fn kabsch(from: &[Vector3], to: &[Vector3]) -> SE3 {
    let count = from.len().max(1) as f64;
    let (mean_from, mean_to) = (from.iter().sum::<Vector3>() / count, to.iter().sum::<Vector3>() / count);
    let covariance: Matrix3 = from.iter().zip(to).map(|(a, b)| (b - mean_to) * (a - mean_from).transpose()).sum();
    let rotation = nearest_rotation(&covariance);
    SE3::new(rotation, mean_to - rotation.act(&mean_from))
}

/// The tracker placement and the tool offsets by alternating least squares: a rigid fit of the
/// tool points (flange poses times the current offsets) onto the measured points, then each
/// tool's offset given the placement (`u = mean R_fᵀ (Rᵀ (p − t) − p_f)`, exact since `R_f` is a
/// rotation), from zero offsets, until the offsets stop moving (`ALTERNATIONS` at most).
fn alternating_fit(
    observations: &[Observation],
    flanges: &[SE3],
    points: &[Vector3],
    tool_count: usize,
) -> (SE3, Vec<Vector3>) {
    // Each alternation cannot raise the residual; 200 of them take a few milliseconds on a
    // thousand rows, and the identification that follows finishes the fit.
    const ALTERNATIONS: usize = 200;
    let mut offsets = vec![Vector3::zeros(); tool_count];
    let mut placement = SE3::identity();
    for _ in 0..ALTERNATIONS {
        let tool_points: Vec<Vector3> =
            observations.iter().zip(flanges).map(|(o, f)| f.transform_point(&offsets[o.tool])).collect();
        placement = kabsch(&tool_points, points);
        let inverse = placement.inverse();
        let mut sums = vec![Vector3::zeros(); tool_count];
        let mut counts = vec![0usize; tool_count];
        for ((o, f), p) in observations.iter().zip(flanges).zip(points) {
            sums[o.tool] += f.rotation().inverse().act(&(inverse.transform_point(p) - f.translation()));
            counts[o.tool] += 1;
        }
        let next: Vec<Vector3> =
            sums.iter().zip(&counts).map(|(s, &n)| if n > 0 { s / n as f64 } else { Vector3::zeros() }).collect();
        let moved = next.iter().zip(&offsets).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
        offsets = next;
        if moved < 1e-12 {
            break;
        }
    }
    (placement, offsets)
}
