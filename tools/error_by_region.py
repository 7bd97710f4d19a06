#!/usr/bin/python3
"""Where a bed study's discretisation error sits (issue 57, item 1): the drag on every boundary face
of each level of a mesh-convergence study, split by kind (form and viscous drag on the particles,
viscous drag on the container wall) and by region (the gap from the face to the nearest other
surface), and how each part changes from level to level; writes docs/error_by_region.md and .json.

    /usr/bin/python3 tools/error_by_region.py                 # runs the study below, then splits it
    /usr/bin/python3 tools/error_by_region.py --dir RUN       # splits a study run already (bedforge run -o RUN)
    /usr/bin/python3 tools/error_by_region.py --edge 0.06 --levels 5

The study: issue 57's bed, a = 4, N = 40 (seed 1), bridges, Re_p = 1, water, cells_per_gap
--gap-cells and a contact edge a third of the surface edge, --levels meshes from a finest surface
edge of --edge d, ratio 1.3 (every length coarsens alike). Each level's fields are reconstructed
(reconstructPar) and OpenFOAM's wallShearStress written (simpleFoam -postProcess); then per face:
- the form drag: (p - p_lin) n_z dA, with p_lin the linear field of the level's own gradient (the
  linear part pushes the solid by that gradient times its volume, proportional to the result by
  construction, and is listed apart); the viscous drag: the wall shear stress's z part times dA;
- the gap: the distance from the face's centre to the nearest other surface (another sphere, or
  the container wall; for a particle face the nearest sphere is its own, for a bridge both of
  its spheres lie within the bridge's gap), binned in d.
The parts' sums are checked against OpenFOAM's own forces objects (postProcessing/forceParticles,
forceWalls) of the same level. Each part's change between levels is given as its share of the
total's change: a part whose share of the change exceeds its share of the drag is where the error
sits.
"""
import argparse
import json
import os
import re
import tempfile
import time

import numpy as np

from benchmark_mesh_case import scene, timed
from bedforge_files import BEDFORGE, DOCS, commit_and_date, foam_file, foam_list, read_bed, read_poly_mesh

GAP_BINS_D = [0.0, 0.02, 0.05, 0.1, 0.15, 0.25, 0.5, np.inf]  # edges of the gap classes (d)


def latest_time(case):
    times = [float(t) for t in os.listdir(case) if re.fullmatch(r"[0-9.eE+-]+", t) and float(t) > 0]
    return None if not times else max(times)


def prepare(case):
    """The level's last time reconstructed, with OpenFOAM's wallShearStress; its name."""
    if latest_time(case) is None:
        timed(["reconstructPar", "-latestTime", "-case", case])
    t = latest_time(case)
    name = f"{t:g}"
    if not os.path.exists(os.path.join(case, name, "wallShearStress")):
        timed(["simpleFoam", "-postProcess", "-func", "wallShearStress", "-latestTime", "-case", case])
    return name


def field_values(path, start_at, width):
    """The nonuniform list (n, width) of an OpenFOAM field file that follows the patterns of
    `start_at` found one after the other (the internal field's, or a patch's block and its value)."""
    data, h, binary = foam_file(path)
    start = h
    for pattern in start_at:
        start = re.compile(pattern).search(data, start).end()
    m = re.compile(rb"(uniform|nonuniform)").search(data, start)
    if m.group(1) == b"uniform":
        raise SystemExit(f"{path}: a uniform value where error_by_region.py expects one per cell or face")
    return foam_list(data, m.end(), "<f8", width, binary)[0]


def patches(case):
    """polyMesh/boundary: {name: (startFace, nFaces)}."""
    text = open(os.path.join(case, "constant/polyMesh/boundary")).read()
    out = {}
    for m in re.finditer(r"\n\s*(\w+)\s*\n\s*\{([^}]*)\}", text):
        body = m.group(2)
        if "startFace" not in body:  # the FoamFile header
            continue
        out[m.group(1)] = (int(re.search(r"startFace\s+(\d+)", body).group(1)),
                           int(re.search(r"nFaces\s+(\d+)", body).group(1)))
    return out


