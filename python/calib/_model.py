"""``fit`` and ``Model``: ``calib fit``, ``eval``, ``predict`` and ``compensate``."""

from __future__ import annotations

import json
import os
import tempfile
from typing import Any, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _calib
from ._common import PathLike, is_path, warn_all
from ._measurements import Measurements, _core_of, _pairs
from ._reports import Compensation, EvalReport, ErrorSummary, FitReport


def _measurements(
    data: Any, robot: Optional[Any] = None, inputs: Optional[Sequence[str]] = None
) -> Measurements:
    if isinstance(data, Measurements):
        return data
    return Measurements(data, robot=robot, inputs=inputs)


def fit(
    robot: _calib.Robot,
    data: Union[Measurements, PathLike, Any],
    method: str,
    effects: Optional[str] = None,
    gp: Optional[str] = None,
    options: Union[None, PathLike, Mapping[str, Any]] = None,
    force: bool = False,
    inputs: Optional[Sequence[str]] = None,
) -> "Model":
    """Fits a calibrated model, as ``calib fit`` does, with the CLI's defaults: the same words give
    the same fit (``calib.fit(robot, data, method="poe")`` is ``calib fit --method poe``).

    Args:
        robot: the robot description (:meth:`Robot.load`).
        data: the training measurements (a :class:`Measurements`, a CSV path, a DataFrame).
        method: ``base-tool``, ``poe``, ``poe-gp`` or ``poe-gp-load`` (required, as ``--method``).
        effects: non-geometric effects identified with the geometry, only when asked for, as
            ``--effects``: ``"auto"`` (what the diagnosis selects), ``"none"`` (the geometry
            alone), or the CLI's list (``"joint_compliance,gear_periodic:1:4"``); ``None`` (not
            given) keeps what ``options`` says, no effects by default.
        gp: ``exact``, ``sparse`` or ``auto``; ``None`` keeps what ``options`` says (default auto).
        options: the CLI's ``--options``: a RON file, or a mapping of the same fields
            (``{"identification": {"max_iterations": 100}}``).
        force: fit data that the plausibility checks refuse, with a warning (``--force``).
        inputs: measured signals the GP takes beside the joints (``--inputs``): column names of
            ``data`` (``["tilt_x_mrad", "temp_c"]``); a :class:`Measurements` passed as ``data``
            must have been read with the same ``inputs``. The model then requires those columns
            in ``eval``, ``predict`` and ``compensate``.

    Returns:
        The model; ``model.report`` is the :class:`FitReport` (``calib fit --json``). The model
        is the one its file holds (written and read back, as ``calib fit`` then ``calib eval``
        see it), so that ``eval`` and ``predict`` give the CLI's numbers to the last bit.
    """
    inputs = None if inputs is None else [str(name) for name in inputs]
    data = _measurements(data, robot, inputs)
    options_path = options if is_path(options) else None
    options_json = None
    if options is not None and options_path is None:
        options_json = json.dumps(dict(options))
    core, report, warnings = _calib.fit(
        robot,
        data._core,
        method,
        effects,
        gp,
        options_path,
        options_json,
        force,
        inputs,
    )
    warn_all(warnings)
    return Model(core, FitReport.from_dict(json.loads(report), warnings))


