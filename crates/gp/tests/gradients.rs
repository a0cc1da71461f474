//! Every analytic gradient against central finite differences at several random points.

mod common;

use common::{central_difference, close, random_kernels, rng, uniform_points};
use faer::Mat;
use gp::{FactorOptions, Kernel, LmlWorkspace, Parallelism, log_marginal_likelihood};
use rand::Rng;

#[test]
fn kernel_gradients_match_central_differences_at_random_points() {
    let d = 3;
    let mut r = rng(7);
    for trial in 0..6 {
        for kernel in random_kernels(&mut r, d) {
            let a: Vec<f64> = (0..d).map(|_| r.random_range(-2.0..2.0)).collect();
            // Pairs: a random other point, a nearby point, and the same point (r = 0, where the
            // Matérn derivative has its removable singularity).
            let far: Vec<f64> = (0..d).map(|_| r.random_range(-2.0..2.0)).collect();
            let near: Vec<f64> = a.iter().map(|v| v + r.random_range(-1e-3..1e-3)).collect();
            for b in [far, near, a.clone()] {
                let mut g = vec![0.0; kernel.parameter_count() - 1];
                let value = kernel.value_and_gradient(&a, &b, &mut g).expect("gradient length");
                assert!(close(value, kernel.value(&a, &b), 1e-14));
                for (j, gj) in g.iter().enumerate() {
                    let fd = central_difference(&kernel, j, |k| k.value(&a, &b));
                    assert!(close(*gj, fd, 1e-7), "trial {trial} {kernel:?} parameter {j}: analytic {gj} vs fd {fd}");
                }
            }
        }
    }
}

#[test]
fn kernel_gradient_refuses_a_buffer_of_the_wrong_length() {
    let mut r = rng(3);
    for kernel in random_kernels(&mut r, 2) {
        let mut g = vec![0.0; kernel.parameter_count()];
        assert!(kernel.value_and_gradient(&[0.0, 1.0], &[1.0, 0.0], &mut g).is_err());
    }
}

