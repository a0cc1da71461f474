"""``Measurements``: a measurement set from a CSV file, numpy arrays or a pandas DataFrame."""

from __future__ import annotations

from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np

from . import _calib
from ._common import PathLike, is_path

TOOL = "tool"


def _text_column(values: Any) -> List[str]:
    """A text column (``tool``): blanks (None, NaN, "") are the default tool."""
    out = []
    for v in values:
        if v is None or (isinstance(v, float) and np.isnan(v)):
            out.append("")
        else:
            out.append(str(v))
    return out


class Measurements:
    """Measured poses (or, with ``positions=False``, commanded joint configurations).

    Built from a CSV path (the SPEC's format, read as ``calib fit --data`` reads it), from a
    mapping of the SPEC's column names to arrays, or from a pandas DataFrame with those column
    names (``q1_rad`` … or ``q1_deg`` …, ``x_mm``, ``y_mm``, ``z_mm`` or ``x_m`` …, optionally
    ``qw``, ``qx``, ``qy``, ``qz`` or ``rx_deg`` …, ``payload_kg``, ``tool``, ``temp_c``, ``t_s``,
    ``tau1_nm`` …). Arrays go through the same reader as a file, so every check holds and a
    refusal names a line and a column: row ``i`` is line ``i + 2`` (line 1 is the header).

    ``robot`` (a :class:`Robot` or :class:`Model`) checks the joint columns against its joints
    when reading, as the CLI does; otherwise they are checked when the set is used. Read for a
    :class:`Model` that takes measured signals as inputs, the set requires their columns;
    ``inputs`` keeps other signal columns by name (``fit(..., inputs=...)``).
    """

    __slots__ = ("_core",)

    def __init__(
        self,
        source: Union[PathLike, Mapping[str, Any], Any],
        *,
        robot: Optional[Any] = None,
        columns: Optional[Mapping[str, str]] = None,
        positions: bool = True,
        name: Optional[str] = None,
        inputs: Optional[Sequence[str]] = None,
    ) -> None:
        inputs = None if inputs is None else [str(i) for i in inputs]
        if isinstance(source, _calib.Measurements):
            self._core = source
        elif is_path(source):
            self._core = _calib.Measurements.read(
                source, _core_of(robot), _pairs(columns), positions, inputs
            )
        elif hasattr(source, "columns") and hasattr(source, "to_numpy"):
            self._core = _from_mapping(
                {str(c): source[c].to_numpy() for c in source.columns},
                name or "DataFrame",
                robot,
                inputs,
            )
        elif isinstance(source, Mapping):
            self._core = _from_mapping(source, name or "arrays", robot, inputs)
        else:
            raise TypeError(
                "Measurements: expected a CSV path, a mapping of column names to arrays "
                f"or a pandas DataFrame, got {type(source).__name__}"
            )

    @classmethod
    def read(
        cls,
        path: PathLike,
        robot: Optional[Any] = None,
        columns: Optional[Mapping[str, str]] = None,
        positions: bool = True,
        inputs: Optional[Sequence[str]] = None,
    ) -> "Measurements":
        """Reads a measurement CSV; ``columns`` maps SPEC names onto other headers
        (``{"x_mm": "X [mm]"}``, the CLI's ``--columns``); ``inputs`` keeps measured signals
        by name for ``fit(..., inputs=...)`` (``--inputs``)."""
        return cls(path, robot=robot, columns=columns, positions=positions, inputs=inputs)

    @classmethod
    def from_arrays(
        cls,
        q: Any,
        positions_mm: Any,
        quaternions: Optional[Any] = None,
        payload_kg: Optional[Any] = None,
        tools: Optional[Sequence[str]] = None,
        temp_c: Optional[Any] = None,
        t_s: Optional[Any] = None,
        torques_nm: Optional[Any] = None,
        robot: Optional[Any] = None,
        name: str = "arrays",
    ) -> "Measurements":
        """A set from arrays: ``q`` ``(n, joints)`` rad, ``positions_mm`` ``(n, 3)`` in the tracker
        frame, ``quaternions`` ``(n, 4)`` as ``qw, qx, qy, qz``, and per-row optional columns."""
        q = np.asarray(q, dtype=np.float64)
        if q.ndim != 2:
            raise ValueError(f"q: expected an (n, joints) array, got shape {q.shape}")
        columns: Dict[str, Any] = {f"q{k + 1}_rad": q[:, k] for k in range(q.shape[1])}
        p = np.asarray(positions_mm, dtype=np.float64)
        if p.shape != (q.shape[0], 3):
            raise ValueError(f"positions_mm: expected shape ({q.shape[0]}, 3), got {p.shape}")
        columns.update({"x_mm": p[:, 0], "y_mm": p[:, 1], "z_mm": p[:, 2]})
        if quaternions is not None:
            o = np.asarray(quaternions, dtype=np.float64)
            if o.shape != (q.shape[0], 4):
                raise ValueError(f"quaternions: expected shape ({q.shape[0]}, 4), got {o.shape}")
            columns.update({"qw": o[:, 0], "qx": o[:, 1], "qy": o[:, 2], "qz": o[:, 3]})
        for key, values in (("payload_kg", payload_kg), ("temp_c", temp_c), ("t_s", t_s)):
            if values is not None:
                columns[key] = values
        if torques_nm is not None:
            t = np.asarray(torques_nm, dtype=np.float64)
            columns.update({f"tau{k + 1}_nm": t[:, k] for k in range(t.shape[1])})
        if tools is not None:
            columns[TOOL] = list(tools)
        return cls(columns, robot=robot, name=name)

    # --- what the set holds -------------------------------------------------------------------

    def __len__(self) -> int:
        return len(self._core)

    def __repr__(self) -> str:
        return repr(self._core)

    @property
    def source(self) -> str:
        """Where the rows come from, as messages name it."""
        return self._core.source

    @property
    def joint_count(self) -> int:
        return self._core.joint_count

    @property
    def full_pose(self) -> bool:
        """Whether every row has an orientation."""
        return self._core.full_pose

    @property
    def positions_measured(self) -> bool:
        return self._core.positions_measured

    @property
    def tools(self) -> List[str]:
        """Tool identifiers in order of first appearance (``""`` is the default tool)."""
        return self._core.tools

    @property
    def ignored_columns(self) -> List[str]:
        return self._core.ignored_columns

    @property
    def read_summary(self) -> str:
        """The reader's one line, as the CLI prints it."""
        return self._core.read_summary()

    @property
    def lines(self) -> np.ndarray:
        """The file line of each row."""
        return self._core.lines()

    @property
    def q(self) -> np.ndarray:
        """Joint values ``(n, joints)``, rad (m for prismatic joints)."""
        return self._core.q()

    @property
    def positions_mm(self) -> np.ndarray:
        """Measured tool points ``(n, 3)``, tracker frame, mm."""
        return self._core.positions_mm()

    @property
    def quaternions(self) -> Optional[np.ndarray]:
        """Measured orientations ``(n, 4)`` as ``qw, qx, qy, qz``; ``None`` for position-only data."""
        return self._core.quaternions()

    @property
    def payload_kg(self) -> np.ndarray:
        return self._core.payload_kg()

    @property
    def tool_of_rows(self) -> List[str]:
        """The tool identifier of each row."""
        return self._core.tool_of_rows()

    @property
    def temp_c(self) -> np.ndarray:
        """Temperature of each row, °C (NaN where none)."""
        return self._core.temp_c()

    @property
    def t_s(self) -> np.ndarray:
        """Time of each row, s (NaN where none)."""
        return self._core.t_s()

    def subset(self, indices: Sequence[int]) -> "Measurements":
        """The rows at ``indices`` (0-based) as a set of their own, lines kept."""
        return Measurements(self._core.subset([int(i) for i in indices]))

    def to_dataframe(self) -> Any:
        """The rows as a pandas DataFrame with the SPEC's column names (needs pandas)."""
        import pandas as pd

        q = self.q
        data: Dict[str, Any] = {f"q{k + 1}_rad": q[:, k] for k in range(q.shape[1])}
        p = self.positions_mm
        data.update({"x_mm": p[:, 0], "y_mm": p[:, 1], "z_mm": p[:, 2]})
        o = self.quaternions
        if o is not None:
            data.update({"qw": o[:, 0], "qx": o[:, 1], "qy": o[:, 2], "qz": o[:, 3]})
        data["payload_kg"] = self.payload_kg
        data[TOOL] = self.tool_of_rows
        return pd.DataFrame(data, index=self.lines)


def _core_of(robot: Optional[Any]) -> Optional[Any]:
    """The native object of a Robot or Model wrapper."""
    if robot is None:
        return None
    return getattr(robot, "_core", robot)


def _pairs(columns: Optional[Mapping[str, str]]) -> Optional[List[tuple]]:
    return None if columns is None else [(str(k), str(v)) for k, v in columns.items()]


def _from_mapping(
    columns: Mapping[str, Any],
    name: str,
    robot: Optional[Any],
    inputs: Optional[List[str]] = None,
) -> Any:
    numeric = []
    text = []
    for key, values in columns.items():
        key = str(key)
        array = np.asarray(values)
        if key == TOOL or array.dtype.kind in "OUS":
            text.append((key, _text_column(array.tolist())))
        else:
            if array.ndim != 1:
                raise ValueError(f"{key}: expected one value per row, got shape {array.shape}")
            numeric.append((key, np.ascontiguousarray(array, dtype=np.float64)))
    return _calib.Measurements.from_columns(numeric, text, name, _core_of(robot), inputs)