def face_geometry(points, offsets, labels, faces):
    """Area vectors (m^2) and centroids (m) of the faces with indices `faces`: fans of triangles."""
    count = offsets[faces + 1] - offsets[faces]
    tri_face = np.repeat(np.arange(len(faces)), count - 2)
    first = np.repeat(offsets[faces], count - 2)
    k = np.arange(len(tri_face)) - np.repeat(np.cumsum(count - 2) - (count - 2), count - 2) + 1
    a, b, c = points[labels[first]], points[labels[first + k]], points[labels[first + k + 1]]
    area = 0.5 * np.cross(b - a, c - a)
    centre = (a + b + c) / 3.0
    s = np.zeros((len(faces), 3))
    np.add.at(s, tri_face, area)
    weight = np.linalg.norm(area, axis=1)
    cw = np.zeros((len(faces), 3))
    np.add.at(cw, tri_face, centre * weight[:, None])
    wsum = np.bincount(tri_face, weight, len(faces))
    return s, cw / wsum[:, None]


def gaps(x, centres, radii, wall_radius, on_particles):
    """Distance (m) from each point to the nearest other surface: the second nearest sphere surface
    for particle faces (the nearest is their own; a bridge's two spheres both lie near), the nearest
    for wall faces; and the container wall's distance for particle faces."""
    best = np.full((len(x), 2), np.inf)
    for c, r in zip(centres, radii):
        s = np.linalg.norm(x - c, axis=1) - r
        s = np.maximum(s, 0.0)
        lower = s < best[:, 0]
        best[:, 1] = np.where(lower, best[:, 0], np.minimum(best[:, 1], s))
        best[:, 0] = np.where(lower, s, best[:, 0])
    wall = wall_radius - np.hypot(x[:, 0], x[:, 1])
    if on_particles:
        return np.minimum(best[:, 1], wall), wall < best[:, 1]
    return best[:, 0], np.zeros(len(x), bool)


def forces_object(case, name):
    """The last row of a forces object: total and viscous force along z (N)."""
    rows = [l for l in open(os.path.join(case, "postProcessing", name, "0", "force.dat")) if not l.startswith("#")]
    v = [float(t) for t in re.findall(r"[-+0-9.eE]+", rows[-1])]
    return v[3], v[9]


def split_level(case, bed, rho, gradient):
    """One level's drag (N) by part: {part: {bin: force}}, the areas per bin, and the check against
    OpenFOAM's forces objects. `gradient`: the level's dp/L (Pa/m)."""
    t = prepare(case)
    points, offsets, labels, owner, _ = read_poly_mesh(os.path.join(case, "constant/polyMesh"))
    p = field_values(os.path.join(case, t, "p"), [rb"internalField"], 1).ravel() * rho
    centres, diameters, container = bed
    if container.get("type") != "cylinder":
        raise SystemExit(f"error_by_region.py splits beds in a cylinder, not a {container.get('type')}")
    wall_radius = container["diameter"] / 2.0
    d = float(np.mean(diameters))
    out = {"parts": {}, "area": {}, "check": {}}
    ranges = patches(case)
    faces_of = {}
    for patch in ("particles", "wall"):
        start, n = ranges[patch]
        faces = np.arange(start, start + n)
        sf, xf = face_geometry(points, offsets, labels, faces)
        tau = field_values(os.path.join(case, t, "wallShearStress"),  # Pa, on the fluid
                           [rb"boundaryField", rb"\n\s*" + re.escape(patch.encode()) + rb"\s*\n\s*\{", rb"value"], 3) * rho
        magsf = np.linalg.norm(sf, axis=1)
        pf = p[owner[faces]]
        faces_of[patch] = (sf, xf, pf, tau, magsf)
    # The linear field of the level's gradient, its level set by the particle faces' mean pressure.
    sf, xf, pf, _, magsf = faces_of["particles"]
    level = np.sum((pf + gradient * xf[:, 2]) * magsf) / np.sum(magsf)
    for patch, (sf, xf, pf, tau, magsf) in faces_of.items():
        g, facing_wall = gaps(xf, centres, diameters / 2.0, wall_radius, patch == "particles")
        bins = np.digitize(g / d, GAP_BINS_D) - 1
        linear = -gradient * xf[:, 2] + level
        form = (pf - linear) * sf[:, 2]
        viscous = -tau[:, 2] * magsf
        total_check = np.sum(pf * sf[:, 2] + viscous)
        fo_total, fo_viscous = forces_object(case, "forceParticles" if patch == "particles" else "forceWalls")
        out["check"][patch] = {"sum_n": float(total_check), "forces_object_n": fo_total,
                               "viscous_sum_n": float(np.sum(viscous)), "forces_object_viscous_n": fo_viscous}
        out["parts"][f"{patch}, linear pressure"] = {"all": float(np.sum(linear * sf[:, 2]))}
        for kind, values in (("form", form), ("viscous", viscous)):
            if patch == "wall" and kind == "form":
                continue  # the wall is parallel to the flow: no form drag
            out["parts"][f"{patch}, {kind}"] = {str(b): float(np.sum(values[bins == b]))
                                                for b in range(len(GAP_BINS_D) - 1)}
        out["area"][patch] = {str(b): float(np.sum(magsf[bins == b]) / d ** 2) for b in range(len(GAP_BINS_D) - 1)}
        if patch == "particles":
            out["parts"]["particles facing the wall"] = {
                kind: float(np.sum(values[facing_wall])) for kind, values in (("form", form), ("viscous", viscous))}
    return out


