"""The reports as dataclasses: the fields a script reads, and ``raw``, the whole JSON object the
CLI's ``--json`` prints (``as_dict()`` returns it)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional

import numpy as np


@dataclass(frozen=True)
class ErrorSummary:
    """Statistics of the pose errors of some rows (mm, mrad)."""

    n: int
    mean_position_error_mm: float
    rms_position_error_mm: float
    max_position_error_mm: float
    median_position_error_mm: float
    mean_rotation_error_mrad: Optional[float] = None
    max_rotation_error_mrad: Optional[float] = None

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "ErrorSummary":
        return cls(
            n=d["n"],
            mean_position_error_mm=d["mean_position_error_mm"],
            rms_position_error_mm=d["rms_position_error_mm"],
            max_position_error_mm=d["max_position_error_mm"],
            median_position_error_mm=d["median_position_error_mm"],
            mean_rotation_error_mrad=d.get("mean_rotation_error_mrad"),
            max_rotation_error_mrad=d.get("max_rotation_error_mrad"),
        )


@dataclass(frozen=True)
class FitReport:
    """What ``calib fit --json`` prints: training errors before (nominal, registered) and after,
    the identification, the effects, the GP, what ``effects="auto"`` chose, and warnings."""

    method: str
    n: int
    full_pose: bool
    before: ErrorSummary
    after: ErrorSummary
    identification: Dict[str, Any]
    effects: List[Dict[str, Any]]
    residual_gp: Optional[Dict[str, Any]]
    auto: Optional[Dict[str, Any]]
    plausibility: Optional[Dict[str, Any]]
    outliers: List[Dict[str, Any]]
    warnings: List[str]
    raw: Dict[str, Any] = field(repr=False)

    @classmethod
    def from_dict(cls, d: Dict[str, Any], warnings: List[str]) -> "FitReport":
        return cls(
            method=d["method"],
            n=d["n"],
            full_pose=d["full_pose"],
            before=ErrorSummary.from_dict(d["before"]),
            after=ErrorSummary.from_dict(d["after"]),
            identification=d["identification"],
            effects=d["effects"],
            residual_gp=d.get("residual_gp"),
            auto=d.get("auto"),
            plausibility=d.get("plausibility"),
            outliers=d["outliers"],
            warnings=list(warnings),
            raw=d,
        )

    @property
    def compensation(self) -> Optional[Dict[str, Any]]:
        """The old name of :attr:`residual_gp` (the JSON key's before SPEC version 5), still read;
        "compensation" now means :meth:`Model.compensate`'s joint targets alone."""
        return self.residual_gp

    def as_dict(self) -> Dict[str, Any]:
        """The JSON object of ``calib fit --json``."""
        return self.raw


@dataclass(frozen=True)
class EvalReport:
    """What ``calib eval --json`` prints, with the error of every row beside it."""

    method: str
    robot: str
    data: str
    full_pose: bool
    summary: ErrorSummary
    coverage: Optional[Dict[str, Any]]
    warnings: List[str]
    position_errors_mm: np.ndarray = field(repr=False)
    """Distance between measured and predicted tool point of each row, mm."""
    rotation_errors_mrad: Optional[np.ndarray] = field(repr=False)
    """Rotation angle between measured and predicted orientation of each row, mrad (full pose)."""
    raw: Dict[str, Any] = field(repr=False)

    @property
    def n(self) -> int:
        return self.summary.n

    @property
    def mean_position_error_mm(self) -> float:
        return self.summary.mean_position_error_mm

    @property
    def rms_position_error_mm(self) -> float:
        return self.summary.rms_position_error_mm

    @property
    def max_position_error_mm(self) -> float:
        return self.summary.max_position_error_mm

    @property
    def mean_rotation_error_mrad(self) -> Optional[float]:
        return self.summary.mean_rotation_error_mrad

    def as_dict(self) -> Dict[str, Any]:
        """The JSON object of ``calib eval --json``."""
        return self.raw


@dataclass(frozen=True)
class Diagnosis:
    """What ``calib diagnose --json`` prints: the verdict, the held-out errors, the candidates."""

    effect: str
    """The verdict's effect: joint_compliance, backlash, gear_periodic, thermal, time_drift,
    link_deflection, screw_periodic, none or unknown."""
    joints: List[int]
    """The 1-based joints the verdict involves."""
    heldout_before_mm: float
    heldout_after_mm: float
    heldout_after_selected_mm: float
    selected: List[Dict[str, Any]]
    candidates: List[Dict[str, Any]]
    summary: str
    """The summary ``calib diagnose`` prints."""
    report_path: Optional[str]
    raw: Dict[str, Any] = field(repr=False)

    @property
    def verdict(self) -> Dict[str, Any]:
        """The verdict object of the JSON (``effect``, ``joints``, …)."""
        return self.raw["verdict"]

    @property
    def predicted_shrink(self) -> float:
        """How much of the geometric model's held-out error the selected effects remove (0.3 = 30 %
        less), cross-validated: ``1 - heldout_after_selected_mm / heldout_before_mm``."""
        return 1.0 - self.heldout_after_selected_mm / max(self.heldout_before_mm, 1e-300)

    def as_dict(self) -> Dict[str, Any]:
        """The JSON object of ``calib diagnose --json``."""
        return self.raw


@dataclass(frozen=True)
class Compensation:
    """What ``calib compensate`` prints, as arrays: the compensated joints of each target (NaN where
    refused), its residuals, its status, and the CSV text the CLI writes."""

    q: np.ndarray
    residual_mm: np.ndarray
    residual_mrad: np.ndarray
    status: List[str]
    summary: Dict[str, Any]
    csv: str = field(repr=False)

    @property
    def ok(self) -> np.ndarray:
        """Whether each row was compensated."""
        return np.array([s == "ok" for s in self.status], dtype=bool)
