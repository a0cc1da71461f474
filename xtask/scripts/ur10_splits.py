#!/usr/bin/env python3
"""Every split of the real UR10 data the house rules name, against the geometry alone.

Usage: ur10_splits.py CALIB DATA_DIR [--series C,B,D] [--methods poe,poe+auto,poe-gp,poe-gp+auto]
                      [--only SPLIT,...] [--out TABLE.md]

DATA_DIR holds `ur10_S_full.csv` (`cargo xtask convert-ur10 --series S --full-pose --out ...`;
the IPA UR10 data set, Landgraf et al., CASE 2021, MIT licence, not part of this repository).
Standard library only. For each series and split it writes the training and test rows to a
temporary folder, runs `calib fit` for every method (`+auto` = `--effects auto`) and `calib eval
--json` on the test rows, and prints one markdown row per split: each method's mean (max)
position error in mm, its ratio to `poe`'s mean, the rows off the model's firm ground, and for the
`auto` fits the diagnosis's predictions (`auto.predicted_*` of `fit --json`: on poses like the
training ones, and off them).

The splits are fixed by rule, not tuned to a series:
- even-odd: even data rows train, odd test (flattering: repeated poses and +20 mm twins).
- halves: the first half in measurement order trains, the second tests (the day's drift).
- jJ-end: joint J's top quarter of angles (by count) held out (past the end of the fitted range).
- jJ-gap: joint J's middle fifth of angles held out (a gap in it).
- elbow / wrist: rows with q3 (elbow) or q5 (wrist 2) of one sign train, the other sign tests,
  when each side has at least 60 rows (arm configurations).
- goals: the tool positions are grouped (every row within 30 mm of a group's first row joins it);
  a random half of the groups (seed 1) trains, the rest tests.
- series: all of one series trains, all of another tests (same tracker set-up for B and C).
"""

import csv
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import time

ROBOT = "fixtures/robots/ur10.ron"


def read(path):
    with open(path, newline="") as f:
        lines = f.read().splitlines()
    header = [i for i, l in enumerate(lines) if l and not l.startswith("#")][0]
    comments = lines[:header]
    rows = list(csv.reader(lines[header:]))
    return comments, rows[0], rows[1:]


def write(path, comments, head, rows):
    with open(path, "w", newline="") as f:
        for c in comments:
            f.write(c + "\n")
        w = csv.writer(f, lineterminator="\n")
        w.writerow(head)
        w.writerows(rows)


def col(head, rows, name):
    i = head.index(name)
    return [float(r[i]) for r in rows]


def quantile_cut(values, lo, hi):
    """Indices whose value's rank lies in [lo, hi) of the sorted order (fractions)."""
    order = sorted(range(len(values)), key=lambda i: values[i])
    n = len(order)
    return set(order[int(lo * n):int(hi * n)])


def goal_groups(head, rows, radius_mm=30.0):
    xs, ys, zs = (col(head, rows, c) for c in ("x_mm", "y_mm", "z_mm"))
    group, seeds = [], []
    for x, y, z in zip(xs, ys, zs):
        for g, (sx, sy, sz) in enumerate(seeds):
            if math.dist((x, y, z), (sx, sy, sz)) <= radius_mm:
                group.append(g)
                break
        else:
            group.append(len(seeds))
            seeds.append((x, y, z))
    return group, len(seeds)