class Model:
    """A calibrated model: the identified geometry, the effects, the GP (``calib fit``'s file)."""

    __slots__ = ("_core", "report")

    def __init__(self, core: _calib.Model, report: Optional[FitReport] = None) -> None:
        self._core = core
        self.report: Optional[FitReport] = report
        """The fit report, for a model fitted in this session (``None`` for one loaded)."""

    @classmethod
    def load(cls, path: PathLike) -> "Model":
        """Reads a model file (RON, from ``calib fit`` or :meth:`save`)."""
        return cls(_calib.Model.load(path))

    def save(self, path: PathLike) -> None:
        """Writes the model file (RON); for a model fitted in this session, byte for byte the file
        ``calib fit --out`` writes."""
        self._core.save(path)

    def __repr__(self) -> str:
        return repr(self._core)

    @property
    def method(self) -> str:
        return self._core.method

    @property
    def robot(self) -> str:
        return self._core.robot

    @property
    def full_pose(self) -> bool:
        """Whether the model calibrates orientation (fitted on full poses)."""
        return self._core.full_pose

    @property
    def tools(self) -> list:
        return self._core.tools

    @property
    def joint_count(self) -> int:
        return self._core.joint_count

    @property
    def predicts_std(self) -> bool:
        """Whether :meth:`predict` returns standard deviations."""
        return self._core.predicts_std

    def eval(self, data: Union[Measurements, PathLike, Any]) -> EvalReport:
        """The model's errors on measurements, as ``calib eval --json`` reports them, with the
        error of every row (``position_errors_mm``, ``rotation_errors_mrad``). What ``calib eval``
        prints as ``note: …`` and ``warning: …`` is raised as :class:`CalibWarning`, the same texts
        in the same order, and kept in the report's ``warnings``."""
        data = _measurements(data, self)
        text, position, rotation, warnings = self._core.eval(data._core)
        warn_all(warnings)
        raw = json.loads(text)
        return EvalReport(
            method=raw["method"],
            robot=raw["robot"],
            data=raw["data"],
            full_pose=raw["full_pose"],
            summary=ErrorSummary.from_dict(raw),
            coverage=raw.get("coverage"),
            warnings=list(warnings),
            position_errors_mm=position,
            rotation_errors_mrad=rotation,
            raw=raw,
        )

    def predict(
        self,
        q: Union[Any, Measurements],
        payload: Union[None, float, Any] = None,
        tool: Union[None, str, Sequence[str]] = None,
        temp_c: Optional[Any] = None,
        t_s: Optional[Any] = None,
        torques_nm: Optional[Any] = None,
        inputs: Optional[Mapping[str, Any]] = None,
    ) -> Tuple[np.ndarray, Optional[np.ndarray]]:
        """The compensated tool pose of joint configurations, as ``calib predict`` computes it.

        Args:
            q: joint values ``(n, joints)`` (or ``(joints,)`` for one), rad (m for prismatic
                joints); or a :class:`Measurements`, whose own payloads and tools are used.
            payload: kg, one for all rows or one per row (``poe-gp-load`` models use it).
            tool: the tool identifier, one for all rows or one per row (default: ``""``).
            temp_c, t_s, torques_nm: per row, where the model's effects need them.
            inputs: the measured signals the model takes (``fit(..., inputs=...)``), by name, one
                value for all rows or one per row; a model's signal left out is refused by name.

        Returns:
            ``(poses, sigma)``. ``poses`` is ``(n, 7)``: ``x_mm, y_mm, z_mm, qw, qx, qy, qz`` in the
            tracker frame for a full-pose model, ``(n, 3)`` positions for a position-only one (it
            did not calibrate orientation). ``sigma`` is the standard deviation of the GP (and of
            what the effects leave where they fade out): ``(n, 6)`` mm and mrad, or ``(n, 3)`` mm;
            ``None`` when the model has neither.
        """
        if isinstance(q, Measurements):
            poses, sigma, warnings = self._core.predict_set(q._core)
            warn_all(warnings)
            return poses, sigma
        q = np.ascontiguousarray(q, dtype=np.float64)
        if q.ndim == 1:
            q = q.reshape(1, -1)
        n = q.shape[0]

        def per_row(name: str, values: Any) -> Optional[np.ndarray]:
            if values is None:
                return None
            array = np.asarray(values, dtype=np.float64)
            if array.ndim == 0:
                array = np.full(n, float(array))
            return np.ascontiguousarray(array)

        tools = None
        if tool is not None:
            tools = [tool] * n if isinstance(tool, str) else [str(t) for t in tool]
        torques = None if torques_nm is None else np.ascontiguousarray(torques_nm, dtype=np.float64)
        poses, sigma, warnings = self._core.predict(
            q,
            per_row("payload", payload),
            tools,
            per_row("temp_c", temp_c),
            per_row("t_s", t_s),
            torques,
            None
            if inputs is None
            else [(str(name), per_row(str(name), values)) for name, values in inputs.items()],
        )
        warn_all(warnings)
        return poses, sigma

    def compensate(
        self,
        targets: Union[PathLike, Mapping[str, Any], Any],
        robot: Optional[_calib.Robot] = None,
        frame: str = "tracker",
        columns: Optional[Mapping[str, str]] = None,
    ) -> Compensation:
        """Joint targets rewritten so that the calibrated robot reaches what they mean, as
        ``calib compensate`` does.

        ``targets`` is a CSV path, a mapping of column names to arrays or a DataFrame: joint
        columns alone (a program taught on the nominal model; needs ``robot``), or tool poses
        (``x_mm`` … and optionally an orientation, in ``frame`` ``"tracker"`` or ``"base"``) with
        seed joint columns; ``payload_kg`` where it matters.
        """
        if is_path(targets):
            return self._compensate(targets, robot, frame, columns)
        # The CLI reads targets from a file, passing every input column on: the same file here.
        data = targets
        if hasattr(data, "columns") and hasattr(data, "to_numpy"):
            data = {str(c): data[c].to_numpy() for c in data.columns}
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "targets.csv")
            _write_csv(path, data)
            return self._compensate(path, robot, frame, columns)

    def _compensate(self, path: PathLike, robot: Any, frame: str, columns: Any) -> Compensation:
        csv, q, residual_mm, residual_mrad, status, summary, warnings = self._core.compensate(
            path, _core_of(robot), frame, _pairs(columns)
        )
        warn_all(warnings, stacklevel=4)
        return Compensation(
            q=q,
            residual_mm=residual_mm,
            residual_mrad=residual_mrad,
            status=status,
            summary=json.loads(summary),
            csv=csv,
        )


def _write_csv(path: str, columns: Mapping[str, Any]) -> None:
    """Columns as CSV, numbers in Python's shortest round-trip form (``repr``)."""
    import csv

    names = [str(k) for k in columns]
    values = [list(np.asarray(v).tolist()) for v in columns.values()]
    n = len(values[0]) if values else 0
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(names)
        for i in range(n):
            w.writerow([repr(v[i]) if isinstance(v[i], float) else v[i] for v in values])