#[test]
fn log_marginal_likelihood_gradient_matches_central_differences_at_random_points() {
    let (n, d) = (25, 3);
    let mut r = rng(11);
    for trial in 0..4 {
        let x = uniform_points(&mut r, n, d, -2.0, 2.0);
        for m in [1, 2] {
            let y = Mat::from_fn(n, m, |i, c| {
                (x[(i, 0)] * (c + 1) as f64).sin() + 0.3 * x[(i, 1)] + 0.1 * r.random::<f64>()
            });
            for kernel in random_kernels(&mut r, d) {
                let lml = log_marginal_likelihood(&kernel, x.as_ref(), y.as_ref(), true, Parallelism::Sequential)
                    .expect("positive definite");
                assert_eq!(lml.gradient.len(), kernel.parameter_count());
                for (j, gj) in lml.gradient.iter().enumerate() {
                    let fd = central_difference(&kernel, j, |k| {
                        log_marginal_likelihood(k, x.as_ref(), y.as_ref(), false, Parallelism::Sequential)
                            .expect("positive definite")
                            .value
                    });
                    assert!(
                        close(*gj, fd, 1e-6),
                        "trial {trial} m {m} {kernel:?} parameter {j}: analytic {gj} vs fd {fd}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_reused_workspace_gives_the_likelihood_of_fresh_buffers_to_the_bit() {
    // Sizes that shrink and grow again, value-only evaluations between gradient ones, serial and
    // rayon: nothing a previous evaluation left in the workspace may show in the next.
    let d = 3;
    let mut r = rng(17);
    let kernels = random_kernels(&mut r, d);
    let mut workspace = LmlWorkspace::default();
    for (step, n) in [40, 25, 40, 40, 60].into_iter().enumerate() {
        let x = uniform_points(&mut r, n, d, -2.0, 2.0);
        let y = Mat::from_fn(n, 2, |i, c| (x[(i, 0)] * (c + 1) as f64).sin() + 0.1 * r.random::<f64>());
        for (k, kernel) in kernels.iter().enumerate() {
            let with_gradient = (step + k) % 2 == 0;
            let parallelism = if k % 2 == 0 { Parallelism::Sequential } else { Parallelism::Rayon };
            let fresh = log_marginal_likelihood(kernel, x.as_ref(), y.as_ref(), with_gradient, parallelism)
                .expect("positive definite");
            let reused = workspace
                .log_marginal_likelihood(kernel, x.as_ref(), y.as_ref(), with_gradient, parallelism)
                .expect("positive definite");
            assert_eq!(reused, fresh, "step {step} n {n} {kernel:?}");
        }
    }
}

#[test]
fn the_gradient_from_the_kept_exponentials_is_the_gradient_computed_afresh_to_the_bit() {
    // The value stage keeps the kernel's exponentials for the gradient stage within its budget;
    // with no budget every one is computed again. The default composite kernel (an additive term)
    // and SE-ARD, serial and rayon, a workspace reused across sizes.
    let d = 4;
    let mut r = rng(23);
    let kernels: Vec<Kernel> = random_kernels(&mut r, d)
        .into_iter()
        .chain(
            [
                gp::KernelChoice::Composite {
                    shape: gp::StationaryShape::SquaredExponential,
                    constant: true,
                    linear: false,
                    additive: true,
                },
                gp::KernelChoice::SquaredExponentialArd,
            ]
            .map(|c| Kernel::start(c, d)),
        )
        .collect();
    let mut kept = LmlWorkspace::default();
    let mut afresh = LmlWorkspace::default().with_cache_budget(0);
    for n in [37, 64, 21] {
        let x = uniform_points(&mut r, n, d, -2.0, 2.0);
        let y = Mat::from_fn(n, 2, |i, c| (x[(i, 0)] * (c + 1) as f64).sin() + 0.1 * r.random::<f64>());
        for kernel in &kernels {
            for parallelism in [Parallelism::Sequential, Parallelism::Rayon] {
                let with = kept.log_marginal_likelihood(kernel, x.as_ref(), y.as_ref(), true, parallelism).unwrap();
                let without =
                    afresh.log_marginal_likelihood(kernel, x.as_ref(), y.as_ref(), true, parallelism).unwrap();
                assert_eq!(with, without, "n {n} {kernel:?} {parallelism:?}");
            }
        }
    }
}

#[test]
fn the_factorisation_block_sizes_change_the_likelihood_only_by_rounding() {
    // Leaves of 3 rows make the factorisation by halves recurse five levels deep at n = 60.
    let (n, d) = (60, 3);
    let mut r = rng(19);
    let x = uniform_points(&mut r, n, d, -2.0, 2.0);
    let y = Mat::from_fn(n, 2, |i, c| (x[(i, 0)] * (c + 1) as f64).sin() + 0.1 * r.random::<f64>());
    let small = FactorOptions { recursion_leaf: 3, leaf_block: 2 };
    let mut halves = LmlWorkspace::with_options(small).expect("valid sizes");
    for kernel in random_kernels(&mut r, d) {
        let expected = log_marginal_likelihood(&kernel, x.as_ref(), y.as_ref(), true, Parallelism::Sequential)
            .expect("positive definite");
        for parallelism in [Parallelism::Sequential, Parallelism::Rayon] {
            let found = halves
                .log_marginal_likelihood(&kernel, x.as_ref(), y.as_ref(), true, parallelism)
                .expect("positive definite");
            assert!(close(found.value, expected.value, 1e-9), "{kernel:?}: {} vs {}", found.value, expected.value);
            for (g, e) in found.gradient.iter().zip(&expected.gradient) {
                assert!(close(*g, *e, 1e-8), "{kernel:?}: gradient {g} vs {e}");
            }
        }
    }
    let zero = FactorOptions { recursion_leaf: 0, leaf_block: 2 };
    assert!(matches!(LmlWorkspace::with_options(zero), Err(gp::Error::InvalidConfig { field: "recursion_leaf", .. })));
}

#[test]
fn log_marginal_likelihood_matches_the_dense_gaussian_density() {
    // ln N(y; 0, K) computed independently: K⁻¹ and |K| from a plain Gauss-Jordan elimination.
    let (n, d) = (12, 2);
    let mut r = rng(5);
    let x = uniform_points(&mut r, n, d, -1.0, 1.0);
    let y = Mat::from_fn(n, 1, |i, _| x[(i, 0)] - 0.5 * x[(i, 1)]);
    for kernel in random_kernels(&mut r, d) {
        let rows: Vec<Vec<f64>> = (0..n).map(|i| vec![x[(i, 0)], x[(i, 1)]]).collect();
        let mut a: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                let mut row: Vec<f64> = (0..n).map(|j| kernel.value(&rows[i], &rows[j])).collect();
                row[i] += kernel.noise_variance();
                row.extend((0..n).map(|j| if i == j { 1.0 } else { 0.0 }));
                row
            })
            .collect();
        let mut log_det = 0.0;
        for col in 0..n {
            let pivot = (col..n).max_by(|&p, &q| a[p][col].abs().total_cmp(&a[q][col].abs())).expect("non-empty");
            a.swap(col, pivot);
            let pv = a[col][col];
            log_det += pv.abs().ln();
            a[col].iter_mut().for_each(|v| *v /= pv);
            for row in 0..n {
                if row != col {
                    let f = a[row][col];
                    let pivot_row = a[col].clone();
                    a[row].iter_mut().zip(&pivot_row).for_each(|(v, p)| *v -= f * p);
                }
            }
        }
        let quad: f64 = (0..n).map(|i| (0..n).map(|j| y[(i, 0)] * a[i][n + j] * y[(j, 0)]).sum::<f64>()).sum();
        let expected = -0.5 * quad - 0.5 * log_det - 0.5 * n as f64 * (2.0 * std::f64::consts::PI).ln();
        let lml = log_marginal_likelihood(&kernel, x.as_ref(), y.as_ref(), false, Parallelism::Rayon).expect("pd");
        assert!(close(lml.value, expected, 1e-9), "{} vs {}", lml.value, expected);
    }
}
