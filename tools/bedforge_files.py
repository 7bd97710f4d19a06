"""Where the tools find bedforge, and readers for the files it writes, shared by the tools."""
import json
import os
import re
import subprocess
import time

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
    """Which code made a result: the commit the program was built from (`bedforge --version`, not
    the checkout, which may be newer than the build), marked "-dirty" if built with uncommitted
    changes, and today's date."""
    version = subprocess.run([BEDFORGE, "--version"], capture_output=True, text=True, check=True).stdout.strip()
    built = version.split("+", 1)[1] if "+" in version else version
    commit = built[:7] + ("-dirty" if built.endswith("-dirty") else "")
    return {"commit": commit, "date": time.strftime("%Y-%m-%d")}


UNSTAMPED = "Made before the generators recorded commits and dates: not regenerated since."


def made_line(result, unstamped=UNSTAMPED):
    """The sentence a generated section opens with: the commit and date in `result` (a dict, or a
    list of them whose first holds the stamp), or `unstamped` for results older than the stamps."""
    r = result[0] if isinstance(result, list) and result else result
    if isinstance(r, dict) and "commit" in r:
        return f"Made at commit {r['commit']} on {r['date']}."
    return unstamped


# From this commit on, a convergence study's coarser levels divide surface.cells_per_gap by their
# scale; before it the gaps' cells were the same on every level.
GAPS_COARSENED_FROM = "ac6e6bc"


# From this commit on, a periodic section's solve stops at residuals of 1e-6 (cases/case_params.hpp);
# before it at 1e-4, where its dp/L read high by 0.3-0.8 % on Stokes arrays (docs/defaults.md).
PERIODIC_RESIDUALS_FROM = "f58b447"


def made_before(result, change, what):
    """Whether `result` (a dict stamped with its commit) was made by code older than commit `change`;
    `what` names the change for the error when git cannot tell."""
    known = subprocess.run(["git", "merge-base", "--is-ancestor", change, result["commit"].removesuffix("-dirty")],
                           cwd=ROOT, capture_output=True, text=True)
    if known.returncode not in (0, 1):  # 1: not an ancestor; anything else: git could not tell
        raise SystemExit(f"cannot tell whether the result made at {result['commit']} {what} (from {change}): "
                         f"{known.stderr.strip()}; a shallow clone lacks the commits: git fetch --unshallow")
    return known.returncode == 1


def gaps_not_coarsened(study):
    """Whether a gap-refined study's result was made before its coarser levels coarsened the gaps."""
    return bool(study.get("cells_per_gap")) and made_before(study, GAPS_COARSENED_FROM, "coarsened its gaps")


def periodic_residuals_note(result):
    """A sentence (with its leading space) for a result whose periodic sections were solved at the old
    residual targets, else ""."""
    if not made_before(result, PERIODIC_RESIDUALS_FROM, "solved to the periodic residual targets"):
        return ""
    return (f" Its periodic sections were solved before {PERIODIC_RESIDUALS_FROM}, at residual targets of 1e-4, where "
            "their dp/L reads high by the iterative error: 0.3-0.8 % on Stokes arrays, growing with the cells "
            "(docs/defaults.md); not regenerated since.")


def level_iteration_error(level):
    """One study level's iteration error (analysis/iteration_error.hpp) in per cent, "-0.25"; a level
    whose changes did not shrink as "(moved x)", its change over its last block of iterations;
    "not recorded" for a level solved before they were."""
    e = level.get("iteration_error")
    return ("not recorded" if not e else f"{100 * e['remaining']:+.2g}" if e["geometric"]
            else f"(moved {100 * e['last_change']:+.2g})")


def iteration_errors(study):
    """A study's levels' iteration errors, finest first, as "-0.25/-0.13/-0.065 %"; "not recorded"
    for a study made before they were."""
    levels = [level for level in study["levels"] if "failure" not in level]
    if not any(level.get("iteration_error") for level in levels):
        return "not recorded"
    return "/".join(level_iteration_error(level) for level in levels) + " %"


def read_bed(path):
    """bed.csv: (centres (n, 3) m, diameters (n,) m, container dict in metres from its header)."""
    container = {}
    for line in open(path):
        if not line.startswith("#"):
            break
        if line.startswith("# container_m:"):
            container = json.loads(line.split(":", 1)[1])
    bed = read_csv(path)
    if "x_m" not in bed:  # an empty container
        return np.zeros((0, 3)), np.zeros(0), container
    return np.column_stack([bed["x_m"], bed["y_m"], bed["z_m"]]), bed["d_m"], container


def foam_file(path):
    """An OpenFOAM file's bytes, where its FoamFile header ends, and whether it is binary."""
    data = open(path, "rb").read()
    header_end = data.index(b"}", data.index(b"FoamFile")) + 1
    return data, header_end, re.search(rb"format\s+binary", data[:header_end]) is not None


def foam_list(data, start, dtype, width, binary):
    """The OpenFOAM list at data[start:], `N (items)` raw or as text: (array (N, width), its end)."""
    m = re.compile(rb"(\d+)\s*\(").search(data, start)
    n, body = int(m.group(1)), m.end()
    if binary:
        end = body + n * width * np.dtype(dtype).itemsize
        return np.frombuffer(data, dtype, n * width, body).reshape(n, width), end + 1
    end = data.index(b"\n)" if width > 1 else b")", body)  # the closing parenthesis
    numbers = re.findall(rb"[-+0-9.eE]+", data[body:end])
    return np.array(numbers, dtype=np.float64).astype(dtype).reshape(n, width), end + 1


def read_poly_mesh(directory):
    """An OpenFOAM polyMesh directory (ASCII or binary, uncompressed): points (n, 3), the faces as
    offsets (faces + 1) into labels (their vertices in order), owner (cell per face) and
    neighbour (cell per internal face)."""
    def load(name):
        return foam_file(os.path.join(directory, name))
    data, h, binary = load("points")
    points, _ = foam_list(data, h, "<f8", 3, binary)
    data, h, binary = load("faces")
    if b"faceCompactList" in data[:h]:
        offsets, end = foam_list(data, h, "<i4", 1, binary)
        labels, _ = foam_list(data, end, "<i4", 1, binary)
        offsets, labels = offsets.ravel().astype(np.int64), labels.ravel().astype(np.int64)
    else:
        body = data[re.compile(rb"(\d+)\s*\(").search(data, h).end():]
        faces = [np.array(f.split(), dtype=np.int64) for f in re.findall(rb"\d+\(([^)]*)\)", body)]
        offsets = np.concatenate([[0], np.cumsum([len(f) for f in faces])])
        labels = np.concatenate(faces)
    cells = []
    for name in ("owner", "neighbour"):
        data, h, binary = load(name)
        cells.append(foam_list(data, h, "<i4", 1, binary)[0].ravel())
    owner, neighbour = cells
    return points, offsets, labels, owner, neighbour
