#!/usr/bin/python3
"""A MATLAB level-5 .mat file of column vectors as text, for the C++ tests (scipy.io reads it; the
product has no .mat reader): one line per variable, "<name> <int|float> <count> <values...>",
floats with 17 significant digits (they read back to the same double).

usage: mat_dump.py FILE.mat
"""
import sys

import numpy as np
import scipy.io

for name, value in sorted(scipy.io.loadmat(sys.argv[1]).items()):
    if name.startswith("__"):
        continue
    column = np.asarray(value).reshape(-1)
    kind = "int" if np.issubdtype(column.dtype, np.integer) else "float"
    text = " ".join(repr(int(v)) if kind == "int" else "%.17g" % v for v in column)
    print(f"{name} {kind} {column.size} {text}")
