"""The package gives the CLI's numbers: each test runs the `calib` binary and the package on the
same files and compares. JSON floats are printed in shortest round-trip form, so `==` on the
parsed objects is equality to the last bit."""

from __future__ import annotations

import contextlib
import csv
import importlib
import io
import os
import re
import threading
import warnings

import numpy as np
import pytest

import calib
from conftest import ROBOT, untimed

# The campaign's test rows put joint 2 a little outside the range of its training rows (3 of 100),
# which the CLI and the package both warn of.
OUTSIDE = "outside the range the model was fitted on"
PAYLOAD = f"payload_kg {OUTSIDE}"
FADE = "where the GP's training rows say little"


@contextlib.contextmanager
def warns_exactly(*patterns: str):
    """Each pattern matches a warning the block gives, and each warning it gives matches one."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    messages = [str(w.message) for w in caught]
    for pattern in patterns:
        assert any(re.search(pattern, m) for m in messages), (pattern, messages)
    for message in messages:
        assert any(re.search(p, message) for p in patterns), (message, patterns)


def test_simulate_writes_the_file_the_cli_writes(cli, robot, tmp_path):
    theirs, ours = tmp_path / "cli.csv", tmp_path / "py.csv"
    cli.run("simulate", "--robot", ROBOT, "--rows", "50", "--seed", "9", "--full-pose", "--torques", "--out", theirs)
    data = calib.simulate(robot, rows=50, seed=9, full_pose=True, torques=True, out=ours)
    assert ours.read_bytes() == theirs.read_bytes()
    assert len(data) == 50 and data.full_pose
    np.testing.assert_array_equal(data.q, calib.Measurements.read(theirs).q)


@pytest.mark.parametrize("method,effects", [("poe", "none"), ("poe-gp-load", "joint_compliance")])
def test_fit_report_and_model_file_equal_the_clis(cli, robot, campaign, tmp_path, method, effects):
    theirs = tmp_path / "cli.ron"
    report = cli.json(
        "fit", "--robot", ROBOT, "--data", campaign["train"], "--method", method,
        "--effects", effects, "--out", theirs, "--json",
    )
    model = calib.fit(robot, calib.Measurements.read(campaign["train"]), method=method, effects=effects)
    assert untimed(model.report.as_dict()) == untimed(report)
    assert model.report.after.mean_position_error_mm == report["after"]["mean_position_error_mm"]
    ours = tmp_path / "py.ron"
    model.save(ours)
    assert ours.read_text() == theirs.read_text()


def test_eval_equals_cli_eval_json(cli, robot, campaign, tmp_path):
    path = tmp_path / "m.ron"
    cli.run("fit", "--robot", ROBOT, "--data", campaign["train"], "--method", "poe-gp", "--out", path)
    theirs = cli.json("eval", "--model", path, "--data", campaign["test"], "--json")
    with pytest.warns(calib.CalibWarning, match=OUTSIDE):
        report = calib.Model.load(path).eval(campaign["test"])
    assert report.as_dict() == theirs
    assert report.n == 100 and report.mean_position_error_mm == theirs["mean_position_error_mm"]
    errors = report.position_errors_mm
    assert errors.shape == (100,)
    assert np.mean(errors) == pytest.approx(theirs["mean_position_error_mm"], rel=1e-12)
    assert np.max(errors) == theirs["max_position_error_mm"]


def test_predict_equals_cli_predict_and_arrays_equal_a_set(cli, robot, campaign, tmp_path):
    path = tmp_path / "m.ron"
    cli.run("fit", "--robot", ROBOT, "--data", campaign["train"], "--method", "poe-gp-load", "--out", path)
    printed = list(csv.DictReader(io.StringIO(cli.run("predict", "--model", path, "--data", campaign["test"]).stdout)))
    model = calib.Model.load(path)
    data = calib.Measurements.read(campaign["test"])
    with pytest.warns(calib.CalibWarning, match=OUTSIDE):
        poses, sigma = model.predict(data.q, payload=data.payload_kg)
    assert poses.shape == (100, 7) and sigma.shape == (100, 6)
    keys = ["x_mm", "y_mm", "z_mm", "qw", "qx", "qy", "qz"]
    theirs = np.array([[float(row[k]) for k in keys] for row in printed])
    # The CLI prints 6 decimals of mm and 9 of a quaternion.
    np.testing.assert_allclose(poses[:, :3], theirs[:, :3], rtol=0, atol=5.1e-7)
    np.testing.assert_allclose(poses[:, 3:], theirs[:, 3:], rtol=0, atol=5.1e-10)
    std_keys = ["std_x_mm", "std_y_mm", "std_z_mm", "std_rx_mrad", "std_ry_mrad", "std_rz_mrad"]
    np.testing.assert_allclose(sigma, [[float(r[k]) for k in std_keys] for r in printed], rtol=0, atol=5.1e-7)
    with pytest.warns(calib.CalibWarning, match=OUTSIDE):
        from_set, sigma_set = model.predict(data)
    np.testing.assert_array_equal(from_set, poses)
    np.testing.assert_array_equal(sigma_set, sigma)
    # The payload matters to a poe-gp-load model: a wrong one must change the answer.
    with pytest.warns(calib.CalibWarning, match=OUTSIDE):
        other, _ = model.predict(data.q, payload=data.payload_kg + 5.0)
    assert np.max(np.abs(other[:, :3] - poses[:, :3])) > 1e-6


def test_arrays_give_the_fit_of_the_file(robot, campaign):
    data = calib.Measurements.read(campaign["train"])
    arrays = calib.Measurements.from_arrays(
        data.q, data.positions_mm, data.quaternions, payload_kg=data.payload_kg,
        temp_c=data.temp_c, t_s=data.t_s,
    )
    assert len(arrays) == len(data) and arrays.full_pose and arrays.lines[0] == 2
    from_file = calib.fit(robot, data, method="poe", effects=None).report.after
    from_arrays = calib.fit(robot, arrays, method="poe", effects=None).report.after
    # Positions went mm -> text -> m: equal to the last bit or two.
    assert from_arrays.mean_position_error_mm == pytest.approx(from_file.mean_position_error_mm, abs=1e-9)
    assert from_arrays.mean_rotation_error_mrad == pytest.approx(from_file.mean_rotation_error_mrad, abs=1e-9)


def test_a_dataframe_reads_as_its_columns(robot, campaign):
    # CI installs pandas (.ci/run), and there a missing pandas fails instead of skipping.
    pd = importlib.import_module("pandas") if os.environ.get("CI") else pytest.importorskip("pandas")
    frame = pd.read_csv(campaign["train"])
    data = calib.Measurements(frame)
    np.testing.assert_array_equal(data.q, calib.Measurements.read(campaign["train"]).q)


def test_refusals_keep_file_line_and_column(cli, robot, campaign, tmp_path):
    lines = campaign["train"].read_text().splitlines()
    header = lines[0].split(",")
    row = lines[3].split(",")
    row[header.index("y_mm")] = "abc"
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join([lines[0], lines[1], lines[2], ",".join(row)]) + "\n")
    column = header.index("y_mm") + 1
    with pytest.raises(calib.CalibError) as caught:
        calib.Measurements.read(bad)
    message = str(caught.value)
    assert f"{bad}:4:{column}:" in message
    assert message in cli.run("fit", "--robot", ROBOT, "--data", bad, "--method", "poe",
                              "--out", tmp_path / "m.ron", check=False).stderr


def test_arrays_name_the_line_of_a_bad_value(robot):
    q = np.zeros((5, 6))
    positions = np.ones((5, 3))
    positions[2, 1] = np.nan
    with pytest.raises(calib.CalibError, match=r"^arrays:4:\d+:"):
        calib.Measurements.from_arrays(q, positions)
    with pytest.raises(calib.CalibError, match="joint"):
        calib.Measurements.from_arrays(np.zeros((5, 5)), np.ones((5, 3)), robot=robot)


def test_a_missing_file_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere.csv"):
        calib.Measurements.read(tmp_path / "nowhere.csv")
    with pytest.raises(FileNotFoundError):
        calib.Robot.load(tmp_path / "nowhere.ron")


def test_bad_arguments_are_refused_by_name(robot, campaign):
    data = calib.Measurements.read(campaign["train"])
    with pytest.raises(ValueError, match="method"):
        calib.fit(robot, data, method="poe+gp")
    with pytest.raises(calib.CalibError, match="joint 9"):
        calib.fit(robot, data, method="poe", effects="gear_periodic:9:2")
    with pytest.raises(ValueError, match="max_iterations"):
        calib.fit(robot, data, method="poe", effects=None, options={"identification": {"max_iterations": 0}})


def test_options_mapping_goes_where_the_ron_file_goes(cli, robot, campaign, tmp_path):
    ron = tmp_path / "fit.ron"
    ron.write_text("(identification: (max_iterations: 3))")
    theirs = cli.json("fit", "--robot", ROBOT, "--data", campaign["train"], "--method", "poe",
                      "--options", ron, "--out", tmp_path / "m.ron", "--json")
    train = calib.Measurements.read(campaign["train"])
    from_dict = calib.fit(robot, train, method="poe", effects=None,
                          options={"identification": {"max_iterations": 3}})
    from_file = calib.fit(robot, train, method="poe", effects=None, options=ron)
    assert untimed(from_dict.report.as_dict()) == untimed(theirs) == untimed(from_file.report.as_dict())


def test_diagnose_equals_cli_diagnose_json(cli, robot, campaign):
    theirs = cli.json("diagnose", "--robot", ROBOT, "--data", campaign["whole"], "--json")
    diagnosis = calib.diagnose(robot, campaign["whole"])
    assert diagnosis.as_dict() == theirs
    assert diagnosis.effect == theirs["verdict"]["effect"]
    assert diagnosis.predicted_shrink == pytest.approx(
        1 - theirs["heldout_after_selected_mm"] / theirs["heldout_before_mm"])
    assert "verdict:" in diagnosis.summary


def test_compensate_prints_what_the_cli_prints(cli, robot, campaign, tmp_path):
    path = tmp_path / "m.ron"
    cli.run("fit", "--robot", ROBOT, "--data", campaign["train"], "--method", "poe", "--out", path)
    data = calib.Measurements.read(campaign["test"])
    targets = tmp_path / "targets.csv"
    with open(targets, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow([f"q{k}_rad" for k in range(1, 7)])
        for row in data.q[:20]:
            w.writerow([repr(float(v)) for v in row])
    theirs = cli.run("compensate", "--model", path, "--targets", targets, "--robot", ROBOT).stdout
    with pytest.warns(calib.CalibWarning, match=OUTSIDE):
        result = calib.Model.load(path).compensate(targets, robot=robot)
    assert result.csv == theirs
    assert result.q.shape == (20, 6) and result.ok.all()
    with pytest.warns(calib.CalibWarning, match=OUTSIDE):
        from_columns = calib.Model.load(path).compensate(
            {f"q{k + 1}_rad": data.q[:20, k] for k in range(6)}, robot=robot)
    np.testing.assert_array_equal(from_columns.q, result.q)


def test_the_gil_is_released_during_a_fit(robot, campaign):
    data = calib.Measurements.read(campaign["whole"])
    done = {}
    worker = threading.Thread(target=lambda: done.setdefault("m", calib.fit(robot, data, method="poe-gp", effects=None)))
    ticks = 0
    worker.start()
    while worker.is_alive():
        ticks += 1
    worker.join()
    assert "m" in done
    # Held, the GIL would stop this thread for the whole fit (a few ticks at most).
    assert ticks > 1000, ticks


def test_a_saved_model_predicts_as_the_fitted_one(robot, campaign, tmp_path):
    model = calib.fit(robot, campaign["train"], method="poe", effects=None)
    model.save(tmp_path / "m.ron")
    q = calib.Measurements.read(campaign["test"]).q
    with pytest.warns(calib.CalibWarning, match=OUTSIDE):
        loaded = calib.Model.load(tmp_path / "m.ron").predict(q)[0]
    with pytest.warns(calib.CalibWarning, match=OUTSIDE):
        fitted = model.predict(q)[0]
    np.testing.assert_array_equal(loaded, fitted)
    # Joints alone: the payload taken as 0, below the campaign's payloads.
    with pytest.warns(calib.CalibWarning, match=f"payload_kg {OUTSIDE}"):
        assert model.predict(q[0])[0].shape == (1, 7)
    with pytest.raises(ValueError, match="joints"):
        model.predict(q[:, :5])


def test_angles_a_turn_away_are_wrapped_as_the_cli_wraps_them(cli, tmp_path):
    """A UR10's joints turn ±360°: rows one turn beyond the fitted range are the same link
    positions, and `calib predict` and `eval` apply the model at the wrapped angles. The package
    must give the same numbers, not the GP's (or the effects') answer at angles never fitted."""
    from conftest import ROOT

    ur10 = ROOT / "fixtures" / "robots" / "ur10.ron"
    effects = tmp_path / "effects.ron"
    effects.write_text("(tracker_noise: Some(()))")
    whole = tmp_path / "whole.csv"
    cli.run("simulate", "--robot", ur10, "--rows", "300", "--seed", "3", "--full-pose", "--effects", effects,
            "--out", whole)
    header, *rows = whole.read_text().splitlines(keepends=True)
    q1 = [float(r.split(",")[0]) for r in rows]
    # Trained on joint 1 within ±180°; tested on the rest of those rows' kind, a turn away.
    inside = [r for r, q in zip(rows, q1) if abs(q) <= np.pi]
    train, test = tmp_path / "train.csv", tmp_path / "test.csv"
    assert len(inside) > 130, len(inside)
    train.write_text(header + "".join(inside[:100]))
    fitted = [float(r.split(",")[0]) for r in inside[:100]]
    shifted = []
    for r in inside[100:]:
        first, rest = r.split(",", 1)
        q = float(first)
        if not min(fitted) <= q <= max(fitted):
            continue  # a turn away and outside the fitted range either way: not wrapped
        shifted.append(f"{q + 2 * np.pi if q < 0 else q - 2 * np.pi!r},{rest}")
    assert len(shifted) > 20, len(shifted)
    test.write_text(header + "".join(shifted))
    path = tmp_path / "m.ron"
    cli.run("fit", "--robot", ur10, "--data", train, "--method", "poe-gp", "--out", path)
    printed = list(csv.DictReader(io.StringIO(cli.run("predict", "--model", path, "--data", test).stdout)))
    model = calib.Model.load(path)
    data = calib.Measurements.read(test)
    with warns_exactly("modulo 2π", PAYLOAD, FADE):
        poses, _ = model.predict(data.q)
    keys = ["x_mm", "y_mm", "z_mm"]
    np.testing.assert_allclose(poses[:, :3], [[float(r[k]) for k in keys] for r in printed], rtol=0, atol=5.1e-7)
    with warns_exactly("modulo 2π", f"temp_c {OUTSIDE}", f"t_s {OUTSIDE}", FADE):
        from_set, _ = model.predict(data)
    np.testing.assert_array_equal(from_set, poses)
    # The same link positions: the prediction at the angles a turn back.
    back = data.q.copy()
    back[:, 0] = np.where(back[:, 0] > 0, back[:, 0] - 2 * np.pi, back[:, 0] + 2 * np.pi)
    with warns_exactly("modulo 2π", PAYLOAD, FADE):
        unwrapped, _ = model.predict(back)
    np.testing.assert_allclose(poses[:, :3], unwrapped[:, :3], rtol=0, atol=1e-6)
    theirs = cli.json("eval", "--model", path, "--data", test, "--json")
    with warns_exactly("modulo 2π", f"temp_c {OUTSIDE}", f"t_s {OUTSIDE}", FADE):
        report = model.eval(test)
    assert report.as_dict() == theirs and theirs["wrapped"][0]["joint"] == 1


def _cli_eval_notices(cli, model, data):
    """What `calib eval` says beside its numbers, without `note: ` / `warning: `: as `--json` prints
    it on stderr, held equal to what the text prints on stdout."""
    kinds = ("note: ", "warning: ")
    printed = cli.run("eval", "--model", model, "--data", data, "--json").stderr.splitlines()
    from_json = [line for line in printed if line.startswith(kinds)]
    text = cli.run("eval", "--model", model, "--data", data).stdout.splitlines()
    from_text = [line[2:] for line in text if line[2:].startswith(kinds) and line.startswith("  ")]
    assert from_json == from_text
    return [line.split(": ", 1)[1] for line in from_json]


def _eval_cases(cli, campaign, tmp_path):
    """Four evaluations that each make `eval` speak, as (model file, data file, what it must say)."""
    header, *rows = campaign["whole"].read_text().splitlines(keepends=True)
    names = header.strip().split(",")

    def planted(row, name, delta):
        cells = row.rstrip("\n").split(",")
        cells[names.index(name)] = repr(float(cells[names.index(name)]) + delta)
        return ",".join(cells) + "\n"

    # Trained on the even rows, tested on the odd ones (within the fitted time and temperature,
    # where eval judges rows), with a row 40 mm off (a suspect row) and a payload never trained.
    even, odd = tmp_path / "even.csv", tmp_path / "odd.csv"
    even.write_text(header + "".join(rows[0::2]))
    tested = rows[1::2]
    tested[9] = planted(tested[9], "y_mm", 40.0)
    tested[8] = planted(tested[8], "payload_kg", 50.0)
    odd.write_text(header + "".join(tested))
    planted_gp = tmp_path / "even.ron"
    cli.run("fit", "--robot", ROBOT, "--data", even, "--method", "poe-gp", "--out", planted_gp)
    # The campaign's test rows put joint 2 outside the fitted range: the geometry's own σ there.
    gp = tmp_path / "gp.ron"
    cli.run("fit", "--robot", ROBOT, "--data", campaign["train"], "--method", "poe-gp", "--out", gp)
    # Another seed places the tracker elsewhere.
    elsewhere = tmp_path / "elsewhere.csv"
    cli.run("simulate", "--robot", ROBOT, "--rows", "40", "--seed", "8", "--full-pose", "--out", elsewhere)
    poe = tmp_path / "poe.ron"
    cli.run("fit", "--robot", ROBOT, "--data", campaign["train"], "--method", "poe", "--out", poe)
    # Positions only: a model that cannot judge the test rows' orientations.
    keep = [i for i, name in enumerate(names) if name not in ("qw", "qx", "qy", "qz")]
    lines = campaign["train"].read_text().splitlines()
    positions = tmp_path / "positions.csv"
    positions.write_text("".join(",".join(line.split(",")[i] for i in keep) + "\n" for line in lines))
    pos = tmp_path / "pos.ron"
    cli.run("fit", "--robot", ROBOT, "--data", positions, "--method", "poe", "--out", pos)
    return [
        (planted_gp, odd, ["robust sigmas of the other rows", PAYLOAD]),
        (gp, campaign["test"], [f"joint 2 {OUTSIDE}", "geometry's own uncertainty"]),
        (poe, elsewhere, ["another tracker placement", f"calib register --model {poe} "]),
        (pos, campaign["test"], ["orientations in the data are not evaluated", OUTSIDE]),
    ]


def test_eval_warns_what_the_cli_prints_in_its_order(cli, campaign, tmp_path):
    for model, data, expected in _eval_cases(cli, campaign, tmp_path):
        theirs = _cli_eval_notices(cli, model, data)
        for words in expected:
            assert any(words in line for line in theirs), (words, theirs)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            report = calib.Model.load(model).eval(data)
        ours = [str(w.message) for w in caught if issubclass(w.category, calib.CalibWarning)]
        assert ours == theirs
        assert report.warnings == theirs
