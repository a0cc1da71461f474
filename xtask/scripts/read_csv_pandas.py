"""Reads a measurement CSV with pandas as a user would, then prints the peak resident memory, MB.

Used by `cargo xtask bench-memory` as the column beside `calib fit`.
"""
import resource
import sys

import pandas

frame = pandas.read_csv(sys.argv[1])
values = frame.select_dtypes("number").to_numpy()
assert values.shape[0] > 0
# ru_maxrss is in kB on Linux.
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
