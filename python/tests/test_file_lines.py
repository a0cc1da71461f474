"""Rows named by the line an editor shows them on, from Python as from the CLI: a file
with Windows line ends, a blank line and notes over two lines, with faults planted at known rows."""

from __future__ import annotations

import math
from pathlib import Path
from typing import List, Tuple

import pytest

import calib
from conftest import ROBOT


def _editor_lines(text: str) -> List[str]:
    return text.replace("\r\n", "\n").replace("\r", "\n").split("\n")


def _quirky(path: Path, header: str, rows: List[str]) -> List[int]:
    """``rows`` written with Windows line ends, a ``note`` over two lines in rows 2 and 5 and a blank
    line before row 4; returns each row's line."""
    text = header + ",note\r\n"
    lines = []
    for i, row in enumerate(rows):
        if i == 4:
            text += "\r\n"
        lines.append(len(_editor_lines(text)))
        note = '"measured twice,\r\nsee the log"' if i in (2, 5) else ""
        text += f"{row},{note}\r\n"
    path.write_bytes(text.encode())
    return lines


def _with(header: str, row: str, name: str, value: str) -> str:
    cells = row.split(",")
    cells[header.split(",").index(name)] = value
    return ",".join(cells)


def _rows(campaign: dict, which: str) -> Tuple[str, List[str]]:
    lines = campaign[which].read_text().splitlines()
    return lines[0], lines[1:]


def _even_odd(campaign: dict) -> Tuple[str, List[str], List[str]]:
    """The whole campaign's header, even rows (to fit) and odd rows (to test): the test rows lie
    within the fitted range (temperature and time drift along the campaign), where eval judges rows."""
    header, rows = _rows(campaign, "whole")
    return header, rows[0::2], rows[1::2]


def _at(path: Path, line: int) -> str:
    return _editor_lines(path.read_bytes().decode())[line - 1]


def test_a_refusal_carries_the_editor_line_as_the_cli_prints_it(cli, campaign, tmp_path):
    header, rows = _rows(campaign, "train")
    rows = rows[:12]
    rows[7] = _with(header, rows[7], "y_mm", "abc")
    bad = tmp_path / "bad.csv"
    lines = _quirky(bad, header, rows)
    with pytest.raises(calib.CalibError) as caught:
        calib.Measurements.read(bad)
    column = header.split(",").index("y_mm") + 1
    assert (caught.value.file, caught.value.line, caught.value.column) == (str(bad), lines[7], column)
    assert str(caught.value).startswith(f"{bad}:{lines[7]}:{column}:")
    printed = cli.run("fit", "--robot", ROBOT, "--data", bad, "--method", "poe", "--out", tmp_path / "m.ron",
                      check=False).stderr
    assert str(caught.value) in printed
    assert _at(bad, lines[7]).split(",")[column - 1] == "abc"


def test_rows_outliers_and_warnings_are_named_by_their_lines(robot, campaign, tmp_path):
    header, train, test = _even_odd(campaign)
    train[9] = _with(header, train[9], "x_mm", str(float(train[9].split(",")[header.split(",").index("x_mm")]) + 1000))
    train_path = tmp_path / "train.csv"
    train_lines = _quirky(train_path, header, train)
    data = calib.Measurements.read(train_path)
    assert list(data.lines) == train_lines
    with pytest.warns(calib.CalibWarning, match=f"gross outliers.*line {train_lines[9]} "):
        model = calib.fit(robot, data, method="poe", effects=None)
    assert model.report.as_dict()["outliers"][0]["line"] == train_lines[9]
    assert _at(train_path, train_lines[9]).startswith(train[9].split(",")[0])
    test[9] = _with(header, test[9], "y_mm", str(float(test[9].split(",")[header.split(",").index("y_mm")]) + 40))
    test[8] = _with(header, test[8], "payload_kg", "50")
    test_path = tmp_path / "test.csv"
    lines = _quirky(test_path, header, test)
    with pytest.warns(calib.CalibWarning):
        report = model.eval(test_path).as_dict()
    assert report["suspect_rows"]["rows"][0]["line"] == lines[9]
    payload = [w for w in report["out_of_range"] if w["input"] == "payload_kg"]
    assert payload[0]["first_line"] == lines[8]
    assert not math.isnan(report["mean_position_error_mm"])
