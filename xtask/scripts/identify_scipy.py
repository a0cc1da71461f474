"""The local POE identification as a user would write it with numpy and SciPy.

Reads the problem `cargo xtask bench-identify` writes (start model, joint values, measured poses,
weights), fits every local transform by `scipy.optimize.least_squares` on the same weighted
residual (point displacement and log(R' R^T); the displacement alone where the problem says
"full_pose": false), with SciPy's finite-difference Jacobian and the
model evaluated for all rows at once with batched numpy products, and prints
one JSON object: seconds per fit, held-in RMS position error, function evaluations.

Usage: python3 identify_scipy.py PROBLEM.json REPEATS
"""

import json
import sys
import time

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation


def hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def exp_se3(xi):
    """exp of a twist (v, w) as a 4x4 matrix."""
    v, w = xi[:3], xi[3:]
    theta = np.linalg.norm(w)
    t = np.eye(4)
    if theta < 1e-9:
        t[:3, 3] = v
        return t
    k = hat(w / theta)
    r = np.eye(3) + np.sin(theta) * k + (1 - np.cos(theta)) * k @ k
    j = np.eye(3) + (1 - np.cos(theta)) / theta * k + (theta - np.sin(theta)) / theta * k @ k
    t[:3, :3] = r
    t[:3, 3] = j @ v
    return t


def rot_z(q):
    """Rotations about z by every angle of `q`, as an (N, 4, 4) array."""
    c, s = np.cos(q), np.sin(q)
    t = np.tile(np.eye(4), (len(q), 1, 1))
    t[:, 0, 0], t[:, 0, 1], t[:, 1, 0], t[:, 1, 1] = c, -s, s, c
    return t


def main():
    problem = json.load(open(sys.argv[1]))
    repeats = int(sys.argv[2])
    start = [np.array(m) for m in problem["local_transforms"]]  # joints then the tool, 4x4
    q = np.array(problem["q"])
    measured = [np.array(m) for m in problem["measured"]]
    wp, wr = 1.0 / problem["position_sigma_m"], 1.0 / problem["rotation_sigma_rad"]
    full_pose = bool(problem.get("full_pose", True))
    n = q.shape[1]
    measured_p = np.array([m[:3, 3] for m in measured])
    measured_r = [m[:3, :3] for m in measured]

    joint_rotations = [rot_z(q[:, i]) for i in range(n)]
    measured_r = np.array(measured_r)

    def poses(x):
        """Every pose at once, as an (N, 4, 4) array (numpy batches the products over the rows)."""
        locals_ = [exp_se3(x[6 * i : 6 * i + 6]) @ start[i] for i in range(n + 1)]
        t = np.tile(np.eye(4), (len(q), 1, 1))
        for i in range(n):
            t = t @ locals_[i] @ joint_rotations[i]
        return t @ locals_[n]

    def residual(x):
        t = poses(x)
        dp = (measured_p - t[:, :3, 3]) * wp
        if not full_pose:
            return dp.ravel()
        dr = Rotation.from_matrix(measured_r @ np.transpose(t[:, :3, :3], (0, 2, 1))).as_rotvec() * wr
        return np.hstack([dp, dr]).ravel()

    x0 = np.zeros(6 * (n + 1))
    times = []
    for _ in range(repeats):
        begin = time.perf_counter()
        fit = least_squares(residual, x0, method="trf", x_scale="jac")
        times.append(time.perf_counter() - begin)
    final = poses(fit.x)
    rms = np.sqrt(np.mean(np.sum((final[:, :3, 3] - measured_p) ** 2, axis=1)))
    print(json.dumps({"seconds": float(np.median(times)), "rms_position_m": float(rms), "evaluations": int(fit.nfev)}))


if __name__ == "__main__":
    main()
