"""Shared fixtures: the `calib` binary the package is pinned to, and a simulated campaign made by it."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import List

import pytest

ROOT = Path(__file__).resolve().parents[2]
ROBOT = ROOT / "fixtures" / "robots" / "irb4400.ron"


def _binary() -> str:
    """The CLI: $CALIB_CLI, else the newest of target/{debug,release}/calib, else built now."""
    given = os.environ.get("CALIB_CLI")
    if given:
        return given
    built = [ROOT / "target" / p / "calib" for p in ("debug", "release")]
    built = [p for p in built if p.exists()]
    if not built:
        subprocess.run(["cargo", "build", "-p", "calib", "--quiet"], cwd=ROOT, check=True)
        built = [ROOT / "target" / "debug" / "calib"]
    return str(max(built, key=lambda p: p.stat().st_mtime))


class Cli:
    """Runs the `calib` binary."""

    def __init__(self, path: str) -> None:
        self.path = path

    def run(self, *args: str, check: bool = True) -> subprocess.CompletedProcess:
        done = subprocess.run([self.path, *map(str, args)], capture_output=True, text=True)
        if check and done.returncode != 0:
            raise AssertionError(f"calib {' '.join(map(str, args))} failed: {done.stderr}")
        return done

    def json(self, *args: str) -> dict:
        return json.loads(self.run(*args).stdout)


@pytest.fixture(scope="session")
def cli() -> Cli:
    return Cli(_binary())


def untimed(report: dict) -> dict:
    """A fit report less its `timings`: the wall and CPU seconds of its phases differ between any
    two runs (and the CLI's add reading and writing files), the rest is equal to the last bit."""
    assert "timings" in report
    return {key: value for key, value in report.items() if key != "timings"}


@pytest.fixture(scope="session")
def robot():
    """The IRB 4400 the campaign is simulated for, as the package loads it."""
    import calib

    return calib.Robot.load(ROBOT)


@pytest.fixture(scope="session")
def campaign(cli: Cli, tmp_path_factory: pytest.TempPathFactory) -> dict:
    """A full-pose IRB 4400 campaign simulated by the CLI (300 rows, seed 5), split into 200 training
    rows and 100 held-out rows, as files."""
    folder = tmp_path_factory.mktemp("campaign")
    whole = folder / "whole.csv"
    cli.run("simulate", "--robot", ROBOT, "--rows", "300", "--seed", "5", "--full-pose", "--out", whole)
    lines: List[str] = whole.read_text().splitlines(keepends=True)
    train, test = folder / "train.csv", folder / "test.csv"
    train.write_text("".join(lines[:201]))
    test.write_text(lines[0] + "".join(lines[201:]))
    return {"folder": folder, "whole": whole, "train": train, "test": test}
