"""``diagnose`` and ``simulate``: ``calib diagnose`` and ``calib simulate``."""

from __future__ import annotations

import json
from typing import Any, Optional, Sequence, Union

from . import _calib
from ._common import PathLike
from ._measurements import Measurements
from ._reports import Diagnosis


def diagnose(
    robot: _calib.Robot,
    data: Union[Measurements, PathLike, Any],
    noise_mm: Optional[float] = None,
    folds: int = 5,
    seed: int = 0,
    report: Optional[PathLike] = None,
) -> Diagnosis:
    """Where the geometric model misses, which effect explains it, how far it shrinks, as
    ``calib diagnose --json`` says.

    Args:
        noise_mm: the instrument's noise per axis, mm, if known.
        folds, seed: the cross-validation folds and their seed.
        report: a folder to write the markdown report with SVG plots into.
    """
    if not isinstance(data, Measurements):
        data = Measurements(data, robot=robot)
    text, summary, path = _calib.diagnose(robot, data._core, noise_mm, folds, seed, report)
    raw = json.loads(text)
    return Diagnosis(
        effect=raw["verdict"]["effect"],
        joints=list(raw["verdict"]["joints"]),
        heldout_before_mm=raw["heldout_before_mm"],
        heldout_after_mm=raw["heldout_after_mm"],
        heldout_after_selected_mm=raw["heldout_after_selected_mm"],
        selected=raw.get("selected", []),
        candidates=raw["candidates"],
        summary=summary,
        report_path=path,
        raw=raw,
    )


def simulate(
    robot: _calib.Robot,
    rows: int = 300,
    seed: int = 0,
    full_pose: bool = False,
    effects: Optional[PathLike] = None,
    payloads: Optional[Sequence[float]] = None,
    moving_joints: Optional[Sequence[int]] = None,
    fixed_jitter_mrad: Optional[float] = None,
    runs: bool = False,
    tool_per_payload: bool = False,
    torques: bool = False,
    torque_sigma_nm: Optional[float] = None,
    out: Optional[PathLike] = None,
) -> Measurements:
    """A simulated tracker campaign, row for row what ``calib simulate`` writes with the same
    arguments (read back through the CSV reader), and written to ``out`` where given.

    ``effects`` is a RON file of loadsim's effects, its fields spelt as ``--effects`` items
    (``joint_compliance``, ``time_drift``, …; default: joint compliance and tracker noise);
    ``moving_joints`` are 1-based; see ``calib simulate --help`` for the rest.
    """
    core = _calib.simulate(
        robot,
        rows,
        seed,
        full_pose,
        effects,
        None if payloads is None else [float(p) for p in payloads],
        None if moving_joints is None else [int(j) for j in moving_joints],
        fixed_jitter_mrad,
        runs,
        tool_per_payload,
        torques,
        torque_sigma_nm,
        out,
    )
    return Measurements(core)
