//! Laws every covariance function obeys, on random parameters and points (proptest).

use gp::{AdditiveTerm, CompositeKernel, Kernel, Matern52Ard, QuadraticKernel, SquaredExponentialArd, StationaryShape};
use proptest::prelude::*;

const DIM: usize = 3;

fn positive() -> impl Strategy<Value = f64> {
    (-3.0f64..3.0).prop_map(f64::exp)
}

fn point() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-5.0f64..5.0, DIM)
}

fn kernel() -> impl Strategy<Value = Kernel> {
    let quadratic = (positive(), positive(), positive(), positive(), positive()).prop_map(|(a, b, c, d, e)| {
        Kernel::Quadratic(QuadraticKernel { theta0: a, theta1: b, theta2: c, theta3: d, noise_variance: e })
    });
    let se = (positive(), prop::collection::vec(positive(), DIM), positive()).prop_map(|(s, l, n)| {
        Kernel::SquaredExponentialArd(SquaredExponentialArd { signal_variance: s, length_scales: l, noise_variance: n })
    });
    let matern = (positive(), prop::collection::vec(positive(), DIM), positive()).prop_map(|(s, l, n)| {
        Kernel::Matern52Ard(Matern52Ard { signal_variance: s, length_scales: l, noise_variance: n })
    });
    let shape = prop_oneof![Just(StationaryShape::SquaredExponential), Just(StationaryShape::Matern52)];
    let composite = (
        shape,
        positive(),
        prop::collection::vec(positive(), DIM),
        prop::option::of(positive()),
        prop::option::of(prop::collection::vec(positive(), DIM)),
        prop::option::of((prop::collection::vec(positive(), DIM), prop::collection::vec(positive(), DIM))),
        positive(),
    )
        .prop_map(|(shape, s, l, c, w, a, n)| {
            Kernel::Composite(CompositeKernel {
                shape,
                signal_variance: s,
                length_scales: l,
                constant: c,
                linear_weights: w,
                additive: a.map(|(variances, length_scales)| AdditiveTerm { variances, length_scales }),
                noise_variance: n,
            })
        });
    prop_oneof![quadratic, se, matern, composite]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn kernel_is_symmetric(k in kernel(), a in point(), b in point()) {
        let (ab, ba) = (k.value(&a, &b), k.value(&b, &a));
        prop_assert!((ab - ba).abs() <= 1e-12 * ab.abs().max(1.0), "{ab} vs {ba}");
    }

    #[test]
    fn kernel_obeys_cauchy_schwarz(k in kernel(), a in point(), b in point()) {
        // A positive semi-definite kernel has k(a, b)² ≤ k(a, a) k(b, b).
        let (ab, aa, bb) = (k.value(&a, &b), k.value(&a, &a), k.value(&b, &b));
        prop_assert!(ab * ab <= aa * bb * (1.0 + 1e-12) + 1e-300, "{ab}² > {aa}·{bb}");
    }

    #[test]
    fn log_parameters_round_trip(k in kernel()) {
        let back = k.with_log_parameters(&k.log_parameters()).expect("finite");
        for (x, y) in k.parameters().iter().zip(back.parameters()) {
            prop_assert!((x - y).abs() <= 1e-14 * x.abs());
        }
    }

    #[test]
    fn kernel_survives_a_ron_round_trip(k in kernel()) {
        let back: Kernel = ron::from_str(&ron::to_string(&k).expect("serialise")).expect("deserialise");
        prop_assert_eq!(back, k);
    }
}
