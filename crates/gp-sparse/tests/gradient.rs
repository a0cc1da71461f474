//! The sparse bound's analytic gradient against central differences.

#[path = "../../gp/tests/common/mod.rs"]
mod common;

use common::{central_difference, close, random_kernels, rng, uniform_points};
use faer::Mat;
use gp::{Kernel, Parallelism};
use gp_sparse::sparse_evidence_lower_bound;
use rand::Rng;

#[test]
fn sparse_bound_gradient_matches_central_differences_at_random_points() {
    // n = 30 rows, m = 7 inducing inputs off the data, one and two outputs, every kernel family.
    let (n, d, m) = (30, 3, 7);
    let mut r = rng(13);
    for trial in 0..3 {
        let x = uniform_points(&mut r, n, d, -2.0, 2.0);
        let z = uniform_points(&mut r, m, d, -2.0, 2.0);
        for outputs in [1, 2] {
            let y = Mat::from_fn(n, outputs, |i, c| {
                (x[(i, 0)] * (c + 1) as f64).sin() + 0.3 * x[(i, 1)] + 0.1 * r.random::<f64>()
            });
            for kernel in random_kernels(&mut r, d) {
                let bound = |k: &Kernel, g: bool| {
                    sparse_evidence_lower_bound(k, x.as_ref(), y.as_ref(), z.as_ref(), g, Parallelism::Sequential)
                        .expect("positive definite")
                };
                let analytic = bound(&kernel, true);
                assert_eq!(analytic.gradient.len(), kernel.parameter_count());
                for (j, gj) in analytic.gradient.iter().enumerate() {
                    let fd = central_difference(&kernel, j, |k| bound(k, false).value);
                    assert!(
                        close(*gj, fd, 1e-6),
                        "trial {trial} outputs {outputs} {kernel:?} parameter {j}: analytic {gj} vs fd {fd}"
                    );
                }
            }
        }
    }
}
