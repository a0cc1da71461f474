"""Compensation of joint targets as a user would write it with numpy and SciPy.

Reads the problem `cargo xtask compensate-check` writes (the calibrated local POE model as 4x4
local transforms, joints then the tool; a seed configuration and a target pose per row) and
solves each row with `scipy.optimize.least_squares` on the point error and log(R* R^T), with
SciPy's finite-difference Jacobian, one row after the other. Prints one JSON object: total
seconds, largest point residual (m).

Usage: python3 compensate_scipy.py PROBLEM.json
"""

import json
import sys
import time

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation


def rot_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    t = np.eye(4)
    t[0, 0], t[0, 1], t[1, 0], t[1, 1] = c, -s, s, c
    return t


def main():
    problem = json.load(open(sys.argv[1]))
    local = [np.array(m) for m in problem["local_transforms"]]
    n = len(local) - 1

    def pose(q):
        t = np.eye(4)
        for i in range(n):
            t = t @ local[i] @ rot_z(q[i])
        return t @ local[n]

    largest = 0.0
    begin = time.perf_counter()
    for seed, target in zip(problem["seeds"], problem["targets"]):
        target = np.array(target)

        def residual(q):
            t = pose(q)
            dp = target[:3, 3] - t[:3, 3]
            dr = Rotation.from_matrix(target[:3, :3] @ t[:3, :3].T).as_rotvec()
            return np.hstack([dp, dr])

        fit = least_squares(residual, np.array(seed), method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15)
        largest = max(largest, float(np.linalg.norm(residual(fit.x)[:3])))
    seconds = time.perf_counter() - begin
    print(json.dumps({"seconds": seconds, "max_residual_m": largest}))


if __name__ == "__main__":
    main()
