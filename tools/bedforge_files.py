"""Readers for the files bedforge writes, shared by the tools."""
import numpy as np


def read_csv(path):
    """A bedforge CSV ('#' comment lines, one line of column names, numbers) as {name: array}."""
    rows = [line for line in open(path) if not line.startswith("#")]
    names = rows[0].strip().split(",")
    data = np.array([[float(v) for v in line.split(",")] for line in rows[1:] if line.strip()])
    return {n: data[:, i] for i, n in enumerate(names)}
