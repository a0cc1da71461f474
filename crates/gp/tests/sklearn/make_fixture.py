#!/usr/bin/env python3
"""Reference numbers from scikit-learn's GaussianProcessRegressor for `crates/gp/tests/sklearn.rs`.

Run from anywhere:  python3 crates/gp/tests/sklearn/make_fixture.py
It rewrites `crates/gp/tests/sklearn/fixture.json` next to this script. The data come from a fixed
seed; the fixture records the scikit-learn and numpy versions that produced it.

Parameterisation (ours -> scikit-learn), all on standardised inputs and normalised outputs:
  Quadratic (paper Eq. 5, Bishop 6.63): th0 exp(-th1 r^2/2) + th2 + th3 x.x' + sn2
      -> C(th0) * RBF(l = 1/sqrt(th1)) + C(th2) + C(th3) * DotProduct(sigma_0 = 0, fixed) + White(sn2)
  SquaredExponentialArd: sf2, l_1..l_d, sn2 -> C(sf2) * RBF(l) + White(sn2)
  Matern52Ard:           sf2, l_1..l_d, sn2 -> C(sf2) * Matern(l, nu=2.5) + White(sn2)
  Composite (SE or Matern 5/2, constant, ARD linear): sf2, l_1..l_d, c, w_1..w_d, sn2
      -> C(sf2) * RBF(l * sqrt(w)) + C(c) + DotProduct(sigma_0 = 0, fixed) + White(sn2) on inputs
         multiplied by sqrt(w) (scikit-learn has no ARD DotProduct; scaling the inputs makes one
         at fixed hyperparameters). Its search has the isotropic slope only, C(s) * DotProduct,
         a special case of ours, so our optimised likelihood must be at least scikit-learn's.
Inputs are standardised here (mean, population std) exactly as `gp` does with
`standardise_inputs = true`; outputs are normalised by scikit-learn's `normalize_y=True`, which
matches `normalise_outputs = true`. `alpha = 0`: the only diagonal term is the WhiteKernel.
"""

import json
import pathlib

import numpy as np
import sklearn
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel as C, DotProduct, Matern, WhiteKernel

SEED = 20240611
N_TRAIN, N_TEST, DIM = 40, 12, 3
RESTARTS = 4

# Default search boxes of `gp` (natural scale, in our parameter order), see `Kernel::default_bounds`.
QUADRATIC_BOUNDS = ([1e-3, 1e-4, 1e-6, 1e-6, 1e-9], [1e2, 1e2, 1e2, 1e2, 1e1])
ARD_BOUNDS = ([1e-3] + [1e-2] * DIM + [1e-9], [1e2] + [1e3] * DIM + [1e1])
COMPOSITE_BOUNDS = (
    [1e-3] + [1e-2] * DIM + [1e-6] + [1e-6] * DIM + [1e-9],
    [1e2] + [1e3] * DIM + [1e2] + [1e2] * DIM + [1e1],
)


def data():
    rng = np.random.default_rng(SEED)
    # Columns on different scales and offsets so that standardisation matters.
    scale = np.array([1.0, 3.0, 0.5])
    offset = np.array([0.5, -2.0, 10.0])
    x = rng.uniform(-1.0, 1.0, size=(N_TRAIN + N_TEST, DIM)) * scale + offset
    u = (x - offset) / scale
    f0 = np.sin(2.0 * u[:, 0]) + 0.5 * u[:, 1] ** 2 - 0.3 * u[:, 2]
    f1 = np.cos(1.5 * u[:, 1]) * u[:, 0] + 0.2 * u[:, 2]
    y = np.stack([f0, 3.0 * f1 + 1.0], axis=1) + 0.05 * rng.standard_normal((N_TRAIN + N_TEST, 2))
    return x[:N_TRAIN], y[:N_TRAIN], x[N_TRAIN:]


