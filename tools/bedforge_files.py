"""Where the tools find bedforge, and readers for the files it writes, shared by the tools."""
import os

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BEDFORGE = os.environ.get("BEDFORGE", os.path.join(ROOT, "build", "bedforge"))  # the program the tools run
DOCS = os.path.join(ROOT, "docs")  # where results, tables and figures go


def read_csv(path):
    """A bedforge CSV ('#' comment lines, one line of column names, numbers) as {name: array}."""
    rows = [line for line in open(path) if not line.startswith("#")]
    names = rows[0].strip().split(",")
    data = np.array([[float(v) for v in line.split(",")] for line in rows[1:] if line.strip()])
    return {n: data[:, i] for i, n in enumerate(names)}
