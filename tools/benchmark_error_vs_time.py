#!/usr/bin/python3
"""Error against run time, one Pareto plot per stage; writes docs/error_vs_time.md, .json and
docs/pareto_*.png.

    /usr/bin/python3 tools/benchmark_error_vs_time.py                  # every section (about 10 minutes on 2 cores)
    /usr/bin/python3 tools/benchmark_error_vs_time.py --only surface   # some sections, keep the others' results

packer:   a = 5, N = 500, seeds 1-5, the overlap tolerance swept in both modes. Error of a setting:
          its seed-mean central void fraction and radial profile (0-3 d from the wall) against those
          of the tightest setting (accelerated, 1e-5 d); the seed-to-seed standard error of the mean
          is the floor below which no setting can be told apart.
surface:  one bed (a = 5, N = 500, seed 1, shrunk contacts, no refinement across gaps), the surface edge length swept (contact
          edge a third of it): volume error against the exact treated geometry and chordal deviation,
          against the stage's time.
mesh:     mesh and CFD from the convergence studies in docs/mesh_case_benchmark.json (study_gaps and
          study_reynolds of tools/benchmark_mesh_case.py): each level's dp/L against the study's
          Richardson-extrapolated value, with the GCI of the finest mesh as the reference's own band,
          against the level's own time (one surface, mesh and simpleFoam run). Studies not in the
          asymptotic range have no trusted reference and are left out, and said so.
Times are the stages' own (report.json), one run at a time.
"""
import argparse
import json
import os
import shutil
import subprocess
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from bedforge_files import BEDFORGE, DOCS, GAPS_COARSENED_FROM, commit_and_date, gaps_not_coarsened, made_line, read_csv  # noqa: E402

RESULTS = os.path.join(DOCS, "error_vs_time.json")
SECTIONS = ["packer", "surface", "mesh"]
ENV = dict(os.environ, OMP_NUM_THREADS="2")
SEEDS = range(1, 6)
SWEEP = {"accelerated": [3e-3, 1e-3, 3e-4, 1e-4, 1e-5], "faithful": [1e-3, 1e-4]}
REFERENCE = ("accelerated", 1e-5)
EDGES = [0.2, 0.15, 0.1, 0.07, 0.05]  # 0.3 d is refused with shrink: wall facets cut into the 0.005 d wall gap
PROFILE_RANGE_D = 3.0


def bedforge(*args):
    subprocess.run([BEDFORGE, "--quiet", *args], check=True, env=ENV)


def report(d):
    return json.load(open(os.path.join(d, "report.json")))


def packer_section(work):
    runs = []
    for mode, tolerances in SWEEP.items():
        for tol in tolerances:
            for seed in SEEDS:
                scene = os.path.join(work, "scene.toml")
                open(scene, "w").write(f"""[container]
diameter_d = 5
[particles]
count = 500
diameter_m = 0.001
[packing]
seed = {seed}
[packing.soft_sphere]
mode = "{mode}"
overlap_tolerance_d = {tol}
[outputs]
files = ["positions", "analysis"]
""")
                out = os.path.join(work, f"{mode}_{tol}_{seed}")
                bedforge("run", scene, "-o", out)
                r = report(out)["stages"]
                prof = read_csv(os.path.join(out, "radial_profile.csv"))
                keep = prof["wall_distance_d"] <= PROFILE_RANGE_D
                runs.append({"mode": mode, "tolerance_d": tol, "seed": seed, "time_s": r["pack"]["time_s"],
                             "iterations": r["pack"]["iterations"],
                             "eps_central": r["analysis"]["void_fraction"]["central_slab"],
                             "profile": prof["void_fraction"][keep].tolist()})
                print(mode, tol, seed, f"{r['pack']['time_s']:.2f} s", flush=True)
    # Seed means, and their distance from the tightest setting's.
    groups = {}
    for r in runs:
        groups.setdefault((r["mode"], r["tolerance_d"]), []).append(r)
    ref = groups[REFERENCE]
    ref_eps = np.mean([r["eps_central"] for r in ref])
    ref_prof = np.mean([r["profile"] for r in ref], axis=0)
    noise_eps = np.std([r["eps_central"] for r in ref], ddof=1) / np.sqrt(len(ref))
    noise_prof = np.sqrt(np.mean(np.var([r["profile"] for r in ref], axis=0, ddof=1))) / np.sqrt(len(ref))
    points = []
    for (mode, tol), rs in groups.items():
        prof = np.mean([r["profile"] for r in rs], axis=0)
        points.append({"mode": mode, "tolerance_d": tol, "time_s": float(np.mean([r["time_s"] for r in rs])),
                       "iterations": float(np.mean([r["iterations"] for r in rs])),
                       "eps_central": float(np.mean([r["eps_central"] for r in rs])),
                       "eps_error": float(abs(np.mean([r["eps_central"] for r in rs]) - ref_eps)),
                       "profile_rms_error": float(np.sqrt(np.mean((prof - ref_prof) ** 2)))})
    return {"points": points, "noise_eps": float(noise_eps), "noise_profile": float(noise_prof), "seeds": len(SEEDS)}


