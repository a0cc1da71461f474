"""One call, one fit: every default of ``calib.fit``, ``calib.diagnose`` and
``calib.simulate`` is the CLI's, read from ``calib <command> --help``, and the calls the same words
name give the same numbers."""

from __future__ import annotations

import inspect
import re
from typing import Dict, Tuple

import pytest

import calib
from conftest import ROBOT, untimed

# Each Python parameter and the CLI flag it stands for.
FLAGS: Dict[str, Dict[str, str]] = {
    "fit": {
        "method": "--method",
        "effects": "--effects",
        "gp": "--gp",
        "options": "--options",
        "force": "--force",
        "inputs": "--inputs",
    },
    "diagnose": {"noise_mm": "--noise-mm", "folds": "--folds", "seed": "--seed", "report": "--report"},
    "simulate": {
        "rows": "--rows",
        "seed": "--seed",
        "full_pose": "--full-pose",
        "effects": "--effects",
        "payloads": "--payloads",
        "moving_joints": "--moving-joints",
        "fixed_jitter_mrad": "--fixed-jitter-mrad",
        "runs": "--runs",
        "tool_per_payload": "--tool-per-payload",
        "torques": "--torques",
        "torque_sigma_nm": "--torque-sigma-nm",
    },
}

# Where the Python default is None for a flag whose help states a value: None is "not given", and
# the CLI treats the flag given apart from the flag left out, at any value.
NOT_GIVEN = {
    ("simulate", "fixed_jitter_mrad"): "given without --moving-joints it is refused, even at 0",
    ("simulate", "torque_sigma_nm"): "given without --torques it is refused",
}

# Parameters of the functions that are not flags: the data, and simulate's `out` (the CLI always
# writes a file; Python returns the rows and writes only where asked).
NOT_FLAGS = {"robot", "data", "out"}

FUNCTIONS = {"fit": calib.fit, "diagnose": calib.diagnose, "simulate": calib.simulate}


def _options(cli, command: str) -> Tuple[set, Dict[str, Tuple[bool, str]]]:
    """The flags `calib COMMAND --help` lists: the required ones, and each flag's (takes a value,
    its `[default: …]` text or '')."""
    text = cli.run(command, "--help").stdout
    usage = next(line for line in text.splitlines() if line.startswith("Usage:"))
    required = set(re.findall(r"(--[a-z-]+) <", usage.split("[OPTIONS]")[-1]))
    options: Dict[str, Tuple[bool, str]] = {}
    # Each option starts a line with its flag; its description runs to the next one.
    blocks = re.split(r"\n\s+(?=--[a-z])", text.split("Options:", 1)[1])
    for block in blocks:
        found = re.match(r"(--[a-z-]+)( <[^>]+>)?", block.strip())
        if not found:
            continue
        default = re.search(r"\[default: ([^\]]*)\]", block)
        options[found.group(1)] = (found.group(2) is not None, default.group(1) if default else "")
    return required, options


def _literal(text: str):
    """A `[default: …]` that is one value (a number or a word), parsed; None for a sentence."""
    text = text.strip()
    for parse in (int, float):
        try:
            return parse(text)
        except ValueError:
            pass
    return text if re.fullmatch(r"[a-z][a-z-]*", text) else None


@pytest.mark.parametrize("command", ["fit", "diagnose", "simulate"])
def test_every_default_is_the_clis(cli, command):
    required, options = _options(cli, command)
    parameters = inspect.signature(FUNCTIONS[command]).parameters
    flags = FLAGS[command]
    assert set(parameters) - NOT_FLAGS == set(flags), f"{command}: parameters without a flag here"
    for name, flag in flags.items():
        assert flag in options, f"{command}: {flag} is not an option of calib {command}"
        default = parameters[name].default
        takes_value, stated = options[flag]
        where = f"calib.{command}({name}=…) against {flag}"
        if flag in required:
            assert default is inspect.Parameter.empty, f"{where}: the CLI requires it, Python has a default"
        elif not takes_value:
            assert default is False, f"{where}: a switch, off unless given"
        elif (command, name) in NOT_GIVEN:
            assert default is None, f"{where}: {NOT_GIVEN[(command, name)]}"
        elif _literal(stated) is not None:
            assert default == _literal(stated), f"{where}: {default!r} against [default: {stated}]"
        else:
            assert default is None, f"{where}: the CLI's default is '{stated or 'none'}', Python's {default!r}"


def test_the_same_words_give_the_same_fit(cli, robot, campaign, tmp_path):
    # `calib.fit(robot, data, method="poe")` and `calib fit --method poe`: no effects in either.
    model = calib.fit(robot, campaign["train"], method="poe")
    path = tmp_path / "cli.ron"
    printed = cli.json("fit", "--robot", ROBOT, "--data", campaign["train"], "--method", "poe", "--out", path, "--json")
    assert untimed(model.report.as_dict()) == untimed(printed)
    assert model.report.as_dict()["effects"] == []
    ours = tmp_path / "py.ron"
    model.save(ours)
    assert ours.read_bytes() == path.read_bytes()


def test_fit_asks_for_the_method_as_the_cli_does(robot, campaign):
    with pytest.raises(TypeError, match="method"):
        calib.fit(robot, campaign["train"])  # type: ignore[call-arg]
