"""Type hints of the native module (crates/python); the documented API is the package's."""

import os
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, os.PathLike[str]]
_F64 = npt.NDArray[np.float64]

class CalibError(Exception):
    file: Optional[str]
    """The file (or command-line option) at fault, where the refusal has one."""
    line: Optional[int]
    """Its line as an editor counts it (the header is line 1), where known."""
    column: Optional[int]
    """Its 1-based column, where known."""


class Robot:
    @staticmethod
    def load(path: _Path, base_link: Optional[str] = None, tip_link: Optional[str] = None) -> Robot:
        """Reads a robot description: RON (axes or DH table) or URDF, with the URDF chain's ends."""
    @property
    def name(self) -> str: ...
    @property
    def path(self) -> str: ...
    @property
    def joint_count(self) -> int: ...
    @property
    def joint_kinds(self) -> List[str]: ...
    @property
    def limits(self) -> List[Tuple[float, float]]: ...
    def to_ron(self) -> str: ...

class Measurements:
    @staticmethod
    def read(
        path: _Path,
        robot: Optional[Union[Robot, Model]] = None,
        columns: Optional[Sequence[Tuple[str, str]]] = None,
        positions: bool = True,
    ) -> Measurements: ...
    @staticmethod
    def from_columns(
        numeric: Sequence[Tuple[str, _F64]],
        text: Sequence[Tuple[str, List[str]]],
        source: str,
        robot: Optional[Union[Robot, Model]] = None,
    ) -> Measurements: ...
    def __len__(self) -> int: ...
    @property
    def source(self) -> str: ...
    @property
    def joint_count(self) -> int: ...
    @property
    def full_pose(self) -> bool: ...
    @property
    def positions_measured(self) -> bool: ...
    @property
    def tools(self) -> List[str]: ...
    @property
    def ignored_columns(self) -> List[str]: ...
    def read_summary(self) -> str: ...
    def lines(self) -> npt.NDArray[np.uint64]: ...
    def q(self) -> _F64: ...
    def positions_mm(self) -> _F64: ...
    def quaternions(self) -> Optional[_F64]: ...
    def payload_kg(self) -> _F64: ...
    def tool_of_rows(self) -> List[str]: ...
    def temp_c(self) -> _F64: ...
    def t_s(self) -> _F64: ...
    def subset(self, indices: List[int]) -> Measurements: ...

class Model:
    @staticmethod
    def load(path: _Path) -> Model: ...
    def save(self, path: _Path) -> None: ...
    @property
    def method(self) -> str: ...
    @property
    def robot(self) -> str: ...
    @property
    def full_pose(self) -> bool: ...
    @property
    def tools(self) -> List[str]: ...
    @property
    def joint_count(self) -> int: ...
    @property
    def predicts_std(self) -> bool: ...
    @property
    def non_geometric_parts(self) -> List[str]: ...
    def eval(self, data: Measurements) -> Tuple[str, _F64, Optional[_F64], List[str]]: ...
    def predict_set(self, data: Measurements) -> Tuple[_F64, Optional[_F64], List[str]]: ...
    def predict(
        self,
        q: _F64,
        payload_kg: Optional[_F64] = None,
        tools: Optional[List[str]] = None,
        temp_c: Optional[_F64] = None,
        t_s: Optional[_F64] = None,
        torques_nm: Optional[_F64] = None,
    ) -> Tuple[_F64, Optional[_F64], List[str]]: ...
    def compensate(
        self,
        targets: _Path,
        robot: Optional[Robot] = None,
        frame: str = "tracker",
        columns: Optional[Sequence[Tuple[str, str]]] = None,
    ) -> Tuple[str, _F64, _F64, _F64, List[str], str, List[str]]: ...

def fit(
    robot: Robot,
    data: Measurements,
    method: str,
    effects: Optional[str] = None,
    gp: Optional[str] = None,
    options_path: Optional[_Path] = None,
    options_json: Optional[str] = None,
    force: bool = False,
) -> Tuple[Model, str, List[str]]: ...
def diagnose(
    robot: Robot,
    data: Measurements,
    noise_mm: Optional[float] = None,
    folds: int = 5,
    seed: int = 0,
    report: Optional[_Path] = None,
) -> Tuple[str, str, Optional[str]]: ...
def simulate(
    robot: Robot,
    rows: int = 300,
    seed: int = 0,
    full_pose: bool = False,
    effects: Optional[_Path] = None,
    payloads: Optional[List[float]] = None,
    moving_joints: Optional[List[int]] = None,
    fixed_jitter_mrad: Optional[float] = None,
    runs: bool = False,
    tool_per_payload: bool = False,
    torques: bool = False,
    torque_sigma_nm: Optional[float] = None,
    out: Optional[_Path] = None,
) -> Measurements: ...
