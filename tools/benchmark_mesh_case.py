#!/usr/bin/python3
"""Volume mesh and OpenFOAM case: pressure drop against run time, the snappyHexMesh route side by
side, and the whole pipeline at scale; writes docs/mesh_case_benchmark.md, .json and .png.

    /usr/bin/python3 tools/benchmark_mesh_case.py                    # every section (about an hour on 2 cores)
    /usr/bin/python3 tools/benchmark_mesh_case.py --only sizes       # some sections, keep the others' results
    /usr/bin/python3 tools/benchmark_mesh_case.py --edges 0.2 0.15   # other surface edge lengths (d)
    /usr/bin/python3 tools/benchmark_mesh_case.py --only gaps --gap-cells 2 3
    /usr/bin/python3 tools/benchmark_mesh_case.py --only layers --layer-thickness 0.02 0.05

sizes:  a = 5, N = 500 (seed 1), bridges, packed once; for each surface edge length (the mesh
        follows the surface, refined 3x where contacts meet) a real `bedforge run` to a case that
        simpleFoam solves on 2 processes (Re_p = 1, water). Per level: cells, time per stage,
        checkMesh, dp/L over the bed section against Eisfeld & Schnitzlein at the section's own
        meshed void fraction, and against the finest level.
gaps:   the same bed, surface edge 0.2 d, refined only where surfaces face each other across
        narrow gaps (surface.cells_per_gap = 2 and 3), solved the same way: the pressure drop
        against cells and time, next to the uniformly refined levels.
layers: a = 4, N = 40 (seed 1), shrink, surface edge 0.1 d without and with 3 prism layers on the
        particles ([mesh.layers] thickness_d as given), and 0.07 d without, solved the same way;
        then the studies' bridged a = 5, N = 500 bed at 0.15 d without and with 3 layers of 0.02 d.
snappy: the finest level's bed, meshed by snappyHexMesh (case.mesher = "snappy", 2 processes) and
        solved the same way: cells, time, checkMesh, dp/L.
scale:  a = 10, N = 4000, the default scene's settings (shrink, 0.1 d), scene to a checkMesh-clean
        case, with the time and peak memory of every stage, bytes per cell.
scale_1e4: the same at a = 14, N = 1e4 with bridges (0.1 d).
scale_out: the scale_1e4 scene by the snappyHexMesh route (case.mesher = "snappy": no gmsh mesh;
        --snappy-cell-d, --snappy-level), meshed and solved on 2 processes, then meshed on 1 (the
        solver cut to one iteration): each Allrun step's time and its largest process's peak
        memory, checkMesh, dp/L; beside it the gmsh route on the same bed at a surface edge of
        --scale-out-gmsh-edge d, solved the same way.
study:  a = 5, N = 500, bridges, the finest surface edge of --edges, one `bedforge run` with
        [case.convergence] (--levels meshes, --ratio between them): each level's cells, dp/L and
        time, the apparent order, the extrapolated dp/L and the GCI of the finest mesh, and the
        run's wall time from scene to that result. The section records the commit and date.
study_gaps: the same study with surface.cells_per_gap = --study-gap-cells from a finest edge of
        --study-gap-edge d (each coarser level divides cells_per_gap by its scale, so the gaps coarsen with the rest).
study_reynolds: the study_gaps run at each Re_p of --reynolds (laminar), with a table of the
        extrapolated dp/L against Eisfeld & Schnitzlein's across Re_p = 1 (study_gaps) and these.
study_treatments: the study_gaps run with each contact treatment of --treatments (bridge is study_gaps),
        the same bed: how much of the pressure drop, and of its difference from E&S, the treatment
        of the contacts carries.
default: the README's path, scenes/default.toml as shipped, one `bedforge run` timed from scene to printed
        answer (its best estimate, band and Eisfeld & Schnitzlein); then its reference: the same scene
        with every mesh length one study ratio finer and --default-reference-levels levels (so its
        coarser levels are the default's), whose finest three's extrapolation the answer is held against:
        the targets of issue 54 (at most 10 min; best estimate within 5 % of the reference; the band
        holding it; a GCI no wider than the study_gaps run's 32.7 % at that cost).
solver: the bed of the studies at a surface edge of 0.2 d, 3 cells across narrow gaps, its case written
        and solved once by `bedforge run`, then solved again from the same mesh with OpenFOAM's settings
        changed one at a time (non-orthogonal correction, gradient scheme, SIMPLE against SIMPLEC,
        gradients not kept for the iteration): iterations, simpleFoam time and dp/L against those of
        the case as written, and against the study_gaps extrapolation of the same bed.
solver_tetrahedra: the same on gmsh's tetrahedra (`case.cells = "tetrahedra"`, the default scene's
        cells) at a surface edge of 0.3 d, 2 cells across narrow gaps: as written, and with the
        gradients computed at each use.
verification: the empty tube of scenes/examples/empty_tube_verification.toml (D = 2 d, 12 d long,
        particles.count = 0), whose exact dp/L is Hagen-Poiseuille's, through the same route on
        tetrahedra and on their polyhedral dual (case.cells): one `bedforge run` each with
        [case.convergence] (--verify-levels meshes from a finest surface edge --verify-edge d,
        ratio --verify-ratio); each level's error against the exact value, the order of those
        errors, and the GCI the study would quote without the exact value.
cost: issue 57's cost curve on its bed (a = 4, N = 40, seed 1, bridges, Re_p = 1): one study each with
        case.cells = "polyhedra", "tetrahedra", and tetrahedra with surface.sphere_facets = "volume" (--cost-levels
        meshes from --cost-edge d, contact edge a third, --cost-gap-cells per gap): each level's cells and seconds
        per sphere, its error against the extrapolation with the narrowest band, and the issue's targets.
cost_20k: the same bed on tetrahedra, inscribed and "volume", from --target-edge d (contact edge half of it,
        some 20 k cells per sphere on the finest), and "volume" with 3 prism layers of 0.02 d from
        --layered-edge and --layered-contact-edge d, ratio --target-ratio: issue 57's target on this bed; the
        particles' drag in the bed section split by the gap at their faces (GAP_BANDS_D): each route's drag by
        kind (walls; the particles' form and viscous drag) and band, level by level: where the error sits
        (issue 57, item 1).
cost_500: the same routes as cost on the README's scene, scenes/default.toml as it is (a = 5, N = 500, its mesh
        and study), and the layered route (LAYERS prism layers of LAYER_THICKNESS_D on tetrahedra with volume
        facets) at the scene's own lengths.
cost_same_lengths: issue 57's bed (a = 4, N = 40) at each of --same-lengths-seeds, the layered route of
        cost_20k and the same without layers at the layered route's own lengths (--layered-edge,
        --layered-contact-edge, --cost-gap-cells, --cost-levels, --target-ratio): whether the layers or the
        lengths made cost_20k's winner, seed by seed.
cost_beds: the same four routes at scenes/default.toml's mesh and study on smaller beds (--cost-beds a:N,
        default a = 4, N = 40, issue 57's bed, and a = 5, N = 200), and with cost_500 a table of the routes
        bed by bed: issue 57's item 3 from the 40-sphere bed to the 500-sphere bed at one set of settings.
verification_spheres: on each of the cost sections' routes and the layered route, a column of a simple cubic array of spheres in
        Stokes flow (Re_p = 0.01) in a square box whose slip walls are the array's mirror planes, as
        scenes/examples/simple_cubic_verification.toml
        (solid fraction 0.216) and at 0.45 (gaps of 0.05 d between neighbours), whose exact drag Zick & Homsy
        (1982) tabulate: one `bedforge run` each with [case.convergence] (--sphere-levels meshes from
        --sphere-edge d, ratio 1.3); each level's error, the order of the errors, the study's own verdict.
verification_touching: the same column with touching spheres (solid fraction pi / 6), its contacts bridged, on
        each of the cost sections' routes and the layered route, against Zick & Homsy's untreated touching array as
        a bound from below (issue 57, item 4: the bridged touching column keeps its order through the new meshes).
verification_periodic: periodic sections, cyclic cases driven by meanVelocityForce: the empty tube of the
        verification (D = 2 d) one period of 3 d long, whose fully developed flow is Hagen-Poiseuille's in every
        cell; and three cells of a simple cubic array as scenes/examples/periodic_cubic_verification.toml at each
        solid fraction (Zick & Homsy's, none of their spheres cut by the periodic planes); one `bedforge run` each
        with [case.convergence] (--periodic-levels meshes from PERIODIC_EDGES_D, or --periodic-edge d for every
        run, ratio 1.3): each level's error,
        the order of the errors, and issue 56's target (within 1 % of Zick & Homsy on the finest level, order at
        least 1.5). --periodic-runs redoes some runs (each keeps its own commit, date and edge), e.g.
        --periodic-runs 0.45 --periodic-edge 0.016.
periodic_slice: issue 56's z-periodic slice: scenes/default.toml's bed (a = 5, N = 500) and settings with shrunk
        contacts, at each seed of --slice-full-seeds, dp/L over the section --slice-full-exclude d clear of floor and
        top (default 2, the central slab of the analysis); then slices of --slice-count spheres packed to the full beds'
        mean central void fraction (a period of about --slice-period d), seed after seed until --slices reach it;
        each bed's finest dp/L, extrapolation, GCI and cells; the slices' mean against the full beds' spread.
random_arrays: issue 56's random periodic arrays: scenes/examples/random_array_stokes.toml (a cube of 4 d periodic
        on every side, Monte Carlo packed, spheres shrunk by 0.99, Re_p = 0.01, three-level study on polyhedra)
        with the count giving each of --array-fractions as packed, at each of --array-seeds: each bed's finest dp/L,
        extrapolation, GCI and order against van der Hoef et al.'s Stokes drag at the solid fraction as solved.
pieces: issue 58's case in pieces: the default bed with shrink in one piece, then in P pieces on P ranks (each of
        --pieces-ranks): each rank's peak and time, checkMesh in parallel, dp/L on 2 ranks against one piece's.
pieces_bridge: the same with the default scene's bridges, cut through at each rank's planes (issue 58's "every
        contact treatment"), the same ranks.
pieces_large: the same bed 3 times longer (--pieces-large-spheres spheres), the case written, not solved, in P pieces
        for each of --pieces-large-ranks (from 2: one rank's whole piece of 1500 spheres fell back to gmsh's
        slow Delaunay): the per-rank peak against 2/P of 2 ranks' on a bed whose pieces hold more than the 62
        spheres per rank the default bed leaves at 8 ranks.
weak_scaling: --weak-spheres spheres per rank, the column P times longer on P ranks (each of --weak-ranks).
projection: the largest rank's peak and time, fitted on the pieces sections' ranks, projected to 1e5 and 1e6 spheres.
pieces_1e4: issue 58's own bed (a = 14, N = 1e4, bridges, 0.1 d, tetrahedra, not solved) in one piece, then in P
        pieces on P ranks (each of --pieces-1e4-ranks): each rank's peak and time, checkMesh in parallel, and at 4
        ranks the pieces joined by reconstructParMesh and checked whole; the issue's targets for it.
pieces_1e4_solved: the same bed at 0.15 d on polyhedra, solved: one piece (simpleFoam on 2 processes) against 2 and 4
        pieces on their ranks: dp/L, scene to dp/L, the largest processes, checkMesh (at 4 ranks reconstructed too).
pieces_1e4_tetrahedra: the same at 0.25 d, contact edge a third, on gmsh's tetrahedra (the cells of
        scenes/default.toml), solved likewise.
weak_scaling_1e4: --weak-1e4-spheres spheres per rank at a = 14 (bridges, 0.1 d, tetrahedra), on 1, 2 and 4 ranks.
projection_1e4: the projection from pieces_1e4's ranks.
Times and peak memory are the stages' own (report.json); a run's peak is the largest of its
stages' and of OpenFOAM's processes. (/usr/bin/time would see only the last stage's: bedforge
resets the kernel's high-water mark at each stage start, and the rusage peak with it.)
"""
import argparse
import functools
import glob
import json
import math
import os
import re
import shutil
import subprocess
import tempfile
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from bedforge_files import (BEDFORGE, DOCS, GAPS_COARSENED_FROM, commit_and_date, gaps_not_coarsened, made_line,  # noqa: E402
                            iteration_errors, level_iteration_error, periodic_residuals_note)

RESULTS = os.path.join(DOCS, "mesh_case_benchmark.json")
# cost_20k's particles split by the gap at their faces (case.drag_by_gap_d, d): the bridges' rims
# and narrowest gaps, gaps of one to a few contact edges, of a few surface edges, and open pores.
GAP_BANDS_D = [0.01, 0.03, 0.1, 0.3]
SECTIONS = ["sizes", "gaps", "layers", "snappy", "scale", "scale_1e4", "scale_out", "study", "study_gaps", "cost", "cost_20k", "cost_500", "cost_beds", "cost_same_lengths", "study_reynolds", "study_treatments",
            "default", "solver", "solver_tetrahedra", "verification", "verification_spheres", "verification_touching",
            "verification_periodic",
            "periodic_slice", "random_arrays", "pieces", "pieces_bridge", "pieces_large", "weak_scaling", "projection", "pieces_1e4",
            "pieces_1e4_solved", "pieces_1e4_tetrahedra", "weak_scaling_1e4",
            "projection_1e4"]
# The cost sections' routes: case.cells, surface.sphere_facets.
COST_ROUTES = [("polyhedra", "inscribed"), ("tetrahedra", "inscribed"), ("tetrahedra", "volume")]
# Issue 57's layered route: tetrahedra with volume facets and this many prism layers of this total thickness (d)
# on the particles, [mesh.layers]. It met issue 57's target on the 40-sphere bed at that issue's lengths
# (cost_20k), as the same lengths without layers did too (cost_same_lengths).
LAYERS, LAYER_THICKNESS_D = 3, 0.02
LAYERS_TOML = f"[mesh.layers]\ncount = {LAYERS}\nthickness_d = {LAYER_THICKNESS_D}\n"
# The routes verification_spheres, verification_touching and cost_500 run: the cost routes and the layered one
# (cells, facets, prism layers).
ROUTES = [(cells, facets, 0) for cells, facets in COST_ROUTES] + [("tetrahedra", "volume", LAYERS)]
# The README's route among them: scenes/default.toml's cells, bedforge's default sphere_facets, no layers
# (check_default_route holds it to the scene and the program before a run that relies on it).
DEFAULT_ROUTE = ("tetrahedra", "volume", 0)


def check_default_route():
    """SystemExit unless DEFAULT_ROUTE is what scenes/default.toml gives: its case.cells, its
    surface.sphere_facets or else the program's default for it (`bedforge scene-keys`), no layers."""
    text = open(DEFAULT_SCENE).read()
    m = re.search(r'^sphere_facets = "(\w+)"', text, re.M)
    if m:
        facets = m.group(1)
    else:
        keys = subprocess.run([BEDFORGE, "scene-keys"], check=True, capture_output=True, text=True).stdout
        surface = keys.split("## [surface]", 1)[-1].split("\n## ", 1)[0]
        row = re.search(r"^\| `sphere_facets` \|[^|]*\|[^|]*\| (\w+) \|", surface, re.M)
        if not row:
            raise SystemExit("bedforge scene-keys lists no default for surface.sphere_facets; update check_default_route")
        facets = row.group(1)
    layers = 1 if re.search(r"^\[mesh\.layers\]", text, re.M) else 0
    route = (scene_value(text, "cells"), facets, layers and LAYERS)
    if route != DEFAULT_ROUTE:
        raise SystemExit(f"scenes/default.toml runs on {route}, DEFAULT_ROUTE says {DEFAULT_ROUTE}; update DEFAULT_ROUTE")


def route_key(cells, facets, layers):
    """A verification run's route as its key names it: "cells, facets[, N layers of T d]"."""
    return f"{cells}, {facets}" + (f", {layers} layers of {LAYER_THICKNESS_D:g} d" if layers else "")
DEFAULT_SCENE = os.path.join(os.path.dirname(DOCS), "scenes", "default.toml")
# A study's order_from_exact is null when its errors lie on both sides of the exact value (no C h^p
# fits them) or fewer than two levels have one (analysis::observed_order).
NO_ORDER = "none (errors on both sides of the exact value, or fewer than two)"
ENV = dict(os.environ, WM_PROJECT_DIR=os.environ.get("WM_PROJECT_DIR", "/usr/share/openfoam"), OMP_NUM_THREADS="2")


def scene(a, n, treatment, edge, run, cells_per_gap=0, layers=0, layer_thickness=0.02, reynolds=1.0, iterations=3000,
          levels=0, ratio=1.3, cells="polyhedra", contact_edge=None, sphere_facets="inscribed", drag_by_gap=(), seed=1):
    return f"""[container]
type = "cylinder"
diameter_d = {a}
[particles]
count = {n}
diameter_m = 0.003
[packing]
seed = {seed}
[contacts]
treatment = "{treatment}"
[surface]
edge_length_d = {edge}
contact_edge_length_d = {edge / 3 if contact_edge is None else contact_edge:.4g}
cells_per_gap = {cells_per_gap}
sphere_facets = "{sphere_facets}"
[mesh]
algorithm = "hxt"
[mesh.layers]
count = {layers}
thickness_d = {layer_thickness}
[case]
cells = "{cells}"
reynolds = {reynolds}
iterations = {iterations}
processors = 2
run = {"true" if run else "false"}
{f"drag_by_gap_d = [{', '.join(f'{g:g}' for g in drag_by_gap)}]" + chr(10) if drag_by_gap else ""}[case.convergence]
levels = {levels}
ratio = {ratio}
[outputs]
files = ["positions", "stl", "mesh", "case"]
"""


def timed(cmd):
    """Runs cmd; returns (wall s, stdout)."""
    t0 = time.time()
    out = subprocess.run(cmd, capture_output=True, text=True, env=ENV)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{out.stdout}\n{out.stderr}")
    return time.time() - t0, out.stdout


def peak_mb(report):
    """A run's peak resident memory: the largest of its stages' and of OpenFOAM's (MB)."""
    stages = report["stages"].values()
    return max([s.get("peak_memory_mb", 0) for s in stages] +
               [s.get("flow", {}).get("solver_peak_memory_mb", 0) for s in stages])


# A number as OpenFOAM prints it; not a class of digits and dots, which takes the full stop of
# "Total volume = 8.1e-05." into the number.
NUMBER = r"([-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)"


def check_mesh_log(log):
    """A checkMesh log: (Mesh OK?, cells, max non-orthogonality, max skewness, total volume m^3)."""
    cells = int(re.search(r"^\s*cells:\s+(\d+)", log, re.M).group(1))
    non_ortho = float(re.search(r"Mesh non-orthogonality Max: " + NUMBER, log).group(1))
    skew = float(re.search(r"Max skewness = " + NUMBER, log).group(1))
    volume = float(re.search(r"Total volume = " + NUMBER, log).group(1))
    return "Mesh OK." in log, cells, non_ortho, skew, volume


def check_mesh(case):
    """checkMesh on a case: (Mesh OK?, cells, max non-orthogonality, max skewness, s)."""
    wall, log = timed(["checkMesh", "-case", case])
    return (*check_mesh_log(log)[:4], wall)


def stage_times(report):
    return {k: v["time_s"] for k, v in report["stages"].items() if "time_s" in v}


def sizes(tmp, levels, a=5, n=500, treatment="bridge", iterations=3000):
    """levels: (surface edge in d, cells per gap, prism layers, their thickness in d)."""
    rows = []
    for edge, gap_cells, layers, thickness in levels:
        path = os.path.join(tmp, f"{treatment}_{a}_{n}_{edge}_{gap_cells}_{layers}_{thickness}")
        open(path + ".toml", "w").write(scene(a, n, treatment, edge, True, gap_cells, layers, thickness,
                                              iterations=iterations))
        wall, _ = timed([BEDFORGE, "--quiet", "run", path + ".toml", "-o", path, "--overwrite"])
        rep = json.load(open(os.path.join(path, "report.json")))
        mb = peak_mb(rep)
        ok, cells, non_ortho, skew, _ = check_mesh(os.path.join(path, "case"))
        flow = rep["stages"]["case"]["flow"]
        mesh = rep["stages"]["mesh"]
        rows.append({"route": "gmsh", "a": a, "n": n, "treatment": treatment, "edge_d": edge, "cells_per_gap": gap_cells, "layers": layers,
                     "layer_thickness_d": thickness if layers else 0, "layer_cells": mesh.get("layers", {}).get("cells"),
                     "layer_mean_thickness_d": mesh.get("layers", {}).get("mean_thickness_d"), "cells": cells,
                     "wall_s": wall,
                     "peak_mb": mb,
                     "stages_s": stage_times(rep), "solve_s": flow["time_s"], "mesh_ok": ok,
                     "max_non_orthogonality": non_ortho, "max_skewness": skew,
                     "iterations": flow["iterations"], "converged": flow["converged"], "iteration_cap": iterations,
                     "dp_dz_pa_m": flow["pressure_gradient_bed_pa_m"], "es_pa_m": flow["eisfeld_schnitzlein_pa_m"],
                     "ratio_es": flow["ratio_to_eisfeld_schnitzlein"], "eps_section": flow["void_fraction_section"],
                     "flow_rate_error": flow["flow_rate_relative_error"],
                     "volume_error": rep["stages"]["mesh"]["fluid_volume_relative_error"]})
        print(rows[-1], flush=True)
    return rows


def snappy(tmp, edge):
    """The bed and surface of the finest gmsh level (made again when the sizes section did not
    run), meshed by snappyHexMesh and solved."""
    path = os.path.join(tmp, f"bridge_5_500_{edge}_0_0_0.02")
    if not os.path.exists(os.path.join(path, "fluid.msh")):
        open(path + ".toml", "w").write(scene(5, 500, "bridge", edge, False))
        timed([BEDFORGE, "--quiet", "run", path + ".toml", "-o", path, "--overwrite"])
    wall, _ = timed([BEDFORGE, "--quiet", "case", path, "--mesher", "snappy", "--run", "--processors", "2",
                     "--overwrite"])
    rep = json.load(open(os.path.join(path, "report.json")))
    mb = peak_mb(rep)
    flow = rep["stages"]["case"]["flow"]
    case = os.path.join(path, "case")
    ok, cells, non_ortho, skew, _ = check_mesh(case)
    snappy_log = open(os.path.join(case, "log.snappyHexMesh")).read()
    meshing = float(re.search(r"Finished meshing in = " + NUMBER + " s", snappy_log).group(1))
    row = {"route": "snappy", "cells": cells, "wall_s": wall, "peak_mb": mb, "snappy_s": meshing,
           "solve_s": flow["time_s"] - meshing, "mesh_ok": ok, "max_non_orthogonality": non_ortho,
           "max_skewness": skew, "iterations": flow["iterations"], "converged": flow["converged"],
           "dp_dz_pa_m": flow["pressure_gradient_bed_pa_m"], "es_pa_m": flow["eisfeld_schnitzlein_pa_m"],
           "ratio_es": flow["ratio_to_eisfeld_schnitzlein"], "flow_rate_error": flow["flow_rate_relative_error"]}
    print(row, flush=True)
    return row