def level_dirs(run_dir, study):
    return [(lv, os.path.join(run_dir, "case") if lv["level"] == 1
             else os.path.join(run_dir, "convergence", f"level_{lv['level']}")) for lv in study["levels"]]


def analyse(run_dir):
    report = json.load(open(os.path.join(run_dir, "report.json")))
    case = report["stages"]["case"]
    study = case["convergence"]
    rho = case["parameters"]["density_kg_m3"]
    bed = read_bed(os.path.join(run_dir, "bed.csv"))
    levels = []
    for lv, path in level_dirs(run_dir, study):
        if "failure" in lv:
            continue
        split = split_level(path, bed, rho, lv["pressure_gradient_bed_pa_m"])
        levels.append({"level": lv["level"], "cells": lv["cells"], "h_d": lv["cell_size_m"] / case["d_ref_m"],
                       "dp_pa_m": lv["pressure_gradient_bed_pa_m"], **split})
    return {"levels": levels, "conclusion": study["conclusion"]}


def bin_name(b):
    lo, hi = GAP_BINS_D[b], GAP_BINS_D[b + 1]
    return f"gap {lo:g}-{hi:g} d" if np.isfinite(hi) else f"gap over {lo:g} d"


def rows(level):
    """(name, force N) of every part of a level, the bins of each kind one by one."""
    out = []
    for part, values in level["parts"].items():
        if part == "particles facing the wall":
            continue
        for b, v in values.items():
            out.append((part if b == "all" else f"{part}, {bin_name(int(b))}", v))
    return out