def surface_section(work):
    bed = os.path.join(work, "bed")
    bedforge("pack", "--aspect-ratio", "5", "--count", "500", "--seed", "1", "--diameter-m", "0.003", "-o", bed)
    points = []
    for e in EDGES:
        d = os.path.join(work, f"surface_{e}")
        shutil.copytree(bed, d)
        bedforge("surface", d, "--contacts", "shrink", "--cells-per-gap", "0", "--edge-length-d", str(e),
                 "--contact-edge-length-d", f"{e / 3:.4g}")
        s = report(d)["stages"]["surface"]
        points.append({"edge_d": e, "time_s": s["time_s"], "triangles": s["triangles"],
                       "volume_error": abs(s["fluid_volume_relative_error"]), "chordal_d": s["chordal_deviation_d"],
                       "min_angle_deg": s["min_angle_deg"], "peak_memory_mb": s["peak_memory_mb"]})
        print("surface", e, f"{s['time_s']:.1f} s", flush=True)
        shutil.rmtree(d)
    return {"points": points}


def mesh_section():
    src = json.load(open(os.path.join(DOCS, "mesh_case_benchmark.json")))
    studies, left_out = [], []
    for r in [src["study_gaps"]] + src.get("study_reynolds", []):
        g = r["study"].get("grid_convergence", {})
        levels = [lv for lv in r["study"]["levels"] if "failure" not in lv]
        why = ("its levels not refined alike (made before " + GAPS_COARSENED_FROM + ", the gaps not coarsened)"
               if gaps_not_coarsened(r) else "not in the asymptotic range" if not g.get("asymptotic") else
               "made before levels recorded their own time" if any("own_time_s" not in lv for lv in levels) else None)
        if why:
            left_out.append({"reynolds": r["reynolds"], "commit": r["commit"], "why": why})
            continue
        ext = g["extrapolated"]
        studies.append({"commit": r["commit"], "date": r["date"], "reynolds": r["reynolds"], "edge_d": r["edge_d"],
                         "cells_per_gap": r["cells_per_gap"], "extrapolated_pa_m": ext, "gci_fine": g["gci_fine"],
                         "order": g["apparent_order"], "es_bed_pa_m": r["es_bed_pa_m"],
                         "points": [{"level": lv["level"], "cells": lv["cells"], "time_s": lv["own_time_s"],
                                     "dp_pa_m": lv["pressure_gradient_bed_pa_m"],
                                     "error": abs(lv["pressure_gradient_bed_pa_m"] - ext) / ext} for lv in levels]})
    return {"studies": studies, "left_out": left_out}


def pareto(ax, xs, ys, labels, **kw):
    order = np.argsort(xs)
    ax.loglog(np.array(xs)[order], np.array(ys)[order], **kw)
    for x, y, t in zip(xs, ys, labels):
        ax.annotate(t, (x, y), fontsize=7, xytext=(3, 3), textcoords="offset points")


