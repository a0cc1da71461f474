#!/usr/bin/env python3
"""scikit-learn side of `cargo xtask bench-gp`: one fit and prediction per call.

Usage: bench_gp_sklearn.py REQUEST.json RESPONSE.json

The request (written by xtask/src/experiments/bench_gp_sklearn.rs) holds the training inputs and outputs, the
test inputs and the kernel's options; the response holds the fit and predict times (seconds), the
peak resident memory of this process and its workers (bytes), the predicted means at the test
inputs, and per GP the fitted kernel and its log marginal likelihood (of the normalised outputs).
The caller applies the time limit (it kills this process).

Kernel, as a scikit-learn user writes it for this problem:
    C * RBF(length_scale=ones(d))  [ARD]  + C  [+ C * DotProduct(sigma_0=0)]  + WhiteKernel
or with "isotropic": true the paper's Eq. 5 as the paper's authors wrote it (one length scale):
    C * RBF(length_scale=1.0) + C + DotProduct + WhiteKernel
Inputs are standardised with the training mean and population std (as `gp` does); outputs are
normalised by normalize_y=True. With "independent": true each output column gets its own GP
(fitted in a pool of "processes" workers), otherwise one GP with shared hyperparameters serves
all columns.
"""

import json
import resource
import sys
import time
from multiprocessing import Pool

import numpy as np
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel as C, DotProduct, WhiteKernel


def kernel(d, linear, isotropic):
    if isotropic:
        return C(1.0) * RBF(1.0) + C(0.1) + DotProduct() + WhiteKernel(0.01)
    k = C(1.0, (1e-3, 1e2)) * RBF(np.ones(d), (1e-2, 1e3)) + C(0.1, (1e-6, 1e2))
    if linear:
        k = k + C(0.1, (1e-6, 1e2)) * DotProduct(sigma_0=0.0, sigma_0_bounds="fixed")
    return k + WhiteKernel(0.01, (1e-9, 1e1))


def fit_predict(args):
    xs, y, xq, linear, isotropic, restarts = args
    gpr = GaussianProcessRegressor(
        kernel(xs.shape[1], linear, isotropic), alpha=1e-10, normalize_y=True, n_restarts_optimizer=restarts, random_state=0
    )
    gpr.fit(xs, y)
    t = time.perf_counter()
    mean = gpr.predict(xq)
    fitted = {"kernel": str(gpr.kernel_), "lml": float(gpr.log_marginal_likelihood_value_)}
    return mean.reshape(len(xq), -1), time.perf_counter() - t, fitted


def peak_bytes():
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return 1024 * (own + children)


def main():
    with open(sys.argv[1]) as f:
        req = json.load(f)
    x = np.asarray(req["x"], dtype=float)
    y = np.asarray(req["y"], dtype=float)
    x_test = np.asarray(req["x_test"], dtype=float)
    mean, std = x.mean(axis=0), x.std(axis=0)
    std[std == 0.0] = 1.0
    xs, xq = (x - mean) / std, (x_test - mean) / std
    linear, restarts = bool(req["linear"]), int(req["restarts"])
    isotropic = bool(req.get("isotropic", False))
    t0 = time.perf_counter()
    if req["independent"]:
        jobs = [(xs, y[:, j], xq, linear, isotropic, restarts) for j in range(y.shape[1])]
        with Pool(int(req["processes"])) as pool:
            parts = pool.map(fit_predict, jobs)
        prediction = np.hstack([p[0] for p in parts])
        predict_s = sum(p[1] for p in parts)
        fitted = [p[2] for p in parts]
    else:
        prediction, predict_s, one = fit_predict((xs, y, xq, linear, isotropic, restarts))
        fitted = [one]
    total = time.perf_counter() - t0
    with open(sys.argv[2], "w") as f:
        json.dump(
            {
                "fit_s": total - predict_s,
                "predict_s": predict_s,
                "peak_bytes": peak_bytes(),
                "mean": prediction.tolist(),
                "fitted": fitted,
            },
            f,
        )


if __name__ == "__main__":
    main()