def splits(head, rows, only):
    n = len(rows)
    out = []
    out.append(("even-odd", list(range(0, n, 2)), list(range(1, n, 2))))
    out.append(("halves", list(range(n // 2)), list(range(n // 2, n))))
    for j in (1, 2, 3):
        q = col(head, rows, f"q{j}_rad")
        if max(q) - min(q) < math.radians(30):
            continue
        test = quantile_cut(q, 0.75, 1.0)
        out.append((f"j{j}-end", [i for i in range(n) if i not in test], sorted(test)))
        test = quantile_cut(q, 0.4, 0.6)
        out.append((f"j{j}-gap", [i for i in range(n) if i not in test], sorted(test)))
    for name, j in (("elbow", 3), ("wrist", 5)):
        q = col(head, rows, f"q{j}_rad")
        pos = [i for i in range(n) if q[i] > 0]
        neg = [i for i in range(n) if q[i] <= 0]
        if min(len(pos), len(neg)) >= 60:
            out.append((f"{name}+to-", pos, neg))
            out.append((f"{name}-to+", neg, pos))
    group, count = goal_groups(head, rows)
    rng = random.Random(1)
    chosen = set(rng.sample(range(count), count // 2))
    out.append((f"goals ({count})", [i for i in range(n) if group[i] in chosen],
                [i for i in range(n) if group[i] not in chosen]))
    if only:
        out = [s for s in out if s[0].split(" ")[0] in only]
    return out


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return None, p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "failed"
    return p.stdout, None


def fit_eval(calib, method, train, test, tmp):
    base, auto = (method[:-5], True) if method.endswith("+auto") else (method, False)
    model = os.path.join(tmp, f"{method}.ron")
    cmd = [calib, "fit", "--robot", ROBOT, "--data", train, "--method", base, "--out", model,
           "--json"]
    if auto:
        cmd += ["--effects", "auto"]
    start = time.time()
    out, err = run(cmd)
    if err:
        return {"error": err}
    report = json.loads(out)
    out, err = run([calib, "eval", "--model", model, "--data", test, "--json"])
    if err:
        return {"error": err}
    ev = json.loads(out)
    res = {"mean": ev["mean_position_error_mm"], "max": ev["max_position_error_mm"],
           "s": time.time() - start}
    cov = ev.get("coverage") or ev.get("range_split") or {}
    res["outside"] = (cov.get("outside") or {}).get("n", 0)
    a = report.get("auto") or {}
    pred = a.get("predicted_with_gp") or {}
    if pred:
        res["pred"] = (pred.get("on_poses_mm"), pred.get("off_poses_mm"))
    elif a:
        off = a.get("off_poses_mm")
        res["pred"] = (a.get("heldout_after_mm"), off[1] if off else None)
    return res


def cell(r, ref):
    if "error" in r:
        return "refused: " + r["error"][:60]
    s = f"{r['mean']:.3f} ({r['max']:.2f})"
    if ref:
        s += f" {r['mean'] / ref:.2f}×"
    return s


def main():
    args = sys.argv[1:]
    if len(args) < 2:
        sys.exit(__doc__)
    calib, data = args[0], args[1]
    opts = dict(zip(args[2::2], args[3::2]))
    series = opts.get("--series", "C,B,D").split(",")
    methods = opts.get("--methods", "poe,poe+auto,poe-gp,poe-gp+auto").split(",")
    only = set(opts["--only"].split(",")) if "--only" in opts else None
    lines = ["| series | split | train / test | " + " | ".join(
        f"`{m.replace('+auto', ' --effects auto')}`" for m in methods)
        + " | off firm ground (auto) | predicted on / off the poses (auto) |",
        "| --- | --- | ---: | " + " | ".join("---" for _ in methods) + " | ---: | --- |"]
    print("\n".join(lines), flush=True)
    jobs = []
    sets = {}
    for s in series:
        comments, head, rows = read(os.path.join(data, f"ur10_{s}_full.csv"))
        sets[s] = (comments, head, rows)
        for name, train, test in splits(head, rows, only):
            jobs.append((s, name, comments, head, [rows[i] for i in train], [rows[i] for i in test]))
    if only is None or "series" in only:
        for a, b in (("C", "B"), ("B", "C")):
            if a in sets and b in sets:
                ca, ha, ra = sets[a]
                _, hb, rb = sets[b]
                if ha == hb:
                    jobs.append((f"{a}→{b}", "series", ca, ha, ra, rb))
    for s, name, comments, head, train, test in jobs:
        with tempfile.TemporaryDirectory() as tmp:
            tr, te = os.path.join(tmp, "train.csv"), os.path.join(tmp, "test.csv")
            write(tr, comments, head, train)
            write(te, comments, head, test)
            res = {m: fit_eval(calib, m, tr, te, tmp) for m in methods}
        ref = res.get("poe", {}).get("mean")
        autos = [m for m in methods if m.endswith("+auto") and "error" not in res[m]]
        outside = ", ".join(f"{res[m]['outside']}" for m in autos)
        preds = ", ".join(
            "/".join("–" if v is None else f"{v:.3f}" for v in res[m].get("pred", (None, None)))
            for m in autos)
        line = (f"| {s} | {name} | {len(train)} / {len(test)} | "
                + " | ".join(cell(res[m], ref if m != "poe" else None) for m in methods)
                + f" | {outside} | {preds} |")
        lines.append(line)
        print(line, flush=True)
    if "--out" in opts:
        with open(opts["--out"], "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
