#!/usr/bin/env python3
"""Two models on the same rows, row by row (docs/results/days.md).

    python3 xtask/scripts/paired_errors.py CALIB TEST.csv PLAIN.ron OTHER.ron

Prints both mean position errors (`calib predict`'s error_mm), their ratio, and the mean paired
difference (other - plain) with its standard error. Standard library only.
"""
import csv
import io
import math
import subprocess
import sys


def errors(calib, model, test):
    out = subprocess.run([calib, "predict", "--model", model, "--data", test],
                         capture_output=True, text=True, check=True).stdout
    return [float(row["error_mm"]) for row in csv.DictReader(io.StringIO(out))]


def main():
    calib, test, plain, other = sys.argv[1:5]
    a, b = errors(calib, plain, test), errors(calib, other, test)
    n = len(a)
    d = [y - x for x, y in zip(a, b)]
    mean = sum(d) / n
    se = math.sqrt(sum((x - mean) ** 2 for x in d) / (n - 1) / n)
    z = f"{mean / se:+.1f} se" if se > 0 else "identical rows"
    print(f"plain {sum(a) / n:.4f} other {sum(b) / n:.4f} ratio {sum(b) / sum(a):.3f} "
          f"diff {mean:+.4f} se {se:.4f} ({z})")


if __name__ == "__main__":
    main()