def mesh_attempts(mesh):
    """The mesh stage's attempts, each slab's in turn when it meshed in slabs."""
    keys = ("algorithm", "optimiser", "cells", "time_generate_s", "optimiser_passes", "cells_failing_gate", "error")
    if "slabs" not in mesh:
        return [{k: attempt.get(k) for k in keys} for attempt in mesh.get("attempts", [])]
    return [{"slab": i, **{k: attempt.get(k) for k in keys}}
            for i, slab in enumerate(mesh["slabs"]) for attempt in slab.get("attempts", [])]


def scale(tmp, a, n, treatment):
    path = os.path.join(tmp, f"scale_{n}")
    open(path + ".toml", "w").write(scene(a, n, treatment, 0.1, False))
    wall, _ = timed([BEDFORGE, "--quiet", "run", path + ".toml", "-o", path, "--overwrite"])
    rep = json.load(open(os.path.join(path, "report.json")))
    mb = peak_mb(rep)
    ok, cells, non_ortho, skew, check_s = check_mesh(os.path.join(path, "case"))
    row = {"a": a, "n": n, "treatment": treatment, "wall_s": wall, "peak_mb": mb, "stages_s": stage_times(rep),
           "cells": cells, "mesh_ok": ok,
           "self_intersections": rep["stages"]["surface"]["check"]["self_intersections"],
           "check_mesh_s": check_s, "max_non_orthogonality": non_ortho, "max_skewness": skew,
           "stages_peak_mb": {k: v.get("peak_memory_mb", 0) for k, v in rep["stages"].items()},
           "mesh_attempts": mesh_attempts(rep["stages"]["mesh"]),
           "mesh_times_s": {k: v for k, v in rep["stages"]["mesh"].items() if k.startswith("time_")}}
    print(row, flush=True)
    return row


def scale_out_run(path, iterations):
    """One route of scale_out: `bedforge run` on path.toml, Allrun's own checkMesh, the flow; the
    fields both routes report."""
    wall, _ = timed([BEDFORGE, "--quiet", "run", path + ".toml", "-o", path])
    rep = json.load(open(os.path.join(path, "report.json")))
    flow = rep["stages"]["case"]["flow"]
    ok, cells, non_ortho, skew, volume = check_mesh_log(open(os.path.join(path, "case", "log.checkMesh")).read())
    row = {"wall_s": wall, "stages_s": stage_times(rep),
           "stages_peak_mb": {k: v.get("peak_memory_mb", 0) for k, v in rep["stages"].items()},
           "surface_triangles": rep["stages"]["surface"]["triangles"], "steps": flow["allrun_steps"],
           "cells": cells, "mesh_ok": ok, "max_non_orthogonality": non_ortho, "max_skewness": skew,
           "volume_error": volume / rep["stages"]["surface"]["fluid_volume_exact_m3"] - 1,
           "iterations": flow["iterations"], "iteration_cap": iterations, "converged": flow["converged"],
           "dp_dz_pa_m": flow["pressure_gradient_bed_pa_m"], "ratio_es_bed": flow["ratio_to_eisfeld_schnitzlein_bed"],
           "flow_rate_error": flow["flow_rate_relative_error"]}
    return rep, row


def scale_out(tmp, snappy_cell_d, snappy_level, gmsh_edge, iterations, a=14, n=10000, treatment="bridge", edge=0.1):
    """Yields each route's row as it is measured: a run of an hour or more keeps what it got."""
    for ranks, its in ((2, iterations), (1, 1)):
        path = os.path.join(tmp, f"scale_out_{ranks}")
        text = scene(a, n, treatment, edge, True, iterations=its).replace("processors = 2", f"processors = {ranks}")
        text = text.replace("[case]\n", f"[case]\nmesher = \"snappy\"\nsnappy_cell_d = {snappy_cell_d}\n"
                                        f"snappy_level = {snappy_level}\n")
        text = text.replace('files = ["positions", "stl", "mesh", "case"]', 'files = ["positions", "case"]')
        open(path + ".toml", "w").write(text)
        _, measured = scale_out_run(path, its)
        row = {"route": "snappy", "ranks": ranks, "a": a, "n": n, "treatment": treatment, "edge_d": edge,
               "snappy_cell_d": snappy_cell_d, "snappy_level": snappy_level, **measured}
        print(row, flush=True)
        shutil.rmtree(path)  # gigabytes of surface and cells
        yield row
    path = os.path.join(tmp, "scale_out_gmsh")
    open(path + ".toml", "w").write(scene(a, n, treatment, gmsh_edge, True, iterations=iterations))
    rep, measured = scale_out_run(path, iterations)
    row = {"route": "gmsh", "ranks": 2, "a": a, "n": n, "treatment": treatment, "edge_d": gmsh_edge,
           "tetrahedra": rep["stages"]["mesh"]["cells"], **measured}
    print(row, flush=True)
    shutil.rmtree(path)
    yield row


def study(tmp, edge, levels, ratio, cells_per_gap=0, a=5, n=500, treatment="bridge", reynolds=1.0, cells="polyhedra",
          contact_edge=None, sphere_facets="inscribed", drag_by_gap=(), layers=0, layer_thickness=0.02, seed=1):
    """One run of the scene with a mesh-convergence study; its levels and verdict. contact_edge:
    the contact edge (d), else a third of `edge`; drag_by_gap: case.drag_by_gap_d; layers prism
    layers of layer_thickness d in all."""
    path = os.path.join(tmp, f"study_{treatment}_{a}_{n}_{edge}_{contact_edge}_{cells_per_gap}_{reynolds}_{cells}_{ratio}_"
                             f"{sphere_facets}_{layers}_{seed}")
    text = scene(a, n, treatment, edge, True, cells_per_gap, layers=layers, layer_thickness=layer_thickness,
                 reynolds=reynolds, levels=levels, ratio=ratio, cells=cells, contact_edge=contact_edge,
                 sphere_facets=sphere_facets, drag_by_gap=drag_by_gap, seed=seed)
    open(path + ".toml", "w").write(text)
    return study_record(path, {"a": a, "n": n, "treatment": treatment, "reynolds": reynolds, "cells": cells,
                               "edge_d": edge, "ratio": ratio, "cells_per_gap": cells_per_gap,
                               "contact_edge_d": edge / 3 if contact_edge is None else contact_edge,
                               "sphere_facets": sphere_facets, "layers": layers,
                               "layer_thickness_d": layer_thickness if layers else 0, "seed": seed})


def default_study(tmp, cells, sphere_facets, layers=0, bed=None):
    """scenes/default.toml as it is, its study included, on `cells` ("polyhedra" or "tetrahedra")
    with `sphere_facets` ("inscribed" or "volume") and, if `layers`, LAYERS_TOML's prism layers;
    `bed` (a, N), if given, replaces its container's diameter (d) and its particle count."""
    text, n = re.subn(r'^cells = "\w+"', f'cells = "{cells}"', open(DEFAULT_SCENE).read(), count=1, flags=re.M)
    if n != 1:
        raise SystemExit("scenes/default.toml: no line sets cells; update default_study")
    for key, value in zip(("diameter_d", "count"), bed or ()):
        text, n = re.subn(rf'^{key} = [0-9.]+', f"{key} = {value}", text, count=1, flags=re.M)
        if n != 1:
            raise SystemExit(f"scenes/default.toml: no line sets {key}; update default_study")
    text = re.sub(r'^sphere_facets = .*\n', "", text, flags=re.M)
    text, n = re.subn(r'^\[surface\]\n', f'[surface]\nsphere_facets = "{sphere_facets}"\n', text, count=1, flags=re.M)
    if n != 1:
        raise SystemExit("scenes/default.toml: no [surface] section; update default_study")
    if layers:
        text, n = re.subn(r'^\[case\]\n', LAYERS_TOML + "\n[case]\n", text, count=1, flags=re.M)
        if n != 1:
            raise SystemExit("scenes/default.toml: no [case] section; update default_study")
    path = os.path.join(tmp, f"default_study_{cells}_{sphere_facets}_{layers}" + ("_{}_{}".format(*bed) if bed else ""))
    open(path + ".toml", "w").write(text)
    sc = lambda key: float(scene_value(text, key))
    return study_record(path, {"a": sc("diameter_d"), "n": int(sc("count")), "treatment": scene_value(text, "treatment"),
                               "reynolds": sc("reynolds"), "cells": cells, "edge_d": sc("edge_length_d"),
                               "ratio": sc("ratio"), "cells_per_gap": sc("cells_per_gap"),
                               "contact_edge_d": sc("contact_edge_length_d"), "sphere_facets": sphere_facets,
                               "layers": layers, "layer_thickness_d": LAYER_THICKNESS_D if layers else 0,
                               "default_scene": True, "bed_changed": bed is not None, "seed": int(sc("seed"))})


def study_record(path, fields):
    """Runs the scene path.toml into `path`; `fields` (what the scene was made with) and what its study gave."""
    wall, _ = timed([BEDFORGE, "--quiet", "run", path + ".toml", "-o", path, "--overwrite"])
    rep = json.load(open(os.path.join(path, "report.json")))
    case = rep["stages"]["case"]
    return {**commit_and_date(), **fields, "wall_s": wall, "peak_mb": peak_mb(rep),
            "study": case["convergence"], "es_pa_m": case["flow"]["eisfeld_schnitzlein_pa_m"],
            "eps_section": case["flow"]["void_fraction_section"], "d_m": case["d_ref_m"],
            "es_bed_pa_m": case["flow"]["eisfeld_schnitzlein_bed_pa_m"],
            "eps_section_bed": case["flow"]["void_fraction_section_bed"],
            "solid_volume_change_relative": rep["stages"]["surface"]["solid_volume_change_relative"],
            "wall_share_es": case["flow"]["drag"]["wall_share_eisfeld_schnitzlein"]}


def finer_default_scene(ratio, levels):
    """scenes/default.toml with every mesh length 1 / ratio of its own and `levels` levels; refuses a
    default scene that does not set each of those lengths."""
    text = open(DEFAULT_SCENE).read()
    changes = [("edge_length_d", lambda v: v / ratio), ("contact_edge_length_d", lambda v: v / ratio),
               ("cells_per_gap", lambda v: v * ratio), ("max_size_d", lambda v: v / ratio)]
    for key, scaled in changes:
        pattern = rf"^{key} = ([0-9.]+)"
        found = re.search(pattern, text, re.M)
        if not found:
            raise SystemExit(f"scenes/default.toml: no line sets {key}; update finer_default_scene")
        text = re.sub(pattern, f"{key} = {scaled(float(found.group(1))):.6g}", text, count=1, flags=re.M)
    text, n = re.subn(r"^levels = \d+", f"levels = {levels}", text, count=1, flags=re.M)
    if n != 1:
        raise SystemExit("scenes/default.toml: no line sets levels; update finer_default_scene")
    return text


def default_path(tmp, reference_levels):
    """The README's path timed from scene to printed answer, and its finer reference study."""
    made = commit_and_date()  # the code the runs are made by: commits made meanwhile are not in it
    out = os.path.join(tmp, "default")
    wall, printed = timed([BEDFORGE, "run", DEFAULT_SCENE, "-o", out, "--overwrite"])
    rep = json.load(open(os.path.join(out, "report.json")))
    case = rep["stages"]["case"]
    ratio = rep["scene"]["case"]["convergence"]["ratio"]
    ref_path = os.path.join(tmp, "default_reference")
    open(ref_path + ".toml", "w").write(finer_default_scene(ratio, reference_levels))
    ref_wall, _ = timed([BEDFORGE, "--quiet", "run", ref_path + ".toml", "-o", ref_path, "--overwrite"])
    ref = json.load(open(os.path.join(ref_path, "report.json")))["stages"]["case"]
    return {**made, "wall_s": wall, "peak_mb": peak_mb(rep), "answer": case["answer"],
            "printed": printed[printed.rfind("answer: "):].rstrip().splitlines(),
            "study": case["convergence"], "d_m": case["d_ref_m"], "ratio": ratio,
            "treatment": rep["scene"]["contacts"]["treatment"], "edge_d": rep["scene"]["surface"]["edge_length_d"],
            "cells": rep["scene"]["case"]["cells"],
            "reference": {"wall_s": ref_wall, "edge_d": rep["scene"]["surface"]["edge_length_d"] / ratio,
                          "study": ref["convergence"], "answer": ref["answer"]}}


# OpenFOAM settings tried against the case as written, per kind of cell: (name, [(file, pattern, replacement)]).
NO_GRADIENT_CACHE = ("gradients computed at each use (no `cache` of grad(U), grad(p) in fvSolution)",
                     [("fvSolution", r"cache\s*\{[^}]*\}\s*", "")])
SOLVER_VARIANTS = {"polyhedra": [
    ("as written (limited 0.5 non-orthogonal correction, 1 corrector; least-squares gradients; SIMPLEC)", []),
    ("full non-orthogonal correction, 2 correctors",
     [("fvSchemes", r"Gauss linear limited 0\.5", "Gauss linear corrected"),
      ("fvSchemes", r"(snGradSchemes\s*\{\s*default\s+)limited 0\.5", r"\1corrected"),
      ("fvSolution", r"nNonOrthogonalCorrectors 1", "nNonOrthogonalCorrectors 2")]),
    ("no non-orthogonal correction",
     [("fvSchemes", r"Gauss linear limited 0\.5", "Gauss linear uncorrected"),
      ("fvSchemes", r"(snGradSchemes\s*\{\s*default\s+)limited 0\.5", r"\1uncorrected"),
      ("fvSolution", r"nNonOrthogonalCorrectors 1", "nNonOrthogonalCorrectors 0")]),
    ("Gauss linear gradients", [("fvSchemes", r"leastSquares", "Gauss linear")]),
    ("SIMPLE, not SIMPLEC (relaxation U 0.7, p 0.3)",
     [("fvSolution", r"consistent\s+yes", "consistent      no"),
      ("fvSolution", r"(U\s+)0\.9;", r"\g<1>0.7;"), ("fvSolution", r"(p\s+)1;", r"\g<1>0.3;")]),
    NO_GRADIENT_CACHE],
    "tetrahedra": [
    ("as written (vertex-fit least-squares gradients, full non-orthogonal correction, H/A's flux skew-corrected; SIMPLEC)",
     []),
    NO_GRADIENT_CACHE]}


SOLVER_CAP = 400  # iterations: ten times what the case as written needs; a variant still going has stalled


