"""UR10 (Landgraf et al., CASE 2021): fit series C's even rows, evaluate on its odd rows, plot the
held-out error per joint angle.

    pip install ./python            # once, from the top of the clone
    python examples/ur10.py [DATA_FOLDER] [--plot residuals.png]

DATA_FOLDER holds ur10_C_full_even.csv and ur10_C_full_odd.csv (default /work/data). The same as

    calib fit --robot fixtures/robots/ur10.ron --data ur10_C_full_even.csv --method poe-gp \\
        --effects auto --out ur10_C.ron
    calib eval --model ur10_C.ron --data ur10_C_full_odd.csv --json

and the numbers are the CLI's to the last bit.
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

import calib

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data", nargs="?", default="/work/data", type=Path)
    parser.add_argument("--plot", type=Path, default=Path("ur10_residuals.png"))
    parser.add_argument("--model", type=Path, help="also write the model file here")
    args = parser.parse_args()

    robot = calib.Robot.load(ROOT / "fixtures" / "robots" / "ur10.ron")
    train = calib.Measurements.read(args.data / "ur10_C_full_even.csv", robot=robot)
    test = calib.Measurements.read(args.data / "ur10_C_full_odd.csv", robot=robot)
    print(train.read_summary)

    start = time.perf_counter()
    model = calib.fit(robot, train, method="poe-gp", effects="auto")
    report = model.report
    print(f"fit poe-gp --effects auto in {time.perf_counter() - start:.1f} s")
    if report.auto is not None:
        chosen = report.auto.get("chosen") or []
        print(f"  effects auto selected: {', '.join(map(str, chosen)) or 'nothing'}")
    print(f"  training error: {report.before.mean_position_error_mm:.4f} mm nominal "
          f"-> {report.after.mean_position_error_mm:.4f} mm")
    if args.model:
        model.save(args.model)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", calib.CalibWarning)  # a few odd rows lie beyond the even rows' range
        held_out = model.eval(test)
    print(f"held-out (odd rows): mean {held_out.mean_position_error_mm!r} mm, "
          f"rms {held_out.rms_position_error_mm:.4f} mm, max {held_out.max_position_error_mm:.4f} mm, "
          f"rotation {held_out.mean_rotation_error_mrad:.4f} mrad")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot")
        return
    q = np.degrees(test.q)
    errors = held_out.position_errors_mm
    fig, axes = plt.subplots(2, 3, figsize=(12, 6), sharey=True)
    for joint, ax in enumerate(axes.flat):
        ax.scatter(q[:, joint], errors, s=4, alpha=0.5)
        ax.set_xlabel(f"joint {joint + 1} (deg)")
        if joint % 3 == 0:
            ax.set_ylabel("held-out position error (mm)")
    fig.suptitle(f"UR10 series C, {model.method} with effects auto: odd rows, "
                 f"mean {held_out.mean_position_error_mm:.3f} mm")
    fig.tight_layout()
    fig.savefig(args.plot, dpi=100)
    print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
