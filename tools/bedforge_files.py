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


def commit_and_date():
    """Which code made a result: the short commit checked out here and today's date."""
    import subprocess
    import time
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    return {"commit": commit, "date": time.strftime("%Y-%m-%d")}


UNSTAMPED = "Made before the generators recorded commits and dates: not regenerated since."


def made_line(result, unstamped=UNSTAMPED):
    """The sentence a generated section opens with: the commit and date in `result` (a dict, or a
    list of them whose first holds the stamp), or `unstamped` for results older than the stamps."""
    r = result[0] if isinstance(result, list) and result else result
    if isinstance(r, dict) and "commit" in r:
        return f"Made at commit {r['commit']} on {r['date']}."
    return unstamped