def solver(tmp, cells="polyhedra", edge=0.2, cells_per_gap=3):
    """The case of the studies' bed on `cells` written once, solved again under each of SOLVER_VARIANTS[cells]."""
    path = os.path.join(tmp, f"solver_bridge_5_500_{cells}_{edge}_{cells_per_gap}")
    open(path + ".toml", "w").write(scene(5, 500, "bridge", edge, True, cells_per_gap, cells=cells))
    timed([BEDFORGE, "--quiet", "run", path + ".toml", "-o", path, "--overwrite"])
    flow = json.load(open(os.path.join(path, "report.json")))["stages"]["case"]["flow"]
    case = os.path.join(path, "case")
    env = dict(ENV, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")

    def last(run, name):  # the last value a surfaceFieldValue function object wrote
        return float(open(os.path.join(run, "postProcessing", name, "0", "surfaceFieldValue.dat")).read().split()[-1])
    rows = []
    for name, edits in SOLVER_VARIANTS[cells]:
        run = os.path.join(tmp, f"solver_{len(rows)}")
        for part in ("0", "constant", "system"):  # constant holds the mesh the case was written with
            shutil.copytree(os.path.join(case, part), os.path.join(run, part))
        shutil.copy2(os.path.join(case, "Allrun"), run)
        for file, pattern, replacement in edits + [("controlDict", r"(endTime\s+)\d+;", rf"\g<1>{SOLVER_CAP};")]:
            f = os.path.join(run, "system", file)
            text, count = re.subn(pattern, replacement, open(f).read())
            if count == 0:
                raise RuntimeError(f"solver variant {name!r}: {pattern!r} not in {file}")
            open(f, "w").write(text)
        # Solved by the case's own Allrun, as a user would: its environment (the solver's heap settings)
        # changes the time an iteration takes; log.time holds the simpleFoam step's own seconds.
        allrun = subprocess.run(["./Allrun", "-np", "2"], cwd=run, capture_output=True, text=True, env=env)
        log = open(os.path.join(run, "log.simpleFoam")).read()
        steps = {l.split()[0]: float(l.split()[1]) for l in open(os.path.join(run, "log.time")) if l.strip()}
        dp_kin = last(run, "pBedBottom") - last(run, "pBedTop")
        rows.append({"variant": name, "ok": allrun.returncode == 0, "solve_s": steps.get("simpleFoam", float("nan")),
                     "iterations": len(re.findall(r"^Time = ", log, re.M)),
                     "converged": "SIMPLE solution converged" in log, "dp_kin": dp_kin})
        print(rows[-1], flush=True)
        shutil.rmtree(run)
    for r in rows:  # bedforge's own conversion of the case as written, applied to each
        r["dp_dz_pa_m"] = flow["pressure_gradient_bed_pa_m"] * r["dp_kin"] / rows[0]["dp_kin"]
    return {**commit_and_date(), "kind": cells, "edge_d": edge, "cells_per_gap": cells_per_gap, "cells": flow["mesh"]["cells"],
            "bedforge_solve_s": flow["time_s"], "iteration_cap": SOLVER_CAP, "rows": rows}


def verification(tmp, edge, levels, ratio):
    """The empty tube on tetrahedra and on their dual: each a run with a convergence study."""
    out = {**commit_and_date(), "edge_d": edge, "levels": levels, "ratio": ratio, "runs": {}}
    for cells in ("polyhedra", "tetrahedra"):
        path = os.path.join(tmp, f"tube_{cells}")
        open(path + ".toml", "w").write(f"""[container]
type = "cylinder"
diameter_d = 2.0
[particles]
count = 0
diameter_m = 0.003
[surface]
inlet_length_d = 0.0
outlet_length_d = 12.0
edge_length_d = {edge}
[mesh]
algorithm = "hxt"
[case]
reynolds = 1.0
section_exclude_d = 3.0
processors = 2
run = true
cells = "{cells}"
convergence = {{levels = {levels}, ratio = {ratio}}}
[outputs]
files = ["case"]
""")
        out["runs"][cells] = study_run(path)
    return out


def study_run(path):
    """`bedforge run` of path.toml into path, timed: its wall time, convergence study and d (m)."""
    wall, _ = timed([BEDFORGE, "--quiet", "run", path + ".toml", "-o", path, "--overwrite"])
    case = json.load(open(os.path.join(path, "report.json")))["stages"]["case"]
    return {"wall_s": wall, "study": case["convergence"], "d_m": case["d_ref_m"]}


def cubic_column_run(tmp, name, phi, count, edge, levels, container="", case="", surface="", treatment="none", mesh=""):
    """One column of a simple cubic array at solid fraction phi, `count` spheres of 3 mm at the
    centres of L-long cells in a square box of side L with slip sides, Stokes flow: one
    `bedforge run` with a convergence study (`levels` meshes from `edge` d, ratio 1.3).
    `container`, `case` and `surface` add keys to those sections, `mesh` whole mesh sections; `treatment` is
    contacts.treatment."""
    side = (math.pi / (6.0 * phi)) ** (1.0 / 3.0)  # in d
    path = os.path.join(tmp, name)
    with open(path + ".txt", "w") as f:
        f.write("x y z d\n" + "".join(f"0 0 {(k + 0.5) * side * 3.0:.12f} 3.0\n" for k in range(count)))
    open(path + ".toml", "w").write(f"""[container]
type = "box"
size_x_d = {side:.12f}
size_y_d = {side:.12f}
{container}[packing]
algorithm = "import"
file = "{path}.txt"
units = "mm"
[contacts]
treatment = "{treatment}"
[surface]
edge_length_d = {edge}
contact_edge_length_d = {edge / 2}
cells_per_gap = 4
{surface}{mesh}[case]
walls = "slip"
reynolds = 0.01
{case}processors = 2
run = true
convergence = {{levels = {levels}, ratio = 1.3}}
[outputs]
files = ["case"]
""")
    return study_run(path)


def verification_spheres(tmp, edge, levels, fractions=(0.216, 0.45), count=6, cells_measured=4):
    """Simple cubic columns at each solid fraction, on each of ROUTES: count
    spheres, the pressure drop over the middle cells_measured, whose planes lie a whole number of
    cells apart at the same phase."""
    out = {**commit_and_date(), "edge_d": edge, "levels": levels, "ratio": 1.3, "runs": {}}
    for phi in fractions:
        side = (math.pi / (6.0 * phi)) ** (1.0 / 3.0)  # in d
        # From the box's bottom and the top sphere's top, both planes at the same phase:
        exclude = ((count - 0.5 - cells_measured) * side + 0.5) / 2.0
        for cells, facets, layers in ROUTES:
            out["runs"][f"{phi}, {route_key(cells, facets, layers)}"] = cubic_column_run(
                tmp, f"simple_cubic_{phi}_{cells}_{facets}_{layers}", phi, count, edge, levels,
                case=f'section_exclude_d = {exclude:.12f}\ncells = "{cells}"\n', surface=f'sphere_facets = "{facets}"\n',
                mesh=LAYERS_TOML if layers else "")
    return out


def verification_touching(tmp, edge, levels, count=6, cells_measured=4):
    """The touching simple cubic column (solid fraction pi / 6, each sphere touching its neighbours
    and the four mirror walls) with its contacts bridged, on each of ROUTES."""
    out = {**commit_and_date(), "edge_d": edge, "levels": levels, "ratio": 1.3, "runs": {}}
    exclude = ((count - 0.5 - cells_measured) + 0.5) / 2.0  # L = d: the planes a whole number of cells apart
    for cells, facets, layers in ROUTES:
        out["runs"][route_key(cells, facets, layers)] = cubic_column_run(
            tmp, f"touching_bridged_{cells}_{facets}_{layers}", math.pi / 6.0, count, edge, levels, treatment="bridge",
            case=f'section_exclude_d = {exclude:.12f}\ncells = "{cells}"\n', surface=f'sphere_facets = "{facets}"\n',
            mesh=LAYERS_TOML if layers else "")
    return out


def has_layered_run(v):
    """Whether a verification section ran the layered route (its run keys name route_key's layers)."""
    return any("layers" in k for k in v["runs"])


def touching_bound_pa_m(run):
    """The bound bedforge gives a treated simple cubic column (Pa/m): the untreated array's drag,
    Zick & Homsy's (the study's "bound"), from below for bridges."""
    return run["study"]["bound"]["pa_m"]


def touching_lines(v):
    """The touching bridged column's levels against Zick & Homsy's bound, per route."""
    lines = ["## Verification at contacts: the touching simple cubic column, bridged, against Zick & Homsy's bound", "",
             f"Made at commit {v['commit']} on {v['date']}: one column of a simple cubic array of touching spheres "
             "(solid fraction 0.5236, each sphere touching its neighbours above and below and the four walls, which "
             "the flow slips along: the array's mirror planes), `contacts.treatment = \"bridge\"`, six cells, the "
             "pressure drop over the middle four, Stokes flow (Re_p = 0.01), through the same route as a bed, on "
             f"{v['levels']} meshes from a surface edge of {v['edge_d']} d, ratio {v['ratio']}, on the cost sections' "
             "routes" + (" and the layered one (prism layers on the particles, their thickness in all as named)"
                         if has_layered_run(v) else "") + ". No exact value is known for the bridged array; Zick & Homsy's untreated touching array "
             "(1982, Table 2) bounds it from below, since at a fixed flow rate Stokes drag only grows with solid "
             "added (the bridges add about 0.2 % solid; docs/findings.md, 2026-11-27): the bound bedforge reports "
             "for a treated simple cubic column (report.json, stages.case.convergence.bound). "
             "Against the bound = dp/L / bound - 1; its order is a least-squares fit of ln |against the bound| against "
             "ln h over all levels, which falls short of the true order as the levels near the bridged array's own "
             "value.", ""]
    lines += level_rows(v, "cells, facets", "against the bound",
                        lambda run, lv: lv["pressure_gradient_bed_pa_m"] / touching_bound_pa_m(run) - 1.0)
    verdicts = []
    for key, run in v["runs"].items():
        bound = touching_bound_pa_m(run)
        ok = [lv for lv in run["study"]["levels"] if "failure" not in lv]
        below = [(lv["cell_size_m"], 1.0 - lv["pressure_gradient_bed_pa_m"] / bound) for lv in ok]
        order = None
        if len(below) >= 2 and all(e > 0 for _, e in below):
            xs = [math.log(h) for h, _ in below]
            ys = [math.log(e) for _, e in below]
            mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
            order = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
        verdicts.append(f"- {key}: bound {bound:.5g} Pa/m; order against it "
                        f"{'none (a level at or above it)' if order is None else f'{order:.2f}'}; whole run "
                        f"{run['wall_s']:.0f} s; the study's own verdict: {run['study']['conclusion']}.")
    return lines + [""] + verdicts + [""]


# verification_periodic's finest surface edge per run (d): finer where the gap between neighbouring
# spheres is narrower (about 0.15 d at 0.343, 0.05 d at 0.45), as those runs were first made
# (cc96566, eb4a6ea); the tube's surface takes twice its run's edge.
PERIODIC_EDGES_D = {"empty tube": 0.025, "0.125": 0.025, "0.216": 0.025, "0.343": 0.019, "0.45": 0.016}


def verification_periodic(tmp, edge, levels, runs, kept, cells=3):
    """The periodic empty tube ("empty tube" in `runs`) and periodic simple cubic columns (`cells` cells
    per period) at each solid fraction in `runs`, each a run with a convergence study from a finest
    edge of `edge` d (None: the run's PERIODIC_EDGES_D) and its own commit, date and edge; the runs
    of `kept` (an earlier result) not redone stay as they were."""
    out = {"levels": levels, "ratio": 1.3, "runs": dict((kept or {}).get("runs", {}))}
    for key in runs:
        edge_d = edge if edge is not None else PERIODIC_EDGES_D[key]
        stamp = {**commit_and_date(), "edge_d": edge_d}
        if key == "empty tube":
            path = os.path.join(tmp, "periodic_tube")
            open(path + ".toml", "w").write(f"""[container]
type = "cylinder"
diameter_d = 2.0
period_z_d = 3.0
[particles]
count = 0
diameter_m = 0.003
[surface]
edge_length_d = {edge_d * 2}
[case]
reynolds = 1.0
processors = 2
run = true
convergence = {{levels = {levels}, ratio = 1.3}}
[outputs]
files = ["case"]
""")
            out["runs"][key] = {**stamp, **study_run(path)}
            continue
        phi = float(key)
        side = (math.pi / (6.0 * phi)) ** (1.0 / 3.0)  # in d
        out["runs"][key] = {**stamp, **cubic_column_run(tmp, f"periodic_cubic_{phi}", phi, cells, edge_d, levels,
                                                        container=f"period_z_d = {cells * side:.12f}\n")}
    return out


def default_scene_with(seed, treatment, count=None):
    """scenes/default.toml with another seed and contact treatment (and sphere count)."""
    text = open(DEFAULT_SCENE).read()
    for pattern, replacement in [(r"^seed = \d+", f"seed = {seed}"),
                                 (r'^treatment = "[a-z]+"', f'treatment = "{treatment}"')] + (
                                     [(r"^count = \d+", f"count = {count}")] if count else []):
        text, n = re.subn(pattern, replacement, text, count=1, flags=re.M)
        if n != 1:
            raise SystemExit(f"scenes/default.toml: no line matches {pattern}; update default_scene_with")
    return text


def slice_run(path, text):
    """A default-settings run of one bed: its convergence study, void fractions and E&S, or the
    packer's refusal (a periodic section that jams before its period) as `jammed`, or any other
    failure of the run (a flow solve that diverged) as `failed`, so that the other beds still run."""
    open(path + ".toml", "w").write(text)
    t0 = time.time()
    out = subprocess.run([BEDFORGE, "--quiet", "run", path + ".toml", "-o", path, "--overwrite"], capture_output=True,
                         text=True, env=ENV)
    if out.returncode == 3 and "jammed" in out.stderr:
        return {"jammed": out.stderr.strip()}
    if out.returncode != 0:
        return {"failed": f"exit {out.returncode}: {out.stderr.strip()}"}
    rep = json.load(open(os.path.join(path, "report.json")))
    case = rep["stages"]["case"]
    finest = case["convergence"]["levels"][0]
    return {"study": case["convergence"], "cells": finest["cells"], "dp_pa_m": finest["pressure_gradient_bed_pa_m"],
            "eps_central": rep["stages"]["analysis"]["void_fraction"]["central_slab"],
            "eps_section_meshed": case["flow"]["void_fraction_section"],
            "es_pa_m": case["flow"]["eisfeld_schnitzlein_pa_m"], "d_m": case["d_ref_m"], "wall_s": time.time() - t0,
            "contacts_opened": rep["stages"]["surface"].get("periodic_planes_m", {}).get("contacts_opened", 0)}


# The periodic slice section's cells, full beds and slices alike (the issue's "same mesh settings"):
# a periodic section refuses tetrahedra (OpenFOAM v1912 carries their gradients across no cyclic patch).
SLICE_CELLS = "polyhedra"


def periodic_slice(tmp, seeds, period_d, count, slices, full_exclude_d, treatment="bridge"):
    """Issue 56's z-periodic slice: full beds of the default scene (a = 5, N = 500) with `treatment`
    at each seed, their dp/L over the section full_exclude_d clear of floor and top (the bulk a
    slice stands for: the default scene's central slab is 2 d clear); then periodic slices of
    `count` spheres packed to the full beds' mean central void fraction (container.period_z_d
    follows from it, about period_d), seed after seed until `slices` of them reach it; both at the
    default scene's mesh settings and study, on polyhedra (SLICE_CELLS) whatever the default scene's cells."""
    out = {**commit_and_date(), "treatment": treatment, "full_section_exclude_d": full_exclude_d, "full": {},
           "slice": {}, "cells": SLICE_CELLS}

    def with_cells(text):
        return re.sub(r'^cells = "[a-z]+"', f'cells = "{SLICE_CELLS}"', text, count=1, flags=re.M)
    for s in seeds:
        text = with_cells(default_scene_with(s, treatment)).replace(
            "[case]\n", f"[case]\nsection_exclude_d = {full_exclude_d}\n", 1)
        out["full"][str(s)] = slice_run(os.path.join(tmp, f"full_{s}"), text)
    full = [r for r in out["full"].values() if "study" in r]
    if not full:
        raise SystemExit("periodic_slice: no full bed was solved: " + "; ".join(r["failed"] for r in out["full"].values()))
    eps = sum(r["eps_central"] for r in full) / len(full)
    out["target_void_fraction"] = eps
    a = float(re.search(r"^diameter_d = ([0-9.]+)", open(DEFAULT_SCENE).read(), re.M).group(1))
    out["period_d"] = count / 6.0 / ((1.0 - eps) * (a / 2.0) ** 2)  # spheres' volume over (1 - eps) x cross-section
    if abs(out["period_d"] - period_d) > 0.5:
        raise SystemExit(f"{count} spheres at void fraction {eps:.4f} make a period of {out['period_d']:.2f} d, "
                         f"not about {period_d} d: change --slice-count")
    s = 0
    target = f"[packing.soft_sphere]\ntarget_void_fraction = {eps:.6f}\n"
    while sum("study" in r for r in out["slice"].values()) < slices and s < 4 * slices:
        s += 1
        text = with_cells(default_scene_with(s, treatment, count)).replace("[packing.soft_sphere]\n", target, 1)
        out["slice"][str(s)] = slice_run(os.path.join(tmp, f"slice_{s}"), text)
    return out


def random_arrays(tmp, fractions, seeds):
    """Issue 56's random periodic arrays: the shipped example with the count that packs each solid
    fraction into its cube of 4 d, at each seed; a run that fails is listed with its reason."""
    example = open(os.path.join(os.path.dirname(DOCS), "scenes", "examples", "random_array_stokes.toml")).read()
    out = {**commit_and_date(), "runs": []}
    for phi in fractions:
        count = round(phi * 64.0 / (math.pi / 6.0))
        for s in seeds:
            text = edited(example, [("count = 49", f"count = {count}"), ("seed = 1", f"seed = {s}")], "random_arrays")
            path = os.path.join(tmp, f"array_{count}_{s}")
            open(path + ".toml", "w").write(text)
            t0 = time.time()
            run = subprocess.run([BEDFORGE, "--quiet", "run", path + ".toml", "-o", path, "--overwrite"],
                                 capture_output=True, text=True, env=ENV)
            row = {"count": count, "seed": s, "solid_packed": count * math.pi / 6.0 / 64.0, "wall_s": time.time() - t0}
            if run.returncode != 0:
                out["runs"].append({**row, "failed": f"exit {run.returncode}: {run.stderr.strip()}"})
                continue
            case = json.load(open(os.path.join(path, "report.json")))["stages"]["case"]
            finest = case["convergence"]["levels"][0]
            out["runs"].append({**row, "study": case["convergence"], "cells": finest["cells"],
                                "dp_pa_m": finest["pressure_gradient_bed_pa_m"],
                                "solid_solved": case["stokes_array"]["solid_fraction"],
                                "vdh_pa_m": case["stokes_array"]["van_der_hoef_pa_m"]})
    return out


def random_array_lines(v):
    """The random arrays against van der Hoef et al.: a row per bed, then each fraction's mean and spread."""
    lines = ["## Random periodic arrays against van der Hoef et al. (issue 56)", "",
             f"Made at commit {v['commit']} on {v['date']}: scenes/examples/random_array_stokes.toml (a cube of 4 d "
             "periodic on every side, 3 mm spheres Monte Carlo packed and compressed to the period, shrunk by 0.99, "
             "Re_p = 0.01, three-level study on polyhedra, surface edge 0.1 d) with particles.count set for each solid "
             "fraction as packed, at each seed. vdH: van der Hoef, Beetstra & Kuipers (2005) at the solid fraction as "
             "solved (the shrunk spheres'); band: the finest dp/L +- its GCI." + periodic_residuals_note(v), "",
             "| count | seed | solid packed | solid solved | cells (finest) | dp/L finest (Pa/m) | extrapolated | GCI fine "
             "| order | iteration error (levels) | vdH (Pa/m) | finest / vdH | extrapolated / vdH | band holds vdH "
             "| wall (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    by_count = {}
    for r in v["runs"]:
        if "failed" in r:
            lines.append(f"| {r['count']} | {r['seed']} | {r['solid_packed']:.4f} | failed: {r['failed']} "
                         "| | | | | | | | | | | |")
            continue
        g = r["study"].get("grid_convergence", {})
        ext = g.get("extrapolated")
        holds = abs(r["dp_pa_m"] - r["vdh_pa_m"]) <= g["gci_fine"] * r["dp_pa_m"] if ext is not None else None
        lines.append(f"| {r['count']} | {r['seed']} | {r['solid_packed']:.4f} | {r['solid_solved']:.4f} | {r['cells']} | "
                     f"{r['dp_pa_m']:.4g} | " + (f"{ext:.4g} | {100 * g['gci_fine']:.1f} % | {g['apparent_order']:.2f}"
                                                  if ext is not None else f"none ({r['study']['conclusion']}) | | ")
                     + f" | {iteration_errors(r['study'])} | {r['vdh_pa_m']:.4g} | {r['dp_pa_m'] / r['vdh_pa_m']:.3f} | "
                     + (f"{ext / r['vdh_pa_m']:.3f} | {'yes' if holds else 'NO'}" if ext is not None else " | ")
                     + f" | {r['wall_s']:.0f} |")
        if ext is not None:
            by_count.setdefault(r["count"], []).append(ext / r["vdh_pa_m"])
    lines.append("")
    for count, ratios in by_count.items():
        mean = sum(ratios) / len(ratios)
        sd = math.sqrt(sum((x - mean) ** 2 for x in ratios) / (len(ratios) - 1)) if len(ratios) > 1 else 0.0
        lines.append(f"- {count} spheres: extrapolated / vdH {mean:.3f} over {len(ratios)} seeds (standard deviation "
                     f"{sd:.3f}, range {min(ratios):.3f} to {max(ratios):.3f}).")
    tried = sorted({r["solid_packed"] for r in v["runs"]})
    untried = "" if tried and max(tried) >= 0.55 else "; the issue's range reaches 0.6, not run here"
    lines += ["", "Issue 56's target (within van der Hoef et al.'s stated accuracy at every solid fraction tried, with the "
              "GCI of each and the spread over at least 3 seeds): NOT judged: their stated accuracy is not in the "
              f"repository (docs/reference.md). Fractions tried as packed: "
              f"{', '.join(f'{x:.2f}' for x in tried)}{untried}.", ""]
    return lines


def slice_lines(v):
    """The periodic slice against the full beds: a row per bed, then issue 56's target."""
    lines = ["## A z-periodic slice against the full bed (issue 56)", "",
             f"Made at commit {v['commit']} on {v['date']}: scenes/default.toml (a = 5, N = 500, its mesh settings and "
             f"three-level study) with contacts.treatment = \"{v['treatment']}\""
             + (f" and case.cells = \"{v['cells']}\" (a periodic section refuses tetrahedra)" if "cells" in v else "")
             + (" (the slices' bridges and caps that a periodic plane crosses are opened there, their spheres shrunk: "
                "column *opened*, counted at both planes)" if v["treatment"] in ("bridge", "cap") else "")
             + f", at each seed; then periodic slices of the same tube, packed to the full beds' mean central void "
             f"fraction {v['target_void_fraction']:.4f} (packing.soft_sphere.target_void_fraction; period "
             f"{v['period_d']:.3f} d), at the same settings, seed after seed (a slice that jams before its period is "
             f"listed and the next seed taken; so is a run that fails). dp/L: the full bed's over its section "
             f"({v.get('full_section_exclude_d', 0.5):g} d clear of floor and top), "
             "the slice's over one period; E&S at that section's meshed void fraction."
             + periodic_residuals_note(v), "",
             "| bed | seed | central eps (packed) | section eps (meshed) | cells (finest) | dp/L finest (Pa/m) | "
             "/ E&S | extrapolated (Pa/m) | GCI fine | order | iteration error (levels) | opened | wall (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for kind in ("full", "slice"):
        for seed, r in v[kind].items():
            if "study" not in r:
                what = "jammed" if "jammed" in r else "failed"
                lines.append(f"| {kind} | {seed} | {what}: {r[what]} | | | | | | | | | | |")
                continue
            g = r["study"].get("grid_convergence", {})
            ext = g.get("extrapolated")
            lines.append(f"| {kind} | {seed} | {r['eps_central']:.4f} | {r['eps_section_meshed']:.4f} | {r['cells']} | "
                         f"{r['dp_pa_m']:.4g} | {r['dp_pa_m'] / r['es_pa_m']:.3f} | "
                         + (f"{ext:.4g} | {100 * g['gci_fine']:.1f} % | {g['apparent_order']:.2f}" if ext is not None
                            else f"none ({r['study']['conclusion']}) | | ")
                         + f" | {iteration_errors(r['study'])} | {r.get('contacts_opened', 0) if kind == 'slice' else ''} | {r['wall_s']:.0f} |")
    solved = {k: [r for r in v[k].values() if "study" in r] for k in ("full", "slice")}
    if not solved["full"] or not solved["slice"]:
        return lines + ["", "Too few beds solved for a comparison.", ""]

    def spread(rows, key):
        values = [key(r) for r in rows]
        mean = sum(values) / len(values)
        sd = math.sqrt(sum((x - mean) ** 2 for x in values) / (len(values) - 1)) if len(values) > 1 else 0.0
        return mean, min(values), max(values), sd

    lines.append("")
    verdicts = []
    for name, key in (("dp/L on the finest mesh (Pa/m)", lambda r: r["dp_pa_m"]),
                      ("dp/L over E&S at the meshed void fraction", lambda r: r["dp_pa_m"] / r["es_pa_m"])):
        f, sl = spread(solved["full"], key), spread(solved["slice"], key)
        inside = f[1] <= sl[0] <= f[2]
        verdicts.append(inside)
        lines.append(f"- {name}: full beds {f[0]:.4g} (range {f[1]:.4g} to {f[2]:.4g}, standard deviation {f[3]:.3g}, "
                     f"{len(solved['full'])} seeds); slices {sl[0]:.4g} (range {sl[1]:.4g} to {sl[2]:.4g}, "
                     f"{len(solved['slice'])} seeds): the slices' mean {'inside' if inside else 'OUTSIDE'} the full "
                     f"beds' range ({100 * (sl[0] / f[0] - 1):+.1f} % from their mean).")
    cells = spread(solved["slice"], lambda r: r["cells"])[0] / spread(solved["full"], lambda r: r["cells"])[0]
    lines.append(f"- cells: the slices' mean finest mesh is {cells:.3f} of the full beds'.")
    met = verdicts[0] and cells <= 0.25
    lines += ["", "Issue 56's target (dp/L within the seed-to-seed spread of the full bed's, read here as the slices' "
              "mean inside the full beds' range over seeds, at no more than a quarter of the full bed's cells for the "
              f"same mesh settings): {'met' if met else 'NOT met'}.", ""]
    return lines


def periodic_target_lines(v):
    """Issue 56's target for the cubic arrays, read off each run's finest solved level and order."""
    lines = []
    for key, run in v["runs"].items():
        if key == "empty tube":
            continue
        solved = [lv for lv in run["study"]["levels"] if "failure" not in lv]
        order = run["study"].get("order_from_exact")
        if not solved:
            lines.append(f"- solid fraction {key}: no level solved: target not met")
            continue
        error = solved[0]["relative_error_to_exact"]
        met = abs(error) <= 0.01 and order is not None and order >= 1.5
        lines.append(f"- solid fraction {key}: finest error {100 * error:+.2f} %, order "
                     f"{NO_ORDER if order is None else f'{order:.2f}'}: {'met' if met else 'NOT met'}")
    return ["Issue 56's target for the cubic arrays: within 1 % of Zick & Homsy on the finest level, order at "
            "least 1.5.", "", *lines, ""]


def pieces_scene(count, solve, spheres=None, treatment="shrink"):
    """scenes/default.toml (a = 5, N = 500 or `spheres`, seed 1) with `treatment`, one mesh, and the case in
    `count` pieces (0: one piece), solved when `solve`."""
    text = default_scene_with(1, treatment, spheres)
    for pattern, replacement in [(r"^levels = \d+", "levels = 0"), (r'^algorithm = "hxt"', f'algorithm = "hxt"\npieces = {count}'),
                                 (r"^run = true", f"run = {'true' if solve else 'false'}")]:
        text, n = re.subn(pattern, replacement, text, count=1, flags=re.M)
        if n != 1:
            raise SystemExit(f"scenes/default.toml: no line matches {pattern}; update pieces_scene")
    return text


BED_1E4 = ("a = 14, seed 1, bridges, surface edge 0.1 d (the default 0.05 d where contacts meet), no refinement "
           "across gaps, gmsh's tetrahedra as the case's cells, not solved (simpleFoam on it would take some 37 GB "
           "here)")


BED_1E4_SOLVED = ("a = 14, seed 1, bridges, surface edge 0.15 d (the default 0.05 d where contacts meet), no "
                  "refinement across gaps, the polyhedral dual as the case's cells (the default), Re_p = 1, solved")


def bed_1e4_scene(count, solve, spheres=10000):
    """Issue 58's bed (BED_1E4) with `spheres` spheres (the column longer or shorter), in `count` pieces (0: one
    piece); `solve` must be False (simpleFoam on it does not fit here)."""
    if solve:
        raise SystemExit("bed_1e4_scene: the 1e4 bed is not solved on this machine at 0.1 d; bed_1e4_solved_scene is")
    return edited(scene(14, spheres, "bridge", 0.1, False, cells="tetrahedra"),
                  [('algorithm = "hxt"', f'algorithm = "hxt"\npieces = {count}'), ("contact_edge_length_d = 0.03333\n", ""),
                   ('files = ["positions", "stl", "mesh", "case"]', 'files = ["positions", "case"]')], "bed_1e4_scene")


def edited(text, replacements, caller):
    """scene()'s `text` with each (old, new) of `replacements` made once; stops naming `caller` where one is missing."""
    for old, new in replacements:
        if old not in text:
            raise SystemExit(f"scene(): no {old}; update {caller}")
        text = text.replace(old, new, 1)
    return text


def bed_1e4_solved_scene(count, solve, spheres=10000):
    """Issue 58's bed as BED_1E4_SOLVED: at 0.15 d, on polyhedra, solved (the one piece on 2 processes, the
    pieces on their ranks), in `count` pieces (0: one piece); unsolved when not `solve`."""
    return edited(scene(14, spheres, "bridge", 0.15, solve),
                  [('algorithm = "hxt"', f'algorithm = "hxt"\npieces = {count}'), ("contact_edge_length_d = 0.05\n", ""),
                   ('files = ["positions", "stl", "mesh", "case"]', 'files = ["positions", "case"]')], "bed_1e4_solved_scene")


def bed_1e4_tetrahedra_scene(count, solve, spheres=10000):
    """Issue 58's bed at 0.25 d, contact edge a third (0.0833 d), on gmsh's tetrahedra (the cells of
    scenes/default.toml), solved, in `count` pieces (0: one piece); unsolved when not `solve`. So coarse because
    simpleFoam takes 3.4 kB per tetrahedron (docs/findings.md, 2026-12-05) and the cells around the 32,866 contacts
    hardly fall with the surface edge: bedforge's estimate refused 0.2 d with the default contact edge (9.3 M
    cells, 30.7 GB) and puts this one at 5.5 M cells, 18.2 GB, of the 24.7 GB here (docs/findings.md, 2026-12-05)."""
    return edited(scene(14, spheres, "bridge", 0.25, solve, cells="tetrahedra"),
                  [('algorithm = "hxt"', f'algorithm = "hxt"\npieces = {count}'),
                   ('files = ["positions", "stl", "mesh", "case"]', 'files = ["positions", "case"]')],
                  "bed_1e4_tetrahedra_scene")


class Diverged(RuntimeError):
    """A run bedforge stopped because its solve diverged (exit 3, "simpleFoam diverging"): a result, not a failure
    of the tool; `message` is bedforge's, `wall_s` the run's time until it stopped."""
    def __init__(self, message, wall_s):
        super().__init__(message)
        self.message, self.wall_s = message, wall_s


def timed_run(path, text, env):
    """`bedforge run` of the scene `text` (written to path.toml) into `path`: its wall time (s). Diverged when
    bedforge stopped a diverging solve, RuntimeError when it failed otherwise."""
    open(path + ".toml", "w").write(text)
    t0 = time.time()
    out = subprocess.run([BEDFORGE, "--quiet", "run", path + ".toml", "-o", path, "--overwrite"], capture_output=True,
                         text=True, env=env)
    if out.returncode == 3 and "simpleFoam diverging" in out.stderr:
        raise Diverged(out.stderr.strip(), time.time() - t0)
    if out.returncode != 0:
        raise RuntimeError(f"bedforge run {path}.toml failed:\n{out.stdout}\n{out.stderr}")
    return time.time() - t0


def one_rank_piece(path, env):
    """The one-piece run's case in `path` made again as one rank's piece (`mpirun -np 1 bedforge piece`):
    its wall time (s)."""
    for old in glob.glob(os.path.join(path, "case", "processor*")):
        shutil.rmtree(old)
    t0 = time.time()
    subprocess.run(["mpirun", "-np", "1", BEDFORGE, "--quiet", "--no-progress", "piece", path], check=True,
                   capture_output=True, env=dict(env, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    return time.time() - t0


def scene_value(text, key):
    """The value a scene's line `key = value` sets (quotes dropped); SystemExit when no line sets it."""
    m = re.search(rf'^{key} = "?([\w.]+)"?', text, re.M)
    if not m:
        raise SystemExit(f"the scene sets no {key}; the pieces sections name it")
    return m.group(1)


def pieces(tmp, ranks, spheres=500, solved=(0, 2), make_scene=pieces_scene, one_piece=None, reconstruct=()):
    """Issue 58 on one machine: the default bed (`spheres` of them; shrunk unless make_scene treats its
    contacts otherwise) in one piece (mesh stage, then the case stage's dual, and the solve when 0 is
    in `solved`), then in P pieces on P ranks
    (`[mesh] pieces = P`, mpirun oversubscribed where P exceeds the cores): each rank's peak and time,
    the run's wall time, dp/L where P is in `solved` against one piece's. P = 1 is one rank's piece of
    the one-piece run's case (`bedforge piece`). The one-piece run is left out when `one_piece` is false
    (by default when `solved` is empty). `make_scene(count, solve, spheres)` gives the scene (pieces_scene,
    bed_1e4_scene); for P in `reconstruct` the pieces are joined (reconstructParMesh) and checked whole.
    Each row records the scene's contacts.treatment (the section says it)."""
    env = dict(ENV, OMPI_MCA_rmaps_base_oversubscribe="1")
    text = make_scene(2, False, spheres)
    treatment = scene_value(text, "treatment")
    # The mesh the section describes, as the scene sets it.
    mesh = {"cells_kind": scene_value(text, "cells"), "edge_d": float(scene_value(text, "edge_length_d")),
            "cells_per_gap": float(scene_value(text, "cells_per_gap"))}
    contact_edge = re.search(r"^contact_edge_length_d = ([\d.]+)", text, re.M)
    if contact_edge:  # else the default, 0.05 d
        mesh["contact_edge_d"] = float(contact_edge.group(1))
    rows = []
    one_run = bool(solved) if one_piece is None else one_piece
    for p in ([0] if one_run else []) + ranks:
        # P = 1 takes the one-piece run's case when there is one, not a second run of it.
        path = os.path.join(tmp, f"pieces_{treatment}_{spheres}_{0 if p == 1 and one_run else p}")
        try:
            wall = 0.0 if p == 1 and one_run else timed_run(path, make_scene(p if p > 1 else 0, p in solved, spheres), env)
            rep = json.load(open(os.path.join(path, "report.json")))
            case = rep["stages"]["case"]
            row = {"pieces": p, "spheres": spheres, "treatment": treatment, **mesh, "wall_s": wall, "cells": case["cells"],
                   "stages_s": stage_times(rep),
                   "stage_peak_mb": {k: v["peak_memory_mb"] for k, v in rep["stages"].items() if "peak_memory_mb" in v}}
        except Diverged as e:
            if p == 0:  # the row the others are held against
                raise
            # The run wrote no report; the ranks' pieces and Allrun's checkMesh are there.
            case = {}
            row = {"pieces": p, "spheres": spheres, "treatment": treatment, **mesh, "wall_s": e.wall_s,
                   "diverged": e.message}
        if "flow" in case and not (p == 1 and one_run):  # P = 1 shares the one-piece run's case and solve
            row["dp_pa_m"] = case["flow"]["pressure_gradient_bed_pa_m"]
            row["solve_s"] = case["flow"]["time_s"]
            row["solver_peak_mb"] = case["flow"]["solver_peak_memory_mb"]
        if p == 1:
            row["wall_s"] = one_rank_piece(path, env)
        if p >= 1:
            row["ranks"] = []
            for k in range(p):
                r = json.load(open(os.path.join(path, "case", f"processor{k}", "bedforge_piece.json")))
                row["ranks"].append({"cells": r["cells"], "peak_mb": r["peak_memory_mb"], "time_s": r["time_s"],
                                     "scope": r["peak_memory_scope"]})
            row["cells"] = sum(r["cells"] for r in row["ranks"])
            if p > 1:  # Allrun's checkMesh when solved, else one run here
                case_dir = os.path.join(path, "case")
                allrun_check = os.path.join(case_dir, "log.checkMesh")
                log = open(allrun_check).read() if os.path.exists(allrun_check) else subprocess.run(
                    ["mpirun", "-np", str(p), "checkMesh", "-parallel", "-case", case_dir], capture_output=True, text=True,
                    env=dict(env, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")).stdout
                row["check_mesh_ok"] = "Mesh OK." in log
                # checkMesh's own failures, or, where it stopped before judging (a crash), its last line.
                row["check_mesh_failed"] = re.findall(r"^\s*\*\*\*(.*)$", log, re.M) or (
                    [] if row["check_mesh_ok"] else ["stopped before its verdict: " + (log.strip().splitlines() or ["no output"])[-1]])
            if p in reconstruct:
                case_dir = os.path.join(path, "case")
                t_join, _ = timed(["reconstructParMesh", "-constant", "-case", case_dir])
                ok, cells, _, _, check_s = check_mesh(case_dir)
                row["reconstructed"] = {"mesh_ok": ok, "cells": cells, "reconstruct_s": t_join, "check_mesh_s": check_s}
        rows.append({**commit_and_date(), **row})
    return rows


def weak_scaling(tmp, ranks, per_rank, make_scene=pieces_scene, bed=None):
    """Issue 58's weak scaling: beds of `per_rank` x P spheres (a = 5, the column P times longer) in P
    pieces on P ranks, the case written (not solved); P = 1 is one rank's piece of the one-piece run's
    case, as in pieces(). Each rank's peak and time. `make_scene` and `bed` (its description, for the section)
    as in pieces()."""
    env = dict(ENV, OMPI_MCA_rmaps_base_oversubscribe="1")
    rows = []
    for p in ranks:
        path = os.path.join(tmp, f"weak_{per_rank}_{p}")
        wall = timed_run(path, make_scene(p if p > 1 else 0, False, per_rank * p), env)
        if p == 1:
            wall = one_rank_piece(path, env)
        ranks_out = [json.load(open(os.path.join(path, "case", f"processor{k}", "bedforge_piece.json"))) for k in range(p)]
        rows.append({**commit_and_date(), **({"bed": bed} if bed else {}), "ranks": p, "spheres": per_rank * p, "wall_s": wall,
                     "cells": sum(r["cells"] for r in ranks_out),
                     "rank_cells": [r["cells"] for r in ranks_out],
                     "rank_peak_mb": [r["peak_memory_mb"] for r in ranks_out], "rank_time_s": [r["time_s"] for r in ranks_out]})
    return rows


def weak_scaling_lines(rows):
    """Issue 58's weak-scaling target: the largest rank's peak within 20 % of one rank's, 1 to 4 ranks."""
    one = max(rows[0]["rank_peak_mb"])
    bed = rows[0].get("bed", "scenes/default.toml with contacts shrunk (a = 5, 0.15 d, 4 cells per gap, seed 1)")
    lines = [f"## Weak scaling of the pieces: a bed P times longer on P ranks ({bed.split(',')[0]}; issue 58)", "",
             f"Made at {rows[0]['commit']} on {rows[0]['date']}. The bed: {bed}; {rows[0]['spheres']} spheres "
             "per rank, the column P times longer; `[mesh] pieces = P`, the case written, not solved (P = 1: one rank's "
             "piece of the one-piece run's case). Ranks beyond the 2 cores are oversubscribed, so their times are not "
             "a speed-up.", "",
             "| ranks | spheres | cells | ranks' cells, largest / smallest | largest rank's peak (MB) | x one rank's | "
             "ranks' time (s) | run's wall time (s) |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        peak = max(r["rank_peak_mb"])
        balance = f"{max(r['rank_cells']) / min(r['rank_cells']):.2f}" if r["ranks"] > 1 else ""
        lines.append(f"| {r['ranks']} | {r['spheres']} | {r['cells']} | {balance} | {peak:.0f} | {peak / one:.2f} | "
                     f"{min(r['rank_time_s']):.0f}-{max(r['rank_time_s']):.0f} | {r['wall_s']:.0f} |")
    worst = max(abs(max(r["rank_peak_mb"]) / one - 1) for r in rows)
    lines += ["", "The ranks' cells show how well the pieces' planes (cut at equal estimated cells, "
              "fluid_surface.hpp's calibrated surface term included) balance a bed they were not tuned on.", "",
              f"Issue 58's target, the per-rank peak within 20 % of one rank's from 1 to 4 ranks: "
              f"{'**met**' if worst <= 0.2 else '**not met**'} (at most {100 * worst:.0f} % off).", ""]
    return lines


def projection(results, keys=("pieces", "pieces_large"), a=5.0, settings=None):
    """Issue 58's projection to 1e5 and 1e6 spheres on 64 to 1024 ranks, from the measured ranks of the sections
    `keys` (no runs; their bed's column is a = `a`, its settings said by `settings`): the largest rank's peak and
    time fitted as a + b x spheres per rank (least squares over 1 to 8 ranks)."""
    rows = [r for key in keys for r in results.get(key, []) if r["pieces"] >= 1]
    x = [r.get("spheres", 500) / r["pieces"] for r in rows]  # rows before the bed size was recorded: 500
    fit = {}
    for key, field in (("peak_mb", "peak_mb"), ("time_s", "time_s")):
        y = [max(k[field] for k in r["ranks"]) for r in rows]
        mx, my = sum(x) / len(x), sum(y) / len(y)
        b = sum((xi - mx) * (yi - my) for xi, yi in zip(x, y)) / sum((xi - mx) ** 2 for xi in x)
        intercept = my - b * mx
        if intercept < 0.0:  # a rank costs no less than nothing: the line through the origin instead
            intercept, b = 0.0, sum(xi * yi for xi, yi in zip(x, y)) / sum(xi * xi for xi in x)
        fit[key] = {"a": intercept, "b": b, "max_residual": max(abs(yi - intercept - b * xi) for xi, yi in zip(x, y))}
    # A slab's thickness goes as its spheres over the column's cross-section, so a rank's slab is no
    # thinner than the thinnest measured (the fewest spheres per rank, at the measured a = 5) while
    # a <= 5 sqrt(spheres per rank / those fewest).
    table = [{"spheres": n, "ranks": p, "per_rank": n / p, "peak_gb": (fit["peak_mb"]["a"] + fit["peak_mb"]["b"] * n / p) / 1024,
              "time_s": fit["time_s"]["a"] + fit["time_s"]["b"] * n / p, "widest_a": a * math.sqrt(n / p / min(x))}
             for n in (100000, 1000000) for p in (64, 128, 256, 512, 1024)]
    return {**commit_and_date(), "from": sorted({r["commit"] for r in rows}), "fit": fit, "table": table,
            "spheres_per_rank": [min(x), max(x)], "a": a, "sections": list(keys),
            **({"settings": settings} if settings else {})}


def projection_lines(r):
    f = r["fit"]
    made_from = r["from"] if isinstance(r["from"], str) else ", ".join(r["from"])
    low, high = r.get("spheres_per_rank", [62, 500])  # results before the range was recorded: the 500-sphere bed's
    a = r.get("a", 5.0)
    settings = r.get("settings", "the default bed's settings (a = 5, shrink, 0.15 d, 4 cells per gap; a wider column "
                                 "has relatively less wall, about as many cells per sphere)")
    sections = " and ".join(r.get("sections", ["pieces", "pieces_large"]))
    lines = [f"## Projection past one machine: 1e5 and 1e6 spheres on 64 to 1024 ranks (from {sections}; issue 58)", "",
             f"Made at {r['commit']} on {r['date']} from the ranks of {sections} (made at {made_from}), no runs. The "
             f"largest rank's peak and time fitted as a + b x spheres per rank over 1 to 8 ranks ({low:.0f} to "
             f"{high:.0f} spheres per rank): peak "
             f"{f['peak_mb']['a']:.0f} MB + {f['peak_mb']['b']:.2f} MB per sphere (largest residual "
             f"{f['peak_mb']['max_residual']:.0f} MB), time {f['time_s']['a']:.0f} s + {f['time_s']['b']:.3f} s per sphere "
             f"(largest residual {f['time_s']['max_residual']:.0f} s; 4 and 8 ranks ran oversubscribed on 2 cores, so "
             f"the time's slope is high). Assumptions: {settings}, a rank's cost grows with "
             "its spheres alone (its pieces' planes and layers are a few per cent), each rank has one core and its "
             "memory to itself, and the pack stage (one process) and simpleFoam (850 bytes per polyhedron together, "
             f"mesh_stage.hpp) are not counted. Not measured outside {low:.0f} to {high:.0f} spheres per rank or past 8 "
             "ranks (where the free fit's intercept came out negative, the line is taken through the origin). The pieces are "
             f"axial slabs, whose thickness goes as the spheres per rank over the column's cross-section: the measured "
             f"slabs were no thinner than {low:.0f} spheres' worth at a = {a:g}, and the last column gives the widest "
             "column (a = D / d) whose slabs stay as thick; a wider bed on that many ranks has thinner slabs, more of "
             "its cost in the planes, and wants blocks (not made yet).", "",
             "| spheres | ranks | spheres per rank | largest rank's peak (GB) | its time (s) | widest column (a) |",
             "|---|---|---|---|---|---|"]
    for t in r["table"]:
        widest = f"{t['widest_a']:.0f}" if "widest_a" in t else ""
        lines.append(f"| {t['spheres']:.0e} | {t['ranks']} | {t['per_rank']:.0f} | {t['peak_gb']:.1f} | {t['time_s']:.0f} | "
                     f"{widest} |")
    lines.append("")
    return lines


def rank_columns(r, reference):
    """A pieces row's columns shared by the pieces sections: its largest rank's peak (MB), that peak over
    `reference`'s scaled by reference's ranks / P (1 where it falls as 1/P; blank without a reference), the
    ranks' times (s) and checkMesh's verdict (with the reconstructed mesh's where checked)."""
    peak = largest_peak(r)
    scaled = f"{peak_over_1_by_p(r, reference):.2f}" if reference else ""
    times = "-".join(f"{t:.0f}" for t in (min(k["time_s"] for k in r["ranks"]), max(k["time_s"] for k in r["ranks"])))
    check = "" if r["pieces"] == 1 else "OK" if r["check_mesh_ok"] else "FAILED: " + "; ".join(r["check_mesh_failed"])
    if "reconstructed" in r:
        w = r["reconstructed"]
        check += (f"; reconstructed ({w['reconstruct_s']:.0f} s): {'OK' if w['mesh_ok'] else 'FAILED'}, "
                  f"{w['cells']} cells ({w['check_mesh_s']:.0f} s)")
    return f"{peak:.0f}", scaled, times, check


def peak_over_1_by_p(r, reference):
    """r's largest rank's peak over reference's scaled by reference's ranks / r's: 1 where it falls as 1/P."""
    return largest_peak(r) / (largest_peak(reference) * reference["pieces"] / r["pieces"])


def one_over_p_line(rows, reference, verdict):
    """The target line 'the largest rank's peak falls as 1/P within 20 % up to 8 ranks' against `reference`."""
    p0 = reference["pieces"]
    ratios = [(r["pieces"], peak_over_1_by_p(r, reference)) for r in rows if p0 < r["pieces"] <= 8]
    if not ratios:
        return []
    against = "1/P of one rank's" if p0 == 1 else f"{p0}/P of {p0} ranks'"
    return [f"- The largest rank's peak falls as 1/P within 20 % from {p0} to 8 ranks (against {against}): " +
            ", ".join(f"{x:.2f} at {p}" for p, x in ratios) + f", {verdict(all(0.8 <= x <= 1.2 for _, x in ratios))}."]


def one_piece_peaks(one):
    """The one-piece run's peaks (MB) in a pieces table: its mesh stage's and its case stage's (the dual)."""
    return f"{one['stage_peak_mb'].get('mesh', 0):.0f} (mesh stage), {one['stage_peak_mb'].get('case', 0):.0f} (case stage)"


def pieces_lines(rows):
    """Issue 58's section: one piece (when run) against P pieces on P ranks, and its targets as far as measured."""
    one = next((r for r in rows if r["pieces"] == 0), None)
    spheres = rows[0].get("spheres", 500)  # rows before the bed size was recorded: the default bed's
    treatment = rows[0].get("treatment", "shrink")  # rows before it was recorded: shrink
    cut = treatment in ("bridge", "cap", "enlarge")
    # Rows made before the mesh was recorded: the default scene's of then, polyhedra at 0.15 d, 4 per gap.
    kind, edge, per_gap = rows[0].get("cells_kind", "polyhedra"), rows[0].get("edge_d", 0.15), rows[0].get("cells_per_gap", 4.0)
    dual = kind == "polyhedra"
    title = ((f"## A case in pieces, one per rank, {treatment} contacts cut through at the planes: memory, time and "
              "the pressure drop (issue 58)" if cut else
              "## A case in pieces, one per rank: memory, time and the pressure drop (issue 58)") if one else
             f"## A case in pieces on a bed of {spheres} spheres: the memory per rank (issue 58)")
    how = {"shrink": "contacts shrunk (the only treatment pieces could cut when this section was first made)",
           "none": "contacts untreated"}.get(treatment, f"contacts.treatment = \"{treatment}\" (each rank's window "
                                                         "holds its spheres whole and cuts them, and the contacts, "
                                                         "at its planes)")
    lines = [title, "",
             f"Made at {rows[0]['commit']} on {rows[0]['date']}. scenes/default.toml (a = 5, N = {spheres}, seed 1, "
             f"{edge:.3g} d, {per_gap:.3g} cells per gap, {kind}) with {how}, one mesh. " +
             (f"*One piece*: the run as today, its mesh stage then its case stage{' (the dual)' if dual else ''} and the "
              "solve. " if one else "The case written, not solved. ") +
             "*P pieces*: `[mesh] pieces = P`, the run writes the case and starts `mpirun -np P bedforge piece`, each "
             f"rank meshing its slab{', making its dual' if dual else ''} and writing `processorK`" +
             ("; P = 1 is one rank's piece of the one-piece run's case" if any(r["pieces"] == 1 for r in rows) else "") +
             ". Ranks beyond the 2 cores are oversubscribed, so their times are not a speed-up." +
             (" dp/L on 2 ranks (solved in pieces, no decomposePar) against one piece's." if one else ""), "",
             "| route | {1} | largest rank's peak (MB) | x {0}/P of P = {0} | ranks' time (s) | run's wall time (s) | "
             "checkMesh | dp/L (Pa/m) |".format(min((r["pieces"] for r in rows if r["pieces"] >= 1), default=1), kind),
             "|---|---|---|---|---|---|---|---|"]
    # The peaks are held against the fewest ranks run: one rank, or where one rank's piece would not fit, two.
    fewest = min((r for r in rows if r["pieces"] >= 1), key=lambda r: r["pieces"], default=None)
    if one:
        lines.append(f"| one piece | {one['cells']} | {one_piece_peaks(one)} | | | {one['wall_s']:.0f} | | "
                     f"{one.get('dp_pa_m', float('nan')):.4g} |")
    for r in rows:
        if r["pieces"] < 1:
            continue
        peak, scaled, times, check = rank_columns(r, fewest)
        solved_here = "dp_pa_m" in r and r["pieces"] > 1  # rows of P = 1 made before it was left out held the one piece's
        dp = (f"{r['dp_pa_m']:.4g} ({100 * (r['dp_pa_m'] / one['dp_pa_m'] - 1):+.2f} %)" if solved_here else
              f"diverged: {diverged_where(r)}" if "diverged" in r else "")
        lines.append(f"| {r['pieces']} piece{'s' if r['pieces'] > 1 else ''} | {r['cells']} | {peak} | {scaled} | "
                     f"{times} | {r['wall_s']:.0f} | {check} | {dp} |")
    lines += ["", "Issue 58's targets as far as this bed goes (its own bed, a = 14, N = 1e4 with bridges, has its "
              "section below when made: \"Issue 58's bed in pieces\"):", ""]
    verdict = lambda ok: "**met**" if ok else "**not met**"
    two = next((r for r in rows if r["pieces"] == 2 and "dp_pa_m" in r), None)
    if two and one and "dp_pa_m" in one:
        change = 100 * (two["dp_pa_m"] / one["dp_pa_m"] - 1)
        lines.append(f"- dp/L on 2 ranks within 0.5 % of one piece's: {change:+.2f} %, {verdict(abs(change) <= 0.5)}; "
                     f"the cells differ by {two['cells'] - one['cells']:+d} ({100 * (two['cells'] / one['cells'] - 1):+.2f} %: "
                     "gmsh's threads make other tetrahedra on each run, and the pieces' planes change the cells "
                     "beside them; this run does not tell the two apart).")
        if "solver_peak_mb" in two and "solver_peak_mb" in one:
            lines.append(f"- The solve: simpleFoam's largest process {two['solver_peak_mb']:.0f} MB on 2 pieces against "
                         f"{one['solver_peak_mb']:.0f} MB on one piece decomposed; scene to dp/L {two['wall_s']:.0f} s "
                         f"against {one['wall_s']:.0f} s (one run each).")
    if fewest:
        lines += one_over_p_line(rows, fewest, verdict)
    checked = [r for r in rows if r["pieces"] > 1]
    if checked:
        lines.append(f"- checkMesh on the pieces (parallel, no decomposePar): "
                     f"{verdict(all(r['check_mesh_ok'] for r in checked))} "
                     f"({', '.join(str(r['pieces']) + ': ' + ('OK' if r['check_mesh_ok'] else 'failed') for r in checked)}).")
    lines.append("")
    return lines


def pieces_1e4_lines(rows):
    """Issue 58's own bed in pieces: each route's ranks, and the issue's targets for it."""
    one = next(r for r in rows if r["pieces"] == 0)
    two = next((r for r in rows if r["pieces"] == 2), None)
    one_peak = one["stage_peak_mb"]["mesh"]
    lines = ["## Issue 58's bed in pieces: a = 14, N = 1e4, bridges, 1 to 8 ranks", "",
             f"Made at {rows[0]['commit']} on {rows[0]['date']}. The bed: {BED_1E4}. *One piece*: the "
             "run as before pieces, its mesh stage holding the whole mesh. *P pieces*: `[mesh] pieces = P`, the run "
             "writes the case and starts `mpirun -np P bedforge piece`, each rank cutting, meshing and writing its "
             "slab as `processorK` (P = 1: one rank's piece of the one-piece run's case). Ranks beyond the 2 cores are "
             "oversubscribed, so their times are not a speed-up. checkMesh: `mpirun -np P checkMesh -parallel` on "
             "the pieces as written, no decomposePar" +
             ("; where marked, the pieces joined by `reconstructParMesh -constant` and checked whole" if any(
                 "reconstructed" in r for r in rows) else "") + ".", "",
             "| route | tetrahedra | largest rank's peak (MB) | each rank's peak (MB) | x 2/P of 2 ranks' | ranks' time (s) "
             "| run's wall time (s) | checkMesh |",
             "|---|---|---|---|---|---|---|---|"]
    lines.append(f"| one piece | {one['cells']} | {one_peak:.0f} (mesh stage) | | | | {one['wall_s']:.0f} | |")
    for r in rows:
        if r["pieces"] < 1:
            continue
        peak, scaled, times, check = rank_columns(r, two)
        each = ", ".join(f"{k['peak_mb']:.0f}" for k in r["ranks"])
        lines.append(f"| {r['pieces']} piece{'s' if r['pieces'] > 1 else ''} | {r['cells']} | {peak} | {each} | "
                     f"{scaled} | {times} | {r['wall_s']:.0f} | {check} |")
    verdict = lambda ok: "**met**" if ok else "**not met**"
    lines += ["", "Issue 58's targets on this bed:", ""]
    four = next((r for r in rows if r["pieces"] == 4), None)
    if four:
        # The issue's figure: the one-piece mesh stage of 2026-11-26 (scale_1e4), 14.2 GB.
        issue_gb = 14.2
        peak_gb = largest_peak(four) / 1024
        lines.append(f"- 4 ranks: the largest rank's peak at most a third of the one-piece route's {issue_gb} GB (the "
                     f"issue's figure): {peak_gb:.2f} GB, {peak_gb / issue_gb:.2f} of it, "
                     f"{verdict(peak_gb <= issue_gb / 3)}; {largest_peak(four) / one_peak:.2f} of the one-piece mesh "
                     f"stage measured in the same run ({one_peak / 1024:.1f} GB). The case runs in parallel without decomposePar "
                     f"(checkMesh -parallel: {'OK' if four['check_mesh_ok'] else 'failed'})" +
                     (f"; checkMesh on the reconstructed mesh: {verdict(four['reconstructed']['mesh_ok'])}"
                      if "reconstructed" in four else "") + ".")
    if two:
        lines += one_over_p_line(rows, two, verdict)
    cells = [r for r in rows if r["pieces"] >= 2]
    if cells:
        lines.append("- The pieces' tetrahedra against the one piece's: " +
                     ", ".join(f"{r['pieces']} pieces {100 * (r['cells'] / one['cells'] - 1):+.2f} %" for r in cells) +
                     " (the planes' cut faces; gmsh's threads also make other tetrahedra on each run).")
    lines += ["- dp/L within 0.5 % of the one-piece route's, and scene to dp/L on 2 ranks no slower than one piece: "
              "not measurable at this edge here (simpleFoam would need some 37 GB); at 0.15 d in the next section "
              "(\"Issue 58's bed solved in pieces\").", ""]
    return lines


def pieces_1e4_solved_lines(rows):
    """Issue 58's bed solved in one piece and in pieces: dp/L, scene to dp/L, memory and checkMesh, and the issue's
    targets that need the solve."""
    one = next(r for r in rows if r["pieces"] == 0)
    # Rows made before the mesh was recorded: polyhedra at 0.15 d (BED_1E4_SOLVED).
    kind, edge = rows[0].get("cells_kind", "polyhedra"), rows[0].get("edge_d", 0.15)
    tets = kind == "tetrahedra"
    bed = (BED_1E4_SOLVED if not tets else
           f"a = 14, seed 1, bridges, surface edge {edge:g} d ("
           + (f"{rows[0]['contact_edge_d']:g} d" if "contact_edge_d" in rows[0] else "the default 0.05 d")
           + " where contacts meet), no refinement "
           "across gaps, gmsh's tetrahedra as the case's cells (those of scenes/default.toml), Re_p = 1, solved")
    lines = [f"## Issue 58's bed solved in pieces: a = 14, N = 1e4, bridges, {edge:g} d"
             + (", tetrahedra" if tets else "") + ", one piece against 2 and 4 ranks", "",
             f"Made at {rows[0]['commit']} on {rows[0]['date']}. The bed: {bed}; at {edge:g} d, not the 0.1 d "
             "of the section above, because simpleFoam on the 0.1 d mesh would need some 37 GB here"
             + (" (3.4 kB per tetrahedron; docs/findings.md, 2026-12-05)" if tets else "") + ". *One piece*: the run "
             "as before pieces (its mesh stage, the case stage" + ("" if tets else "'s dual") + ", decomposePar, "
             "simpleFoam on 2 processes). *P pieces*: `[mesh] pieces = P`, each rank cutting, meshing and writing its "
             f"slab's {kind} as `processorK`, then simpleFoam on the P pieces as written (no decomposePar); 4 ranks run "
             "oversubscribed on the 2 cores. Scene to dp/L: the whole `bedforge run`, packing included, one run after "
             "the other. checkMesh: Allrun's, `-parallel` on the pieces; where marked, the pieces joined by "
             "`reconstructParMesh -constant` and checked whole.", "",
             f"| route | {kind} | largest mesh process (MB) | simpleFoam, largest process (MB) | simpleFoam (s) | "
             "scene to dp/L (s) | checkMesh | dp/L (Pa/m) |",
             "|---|---|---|---|---|---|---|---|"]
    lines.append(f"| one piece, 2 processes | {one['cells']} | {one_piece_peaks(one)} | {one['solver_peak_mb']:.0f} | "
                 f"{one['solve_s']:.0f} | {one['wall_s']:.0f} | | {one['dp_pa_m']:.6g} |")
    for r in rows:
        if r["pieces"] < 2:
            continue
        _, _, _, check = rank_columns(r, None)
        if "diverged" in r:
            lines.append(f"| {r['pieces']} pieces on {r['pieces']} ranks | {r['cells']} | {largest_peak(r):.0f} (a rank) | "
                         f"| diverged: {diverged_where(r)} | {r['wall_s']:.0f} (stopped) | {check} | |")
            continue
        lines.append(f"| {r['pieces']} pieces on {r['pieces']} ranks | {r['cells']} | {largest_peak(r):.0f} (a rank) | "
                     f"{r['solver_peak_mb']:.0f} | {r['solve_s']:.0f} | {r['wall_s']:.0f} | {check} | "
                     f"{r['dp_pa_m']:.6g} ({100 * (r['dp_pa_m'] / one['dp_pa_m'] - 1):+.3f} %) |")
    verdict = lambda ok: "**met**" if ok else "**not met**"
    lines += ["", f"Issue 58's targets that need the solve, on this bed at {edge:g} d:", ""]
    for p in (4, 2):
        r = next((r for r in rows if r["pieces"] == p), None)
        if r is None:
            continue
        if "diverged" in r:
            lines.append(f"- dp/L on {p} ranks within 0.5 % of the one-piece route's: **not met**, the solve diverged "
                         f"and bedforge stopped it ({diverged_where(r)}; its fields are written there); the {kind} "
                         f"differ from one piece's by {r['cells'] - one['cells']:+d} "
                         f"({100 * (r['cells'] / one['cells'] - 1):+.2f} %).")
            continue
        change = 100 * (r["dp_pa_m"] / one["dp_pa_m"] - 1)
        lines.append(f"- dp/L on {p} ranks within 0.5 % of the one-piece route's: {change:+.3f} %, "
                     f"{verdict(abs(change) <= 0.5)}; the {kind} differ by {r['cells'] - one['cells']:+d} "
                     f"({100 * (r['cells'] / one['cells'] - 1):+.2f} %: the planes' cut faces"
                     + ("" if tets else " and whole dual cells across them")
                     + ", and gmsh's threads make other tetrahedra on each run).")
    four = next((r for r in rows if r["pieces"] == 4 and "reconstructed" in r), None)
    if four:
        lines.append(f"- 4 ranks: the case runs in parallel without decomposePar (checkMesh -parallel: "
                     f"{'OK' if four['check_mesh_ok'] else 'failed'}); checkMesh on the reconstructed mesh: "
                     f"{verdict(four['reconstructed']['mesh_ok'])}.")
    two = next((r for r in rows if r["pieces"] == 2 and "diverged" not in r), None)
    if two:
        lines.append(f"- Scene to dp/L on 2 ranks no slower than today's one-piece route: {two['wall_s']:.0f} s against "
                     f"{one['wall_s']:.0f} s, {two['wall_s'] / one['wall_s']:.2f} times, "
                     f"{verdict(two['wall_s'] <= one['wall_s'])} (one run each; simpleFoam "
                     f"{two['solve_s']:.0f} s against {one['solve_s']:.0f} s, the rest meshing"
                     + ("" if tets else ", the dual") + " and, for the one piece, decomposePar).")
    lines.append("")
    return lines


def diverged_where(row):
    """Where a diverged row's solve turned back and stopped, from bedforge's message."""
    m = re.search(r"initial residual of (\w+) rose from ([\d.e+-]+) at iteration (\d+) to ([\d.e+-]+) at iteration (\d+)"
                  r".*?stopped at iteration (\d+)", row["diverged"], re.S)
    if not m:
        return row["diverged"].splitlines()[0]
    return (f"{m.group(1)}'s residual from {m.group(2)} (iteration {m.group(3)}) to {m.group(4)} (iteration "
            f"{m.group(5)}), stopped at iteration {m.group(6)}")


def largest_peak(row):
    return max(k["peak_mb"] for k in row["ranks"])


def stamp(rows):
    """The line that says which code made a section: its commit and date, or that it predates them."""
    return [made_line(rows, "Made before this script recorded commits and dates, on gmsh's tetrahedra (before 3d88d5a "
                            "made the polyhedral dual the default, see the Verification section): not regenerated "
                            "since."), ""]


def made(r):
    """A study row's commit and date, marked when its levels were not refined alike."""
    return f"{r['commit']} {r['date']}" + (" (gaps not coarsened)" if gaps_not_coarsened(r) else "")


def study_lines(r):
    """A convergence study's section: its levels against E&S, the verdict, and the extrapolation
    when the levels are in the asymptotic range."""
    st = r["study"]
    gaps = r.get("cells_per_gap", 0)
    lines = [f"## a = {r['a']}, N = {r['n']}, {r['treatment']}" + (f", {gaps:g} cells across narrow gaps" if gaps else "")
             + f", Re_p = {r.get('reynolds', 1.0):g}: mesh-convergence study ([case.convergence])", "",
             f"Made at commit {r['commit']} on {r['date']}: one `bedforge run` whose finest mesh has a surface "
             f"edge of {r['edge_d']} d, {len(st['levels'])} levels, ratio {r['ratio']}; scene to extrapolated "
             f"pressure drop in {r['wall_s'] / 60:.1f} min wall, peak {r['peak_mb'] / 1024:.1f} GB."
             + (f" Made before {GAPS_COARSENED_FROM}: its coarser levels kept cells_per_gap, so the gaps' cells were "
                "the same on every level, the levels were not refined alike, and the order, extrapolation and GCI "
                "below rest on the rest of the mesh alone." if gaps_not_coarsened(r) else ""), "",
             "| level | lengths x | cells | h / d | h / finer h | dp/L (Pa/m) | / E&S at the bed's eps | "
             "/ E&S at the finest mesh's eps | walls' share of the drag | momentum balance | time (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]

    def bed_ratio(dp):  # runs before the bed's eps was recorded (before a877da4) have none
        return f"{dp / r['es_bed_pa_m']:.3f}" if "es_bed_pa_m" in r else "not recorded"

    finer = None
    for lv in st["levels"]:
        if "failure" in lv:
            lines.append(f"| {lv['level']} | {lv['scale']:.3g} | failed: {lv['failure']} | | | | | | | | "
                         f"{lv['time_s']:.0f} |")
            finer = None
            continue
        step = f"{lv['cell_size_m'] / finer:.3f}" if finer else ""
        finer = lv["cell_size_m"]
        lines.append(f"| {lv['level']} | {lv['scale']:.3g} | {lv['cells']} | {lv['cell_size_m'] / r['d_m']:.4f} | {step} | "
                     f"{lv['pressure_gradient_bed_pa_m']:.4g} | "
                     f"{bed_ratio(lv['pressure_gradient_bed_pa_m'])} | "
                     f"{lv['pressure_gradient_bed_pa_m'] / r['es_pa_m']:.3f} | {drag_share(lv)} | {drag_balance(lv)} | "
                     f"{lv['time_s']:.0f} |")
    if "wall_share_es" in r:
        lines += ["", f"The walls' share of the drag is OpenFOAM's force on them over the force on walls and particles "
                      f"(the whole domain); their share of the wetted area at the bed's void fraction, which is what "
                      f"Eisfeld & Schnitzlein's wall term A_w gives them, is {100 * r['wall_share_es']:.1f} %. The "
                      f"momentum balance is that drag over the push through inlet and outlet, less 1."]
    lines += ["", f"Verdict: {st['conclusion']}."]
    g = st.get("grid_convergence", {})
    if g.get("extrapolated") is not None and g.get("asymptotic", g.get("apparent_order", 0) >= 1):
        lines += [f"Extrapolated dp/L {g['extrapolated']:.4g} Pa/m = {g['extrapolated'] / r['es_bed_pa_m']:.3f} x "
                  f"Eisfeld & Schnitzlein at the bed's exact section void fraction {r['eps_section_bed']:.4f}; "
                  f"apparent order {g['apparent_order']:.2f}; GCI of the finest mesh {100 * g['gci_fine']:.1f} % "
                  f"(target: at most 5 %); asymptotic-range ratio GCI_32 / (r^p GCI_21) "
                  f"{g['asymptotic_ratio']:.3f} (1 in the asymptotic range)."]
    lines += [""]
    return lines


def route(r):
    """A cost run's cells and, where set, its spheres' facets (runs before 2026-12-06 were inscribed)
    and its prism layers, named with the run's own surface lengths."""
    return r["cells"] + (", facets holding the spheres' volume" if r.get("sphere_facets") == "volume" else "") + \
        (f", {r['layers']} prism layers of {r['layer_thickness_d']:g} d in all (edge {r['edge_d']:g} d, contact edge "
         f"{r['contact_edge_d']:g} d)" if r.get("layers") else "")


def finest_solved(r):
    """A study run's finest level that did not fail, or None."""
    return next((lv for lv in r["study"]["levels"] if "failure" not in lv), None)


def band_agreement_lines(runs, fits):
    """Issue 57's target that the new mesh's extrapolation (the last route's) and today's agree
    within their bands: each band the finest level's dp/L +- its GCI (Celik et al. 2008), the
    new route's against each other route's."""
    def band(r):
        g = fits(r)[0]
        finest = finest_solved(r)
        if g.get("gci_fine") is None or finest is None:
            return None
        dp = finest["pressure_gradient_bed_pa_m"]
        return dp * (1 - g["gci_fine"]), dp * (1 + g["gci_fine"])

    new = runs[-1]
    lines = [f"Issue 57's target that the extrapolations of the new mesh ({route(new)}) and of today's agree within "
             "their bands (each the finest level's dp/L +- its GCI, the band Celik et al. 2008 give the finest "
             "solution; the extrapolation lies inside it):", ""]
    for r in runs[:-1]:
        a, b = band(new), band(r)
        if a is None or b is None:
            lines.append(f"- against {route(r)}: no band for " + (route(new) if a is None else route(r)) + ": not met.")
            continue
        overlap = a[0] <= b[1] and b[0] <= a[1]
        lines.append(f"- against {route(r)}: {a[0]:.4g}-{a[1]:.4g} Pa/m and {b[0]:.4g}-{b[1]:.4g} Pa/m: "
                     + ("**met** (they overlap)." if overlap else "**not met** (apart)."))
    return lines


def cost_lines(runs):
    """Issue 57's cost curve on one bed: each route's levels as error against the best
    extrapolation, against cells and seconds per sphere; the route whose band is narrowest gives
    the reference."""
    def fits(r):
        st = r["study"]
        return st.get("grid_convergence", {}), st.get("least_squares", {})

    usable = [r for r in runs if fits(r)[0].get("extrapolated") is not None and fits(r)[0].get("gci_fine") is not None]
    best = min(usable, key=lambda r: fits(r)[0]["gci_fine"]) if usable else None
    r0 = runs[0]
    n = r0["n"]
    routes = [route(r) for r in runs]
    lines = [f"## Cost per sphere: {', '.join(routes[:-1])} against {routes[-1]} (a = {r0['a']:g}, N = {n}, "
             f"{r0['treatment']}, Re_p = {r0['reynolds']:g}, from {r0['edge_d']:g} d, ratio {r0['ratio']:g})", "",
             f"Made at commit {r0['commit']} on {r0['date']}: "
             + (f"the README's scene, scenes/default.toml, with its bed changed to a = {r0['a']:g}, N = {n}"
                + (", issue 57's bed" if n == 40 else "") if r0.get("bed_changed")
                else ("issue 57's bed" if r0.get("seed", 1) == 1 else "issue 57's tube and count") if n == 40 else "the README's scene, scenes/default.toml as it is"
                if r0.get("default_scene") else "the README's bed at the mesh settings scenes/default.toml had until "
                "2026-12-04, when its cells were polyhedra")
             + f" (seed {r0.get('seed', 1)}), one `bedforge run` per route with "
             f"a study of {len(r0['study']['levels'])} levels, ratio {r0['ratio']}, from a surface edge of "
             f"{r0['edge_d']} d, contact edge "
             # scene() sets a third of the edge; the default scene its own (rows before 2026-12-05: a third).
             + (f"{r0['contact_edge_d']:g} d" if "contact_edge_d" in r0 else "a third")
             + f", {r0['cells_per_gap']:g} cells per gap, on 2 processes; "
             + ("`case.cells` and `surface.sphere_facets` (inscribed: vertices on the spheres; volume: moved out so "
                "that the facets hold each sphere's volume) the only differences"
                if any(r.get("sphere_facets") for r in runs) else "`case.cells` the only difference")
             + ("; a route with prism layers has its own surface lengths, named in it (its study's levels decide "
                "their stacks at the coarsest level's lengths, so that every level layers the same region)"
                if any(r.get("layers") and mesh_settings(r) != mesh_settings(r0) for r in runs) else "")
             + ". Seconds per sphere are a level's wall time (surface, mesh, case and "
             "solve) on the 2 cores over N; core-seconds are at most twice that. The reference is the extrapolation "
             "with the narrowest GCI band"
             + (f": that of the {route(best)}, {fits(best)[0]['extrapolated']:.4g} Pa/m (GCI "
                f"{100 * fits(best)[0]['gci_fine']:.1f} %)." if best else "; no route gave one."), "",
             "| cells | level | cells per sphere | dp/L (Pa/m) | against the reference | s per sphere (2 cores) |",
             "|---|---|---|---|---|---|"]
    ref = fits(best)[0]["extrapolated"] if best else None
    for r in runs:
        for lv in r["study"]["levels"]:
            if "failure" in lv:
                lines.append(f"| {route(r)} | {lv['level']} | failed: {lv['failure']} | | | {lv['time_s'] / n:.1f} |")
                continue
            dp = lv["pressure_gradient_bed_pa_m"]
            lines.append(f"| {route(r)} | {lv['level']} | {lv['cells'] / n:,.0f} | {dp:.4g} | "
                         + (f"{100 * (dp / ref - 1):+.1f} %" if ref else "") + f" | {lv['time_s'] / n:.1f} |")
    lines += ["", "| cells | finest level's GCI | order, finest three | least squares over all: order, extrapolation "
                  "| extrapolation (Pa/m) | issue 57's targets (GCI <= 5 %, <= 20 k cells per sphere, order 1.5-2.5 "
                  "by the finest three and by least squares over all, the two within 0.3) |", "|---|---|---|---|---|---|"]
    for r in runs:
        g, ls = fits(r)
        finest = finest_solved(r)
        if g.get("gci_fine") is None or finest is None:
            lines.append(f"| {route(r)} | none: {r['study']['conclusion']} | | | | not met |")
            continue
        per_sphere = finest["cells"] / n
        gap = abs(ls["order"] - g["apparent_order"]) if ls.get("order") is not None else None
        missed = ([f"GCI {100 * g['gci_fine']:.1f} %"] if g["gci_fine"] > 0.05 else []) + \
                 ([f"{per_sphere / 1000:.1f} k cells per sphere"] if per_sphere > 20000 else []) + \
                 ([f"order {g['apparent_order']:.2f}"] if not 1.5 <= g["apparent_order"] <= 2.5 else []) + \
                 ([f"least-squares order {ls['order']:.2f}"] if ls.get("order") is not None and
                  not 1.5 <= ls["order"] <= 2.5 else []) + \
                 ([f"orders {gap:.2f} apart" if gap is not None else "no least-squares fit"]
                  if gap is None or gap > 0.3 else [])
        lines.append(f"| {route(r)} | {100 * g['gci_fine']:.1f} % | {g['apparent_order']:.2f} | "
                     + (f"{ls['order']:.2f}, {ls['extrapolated']:.4g}" if ls.get("order") is not None else "none")
                     + f" | {g['extrapolated']:.4g} | " + ("met" if not missed else "not met: " + ", ".join(missed)) + " |")
    lines += [""] + band_agreement_lines(runs, fits)
    if not r0.get("default_scene") or r0.get("bed_changed"):
        return lines + [""]
    # The README's scene is the bed of issue 57's target on this machine.
    lines += ["", "Issue 57's target on this machine (GCI of the finest mesh <= 15 %, scene to extrapolated pressure "
                  "drop <= 15 minutes, the study's peak <= 12 GB; that peak taken as at most twice the run's largest "
                  "process: the solver's 2 processes hold about the same each, and no other stage runs beside them):",
              ""]
    for r in runs:
        gci = fits(r)[0].get("gci_fine")
        whole_gb = 2 * r["peak_mb"] / 1024
        missed = ([f"GCI {100 * gci:.1f} %" if gci is not None else "no GCI"] if gci is None or gci > 0.15 else []) + \
                 ([f"{r['wall_s'] / 60:.1f} min"] if r["wall_s"] > 15 * 60 else []) + \
                 ([f"at most {whole_gb:.1f} GB"] if whole_gb > 12 else [])
        lines.append(f"- {route(r)}: GCI " + (f"{100 * gci:.1f} %" if gci is not None else "none")
                     + f", {r['wall_s'] / 60:.1f} min, at most {whole_gb:.1f} GB (largest process {r['peak_mb']:.0f} MB): "
                     + ("**met**" if not missed else "**not met** (" + ", ".join(missed) + ")") + ".")
    return lines + [""]


def mesh_settings(r):
    """The mesh settings a cost run was made with, which must agree for beds to be compared."""
    return tuple(r.get(k) for k in ("edge_d", "contact_edge_d", "cells_per_gap", "ratio")) + \
        (len(r["study"]["levels"]),)


def beds_lines(beds):
    """Issue 57's item 3 across beds: on each bed (a list of cost runs, one per route, all at the
    README's scene's mesh settings) each route's finest GCI, order, extrapolation and cost, and the
    route with the narrowest band; the default is the route scenes/default.toml sets."""
    r0 = beds[0][0]
    made_on = lambda r: f"{r['commit']} on {r['date']}"
    lines = [f"## Cost per sphere from bed to bed: the README's scene's mesh on {len(beds)} beds (issue 57, item 3)", "",
             "Made " + "; ".join(f"at commit {stamp} for " + " and ".join(
                 f"a = {runs[0]['a']:g}, N = {runs[0]['n']}" for runs in beds if made_on(runs[0]) == stamp)
                                 for stamp in dict.fromkeys(made_on(runs[0]) for runs in beds))
             + f": scenes/default.toml's mesh and study (surface edge {r0['edge_d']:g} d, contact edge "
             f"{r0['contact_edge_d']:g} d, {r0['cells_per_gap']:g} cells per gap, {len(r0['study']['levels'])} levels, "
             f"ratio {r0['ratio']:g}; seed {r0.get('seed', 1)}, {r0['treatment']}, Re_p = {r0['reynolds']:g}) on beds from "
             f"N = {beds[0][0]['n']} to N = {beds[-1][0]['n']}, each route as in the sections above; the default route "
             "is the scene's own (tetrahedra, facets holding the spheres' volume, no layers). GCI of the finest mesh "
             "(Celik et al. 2008); cost on the finest level, per sphere.", "",
             "| bed | route | finest cells per sphere | finest s per sphere | GCI | order, finest three | extrapolation "
             "(Pa/m) | whole run (min) |", "|---|---|---|---|---|---|---|---|"]
    verdicts = []
    for runs in beds:
        bed = f"a = {runs[0]['a']:g}, N = {runs[0]['n']}"
        gcis = {}
        for r in runs:
            g = r["study"].get("grid_convergence", {})
            finest = finest_solved(r)
            if finest is None or g.get("gci_fine") is None:
                lines.append(f"| {bed} | {route(r)} | | | none: {r['study']['conclusion']} | | | {r['wall_s'] / 60:.1f} |")
                continue
            gcis[route(r)] = (g["gci_fine"], (r["cells"], r.get("sphere_facets"), r.get("layers", 0)) == DEFAULT_ROUTE)
            lines.append(f"| {bed} | {route(r)} | {finest['cells'] / r['n']:,.0f} | {finest['time_s'] / r['n']:.1f} | "
                         f"{100 * g['gci_fine']:.1f} % | {g['apparent_order']:.2f} | {g['extrapolated']:.4g} | "
                         f"{r['wall_s'] / 60:.1f} |")
        if gcis:
            best = min(gcis, key=lambda k: gcis[k][0])
            verdicts.append(f"- {bed}: narrowest band {100 * gcis[best][0]:.1f} %, on {best}"
                            + (", the default." if gcis[best][1] else "; the default's: "
                               + ", ".join(f"{100 * v[0]:.1f} %" for v in gcis.values() if v[1]) + "."))
    return lines + [""] + verdicts + [""]


def error_seat_lines(r):
    """Issue 57's item 1 on one study: the drag in the bed section split by kind (walls; the
    particles' form drag, their pressure less the section's mean linear pressure, and their
    viscous drag) and the particles' by the gap at their faces, level by level: each part's changes
    between levels and its share of the finest level's error. Nothing for a study without the split."""
    levels = [lv for lv in r["study"]["levels"] if "failure" not in lv and "drag" in lv]
    if len(levels) < 3 or "particles_by_gap" not in levels[0]["drag"] or \
            "form_n" not in levels[0]["drag"]["particles_by_gap"][0]:
        return []
    g = r["study"].get("grid_convergence", {})
    ratio = r["ratio"]
    bands = levels[0]["drag"]["particles_by_gap"]
    inside = [k for k, b in enumerate(bands) if b["in_section"]]
    # The walls in the section: theirs less their ends' (runs before 2026-12-06 did not split them).
    split_walls = "walls_ends_n" in levels[0]["drag"]
    walls = "walls in the section" if split_walls else "walls (whole)"
    ends = (lambda d: d["walls_ends_n"]) if split_walls else (lambda d: 0.0)
    ends_viscous = (lambda d: d["walls_ends_viscous_n"]) if split_walls else (lambda d: 0.0)
    parts = [(f"{walls}, pressure",
              lambda d: d["walls_n"] - d["walls_viscous_n"] - (ends(d) - ends_viscous(d)), None),
             (f"{walls}, viscous", lambda d: d["walls_viscous_n"] - ends_viscous(d), None)]
    for k in inside:
        b = bands[k]
        span = f"gap {b['gap_from_d']:g}-{b['gap_to_d']:g} d" if b["gap_to_d"] is not None \
            else f"gap beyond {b['gap_from_d']:g} d"
        parts += [(f"particles, {span}, form", lambda d, k=k: d["particles_by_gap"][k]["form_n"], k),
                  (f"particles, {span}, viscous", lambda d, k=k: d["particles_by_gap"][k]["viscous_n"], k)]
    # The section's drag less its mean pressure's share: about dp/L times the section's fluid volume.
    whole = lambda d: d["walls_n"] - ends(d) + sum(d["particles_by_gap"][k]["form_n"] + d["particles_by_gap"][k]["viscous_n"]
                                         for k in inside)
    s1 = whole(levels[0]["drag"])
    area1 = sum(bands[k]["area_m2"] for k in inside)
    p = g.get("apparent_order")
    factor = ratio ** p - 1.0 if p else None  # Richardson with the pressure drop's own order
    err_whole = -(s1 - whole(levels[1]["drag"])) / factor if factor else None
    names = ", ".join(f"{lv['level'] + 1} to {lv['level']}" for lv in reversed(levels[:-1]))
    lines = [f"### Where the error sits: {route(r)} (issue 57, item 1)", "",
             f"Made at commit {r['commit']} on {r['date']}, the same run as the cost table above, with "
             f"`case.drag_by_gap_d = {GAP_BANDS_D}`: the particles' faces in the bed section (where dp/L is measured) "
             "split by the gap at their centres (to the nearest other sphere or wall); the cells are the same with "
             "and without the split. A band's faces are no closed surface, so its pressure force holds the "
             "section's mean pressure (linear between the section's planes) times their projected area; less that, "
             "its form drag. "
             + ("The walls' drag is theirs in the section (less that beyond its planes). " if split_walls
                else "The walls' forces are over the whole domain (not split). ")
             + "The parts sum to the "
             "section's drag less its mean pressure's share, about dp/L times the section's fluid volume. Changes "
             "are between successive levels, coarser to finer, over that sum on the finest level; the order of a "
             f"part is ln(change / next finer change) / ln {ratio} over the finest three; its error on the finest "
             "(finest less extrapolated) is minus its last change / (ratio^p - 1) with p "
             + (f"= {p:.2f}, the pressure drop's order; its share is of the sum's error." if p
                else "the pressure drop's order: the study gave none."), "",
             f"| part | area (of the section's particles') | share of the finest | changes, levels {names} | order "
             "| error on the finest | share of the error |",
             "|---|---|---|---|---|---|---|"]
    for name, part, k in parts + [("all (the sum)", whole, None)]:
        values = [part(lv["drag"]) for lv in levels]
        changes = [(values[i] - values[i + 1]) / s1 for i in range(len(values) - 1)]  # finer less coarser
        order = (math.log(changes[1] / changes[0]) / math.log(ratio)
                 if changes[0] != 0 and changes[1] / changes[0] > 0 else None)
        err = -changes[0] * s1 / factor if factor else None
        area = f"{100 * bands[k]['area_m2'] / area1:.1f} %" if k is not None else ""
        lines.append(f"| {name} | {area} | {100 * values[0] / s1:.1f} % | "
                     + ", ".join(f"{100 * c:+.2f} %" for c in reversed(changes)) + " | "
                     + (f"{order:.2f}" if order is not None else "-") + " | "
                     + (f"{100 * err / s1:+.2f} %" if err is not None else "") + " | "
                     + (f"{100 * err / err_whole:.0f} %" if err is not None and err_whole else "") + " |")
    dp = [lv["pressure_gradient_bed_pa_m"] for lv in levels]
    lines += ["", "Beside it, dp/L's own changes between the same levels: "
              + ", ".join(f"{100 * (dp[i] - dp[i + 1]) / dp[0]:+.2f} %" for i in reversed(range(len(dp) - 1)))
              + " of the finest's."]
    return lines + [""]


def level_drag(level, key):
    """A level's drag entry: under "drag" since 2026-12-06, at the level before; runs before
    2026-11-26 did not record it (None)."""
    return level.get("drag", {}).get(key, level.get(key + "_of_drag" if key == "wall_share" else key))


def drag_share(level):
    share = level_drag(level, "wall_share")
    return "not recorded" if share is None else f"{100 * share:.1f} %"


def drag_balance(level):
    balance = level_drag(level, "force_balance_relative_error")
    return "" if balance is None else f"{100 * balance:+.2f} %"


def study_values(r):
    """A study run's verdict on its finest three levels, its finest dp/L (None when that level
    failed) and its extrapolated dp/L (None when it has none)."""
    g = r["study"].get("grid_convergence", {})
    return g, r["study"]["levels"][0].get("pressure_gradient_bed_pa_m"), g.get("extrapolated")


def scale_lines(r):
    """The section of one scale run: each stage's time and peak, the cells and their bytes."""
    st = r["stages_s"]
    # Runs before the bed's size and treatment were recorded were all the default scene's bed.
    a, n, treatment = r.get("a", 10), r.get("n", 4000), r.get("treatment", "shrink")
    lines = [f"## Scale: a = {a}, N = {n}, {treatment}, 0.1 d, scene to case", "", *stamp(r),
             "| stage | time (s) | peak memory (MB) |", "|---|---|---|"]
    order = [k for k in ("pack", "analysis", "surface", "mesh", "case") if k in st]
    lines += [f"| {k} | {st[k]:.1f} | {r.get('stages_peak_mb', {}).get(k, float('nan')):.0f} |" for k in order]
    si = r.get("self_intersections")
    lines += [f"| whole command (wall) | {r['wall_s']:.1f} |", "",
              f"{r['cells']} cells, peak memory {r['peak_mb'] / 1024:.1f} GB ({r['peak_mb'] * 2**20 / r['cells']:.0f} "
              f"bytes per cell), checkMesh {'Mesh OK' if r['mesh_ok'] else 'FAILED'} (max non-orthogonality "
              f"{r['max_non_orthogonality']:.1f}, max skewness {r['max_skewness']:.2f}; checkMesh itself "
              f"{r['check_mesh_s']:.0f} s). Surface self-intersection test: "
              f"{'not recorded' if si is None else 'not run' if si == 'not checked' else 'none found' if si is False else 'FOUND'}. "
              f"Mesh stage attempts: {json.dumps(r['mesh_attempts'])}.", ""]
    slabs = sorted({a["slab"] for a in r["mesh_attempts"] if "slab" in a})
    if slabs:
        # The tetrahedra of each slab's attempt that passed (its last).
        gen = sum([a for a in r["mesh_attempts"] if a.get("slab") == k][-1]["time_generate_s"] for k in slabs)
        t = r["mesh_times_s"]
        where = (f"in {len(slabs)} slabs: gmsh's tetrahedra {gen:.0f} s (all slabs), the slabs' surfaces, optimiser "
                 f"passes and quality checks {t['time_slabs_s'] - gen:.0f} s, the .msh file "
                 f"{t.get('time_msh_s', 0):.0f} s, the join {t['time_join_s']:.0f} s and the joined mesh's quality "
                 f"{t['time_quality_s']:.0f} s")
    else:
        gen = r["mesh_attempts"][-1]["time_generate_s"]
        where = (f"of which gmsh's tetrahedra {gen:.0f} s and the optimiser pass with the quality checks "
                 f"{st['mesh'] - gen:.0f} s")
    lines += [f"Where the time goes: the mesh stage takes {st['mesh'] / r['wall_s']:.0%} of the run, {where}; the "
              f"surface {st['surface'] / r['wall_s']:.0%}, the packer {st['pack'] / r['wall_s']:.1%}.", ""]
    return lines


def scale_out_lines(rows):
    snappy = {r["ranks"]: r for r in rows if r["route"] == "snappy"}
    gmsh = next((r for r in rows if r["route"] == "gmsh"), None)
    if len(snappy) < 2 or gmsh is None:
        return ["## Past one machine: by the snappyHexMesh route", "", *stamp(rows),
                f"The run did not finish: {len(rows)} of its 3 routes measured (docs/mesh_case_benchmark.json).", ""]
    two, one = snappy[2], snappy[1]
    finest = two["snappy_cell_d"] / 2 ** two["snappy_level"]
    lines = [f"## Past one machine: a = {two['a']}, N = {two['n']}, {two['treatment']}, by the snappyHexMesh route", "",
             *stamp(rows),
             f"The scale_1e4 scene (surface edge {two['edge_d']} d, {two['surface_triangles']} triangles) with "
             f"`case.mesher = \"snappy\"`: no gmsh mesh is made; snappyHexMesh refines background cells of "
             f"{two['snappy_cell_d']} d to level {two['snappy_level']} at walls and particles (cells of {finest:.3g} d "
             "there), then simpleFoam solves on the decomposed cells as they are. Each step of the case's Allrun with "
             "its wall time and its largest process's peak memory (GNU time: on 2 processes, the larger rank's). "
             f"The run on 1 process stops simpleFoam after one iteration: it measures the meshing.", "",
             "| step | 2 processes: s | MB per process | 1 process: s | MB |", "|---|---|---|---|---|"]
    steps1 = {s["step"]: s for s in one["steps"]}
    for s2 in two["steps"]:
        s1 = steps1.get(s2["step"])
        lines.append(f"| {s2['step']} | {s2['time_s']:.0f} | {s2['peak_memory_mb']:.0f} | "
                     + (f"{s1['time_s']:.0f} | {s1['peak_memory_mb']:.0f} |" if s1 else "not run | |"))
    lines += ["", "| route | processes | cells | checkMesh | max non-ortho | max skewness | fluid volume against the exact "
              "| simpleFoam its | dp/L (Pa/m) | / E&S at the bed's eps | scene to result s |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in (two, one, gmsh):
        name = (f"snappyHexMesh ({r['snappy_cell_d']} d, level {r['snappy_level']})" if r["route"] == "snappy"
                else f"gmsh, surface edge {r['edge_d']} d, polyhedral dual of {r['tetrahedra']} tetrahedra")
        result = (f"{r['dp_dz_pa_m']:.4g} | {r['ratio_es_bed']:.3f}" if r["iteration_cap"] > 1
                  else "(one iteration) | ")
        its = f"{r['iterations']}" + ("" if r["converged"] or r["iteration_cap"] == 1 else ", not converged")
        volume = f"{100 * r['volume_error']:+.2f} %" if "volume_error" in r else "not recorded"
        lines.append(f"| {name} | {r['ranks']} | {r['cells']} | {'OK' if r['mesh_ok'] else 'FAILED'} | "
                     f"{r['max_non_orthogonality']:.1f} | {r['max_skewness']:.2f} | {volume} | {its} | {result} | "
                     f"{r['wall_s']:.0f} |")
    # Memory per process: what every rank holds (the surface and its search tree) and what divides
    # among the ranks (the cells), from the meshing step's peak on 1 and 2 processes.
    m1 = next(s["peak_memory_mb"] for s in one["steps"] if s["step"] == "snappyHexMesh")
    m2 = next(s["peak_memory_mb"] for s in two["steps"] if s["step"] == "snappyHexMesh")
    divided, held = 2 * (m1 - m2), 2 * m2 - m1
    sfe = next(s for s in two["steps"] if s["step"] == "surfaceFeatureExtract")
    split = (f"Read as a part every process holds and a part the processes share, that is {held:.0f} MB held by each "
             f"({held * 1e6 / two['surface_triangles']:.0f} bytes per surface triangle) and {divided:.0f} MB shared "
             f"({divided * 1e6 / two['cells']:.0f} bytes per cell): on N processes about {held:.0f} + {divided:.0f} / N MB "
             "each for this bed, both parts growing in proportion to the bed at the same settings."
             if divided > 0 and held > 0 else
             "The two peaks do not split into a part every process holds and a part they share.")
    lines += ["", f"snappyHexMesh's peak per process: {m1:.0f} MB on 1 process, {m2:.0f} MB on 2. {split} "
              f"surfaceFeatureExtract runs once, serially, on the whole surface: {sfe['time_s']:.0f} s, {sfe['peak_memory_mb']:.0f} MB. "
              f"The gmsh route on the same bed took {gmsh['wall_s']:.0f} s scene to result, its stages at a peak of "
              f"{max(gmsh['stages_peak_mb'].values()):.0f} MB in one process and OpenFOAM's at "
              f"{max(s['peak_memory_mb'] for s in gmsh['steps']):.0f} MB per process; snappyHexMesh's dp/L is "
              + (f"{two['dp_dz_pa_m'] / gmsh['dp_dz_pa_m']:.3f} times gmsh's." if two["iteration_cap"] > 1 else "not measured."),
              "", "For more processes a cluster user sets `case.processors` (or `./Allrun -np N`); the case decomposes "
              "by `hierarchical` slabs along the column (`decomposeParDict`, n = (1 1 N)); for hundreds of processes "
              "n = (a b c) with a b c = N keeps the slabs from getting thinner than a few cells, or `scotch` where the "
              "OpenFOAM build has it (Debian's ships a stub). Each process also holds the whole surface, so the part "
              "held by each sets the floor of memory per process.", ""]
    return lines


# Issue 54's targets for the default scene's answer (a rule, not tuned here): scene to answer in at
# most 10 min on this machine; the best estimate within 5 % of the finer reference; the band
# holding the reference; a GCI no wider than the study_gaps run gave at that cost (4e6b193).
DEFAULT_TARGETS = {"minutes": 10.0, "reference": 0.05, "gci": 0.327}


def default_lines(r, same_settings=None):
    """The README's path: what it printed, the levels, the reference study and the targets;
    `same_settings`, an earlier study_gaps run, whose levels' times show the machine's speed."""
    a, ref = r["answer"], r["reference"]
    g_ref = ref["study"].get("grid_convergence", {})
    lines = ["## The README's path: scenes/default.toml, from scene to answer", "",
             f"Made at commit {r['commit']} on {r['date']}: `bedforge run scenes/default.toml` as shipped "
             f"({r['treatment']} contacts, " + (f"{r['cells']}, " if "cells" in r else "") + f"surface edge {r['edge_d']:g} d, {len(r['study']['levels'])} levels of "
             f"ratio {r['ratio']:g}), {r['wall_s'] / 60:.1f} min wall from scene to answer (bed, surface, mesh, "
             f"case and every solve), peak {r['peak_mb'] / 1024:.1f} GB. It printed:", "", "```",
             *r["printed"], "```", "",
             "| level | cells | h / d | dp/L (Pa/m) | own time (s) |", "|---|---|---|---|---|"]
    for lv in r["study"]["levels"]:
        lines.append(f"| {lv['level']} | {lv.get('cells', 'failed')} | "
                     + (f"{lv['cell_size_m'] / r['d_m']:.4f} | {lv['pressure_gradient_bed_pa_m']:.4g} | {lv['own_time_s']:.0f} |"
                        if "failure" not in lv else f"| {lv['failure']} | |"))
    # Only a run with the same edge and cells times the same work (runs before 2026-12-04 recorded no cells).
    if same_settings and len(same_settings["study"]["levels"]) == len(r["study"]["levels"]) and \
            (same_settings["edge_d"], same_settings.get("cells")) == (r["edge_d"], r.get("cells")):
        then = [lv.get("own_time_s", 0) for lv in same_settings["study"]["levels"]]
        now = [lv.get("own_time_s", 0) for lv in r["study"]["levels"]]
        lines += ["", f"The study_gaps run below has these settings; made at {same_settings['commit']} on "
                      f"{same_settings['date']}, its levels' own times were {', '.join(f'{t:.0f}' for t in then)} s "
                      f"against {', '.join(f'{t:.0f}' for t in now)} s here "
                      f"({', '.join(f'{b / a:.2f}' for a, b in zip(then, now) if a > 0)} times), its whole run "
                      f"{same_settings['wall_s'] / 60:.1f} min: what the same work takes on the machine of each run."]
    lines += ["", f"Reference: the same scene with every mesh length 1 / {r['ratio']:g} of the default's (finest surface "
                  f"edge {ref['edge_d']:.4g} d) and {len(ref['study']['levels'])} levels, so its finest level is one "
                  f"ratio finer than the default's and its coarser ones repeat the default's; "
                  f"{ref['wall_s'] / 60:.1f} min. Its levels:", "",
              "| level | cells | h / d | dp/L (Pa/m) |", "|---|---|---|---|"]
    for lv in ref["study"]["levels"]:
        lines.append(f"| {lv['level']} | {lv.get('cells', 'failed')} | "
                     + (f"{lv['cell_size_m'] / r['d_m']:.4f} | {lv['pressure_gradient_bed_pa_m']:.4g} |"
                        if "failure" not in lv else f"{lv['failure']} | |"))
    lines += ["", f"Its verdict: {ref['study']['conclusion']}.", ""]
    best = a.get("best_estimate_pa_m")
    ref_value = g_ref.get("extrapolated") if g_ref.get("asymptotic") else None
    if best is None or ref_value is None:
        lines += ["Targets: not assessed: " + ("the default gave no best estimate." if best is None else
                                              "the reference study is not in the asymptotic range."), ""]
        return lines
    low, high = a["band_pa_m"]
    off = best / ref_value - 1.0
    t = DEFAULT_TARGETS
    lines += ["| target (issue 54) | measured | met |", "|---|---|---|",
              f"| scene to answer at most {t['minutes']:g} min (aim 5) | {r['wall_s'] / 60:.1f} min | "
              f"{'yes' if r['wall_s'] <= 60 * t['minutes'] else 'NO'} |",
              f"| best estimate within {100 * t['reference']:g} % of the reference (its finest three extrapolated, "
              f"{ref_value:.4g} Pa/m, GCI {100 * g_ref['gci_fine']:.1f} %) | {best:.4g} Pa/m, {100 * off:+.1f} % | "
              f"{'yes' if abs(off) <= t['reference'] else 'NO'} |",
              f"| the band holds the reference | {low:.4g} to {high:.4g} Pa/m | "
              f"{'yes' if low <= ref_value <= high else 'NO'} |",
              f"| GCI no wider than {100 * t['gci']:.1f} % (study_gaps, 7.0 min) | {100 * a['gci_fine']:.1f} % | "
              f"{'yes' if a['gci_fine'] <= t['gci'] else 'NO'} |", ""]
    return lines


def write(results):
    json.dump(results, open(RESULTS, "w"), indent=1)
    lines = ["# Volume mesh and OpenFOAM case: pressure drop against run time", "",
             "Made by `/usr/bin/python3 tools/benchmark_mesh_case.py` on the 2-core machine of the CI "
             "(Debian 12, gmsh 4.8 HXT, OpenFOAM v1912 simpleFoam on 2 MPI processes). Water, Re_p = 1, "
             "d = 3 mm; dp/L is measured between the bed-section planes (0.5 d above the floor and below "
             "the bed top); Eisfeld & Schnitzlein (2001) is evaluated at that section's meshed void "
             "fraction and aspect ratio; *finest* is the finest gmsh level.", ""]
    if "default" in results:
        lines += default_lines(results["default"], results.get("study_gaps"))
    if "sizes" in results:
        lines += ["## a = 5, N = 500, bridges: mesh size against the pressure drop", "", *stamp(results["sizes"]),
                  "| surface edge (d) | cells | surface s | mesh s | case s | simpleFoam s (its) | checkMesh | "
                  "max non-ortho | dp/L (Pa/m) | / E&S | / finest | eps section | peak MB |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        finest = min(results["sizes"], key=lambda r: r["edge_d"])["dp_dz_pa_m"]
        for r in results["sizes"]:
            r["ratio_finest"] = r["dp_dz_pa_m"] / finest
            st = r["stages_s"]
            lines.append(f"| {r['edge_d']} | {r['cells']} | {st.get('surface', 0):.1f} | {st.get('mesh', 0):.1f} | "
                         f"{st['case'] - r['solve_s']:.1f} | {r['solve_s']:.0f} ({r['iterations']}"
                         f"{'' if r['converged'] else ', not converged'}) | {'OK' if r['mesh_ok'] else 'FAILED'} | "
                         f"{r['max_non_orthogonality']:.1f} | {r['dp_dz_pa_m']:.4g} | {r['ratio_es']:.3f} | "
                         f"{r['ratio_finest']:.3f} | {r['eps_section']:.4f} | {r['peak_mb']:.0f} |")
        lines += ["", "![dp against run time](mesh_case_convergence.png)", ""]
        plot(results)
    if "gaps" in results:
        lines += ["## The same bed, refined across the narrow gaps only (`surface.cells_per_gap`)", "", *stamp(results["gaps"]),
                  "Surface edge 0.2 d, shortened to gap / cells_per_gap (not below the contact edge, 0.0667 d) "
                  "wherever a sphere or the wall faces another surface across a narrow gap.", "",
                  "| cells per gap | cells | surface s | mesh s | simpleFoam s (its) | checkMesh | max non-ortho | "
                  "dp/L (Pa/m) | / E&S | eps section | peak MB |", "|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in results["gaps"]:
            st = r["stages_s"]
            lines.append(f"| {r['cells_per_gap']:g} | {r['cells']} | {st.get('surface', 0):.1f} | {st.get('mesh', 0):.1f} | "
                         f"{r['solve_s']:.0f} ({r['iterations']}{'' if r['converged'] else ', not converged'}) | "
                         f"{'OK' if r['mesh_ok'] else 'FAILED'} | {r['max_non_orthogonality']:.1f} | "
                         f"{r['dp_dz_pa_m']:.4g} | {r['ratio_es']:.3f} | {r['eps_section']:.4f} | {r['peak_mb']:.0f} |")
        lines.append("")
    if "layers" in results:
        lines += ["## Prism layers on the particles (`[mesh.layers]`)", "", *stamp(results["layers"]),
                  "a = 4, N = 40, shrink: the bed of `scenes/examples/small_bed_flow.toml`; a = 5, N = 500, bridges: "
                  "the bed of the studies. 3 layers growing by 1.2, at most 0.2 of the "
                  "gap ahead of each stack and at least one surface edge of it left to the tetrahedra; none where "
                  "that leaves under half the thickness. The flow is solved on the cells `case.cells` made at the "
                  "run's commit (the line above; the polyhedral dual by default since 3d88d5a; cells = checkMesh's "
                  "count). */ finest* compares with the finest mesh without layers of the same bed.", "",
                  "| bed | surface edge (d) | layers, thickness (d), mean reached | cells (prisms, pyramids, tets in the "
                  "layers) | mesh s | simpleFoam s (its) | whole run s | checkMesh | max non-ortho | dp/L (Pa/m) | "
                  "/ E&S | / finest | eps section |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        bed = lambda r: (r.get("a", 4), r.get("n", 40), r.get("treatment", "shrink"))  # rows before the bed was recorded
        for r in results["layers"]:
            finest = min((x for x in results["layers"] if bed(x) == bed(r) and not x["layers"]), key=lambda x: x["edge_d"])
            st, lc = r["stages_s"], r.get("layer_cells") or {}
            reached = f"3, {r['layer_thickness_d']:g}, {r['layer_mean_thickness_d']:.3f}" if r["layers"] else "none"
            cells = f"{r['cells']} ({lc.get('prisms', 0)}, {lc.get('pyramids', 0)}, {lc.get('tetrahedra', 0)})" \
                if r["layers"] else f"{r['cells']}"
            lines.append(f"| a = {bed(r)[0]:g}, N = {bed(r)[1]}, {bed(r)[2]} | {r['edge_d']} | {reached} | {cells} | "
                         f"{st.get('mesh', 0):.1f} | {r['solve_s']:.0f} "
                         f"({r['iterations']}{'' if r['converged'] else ', not converged'}) | {r['wall_s']:.0f} | "
                         f"{'OK' if r['mesh_ok'] else 'FAILED'} | {r['max_non_orthogonality']:.1f} | "
                         f"{r['dp_dz_pa_m']:.4g} | {r['ratio_es']:.3f} | {r['dp_dz_pa_m'] / finest['dp_dz_pa_m']:.3f} | "
                         f"{r['eps_section']:.4f} |")
        lines += ["", "On gmsh's tetrahedra, layers on the bridged a = 5 bed did not converge in simpleFoam "
                  "(2026-11-22, not regenerated): [findings.md](findings.md).", ""]
    for key in ("solver", "solver_tetrahedra"):
        if key not in results:
            continue
        r = results[key]
        kind = r.get("kind", "polyhedra")
        # The study_gaps extrapolation is of the same bed on polyhedra.
        ref = results.get("study_gaps", {}).get("study", {}).get("grid_convergence", {}) if kind == "polyhedra" else {}
        lines += [f"## OpenFOAM's settings on the same mesh: {kind}", "", made_line(r), "",
                  f"The bed of the studies (a = 5, N = 500, bridges, Re_p = 1), surface edge {r['edge_d']} d with "
                  f"{r['cells_per_gap']:g} cells across narrow gaps: {r['cells']} {kind}, written and solved once "
                  f"by `bedforge run` (simpleFoam {r['bedforge_solve_s']:.0f} s with the Allrun steps before it), then "
                  "solved again from that mesh with one setting changed at a time, side by side in one run, each "
                  "by the case's own `./Allrun -np 2` (the simpleFoam step's seconds, at most "
                  f"{r.get('iteration_cap', 3000)} iterations). dp/L as "
                  "bedforge converts the case as written; the iteration and time ratios are each variant's over "
                  "the case as written."
                  + (f" Reference: the study_gaps extrapolation of the same bed, {ref['extrapolated']:.4g} Pa/m "
                     f"(its GCI {100 * ref['gci_fine']:.0f} %)." if ref.get("asymptotic") else ""), "",
                  "| settings | iterations | simpleFoam s | iteration ratio | time ratio | dp/L (Pa/m) | / as written |"
                  + (" / extrapolated |" if ref.get("asymptotic") else ""),
                  "|---|---|---|---|---|---|---|" + ("---|" if ref.get("asymptotic") else "")]
        first = r["rows"][0]
        for v in r["rows"]:
            state = "" if v["converged"] else (", failed" if not v["ok"] else ", not converged")
            lines.append(f"| {v['variant']} | {v['iterations']}{state} | {v['solve_s']:.0f} | "
                         f"{v['iterations'] / first['iterations']:.2f} | {v['solve_s'] / first['solve_s']:.2f} | "
                         f"{v['dp_dz_pa_m']:.4g} | {v['dp_kin'] / first['dp_kin']:.4f} |"
                         + (f" {v['dp_dz_pa_m'] / ref['extrapolated']:.3f} |" if ref.get("asymptotic") else ""))
        lines.append("")
    if "snappy" in results:
        r, g = results["snappy"], min(results.get("sizes", [{}]), key=lambda x: x.get("edge_d", 1))
        lines += ["## The same bed by the snappyHexMesh route", "", *stamp(results["snappy"]),
                  "| route | cells | meshing s | simpleFoam s (its) | checkMesh | max non-ortho | max skewness | "
                  "dp/L (Pa/m) | / E&S |", "|---|---|---|---|---|---|---|---|---|"]
        if g:
            lines.append(f"| gmsh (edge {g['edge_d']} d) | {g['cells']} | {g['stages_s'].get('mesh', 0):.0f} | "
                         f"{g['solve_s']:.0f} ({g['iterations']}) | {'OK' if g['mesh_ok'] else 'FAILED'} | "
                         f"{g['max_non_orthogonality']:.1f} | {g['max_skewness']:.2f} | {g['dp_dz_pa_m']:.4g} | "
                         f"{g['ratio_es']:.3f} |")
        lines.append(f"| snappyHexMesh (2 processes) | {r['cells']} | {r['snappy_s']:.0f} | {r['solve_s']:.0f} "
                     f"({r['iterations']}) | {'OK' if r['mesh_ok'] else 'FAILED'} | {r['max_non_orthogonality']:.1f} | "
                     f"{r['max_skewness']:.2f} | {r['dp_dz_pa_m']:.4g} | {r['ratio_es']:.3f} |")
        lines.append("")
    for key in ("scale", "scale_1e4"):
        if key in results:
            lines += scale_lines(results[key])
    if "scale_out" in results:
        lines += scale_out_lines(results["scale_out"])
    for key in ("study", "study_gaps"):
        if key in results:
            lines += study_lines(results[key])
    if "study_reynolds" in results:
        runs = [results["study_gaps"]] + results["study_reynolds"] if "study_gaps" in results else results["study_reynolds"]
        lines += ["## The same gap-refined study against the Reynolds number", "",
                  "Each row one `bedforge run` with [case.convergence], the study_gaps settings; Re_p = 1 is the "
                  "section above. E&S at the bed's exact section void fraction; its own stated accuracy is in "
                  "docs/reference.md.", "",
                  "| Re_p | made | finest dp/L (Pa/m) | extrapolated (Pa/m) | order | GCI fine | in the asymptotic range | "
                  "E&S (Pa/m) | finest / E&S | extrapolated / E&S | wall (min) |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in runs:
            g, finest, ext = study_values(r)
            lines.append(f"| {r.get('reynolds', 1.0):g} | {made(r)} | "
                         + (f"{finest:.4g}" if finest else "failed") + " | "
                         + (f"{ext:.4g} | {g['apparent_order']:.2f} | {100 * g['gci_fine']:.1f} % | "
                            f"{'yes' if g.get('asymptotic') else 'no'}" if ext is not None else "none | | | no")
                         + f" | {r['es_bed_pa_m']:.4g} | " + (f"{finest / r['es_bed_pa_m']:.3f}" if finest else "")
                         + " | " + (f"{ext / r['es_bed_pa_m']:.3f}" + ("" if g.get("asymptotic") else " (not trusted)")
                                    if ext is not None else "") + f" | {r['wall_s'] / 60:.1f} |")
        lines.append("")
        for r in results["study_reynolds"]:
            lines += study_lines(r)
    if "study_treatments" in results:
        runs = sorted(([results["study_gaps"]] if "study_gaps" in results else []) + results["study_treatments"],
                      key=lambda r: r["treatment"])
        lines += ["## The same gap-refined study against the contact treatment", "",
                  "Each row one `bedforge run` with [case.convergence], the study_gaps settings (Re_p = 1) but for "
                  "`contacts.treatment`; the same bed, so E&S at the bed's exact section void fraction is the same "
                  "for all. *Solid change*: the treatment's change of the solid volume, whole bed, exact geometry. "
                  "*E&S treated*: E&S at the bed's void fraction less that change spread evenly over the height "
                  "(interpolated log-linearly between bedforge's two E&S values of the run, at the bed's and at the "
                  "meshed void fraction): how far the treatment's volume alone moves the correlation.", "",
                  "| treatment | made | solid change | finest dp/L (Pa/m) | level 1, 2 / bridge's (level 2 when sized alike) | extrapolated (Pa/m) | "
                  "order | GCI fine | E&S (Pa/m) | extrapolated / E&S | E&S treated (Pa/m) | extrapolated / E&S treated | "
                  "wall (min) |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        bridge = next((r for r in runs if r["treatment"] == "bridge"), None)

        def against_bridge(r):  # level by level at the same settings: what the treatment alone changes
            if not bridge:
                return ""
            if (r.get("cells_per_gap"), r["edge_d"]) != (bridge.get("cells_per_gap"), bridge["edge_d"]):
                return f"not compared: {r.get('cells_per_gap', 0):g} per gap from {r['edge_d']} d"
            # Level 2's gaps are sized alike only when both studies coarsened them alike.
            same = 2 if gaps_not_coarsened(r) == gaps_not_coarsened(bridge) else 1
            return ", ".join(f"{lv['pressure_gradient_bed_pa_m'] / b['pressure_gradient_bed_pa_m']:.3f}"
                             for lv, b in zip(r["study"]["levels"][:same], bridge["study"]["levels"][:same])
                             if "failure" not in lv and "failure" not in b)
        for r in runs:
            g, finest, ext = study_values(r)
            ext = ext if g.get("asymptotic") else None
            change = r.get("solid_volume_change_relative")
            treated = None
            if change is not None and r["eps_section"] != r["eps_section_bed"]:
                slope = math.log(r["es_pa_m"] / r["es_bed_pa_m"]) / (r["eps_section"] - r["eps_section_bed"])
                treated = r["es_bed_pa_m"] * math.exp(slope * -change * (1 - r["eps_section_bed"]))
            lines.append(f"| {r['treatment']} | {made(r)} | "
                         + (f"{100 * change:+.2f} %" if change is not None else "not recorded") + " | "
                         + (f"{finest:.4g}" if finest else "failed") + f" | {against_bridge(r)} | "
                         + (f"{ext:.4g} | {g['apparent_order']:.2f} | {100 * g['gci_fine']:.1f} %" if ext else
                            ("not in the asymptotic range" if r["study"]["complete"] else "none: a level failed")
                            + " | | ")
                         + f" | {r['es_bed_pa_m']:.4g} | " + (f"{ext / r['es_bed_pa_m']:.3f}" if ext else "")
                         + " | " + (f"{treated:.4g}" if treated else "") + " | "
                         + (f"{ext / treated:.3f}" if ext and treated else "") + f" | {r['wall_s'] / 60:.1f} |")
        lines.append("")
        for r in results["study_treatments"]:
            lines += study_lines(r)
    for key in ("cost", "cost_20k", "cost_500"):
        if key in results:
            lines += cost_lines(results[key])
            for r in results[key]:
                lines += error_seat_lines(r)
    for runs in results.get("cost_same_lengths", []):
        lines += cost_lines(runs)
    if "cost_beds" in results:
        for runs in results["cost_beds"]:
            lines += cost_lines(runs)
        # The README's bed joins the others where its section was made at the same mesh settings.
        beds = results["cost_beds"] + [results["cost_500"]] * (
            "cost_500" in results and mesh_settings(results["cost_500"][0]) == mesh_settings(results["cost_beds"][0][0]))
        lines += beds_lines(sorted(beds, key=lambda runs: runs[0]["n"]))
    if "verification" in results:
        v = results["verification"]
        lines += ["## Verification: the empty tube against Hagen-Poiseuille, tetrahedra and their polyhedral dual", "",
                  f"Made at commit {v['commit']} on {v['date']}: the empty tube (D = 2 d, 12 d long, section 3 d clear "
                  f"of either end, Re_p = 1) through the same route as a bed, on {v['levels']} meshes from a surface "
                  f"edge of {v['edge_d']} d, ratio {v['ratio']}; `case.cells` the only difference. Error = dp/L / "
                  "exact - 1; the order is a least-squares fit of ln |error| against ln h over all levels.", ""]
        lines += verification_lines(v, "cells", "verification_tube.png")
        plot_verification(v)
    if "verification_spheres" in results:
        v = results["verification_spheres"]
        on_routes = any(", " in k for k in v["runs"])  # runs named "fraction, cells, facets"
        lines += ["## Verification around spheres: a simple cubic array against Zick & Homsy", "",
                  f"Made at commit {v['commit']} on {v['date']}: one column of a simple cubic array of spheres in a "
                  "square box whose sides the flow slips along (the array's mirror planes), six cells, the pressure "
                  "drop over the middle four, Stokes flow (Re_p = 0.01), through the same route as a bed, on "
                  f"{v['levels']} meshes from a surface edge of {v['edge_d']} d, ratio {v['ratio']}. Exact: Zick & "
                  "Homsy (1982, Table 2), drag 6 pi mu a K U per sphere to about 0.1 %: K = 7.442 at solid fraction "
                  "0.216, 28.1 at 0.45 (gaps of 0.05 d between neighbours). Error = dp/L / exact - 1; the order is a "
                  "least-squares fit of ln |error| against ln h over all levels."
                  + (" Each fraction on the cost sections' routes: `case.cells` and `surface.sphere_facets` "
                     "(inscribed: vertices on the spheres; volume: moved out so that the facets hold each sphere's "
                     "volume)" + (", and on the layered route: prism layers on the particles, `[mesh.layers]`, their "
                                  "thickness in all as named"
                                  if has_layered_run(v) else "") + "." if on_routes else ""), ""]
        lines += verification_lines(v, "solid fraction" + (", cells, facets" if on_routes else "")
                                    + (", layers" if has_layered_run(v) else ""),
                                    "verification_spheres.png")
        plot_verification(v, "verification_spheres.png", "simple cubic array, Stokes flow", "Zick & Homsy",
                          "solid fraction ")
    if "verification_touching" in results:
        lines += touching_lines(results["verification_touching"])
    if "verification_periodic" in results:
        v = results["verification_periodic"]
        lines += ["## Verification of periodic sections: cyclic cases against Hagen-Poiseuille and Zick & Homsy", "",
                  "Periodic sections whose inlet and outlet are one "
                  "cyclic pair, the flow driven by meanVelocityForce at the superficial velocity set (dp/L the driving "
                  "gradient scaled to the flow rate set). The empty tube, D = 2 d, one period of 3 d, Re_p = 1: its "
                  "fully developed flow is Hagen-Poiseuille's in every cell. Three cells of a simple cubic array "
                  "(one column in a square box with slip sides, the array's mirror planes), Stokes flow (Re_p = 0.01), "
                  f"at each solid fraction; exact: Zick & Homsy (1982, Table 2), to about 0.1 %. {v['levels']} meshes "
                  f"from each run's finest surface edge (listed below its table; the tube's twice that), ratio "
                  f"{v['ratio']}; each run's commit and date listed with it. Error = dp/L / "
                  "exact - 1; the order is a least-squares fit of ln |error| against ln h over all levels. "
                  "Body-centred and face-centred arrays are not run: their tables are not in the repository.", ""]
        lines += verification_lines(v, "case", "verification_periodic.png")
        lines += periodic_target_lines(v)
        plot_verification(v, "verification_periodic.png", "periodic sections (cyclic)", "exact", "")
    for key, section_lines in (("periodic_slice", slice_lines), ("random_arrays", random_array_lines),
                               ("pieces", pieces_lines),
                               ("pieces_bridge", pieces_lines), ("pieces_large", pieces_lines),
                               ("weak_scaling", weak_scaling_lines), ("projection", projection_lines),
                               ("pieces_1e4", pieces_1e4_lines), ("pieces_1e4_solved", pieces_1e4_solved_lines),
                               ("pieces_1e4_tetrahedra", pieces_1e4_solved_lines),
                               ("weak_scaling_1e4", weak_scaling_lines),
                               ("projection_1e4", projection_lines)):
        if key in results:
            lines += section_lines(results[key])
    open(os.path.join(DOCS, "mesh_case_benchmark.md"), "w").write("\n".join(lines))


def level_rows(v, column, error_name, error_of):
    """A verification section's table: a row per level of each run (runs keyed by what `column`
    names), its error error_of(run, level) as a fraction headed `error_name`, and what its residual
    targets left (bedforge_files.level_iteration_error)."""
    lines = [f"| {column} | level | cells solved on | h / d | dp/L (Pa/m) | {error_name} | iteration error (%) | "
             "time (s) |", "|---|---|---|---|---|---|---|---|"]
    for key, run in v["runs"].items():
        for lv in run["study"]["levels"]:
            if "failure" in lv:
                lines.append(f"| {key} | {lv['level']} | failed: {lv['failure']} | | | | | {lv['time_s']:.0f} |")
                continue
            lines.append(f"| {key} | {lv['level']} | {lv['cells']} | {lv['cell_size_m'] / run['d_m']:.4f} | "
                         f"{lv['pressure_gradient_bed_pa_m']:.5g} | {100 * error_of(run, lv):+.2f} % | "
                         f"{level_iteration_error(lv)} | {lv['time_s']:.1f} |")
    return lines + ["", "Iteration error: what the level's dp/L would still have moved had its solve run on past its "
                    "residual targets, estimated from how its last changes shrank (stages.case.convergence.levels"
                    "[].iteration_error); in brackets, for a level whose changes did not shrink, how far it moved over "
                    "its last block of iterations."]


def verification_lines(v, column, png):
    """A verification section's levels against the exact value, one table row per level of each
    run (runs keyed by what `column` names), then each run's order and the study's own verdict."""
    lines = level_rows(v, column, "error", lambda run, lv: lv["relative_error_to_exact"]) + [""]
    for key, run in v["runs"].items():
        st = run["study"]
        order = st.get("order_from_exact")
        made_by = (f"made at commit {run['commit']} on {run['date']} from a finest edge of {run['edge_d']} d; "
                   if "commit" in run else "")
        lines.append(f"- {key}: {made_by}exact {st['exact_pa_m']:.5g} Pa/m; order of the errors "
                     f"{NO_ORDER if order is None else f'{order:.2f}'}; whole run {run['wall_s']:.0f} s; "
                     f"the study's own verdict: {st['conclusion']}.")
    return lines + ["", f"![error against cell size]({png})", ""]


def plot_verification(v, name="verification_tube.png", title="empty tube D = 2 d, Re_p = 1",
                      reference="Hagen-Poiseuille", label=""):
    """|error| against cell size, one line per run of a verification section."""
    fig, ax = plt.subplots(figsize=(6, 4))
    for key, run in v["runs"].items():
        ok = [lv for lv in run["study"]["levels"] if "failure" not in lv]
        h = [lv["cell_size_m"] / run["d_m"] for lv in ok]
        ax.loglog(h, [abs(lv["relative_error_to_exact"]) for lv in ok], "o-", label=label + key)
    ax.set_xlabel("cell size h / d, (V / N)^(1/3) of the cells solved on")
    ax.set_ylabel(f"|dp/L / {reference} - 1|")
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, name), dpi=120)


def plot(results):
    rows = sorted(results["sizes"], key=lambda r: r["edge_d"])
    fig, ax = plt.subplots(figsize=(6, 4))
    total = [sum(r["stages_s"].values()) for r in rows]
    ax.plot(total, [r["ratio_es"] for r in rows], "o-", label="gmsh route")
    for t, r in zip(total, rows):
        ax.annotate(f"{r['edge_d']} d, {r['cells'] / 1e6:.2f} M cells", (t, r["ratio_es"]), fontsize=8,
                    textcoords="offset points", xytext=(4, 4))
    if "gaps" in results:
        g = sorted(results["gaps"], key=lambda r: r["cells_per_gap"])
        t = [sum(r["stages_s"].values()) for r in g]
        ax.plot(t, [r["ratio_es"] for r in g], "^-", label="0.2 d, refined across gaps")
        for x, r in zip(t, g):
            ax.annotate(f"{r['cells_per_gap']:g} per gap, {r['cells'] / 1e6:.2f} M cells", (x, r["ratio_es"]), fontsize=8,
                        textcoords="offset points", xytext=(-6, 4), ha="right")
    if "snappy" in results:
        s = results["snappy"]
        ax.plot([s["wall_s"]], [s["ratio_es"]], "s", label="snappyHexMesh route")
    ax.axhline(1.0, color="grey", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel("run time, scene to solved case (s)")
    ax.set_ylabel("dp/L over Eisfeld & Schnitzlein")
    ax.set_title("a = 5, N = 500, bridges, Re_p = 1")
    ax.legend(loc="upper left")
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "mesh_case_convergence.png"), dpi=120)


def bed_argument(text):
    """--cost-beds' a:N (container diameter in d, particle count), refused unless both are positive."""
    try:
        a, n = text.split(":")
        bed = (float(a), int(n))
    except ValueError:
        bed = None
    if bed is None or bed[0] <= 0 or bed[1] <= 0:
        raise argparse.ArgumentTypeError(f"{text!r}: a bed is a:N, a positive diameter in d and a positive count")
    return bed


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", nargs="+", choices=SECTIONS, default=SECTIONS)
    ap.add_argument("--edges", type=float, nargs="+", default=[0.2, 0.15, 0.1])
    ap.add_argument("--gap-cells", type=float, nargs="+", default=[2, 3])
    ap.add_argument("--layer-thickness", type=float, nargs="+", default=[0.02, 0.05])
    ap.add_argument("--levels", type=int, default=3, help="study: meshes in all")
    ap.add_argument("--snappy-cell-d", type=float, default=0.25, help="scale_out: snappyHexMesh's background cell (d)")
    ap.add_argument("--snappy-level", type=int, default=1, help="scale_out: its refinement levels at the surfaces")
    ap.add_argument("--scale-out-gmsh-edge", type=float, default=0.15, help="scale_out: the gmsh route's surface edge (d)")
    ap.add_argument("--scale-out-iterations", type=int, default=500, help="scale_out: simpleFoam's iteration cap")
    ap.add_argument("--ratio", type=float, default=1.3, help="study: cell size ratio between levels")
    ap.add_argument("--study-gap-edge", type=float, default=0.15, help="study_gaps: finest surface edge (d)")
    ap.add_argument("--study-gap-cells", type=float, default=4, help="study_gaps: surface.cells_per_gap")
    ap.add_argument("--cost-edge", type=float, default=0.07, help="cost: finest surface edge (d)")
    ap.add_argument("--cost-levels", type=int, default=4, help="cost: meshes in all")
    ap.add_argument("--cost-gap-cells", type=float, default=4, help="cost: surface.cells_per_gap on the finest")
    ap.add_argument("--cost-beds", type=bed_argument,
                    nargs="+", default=[(4.0, 40), (5.0, 200)],
                    help="cost_beds: beds as a:N (container diameter in d, particle count)")
    ap.add_argument("--same-lengths-seeds", type=int, nargs="+", default=[1, 2],
                    help="cost_same_lengths: packing seeds of issue 57's bed (a = 4, N = 40)")
    ap.add_argument("--target-edge", type=float, default=0.0868,
                    help="cost_20k: finest surface edge (d), contact edge half of it: some 20 k tetrahedra per sphere")
    ap.add_argument("--target-ratio", type=float, default=1.2, help="cost_20k: cell size ratio between levels")
    ap.add_argument("--layered-edge", type=float, default=0.17,
                    help="cost_20k's layered route (3 prism layers of 0.02 d): finest surface edge (d)")
    ap.add_argument("--layered-contact-edge", type=float, default=0.046,
                    help="cost_20k's layered route: finest contact edge (d); with --layered-edge some 19 k cells per "
                         "sphere (docs/findings.md, 2026-12-07, session 91)")
    ap.add_argument("--reynolds", type=float, nargs="+", default=[10, 100], help="study_reynolds: Re_p values")
    ap.add_argument("--treatments", nargs="+", default=["shrink", "cap"], help="study_treatments: contacts.treatment")
    ap.add_argument("--default-reference-levels", type=int, default=4,
                    help="default: levels of the reference study, one ratio finer than the default's")
    ap.add_argument("--verify-edge", type=float, default=0.07, help="verification: finest surface edge (d)")
    ap.add_argument("--verify-levels", type=int, default=5, help="verification: meshes in all")
    ap.add_argument("--verify-ratio", type=float, default=1.4, help="verification: cell size ratio between levels")
    ap.add_argument("--sphere-edge", type=float, default=0.05, help="verification_spheres: finest surface edge (d)")
    ap.add_argument("--periodic-edge", type=float,
                    help="verification_periodic: finest surface edge (d) of every run redone; by default each run's "
                         "own, PERIODIC_EDGES_D")
    ap.add_argument("--periodic-levels", type=int, default=4, help="verification_periodic: meshes in all")
    ap.add_argument("--periodic-runs", nargs="+", default=["empty tube", "0.125", "0.216", "0.343", "0.45"],
                    help="verification_periodic: the runs to redo (\"empty tube\", solid fractions Zick & Homsy tabulate); "
                         "the others' results are kept")
    ap.add_argument("--sphere-levels", type=int, default=4, help="verification_spheres: meshes in all")
    ap.add_argument("--slice-full-seeds", type=int, nargs="+", default=[1, 2, 3], help="periodic_slice: full beds' seeds")
    ap.add_argument("--slice-period", type=float, default=5.0, help="periodic_slice: the slice's period, about (d)")
    ap.add_argument("--slice-count", type=int, default=105, help="periodic_slice: spheres per slice")
    ap.add_argument("--slices", type=int, default=3, help="periodic_slice: slices that reach their period")
    ap.add_argument("--slice-full-exclude", type=float, default=2.0,
                    help="periodic_slice: the full beds' dp/L section, clear of floor and top (d)")
    ap.add_argument("--array-fractions", type=float, nargs="+", default=[0.3, 0.4, 0.5, 0.6],
                    help="random_arrays: solid fractions as packed")
    ap.add_argument("--array-seeds", type=int, nargs="+", default=[1, 2, 3], help="random_arrays: seeds")
    ap.add_argument("--pieces-ranks", type=int, nargs="+", default=[1, 2, 4, 8], help="pieces: ranks (pieces) to run")
    ap.add_argument("--pieces-large-spheres", type=int, default=1500, help="pieces_large: the bed's spheres")
    ap.add_argument("--pieces-large-ranks", type=int, nargs="+", default=[2, 4, 8], help="pieces_large: ranks to run")
    ap.add_argument("--weak-ranks", type=int, nargs="+", default=[1, 2, 4], help="weak_scaling: ranks (pieces) to run")
    ap.add_argument("--weak-spheres", type=int, default=200, help="weak_scaling: spheres per rank")
    ap.add_argument("--pieces-1e4-ranks", type=int, nargs="+", default=[1, 2, 4, 8], help="pieces_1e4: ranks to run")
    ap.add_argument("--weak-1e4-spheres", type=int, default=1250, help="weak_scaling_1e4: spheres per rank (1, 2, 4 ranks)")
    args = ap.parse_args()
    results = json.load(open(RESULTS)) if os.path.exists(RESULTS) else {}
    if {"cost_500", "cost_beds"} & set(args.only):
        check_default_route()  # their pages name the README's route: refused before any run if it moved
    with tempfile.TemporaryDirectory() as tmp:
        if "sizes" in args.only:
            results["sizes"] = [{**commit_and_date(), **r} for r in sizes(tmp, [(e, 0, 0, 0.02) for e in args.edges])]
            write(results)
        if "gaps" in args.only:
            results["gaps"] = [{**commit_and_date(), **r} for r in sizes(tmp, [(0.2, c, 0, 0.02) for c in args.gap_cells])]
            write(results)
        if "layers" in args.only:
            # Without layers these converge in under 100 iterations; a run still going at 1000 has stalled.
            results["layers"] = [{**commit_and_date(), **r} for r in sizes(
                tmp, [(0.1, 0, 0, 0.02)] + [(0.1, 0, 3, t) for t in args.layer_thickness] + [(0.07, 0, 0, 0.02)],
                a=4, n=40, treatment="shrink", iterations=1000)]
            # The bridged bed of the studies, where layers had stalled simpleFoam on tetrahedra.
            results["layers"] += [{**commit_and_date(), **r} for r in sizes(
                tmp, [(0.15, 0, 0, 0.02), (0.15, 0, 3, 0.02)], a=5, n=500, treatment="bridge", iterations=1000)]
            write(results)
        if "snappy" in args.only:
            results["snappy"] = {**commit_and_date(), **snappy(tmp, min(args.edges))}
            write(results)
        if "scale" in args.only:
            results["scale"] = {**commit_and_date(), **scale(tmp, 10, 4000, "shrink")}
            write(results)
        if "scale_out" in args.only:
            results["scale_out"] = []
            for r in scale_out(tmp, args.snappy_cell_d, args.snappy_level, args.scale_out_gmsh_edge,
                               args.scale_out_iterations):
                results["scale_out"].append({**commit_and_date(), **r})
                json.dump(results, open(RESULTS, "w"), indent=1)
            write(results)
        if "scale_1e4" in args.only:
            results["scale_1e4"] = {**commit_and_date(), **scale(tmp, 14, 10000, "bridge")}
            write(results)
        if "study" in args.only:
            results["study"] = study(tmp, min(args.edges), args.levels, args.ratio)
            write(results)
        if "study_gaps" in args.only:
            results["study_gaps"] = study(tmp, args.study_gap_edge, args.levels, args.ratio, args.study_gap_cells)
            write(results)
        if "cost" in args.only:
            results["cost"] = [study(tmp, args.cost_edge, args.cost_levels, args.ratio, args.cost_gap_cells, a=4, n=40,
                                     cells=cells, sphere_facets=facets) for cells, facets in COST_ROUTES]
            write(results)
        if "cost_20k" in args.only:
            results["cost_20k"] = [study(tmp, args.target_edge, args.cost_levels, args.target_ratio, args.cost_gap_cells,
                                         a=4, n=40, cells="tetrahedra", contact_edge=args.target_edge / 2,
                                         sphere_facets=facets, drag_by_gap=GAP_BANDS_D)
                                   for facets in ("inscribed", "volume")]
            results["cost_20k"].append(study(tmp, args.layered_edge, args.cost_levels, args.target_ratio,
                                             args.cost_gap_cells, a=4, n=40, cells="tetrahedra",
                                             contact_edge=args.layered_contact_edge, sphere_facets="volume",
                                             drag_by_gap=GAP_BANDS_D, layers=LAYERS, layer_thickness=LAYER_THICKNESS_D))
            write(results)
        if "cost_same_lengths" in args.only:
            results["cost_same_lengths"] = [
                [study(tmp, args.layered_edge, args.cost_levels, args.target_ratio, args.cost_gap_cells, a=4, n=40,
                       cells="tetrahedra", contact_edge=args.layered_contact_edge, sphere_facets="volume",
                       layers=layers, layer_thickness=LAYER_THICKNESS_D, seed=seed) for layers in (0, LAYERS)]
                for seed in args.same_lengths_seeds]
            write(results)
        if "cost_500" in args.only:
            results["cost_500"] = [default_study(tmp, cells, facets, layers) for cells, facets, layers in ROUTES]
            write(results)
        if "cost_beds" in args.only:
            results["cost_beds"] = [[default_study(tmp, cells, facets, layers, bed) for cells, facets, layers in ROUTES]
                                    for bed in args.cost_beds]
            write(results)
        # Runs at other Re_p or treatments are kept, so one can be redone alone.
        for key, field, values in (("study_reynolds", "reynolds", args.reynolds),
                                   ("study_treatments", "treatment", args.treatments)):
            if key in args.only:
                kept = [r for r in results.get(key, []) if r[field] not in values]
                new = [study(tmp, args.study_gap_edge, args.levels, args.ratio, args.study_gap_cells, **{field: v})
                       for v in values]
                results[key] = sorted(kept + new, key=lambda r: r[field])
                write(results)
        if "default" in args.only:
            results["default"] = default_path(tmp, args.default_reference_levels)
            write(results)
        if "solver" in args.only:
            results["solver"] = solver(tmp)
            write(results)
        if "solver_tetrahedra" in args.only:
            results["solver_tetrahedra"] = solver(tmp, "tetrahedra", edge=0.3, cells_per_gap=2)
            write(results)
        if "verification" in args.only:
            results["verification"] = verification(tmp, args.verify_edge, args.verify_levels, args.verify_ratio)
            write(results)
        if "verification_spheres" in args.only:
            results["verification_spheres"] = verification_spheres(tmp, args.sphere_edge, args.sphere_levels)
            write(results)
        if "verification_touching" in args.only:
            results["verification_touching"] = verification_touching(tmp, args.sphere_edge, args.sphere_levels)
            write(results)
        if "verification_periodic" in args.only:
            results["verification_periodic"] = verification_periodic(tmp, args.periodic_edge, args.periodic_levels,
                                                                     args.periodic_runs,
                                                                     results.get("verification_periodic"))
            write(results)
        if "periodic_slice" in args.only:
            results["periodic_slice"] = periodic_slice(tmp, args.slice_full_seeds, args.slice_period, args.slice_count,
                                                       args.slices, args.slice_full_exclude)
            write(results)
        if "random_arrays" in args.only:
            results["random_arrays"] = random_arrays(tmp, args.array_fractions, args.array_seeds)
            write(results)
        if "pieces" in args.only:
            results["pieces"] = pieces(tmp, args.pieces_ranks)
            write(results)
        if "pieces_bridge" in args.only:
            results["pieces_bridge"] = pieces(tmp, args.pieces_ranks,
                                              make_scene=functools.partial(pieces_scene, treatment="bridge"))
            write(results)
        if "pieces_large" in args.only:
            results["pieces_large"] = pieces(tmp, args.pieces_large_ranks, args.pieces_large_spheres, solved=())
            write(results)
        if "weak_scaling" in args.only:
            results["weak_scaling"] = weak_scaling(tmp, args.weak_ranks, args.weak_spheres)
            write(results)
        if "projection" in args.only:
            results["projection"] = projection(results)
            write(results)
        if "pieces_1e4" in args.only:
            results["pieces_1e4"] = pieces(tmp, args.pieces_1e4_ranks, 10000, solved=(), make_scene=bed_1e4_scene,
                                           one_piece=True, reconstruct=(4,))
            write(results)
        if "pieces_1e4_solved" in args.only:
            results["pieces_1e4_solved"] = pieces(tmp, [2, 4], 10000, solved=(0, 2, 4), make_scene=bed_1e4_solved_scene,
                                                  reconstruct=(4,))
            write(results)
        if "pieces_1e4_tetrahedra" in args.only:
            results["pieces_1e4_tetrahedra"] = pieces(tmp, [2, 4], 10000, solved=(0, 2, 4),
                                                      make_scene=bed_1e4_tetrahedra_scene, reconstruct=(4,))
            write(results)
        if "weak_scaling_1e4" in args.only:
            results["weak_scaling_1e4"] = weak_scaling(tmp, [1, 2, 4], args.weak_1e4_spheres, bed_1e4_scene, BED_1E4)
            write(results)
        if "projection_1e4" in args.only:
            results["projection_1e4"] = projection(results, ("pieces_1e4",), 14.0, BED_1E4)
            write(results)


if __name__ == "__main__":
    main()
