//! The identification Jacobian against central finite differences.

mod common;

use common::{iiwa7, irb4400, perturb, random_q, rng};
use lie::SE3;
use poe::{LocalPoe, RowKind};

/// Central differences of `y(x) = log(T(x) T(0)⁻¹)^∨` (or of the tool point) with respect to the
/// left perturbation of every parameter.
fn finite_difference(model: &LocalPoe, q: &[f64], tool: usize, kind: RowKind) -> Vec<f64> {
    let columns = model.layout().len();
    let rows = kind.rows();
    let base = model.forward(q, tool).unwrap();
    let h = 1e-6;
    let mut out = vec![0.0; rows * columns];
    let eval = |sign: f64, c: usize| -> Vec<f64> {
        let mut delta = vec![0.0; columns];
        delta[c] = sign * h;
        let mut moved = model.clone();
        moved.apply_update(&delta);
        let pose: SE3 = moved.forward(q, tool).unwrap();
        match kind {
            RowKind::FullPose => (pose * base.inverse()).log().to_vector().as_slice().to_vec(),
            RowKind::Position => (pose.translation() - base.translation()).as_slice().to_vec(),
            RowKind::PointAndRotation => {
                let mut y = (pose.translation() - base.translation()).as_slice().to_vec();
                y.extend_from_slice((pose.rotation() * base.rotation().inverse()).log().as_slice());
                y
            }
        }
    };
    for c in 0..columns {
        let plus = eval(1.0, c);
        let minus = eval(-1.0, c);
        for r in 0..rows {
            out[r * columns + c] = (plus[r] - minus[r]) / (2.0 * h);
        }
    }
    out
}

fn check(model: &LocalPoe, q: &[f64], tool: usize, kind: RowKind) {
    let columns = model.layout().len();
    let mut analytic = vec![0.0; kind.rows() * columns];
    model.identification_jacobian(q, tool, kind, &mut analytic).unwrap();
    let numeric = finite_difference(model, q, tool, kind);
    for (i, (a, n)) in analytic.iter().zip(&numeric).enumerate() {
        assert!((a - n).abs() < 1e-6 * (1.0 + n.abs()), "entry {i}: analytic {a} numeric {n}");
    }
}

#[test]
fn full_pose_identification_jacobian_matches_finite_differences() {
    let mut rng = rng(10);
    for (nominal, limits) in [irb4400(), iiwa7()] {
        let model = perturb(&nominal, &mut rng, 0.01, 0.01);
        for _ in 0..3 {
            check(&model, &random_q(&mut rng, &limits), 0, RowKind::FullPose);
        }
        check(&model, &vec![0.0; limits.len()], 0, RowKind::FullPose);
    }
}

#[test]
fn decoupled_point_and_rotation_jacobian_matches_finite_differences() {
    let mut rng = rng(13);
    for (nominal, limits) in [irb4400(), iiwa7()] {
        let model = perturb(&nominal, &mut rng, 0.01, 0.01);
        for _ in 0..3 {
            check(&model, &random_q(&mut rng, &limits), 0, RowKind::PointAndRotation);
        }
    }
}

#[test]
fn position_identification_jacobian_matches_finite_differences() {
    let mut rng = rng(11);
    for (nominal, limits) in [irb4400(), iiwa7()] {
        let model = perturb(&nominal, &mut rng, 0.01, 0.01);
        for _ in 0..3 {
            check(&model, &random_q(&mut rng, &limits), 0, RowKind::Position);
        }
    }
}

#[test]
fn jacobian_of_a_second_tool_touches_only_that_tool_block() {
    let mut rng = rng(12);
    let (nominal, limits) = irb4400();
    let mut model = perturb(&nominal, &mut rng, 0.01, 0.01);
    let second = common::random_twist(&mut rng, 0.2, 0.5).exp() * model.tools()[0];
    model.set_tools(vec![model.tools()[0], second]);
    let q = random_q(&mut rng, &limits);
    check(&model, &q, 1, RowKind::FullPose);
    check(&model, &q, 1, RowKind::Position);
    let columns = model.layout().len();
    let mut analytic = vec![0.0; 6 * columns];
    model.identification_jacobian(&q, 1, RowKind::FullPose, &mut analytic).unwrap();
    let tool0 = model.layout().offset(poe::Block::Tool(0));
    for r in 0..6 {
        assert!(analytic[r * columns + tool0..r * columns + tool0 + 6].iter().all(|v| *v == 0.0));
    }
}