def plots(R):
    if "packer" in R:
        P = R["packer"]
        fig, axes = plt.subplots(1, 2, figsize=(11, 4))
        for ax, key, noise, what in ((axes[0], "eps_error", P["noise_eps"], "|central eps - tightest|"),
                                     (axes[1], "profile_rms_error", P["noise_profile"],
                                      f"rms radial profile difference (0-{PROFILE_RANGE_D:g} d)")):
            for mode, style in (("accelerated", "o-"), ("faithful", "s-")):
                pts = [p for p in P["points"] if p["mode"] == mode and (mode, p["tolerance_d"]) != REFERENCE]
                pareto(ax, [p["time_s"] for p in pts], [max(p[key], 1e-6) for p in pts],
                       [f"{p['tolerance_d']:g}" for p in pts], marker=style[0], label=mode)
            ax.axhline(noise, color="gray", ls="--", label="seed-to-seed standard error")
            ax.set_xlabel("packing time per bed (s)"), ax.set_ylabel(what), ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=7)
        fig.suptitle("packer, a = 5, N = 500: error against time (labels: overlap tolerance / d)", fontsize=9)
        fig.tight_layout(), fig.savefig(os.path.join(DOCS, "pareto_packer.png"), dpi=110), plt.close(fig)
    if "surface" in R:
        pts = R["surface"]["points"]
        fig, ax = plt.subplots(figsize=(6, 4))
        labels = [f"{p['edge_d']:g} d" for p in pts]
        pareto(ax, [p["time_s"] for p in pts], [p["volume_error"] for p in pts], labels, marker="o",
               label="fluid volume error")
        pareto(ax, [p["time_s"] for p in pts], [p["chordal_d"] for p in pts], labels, marker="s",
               label="chordal deviation / d")
        ax.set_xlabel("surface stage time (s)"), ax.grid(alpha=0.3, which="both"), ax.legend(fontsize=7)
        ax.set_title("surface, a = 5, N = 500, shrink (labels: edge length)", fontsize=9)
        fig.tight_layout(), fig.savefig(os.path.join(DOCS, "pareto_surface.png"), dpi=110), plt.close(fig)
    if "mesh" in R and R["mesh"]["studies"]:
        fig, ax = plt.subplots(figsize=(6, 4))
        for st, marker in zip(R["mesh"]["studies"], "osd^"):
            pts = st["points"]
            line, = ax.loglog([p["time_s"] for p in pts], [p["error"] for p in pts], marker=marker,
                              label=f"Re_p = {st['reynolds']:g}: |dp/L - extrapolated| / extrapolated")
            ax.axhline(st["gci_fine"], color=line.get_color(), ls=":", lw=1,
                       label=f"Re_p = {st['reynolds']:g}: GCI of the finest mesh (the study's band)")
            for p in pts:
                ax.annotate(f"{p['cells'] / 1e6:.2f}M", (p["time_s"], p["error"]), fontsize=7, xytext=(3, 3),
                            textcoords="offset points")
        ax.set_xlabel("the level's own surface + mesh + simpleFoam time (s)"), ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=6), ax.set_title("mesh and CFD, a = 5, N = 500, bridges, 3 cells across gaps", fontsize=9)
        fig.tight_layout(), fig.savefig(os.path.join(DOCS, "pareto_mesh_case.png"), dpi=110), plt.close(fig)