def composite_parts(p):
    sf2, ls, c, w, sn2 = p[0], np.array(p[1 : 1 + DIM]), p[1 + DIM], np.array(p[2 + DIM : 2 + 2 * DIM]), p[-1]
    return sf2, ls, c, w, sn2


def sk_kernel(family, p, lower, upper):
    """scikit-learn kernel for our natural parameters `p` and box (lower, upper)."""
    if isinstance(family, dict):
        shape = family["Composite"]["shape"]
        sf2, ls, c, w, sn2 = composite_parts(p)
        core = RBF(ls * np.sqrt(w), "fixed") if shape == "SquaredExponential" else Matern(ls * np.sqrt(w), "fixed", nu=2.5)
        return C(sf2, "fixed") * core + C(c, "fixed") + DotProduct(sigma_0=0.0, sigma_0_bounds="fixed") + WhiteKernel(sn2, "fixed")
    if isinstance(family, tuple):
        sf2, ls, c, w, sn2 = composite_parts(p)
        ls_bounds = list(zip(lower[1 : 1 + DIM], upper[1 : 1 + DIM]))
        core = RBF(ls, ls_bounds) if family[1] == "SquaredExponential" else Matern(ls, ls_bounds, nu=2.5)
        return (
            C(sf2, (lower[0], upper[0])) * core
            + C(c, (lower[1 + DIM], upper[1 + DIM]))
            + C(float(np.mean(w)), (lower[2 + DIM], upper[2 + DIM])) * DotProduct(sigma_0=0.0, sigma_0_bounds="fixed")
            + WhiteKernel(sn2, (lower[-1], upper[-1]))
        )
    if family == "Quadratic":
        th0, th1, th2, th3, sn2 = p
        # th1 = 1/l^2, so th1 in [a, b] is l in [1/sqrt(b), 1/sqrt(a)].
        return (
            C(th0, (lower[0], upper[0])) * RBF(1.0 / np.sqrt(th1), (1.0 / np.sqrt(upper[1]), 1.0 / np.sqrt(lower[1])))
            + C(th2, (lower[2], upper[2]))
            + C(th3, (lower[3], upper[3])) * DotProduct(sigma_0=0.0, sigma_0_bounds="fixed")
            + WhiteKernel(sn2, (lower[4], upper[4]))
        )
    sf2, ls, sn2 = p[0], np.array(p[1:-1]), p[-1]
    ls_bounds = list(zip(lower[1:-1], upper[1:-1]))
    if family == "SquaredExponentialArd":
        core = RBF(ls, ls_bounds)
    else:
        core = Matern(ls, ls_bounds, nu=2.5)
    return C(sf2, (lower[0], upper[0])) * core + WhiteKernel(sn2, (lower[-1], upper[-1]))


def our_parameters(family, k):
    """Our natural parameters from a fitted scikit-learn kernel."""
    if isinstance(family, dict):
        # ((C0 * RBF + Cc) + Cs * Dot) + White: the isotropic slope as one weight per input.
        c0_rbf, cc = k.k1.k1.k1, k.k1.k1.k2
        slope = k.k1.k2.k1.constant_value
        return (
            [c0_rbf.k1.constant_value]
            + list(np.atleast_1d(c0_rbf.k2.length_scale))
            + [cc.constant_value]
            + [slope] * DIM
            + [k.k2.noise_level]
        )
    if family == "Quadratic":
        # ((C0 * RBF + C2) + C3 * Dot) + White
        white = k.k2
        c0_rbf, c2 = k.k1.k1.k1, k.k1.k1.k2
        c0, rbf = c0_rbf.k1, c0_rbf.k2
        c3 = k.k1.k2.k1
        return [
            c0.constant_value,
            1.0 / rbf.length_scale**2,
            c2.constant_value,
            c3.constant_value,
            white.noise_level,
        ]
    prod, white = k.k1, k.k2
    return [prod.k1.constant_value] + list(np.atleast_1d(prod.k2.length_scale)) + [white.noise_level]


