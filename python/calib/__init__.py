"""Robot calibration from Python: numpy in, numpy out, the same numbers as the ``calib`` CLI.

The package calls the same library functions as the ``calib`` binary (the workspace's ``pipeline``
crate, through the native module ``calib._calib``), so a number here equals the CLI's::

    import calib

    robot = calib.Robot.load("fixtures/robots/ur10.ron")
    train = calib.Measurements.read("ur10_C_full_even.csv")
    model = calib.fit(robot, train, method="poe-gp", effects="auto")     # calib fit
    report = model.eval(calib.Measurements.read("ur10_C_full_odd.csv"))  # calib eval --json
    poses, sigma = model.predict(q)                                       # calib predict

Units are the SPEC's: joint values in rad (m for prismatic joints), positions in mm, rotation
errors in mrad, payloads in kg. Refusals raise :class:`CalibError` (or ``FileNotFoundError``)
whose message names the file, line and column; what the CLI prints as a warning is a
:class:`CalibWarning`. Long calls release the GIL.
"""

from ._calib import CalibError, Robot
from ._common import CalibWarning
from ._measurements import Measurements
from ._model import Model, fit
from ._reports import Compensation, Diagnosis, ErrorSummary, EvalReport, FitReport
from ._studies import diagnose, simulate

__all__ = [
    "CalibError",
    "CalibWarning",
    "Compensation",
    "Diagnosis",
    "ErrorSummary",
    "EvalReport",
    "FitReport",
    "Measurements",
    "Model",
    "Robot",
    "diagnose",
    "fit",
    "simulate",
]