def table(title, made, intro, columns, rows, image):
    """A stage's section of the report: heading, which commit made it, what was run, its table and its plot."""
    return ([f"## {title}", "", made_line(made), "", intro, "", "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)] +
            ["| " + " | ".join(r) + " |" for r in rows] + ["", image, ""])


def write_report(R):
    L = ["# Error against run time, stage by stage", "",
         "Made by `/usr/bin/python3 tools/benchmark_error_vs_time.py` on the 2-core machine of the CI; "
         "each stage's accuracy knob swept on a fixed scene, error against the stage's own time. "
         "What each run spends and reaches on the user's own scene is in its report (`history` of every "
         "iterative stage; `tools/plot_bed.py DIR` draws it).", ""]
    if "packer" in R:
        P = R["packer"]
        L += table("Packer: overlap tolerance and mode", R["packer"],
                   f"a = 5, N = 500, {P['seeds']} seeds per setting. Error = distance of the seed-mean central void "
                   f"fraction and radial profile from those of the tightest setting (accelerated, 1e-5 d). Seed-to-seed "
                   f"standard error of that mean: {P['noise_eps']:.4f} (void fraction), {P['noise_profile']:.4f} "
                   "(profile): errors below these are noise.",
                   ["mode", "overlap tolerance (d)", "time per bed (s)", "iterations", "central eps", "error eps",
                    "error profile (rms)"],
                   [[p["mode"], f"{p['tolerance_d']:g}", f"{p['time_s']:.2f}", f"{p['iterations']:.0f}",
                     f"{p['eps_central']:.4f}", f"{p['eps_error']:.4f}", f"{p['profile_rms_error']:.4f}"]
                    for p in sorted(P["points"], key=lambda p: (p["mode"], -p["tolerance_d"]))],
                   "![packer](pareto_packer.png)")
    if "surface" in R:
        L += table("Surface: edge length", R["surface"],
                   "One bed (a = 5, N = 500, seed 1, d = 3 mm), `shrink` (the default), contact edge a third of the "
                   "edge length.",
                   ["edge (d)", "triangles", "time (s)", "peak MB", "volume error", "chordal deviation (d)",
                    "min angle (deg)"],
                   [[f"{p['edge_d']:g}", str(p["triangles"]), f"{p['time_s']:.1f}", f"{p['peak_memory_mb']:.0f}",
                     f"{p['volume_error']:.2e}", f"{p['chordal_d']:.2e}", f"{p['min_angle_deg']:.1f}"]
                    for p in R["surface"]["points"]],
                   "![surface](pareto_surface.png)")
    if "mesh" in R:
        L += ["## Mesh and CFD: cell size, against the extrapolated pressure drop", ""]
        for st in R["mesh"]["studies"]:
            L += [f"Re_p = {st['reynolds']:g}: " + made_line(st), "",
                  f"From the convergence study of [mesh_case_benchmark.md](mesh_case_benchmark.md) (a = 5, N = 500, "
                  f"bridges, finest surface edge {st['edge_d']:g} d, {st['cells_per_gap']:g} cells across narrow gaps, "
                  f"simpleFoam on 2 processes). Reference: its Richardson extrapolation, {st['extrapolated_pa_m']:.4g} Pa/m "
                  f"(apparent order {st['order']:.2f}). Its band is the GCI of the finest mesh, {100 * st['gci_fine']:.1f} % "
                  "(Celik et al. 2008: the finest value's numerical uncertainty at about 95 % confidence): these "
                  "errors are estimates good to about that much, not measurements against an exact value.", "",
                  "| level | cells | own time (s) | dp/L (Pa/m) | error against extrapolated | / E&S at the bed's eps |",
                  "|---|---|---|---|---|---|"]
            L += [f"| {p['level']} | {p['cells']} | {p['time_s']:.0f} | {p['dp_pa_m']:.4g} | {100 * p['error']:.1f} % | "
                  f"{p['dp_pa_m'] / st['es_bed_pa_m']:.3f} |" for p in st["points"]]
            L += [""]
        for lo in R["mesh"]["left_out"]:
            L += [f"Left out: the study at Re_p = {lo['reynolds']:g} (made at {lo['commit']}), {lo['why']}.", ""]
        if R["mesh"]["studies"]:
            L += ["![mesh and CFD](pareto_mesh_case.png)", ""]
        else:
            L += ["No study gives a reference: none is in the asymptotic range with its levels refined alike.", ""]
    L += ["Why the defaults are what they are, read from these curves: [defaults.md](defaults.md).", ""]
    open(os.path.join(DOCS, "error_vs_time.md"), "w").write("\n".join(L))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", nargs="+", choices=SECTIONS, default=SECTIONS,
                    help="sections to run; the others are kept from docs/error_vs_time.json")
    args = ap.parse_args()
    if not os.path.exists(BEDFORGE):
        raise SystemExit("build/bedforge is missing: run `bash tools/setup.sh` first")
    R = json.load(open(RESULTS)) if os.path.exists(RESULTS) and args.only != SECTIONS else {}
    with tempfile.TemporaryDirectory(prefix="bedforge_pareto_") as work:
        if "packer" in args.only:
            R["packer"] = {**commit_and_date(), **packer_section(work)}
        if "surface" in args.only:
            R["surface"] = {**commit_and_date(), **surface_section(work)}
    if "mesh" in args.only:
        R["mesh"] = mesh_section()
    json.dump(R, open(RESULTS, "w"), indent=1)
    plots(R)
    write_report(R)


if __name__ == "__main__":
    main()
