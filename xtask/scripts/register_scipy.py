"""Reference for `calib register`: the tracker-to-base transform re-fitted by SciPy.

Reads the calibrated model's predictions (`calib predict` CSV: x_mm … and qw … in the model's old
tracker frame) and the measured rows (SPEC CSV) of the same configurations, fits the
rigid motion X minimising |X·p − m|² + w²|log(R_X R_p R_mᵀ)|² over the registration rows with
`scipy.optimize.least_squares` (start: Kabsch), and prints the mean position error of X·prediction
on the other rows as JSON. Usage:
    register_scipy.py PREDICTED.csv MEASURED.csv REGISTER_LINES [ROTATION_WEIGHT_M_PER_RAD]
REGISTER_LINES: comma-separated 0-based data-row indices used for the fit.
"""
import csv
import json
import sys

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation


def table(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return rows


def main():
    predicted, measured = table(sys.argv[1]), table(sys.argv[2])
    fit_rows = [int(i) for i in sys.argv[3].split(",")]
    weight = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0
    keys = predicted[0].keys()
    p = np.array([[float(r[k]) for k in ("x_mm", "y_mm", "z_mm")] for r in predicted]) / 1e3
    m = np.array([[float(r[k]) for k in ("x_mm", "y_mm", "z_mm")] for r in measured]) / 1e3
    full = "qw" in measured[0] and "qw" in keys
    if full:
        rp = Rotation.from_quat([[float(r[k]) for k in ("qx", "qy", "qz", "qw")] for r in predicted])
        rm = Rotation.from_quat([[float(r[k]) for k in ("qx", "qy", "qz", "qw")] for r in measured])
    sel = np.array(fit_rows)
    a, b = p[sel], m[sel]
    ca, cb = a.mean(0), b.mean(0)
    u, _, vt = np.linalg.svd((b - cb).T @ (a - ca))
    d = np.diag([1, 1, np.sign(np.linalg.det(u @ vt))])
    r0 = u @ d @ vt
    x0 = np.concatenate([Rotation.from_matrix(r0).as_rotvec(), cb - r0 @ ca])

    def residual(x):
        r = Rotation.from_rotvec(x[:3])
        out = [(r.apply(a) + x[3:] - b).ravel()]
        if full:
            out.append(weight * (r * rp[sel] * rm[sel].inv()).as_rotvec().ravel())
        return np.concatenate(out)

    x = least_squares(residual, x0, xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    r = Rotation.from_rotvec(x[:3])
    rest = np.setdiff1d(np.arange(len(m)), sel)
    error = np.linalg.norm(r.apply(p[rest]) + x[3:] - m[rest], axis=1) * 1e3
    print(json.dumps({"n_fit": len(sel), "n_test": len(rest), "mean_position_error_mm": float(error.mean()),
                      "full_pose": bool(full)}))


if __name__ == "__main__":
    main()
