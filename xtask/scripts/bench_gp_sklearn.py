#!/usr/bin/env python3
"""scikit-learn side of `cargo xtask bench-gp`.

Reads the JSON request written by xtask/src/bench_gp.rs (argv[1]), fits scikit-learn's
GaussianProcessRegressor on exactly the same data, kernel, start, bounds and normalisation, and
writes timings and log marginal likelihoods as JSON to argv[2].

Kernel: the paper's Eq. 5, th0 exp(-th1 r^2/2) + th2 + th3 x.x' + white noise, written as
C(th0) * RBF(1/sqrt(th1)) + C(th2) + C(th3) * DotProduct(sigma_0=0, fixed) + WhiteKernel(sn2).
Inputs are standardised here with the training mean and population std (as `gp` does); outputs are
normalised by normalize_y=True; all six outputs share one kernel (gp's OutputMode::Shared), and
scikit-learn sums the log marginal likelihood over them as gp does.
"""

import json
import sys
import time

import numpy as np
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel as C, DotProduct, WhiteKernel


def kernel(p, lower, upper):
    th0, th1, th2, th3, sn2 = p
    return (
        C(th0, (lower[0], upper[0])) * RBF(1.0 / np.sqrt(th1), (1.0 / np.sqrt(upper[1]), 1.0 / np.sqrt(lower[1])))
        + C(th2, (lower[2], upper[2]))
        + C(th3, (lower[3], upper[3])) * DotProduct(sigma_0=0.0, sigma_0_bounds="fixed")
        + WhiteKernel(sn2, (lower[4], upper[4]))
    )


def main():
    with open(sys.argv[1]) as f:
        req = json.load(f)
    x = np.asarray(req["x"])
    y = np.asarray(req["y"])
    x_test = np.asarray(req["x_test"])
    results = []
    for n in req["sizes"]:
        xt, yt = x[:n], y[:n]
        mean, std = xt.mean(axis=0), xt.std(axis=0)
        std[std == 0.0] = 1.0
        xs, xq = (xt - mean) / std, (x_test - mean) / std
        gpr = GaussianProcessRegressor(
            kernel(req["start"], req["lower"], req["upper"]),
            alpha=0.0,
            normalize_y=True,
            n_restarts_optimizer=req["restarts"],
            random_state=0,
        )
        t0 = time.perf_counter()
        gpr.fit(xs, yt)
        t1 = time.perf_counter()
        gpr.predict(xq, return_std=True)
        t2 = time.perf_counter()
        results.append({"n": n, "fit_s": t1 - t0, "predict_s": t2 - t1, "lml": float(gpr.log_marginal_likelihood_value_)})
        print(f"sklearn n={n}: fit {t1 - t0:.3f} s, predict {t2 - t1:.3f} s", file=sys.stderr, flush=True)
    with open(sys.argv[2], "w") as f:
        json.dump({"results": results}, f)


if __name__ == "__main__":
    main()