def write(result):
    json.dump(result, open(os.path.join(DOCS, "error_by_region.json"), "w"), indent=1)
    levels = result["levels"]
    finest = levels[0]
    total = {lv["level"]: sum(v for _, v in rows(lv)) for lv in levels}
    # The interphase drag: without the linear field's push, which is the result itself.
    interphase = {lv["level"]: sum(v for name, v in rows(lv) if "linear" not in name) for lv in levels}
    lines = ["# Where a bed study's discretisation error sits (issue 57, item 1)", "",
             f"Made at commit {result['commit']} on {result['date']} by `/usr/bin/python3 tools/error_by_region.py"
             f"{result['arguments']}` ({result['wall_s'] / 60:.1f} min): {result['what']}. "
             "Form drag: the pressure less the linear field of the level's own gradient, on the particles; the "
             "linear field's push (the gradient times the solid volume, so the result itself, whatever the mesh) is "
             "listed apart and left out of the shares below, which are of the interphase drag (form and viscous, "
             "particles and wall). Viscous drag: OpenFOAM's wallShearStress. Gap: from the face's centre to the "
             "nearest other surface (another sphere or the container wall). Forces in N along the flow.", "",
             "| level | cells | h / d | dp/L (Pa/m) | linear field's push (N) | interphase drag (N) | sum of all "
             "(N) | OpenFOAM's forces objects (N) |", "|---|---|---|---|---|---|---|---|"]
    for lv in levels:
        fo = sum(c["forces_object_n"] for c in lv["check"].values())
        lines.append(f"| {lv['level']} | {lv['cells']} | {lv['h_d']:.4f} | {lv['dp_pa_m']:.4g} | "
                     f"{total[lv['level']] - interphase[lv['level']]:.5e} | {interphase[lv['level']]:.5e} | "
                     f"{total[lv['level']]:.5e} | {fo:.5e} |")
    lines += ["", f"Study's verdict: {result['conclusion']}.", "",
              "Each part's share of the finest level's interphase drag, and of its change from each coarser level to the "
              "finest (a part whose share of the change is well above its share of the drag is where the error sits); "
              "area in d^2 on the finest level:", "",
              "| part | area (d^2) | share of the interphase drag | " + " | ".join(f"of the change {lv['level']} to {finest['level']}"
                                                              for lv in levels[1:]) + " |",
              "|---|---|---|" + "---|" * (len(levels) - 1)]
    coarse_rows = {lv["level"]: dict(rows(lv)) for lv in levels}
    for name, v in rows(finest):
        if "linear" in name:
            continue
        patch = name.split(",")[0]
        b = re.search(r"gap (over )?([0-9.]+)", name)
        k = next(i for i in range(len(GAP_BINS_D) - 1) if f"{GAP_BINS_D[i]:g}" == b.group(2))
        changes = []
        for lv in levels[1:]:
            change = interphase[finest["level"]] - interphase[lv["level"]]
            changes.append(f"{100 * (v - coarse_rows[lv['level']][name]) / change:+.1f} %" if change else "")
        lines.append(f"| {name} | {finest['area'][patch][str(k)]:.3g} | {100 * v / interphase[finest['level']]:.1f} % | "
                     + " | ".join(changes) + " |")
    fw = finest["parts"]["particles facing the wall"]
    lines += ["", f"Particle faces whose nearest other surface is the container wall carry "
                  f"{100 * (fw['form'] + fw['viscous']) / interphase[finest['level']]:.1f} % of the finest level's "
                  "interphase drag.", ""]
    open(os.path.join(DOCS, "error_by_region.md"), "w").write("\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dir", help="a `bedforge run` output with a convergence study, already solved")
    ap.add_argument("--edge", type=float, default=0.1, help="finest surface edge (d)")
    ap.add_argument("--levels", type=int, default=4, help="meshes in all")
    ap.add_argument("--gap-cells", type=float, default=4, help="surface.cells_per_gap on the finest level")
    args = ap.parse_args()
    t0 = time.time()
    made = commit_and_date()
    with tempfile.TemporaryDirectory() as tmp:
        if args.dir:
            run_dir, what = args.dir, f"the study in {args.dir}"
            arguments = f" --dir {args.dir}"
        else:
            run_dir = os.path.join(tmp, "bed")
            open(run_dir + ".toml", "w").write(scene(4, 40, "bridge", args.edge, True, args.gap_cells, levels=args.levels))
            timed([BEDFORGE, "--quiet", "run", run_dir + ".toml", "-o", run_dir, "--overwrite"])
            what = (f"a = 4, N = 40 (seed 1), bridges, Re_p = 1, {args.levels} levels from a surface edge of "
                    f"{args.edge} d with {args.gap_cells:g} cells per gap, ratio 1.3")
            arguments = f" --edge {args.edge} --levels {args.levels} --gap-cells {args.gap_cells:g}"
        result = {**made, "what": what, "arguments": arguments, **analyse(run_dir), "wall_s": time.time() - t0}
    write(result)


if __name__ == "__main__":
    main()