def case(family, outputs, fixed, bounds, xs, y, xs_test):
    lower, upper = bounds
    yc = y[:, outputs] if len(outputs) > 1 else y[:, outputs[0]]
    # The composite's slope weights are applied by scaling the inputs (see the module doc).
    root = np.sqrt(composite_parts(fixed)[3]) if isinstance(family, dict) else np.ones(DIM)
    gpr = GaussianProcessRegressor(sk_kernel(family, fixed, lower, upper), alpha=0.0, optimizer=None, normalize_y=True)
    gpr.fit(xs * root, yc)
    mean, std = gpr.predict(xs_test * root, return_std=True)
    opt = GaussianProcessRegressor(
        sk_kernel(("search", family["Composite"]["shape"]) if isinstance(family, dict) else family, fixed, lower, upper),
        alpha=0.0,
        normalize_y=True,
        n_restarts_optimizer=RESTARTS,
        random_state=0,
    )
    opt.fit(xs, yc)
    mean = np.asarray(mean).reshape(len(xs_test), -1)
    std = np.asarray(std).reshape(len(xs_test), -1)
    if std.shape[1] == 1 and len(outputs) > 1:
        std = np.repeat(std, len(outputs), axis=1)
    return {
        "kernel": family,
        "outputs": outputs,
        "parameters": list(map(float, fixed)),
        "lower": list(map(float, lower)),
        "upper": list(map(float, upper)),
        "log_marginal_likelihood": float(gpr.log_marginal_likelihood_value_),
        "mean": mean.tolist(),
        "std_with_noise": std.tolist(),
        "optimised_log_marginal_likelihood": float(opt.log_marginal_likelihood_value_),
        "optimised_parameters": list(map(float, our_parameters(family, opt.kernel_))),
    }


def main():
    x, y, x_test = data()
    mean, std = x.mean(axis=0), x.std(axis=0)
    xs, xs_test = (x - mean) / std, (x_test - mean) / std
    cases = [
        case("Quadratic", [0], [0.8, 0.6, 0.2, 0.3, 0.02], QUADRATIC_BOUNDS, xs, y, xs_test),
        case("SquaredExponentialArd", [0], [1.2, 0.9, 1.7, 2.5, 0.01], ARD_BOUNDS, xs, y, xs_test),
        case("Matern52Ard", [1], [0.7, 1.1, 0.8, 3.0, 0.05], ARD_BOUNDS, xs, y, xs_test),
        case("SquaredExponentialArd", [0, 1], [1.0, 1.3, 1.1, 2.0, 0.03], ARD_BOUNDS, xs, y, xs_test),
        case(
            {"Composite": {"shape": "SquaredExponential", "constant": True, "linear": True}},
            [0],
            [1.1, 0.9, 1.5, 2.2, 0.2, 0.3, 0.05, 0.1, 0.02],
            COMPOSITE_BOUNDS,
            xs,
            y,
            xs_test,
        ),
        case(
            {"Composite": {"shape": "Matern52", "constant": True, "linear": True}},
            [0, 1],
            [0.8, 1.2, 0.7, 2.8, 0.1, 0.2, 0.4, 0.03, 0.04],
            COMPOSITE_BOUNDS,
            xs,
            y,
            xs_test,
        ),
    ]
    fixture = {
        "generator": "crates/gp/tests/sklearn/make_fixture.py",
        "seed": SEED,
        "sklearn_version": sklearn.__version__,
        "numpy_version": np.__version__,
        "x_train": x.tolist(),
        "y_train": y.tolist(),
        "x_test": x_test.tolist(),
        "cases": cases,
    }
    out = pathlib.Path(__file__).with_name("fixture.json")
    out.write_text(json.dumps(fixture, indent=1) + "\n")
    for c in cases:
        print(c["kernel"], c["outputs"], "lml", c["log_marginal_likelihood"], "optimised", c["optimised_log_marginal_likelihood"])


if __name__ == "__main__":
    main()
