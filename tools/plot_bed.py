#!/usr/bin/python3
"""Plots the analysis of a run directory as PNG files beside its CSVs.

    /usr/bin/python3 tools/plot_bed.py DIR

DIR holds what `bedforge run` or `bedforge analyse` wrote: the wall profiles (radial_profile*.csv,
wall_profile_*.csv, with their centre distributions and line-intersection versions),
axial_profile.csv and report.json. Writes a PNG per wall profile,
DIR/axial_profile.png and DIR/convergence.png: the convergence history of every iterative stage
the report holds (packer, mesh optimiser, flow solve), error against elapsed time; and, when the
case ran a mesh-convergence study ([case.convergence]), DIR/mesh_convergence.png: dp/L against
cell size on each level, the Richardson extrapolation with the grid convergence index of the
finest mesh, and Eisfeld & Schnitzlein's correlation at the bed's exact void fraction of the
section with the +-20 % scatter of its data
(docs/reference.md).
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from bedforge_files import read_csv  # noqa: E402


def main(d):
    report = json.load(open(os.path.join(d, "report.json")))
    title = f"{report.get('scene', {}).get('container', {})} seed {report.get('seed')}"
    # Every wall profile: radial (cylinder, both annulus walls) or flat (box walls).
    walls = sorted(f[:-4] for f in os.listdir(d)
                   if f.startswith(("radial_profile", "wall_profile")) and f.endswith(".csv") and "_line" not in f)
    for name in walls:
        rad = read_csv(os.path.join(d, name + ".csv"))
        centres = os.path.join(d, name.replace("radial_profile", "centre_distribution") + ".csv")
        fig, ax = plt.subplots(1, 2 if os.path.exists(centres) and name.startswith("radial") else 1, figsize=(10, 4),
                               squeeze=False)
        ax = ax[0]
        ax[0].plot(rad["wall_distance_d"], rad["void_fraction"], "b-", label="volume intersection")
        if os.path.exists(os.path.join(d, name + "_line.csv")):
            line = read_csv(os.path.join(d, name + "_line.csv"))
            ax[0].plot(line["wall_distance_d"], line["void_fraction"], "r--", label="line intersection")
            ax[0].legend(fontsize=8)
        ax[0].set_xlabel("distance from the wall / d"), ax[0].set_ylabel("void fraction"), ax[0].grid(alpha=0.3)
        if len(ax) > 1:
            cen = read_csv(centres)
            ax[1].bar(cen["wall_distance_d"], cen["fraction"], width=np.diff(cen["wall_distance_d"]).mean())
            ax[1].set_xlabel("distance from the wall / d"), ax[1].set_ylabel("fraction of centres")
            ax[1].grid(alpha=0.3)
        fig.suptitle(f"{name}: {title}", fontsize=8), fig.tight_layout()
        fig.savefig(os.path.join(d, name + ".png"), dpi=110), plt.close(fig)
    if os.path.exists(os.path.join(d, "axial_profile.csv")):
        ax_ = read_csv(os.path.join(d, "axial_profile.csv"))
        fig, ax = plt.subplots(figsize=(4, 6))
        ax.plot(ax_["void_fraction"], ax_["z_d"], "k-")
        ax.set_xlabel("void fraction"), ax.set_ylabel("height z/d"), ax.grid(alpha=0.3)
        fig.tight_layout(), fig.savefig(os.path.join(d, "axial_profile.png"), dpi=110), plt.close(fig)
    plot_convergence(report, os.path.join(d, "convergence.png"))
    case = report.get("stages", {}).get("case", {})
    if "convergence" in case:
        plot_mesh_convergence(case, os.path.join(d, "mesh_convergence.png"))


def plot_mesh_convergence(case, path):
    """dp/L against cell size h = (V/N)^(1/3) over d on every level that gave a value; the
    extrapolation to h = 0 with the finest level's GCI as its band, when the study concluded one;
    the correlation at the bed's exact section void fraction with its data's scatter, or an empty
    container's exact value."""
    study, d = case["convergence"], case["d_ref_m"]
    ok = [lv for lv in study["levels"] if "failure" not in lv]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    h = [lv["cell_size_m"] / d for lv in ok]
    ax.plot(h, [lv["pressure_gradient_bed_pa_m"] for lv in ok], "ko-", label="levels (1 = the scene's mesh)")
    for lv in ok:
        ax.annotate(str(lv["level"]), (lv["cell_size_m"] / d, lv["pressure_gradient_bed_pa_m"]), fontsize=8,
                    textcoords="offset points", xytext=(4, 4))
    g = study.get("grid_convergence", {})
    if g.get("extrapolated") is not None and g.get("asymptotic", True):  # drawn only when it means something
        fine = ok[0]["pressure_gradient_bed_pa_m"]
        band = g["gci_fine"] * abs(fine)
        ax.errorbar([0.0], [g["extrapolated"]], fmt="rs", label=f"extrapolated, order {g['apparent_order']:.2f}")
        ax.errorbar([h[0]], [fine], yerr=[[band], [band]], fmt="none", ecolor="r", capsize=4,
                    label=f"GCI of the finest mesh {100 * g['gci_fine']:.1f} %")
    flow = case.get("flow", {})
    if "eisfeld_schnitzlein_bed_pa_m" in flow:
        es = flow["eisfeld_schnitzlein_bed_pa_m"]
        ax.axhspan(0.8 * es, 1.2 * es, color="g", alpha=0.12)
        ax.axhline(es, color="g", lw=1,
                   label=f"Eisfeld & Schnitzlein +-20 % at the bed's eps {flow['void_fraction_section_bed']:.3f}")
    if "exact_pa_m" in study:  # an empty container: the known answer
        ax.axhline(study["exact_pa_m"], color="b", lw=1, label="exact (fully developed laminar flow)")
    ax.set_xlim(left=-0.02 * max(h + [0.1]))
    ax.set_xlabel("cell size (V/N)^(1/3) / d"), ax.set_ylabel("dp/L (Pa/m)"), ax.grid(alpha=0.3)
    ax.set_title(study["conclusion"][:110], fontsize=7), ax.legend(fontsize=7)
    fig.tight_layout(), fig.savefig(path, dpi=110), plt.close(fig)


def plot_convergence(report, path):
    """One panel per iterative stage the report holds (packer, mesh optimiser, flow solve): its
    error measures against elapsed time, so a user sees what each extra second bought."""
    stages = report.get("stages", {})
    panels = []
    pack = stages.get("pack", {}).get("history", [])
    if pack:
        panels.append(("pack", pack))
    for attempt in stages.get("mesh", {}).get("attempts", []):
        if attempt.get("history"):
            panels.append((f"mesh optimiser ({attempt['algorithm']})", attempt["history"]))
    flow = stages.get("case", {}).get("flow", {}).get("history", [])
    if flow:
        panels.append(("flow solve (simpleFoam)", flow))
    if not panels:
        return
    fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 4), squeeze=False)
    for ax, (name, h) in zip(axes[0], panels):
        t = [p["time_s"] for p in h]
        floor = lambda key: [max(p[key], 1e-12) for p in h]  # noqa: E731 (log axes)
        if "mass_centre_d" in h[0]:  # Monte Carlo: settling of the mass centre
            ax.plot(t, [p["mass_centre_d"] for p in h], label="mass centre / d")
            ax.plot(t, [p["acceptance"] for p in h], label="acceptance")
            ax.set_yscale("log")
        elif "max_pair_overlap_d" in h[0]:  # soft-sphere packer
            ax.semilogy(t, floor("max_pair_overlap_d"), label="max pair overlap / d_min")
            ax.semilogy(t, floor("max_wall_overlap_d"), label="max wall overlap / d_min")
            if "force_residual_rms" in h[0]:
                ax.semilogy(t, floor("force_residual_rms"), label="rms force residual / weight")
        elif "max_non_orthogonality_deg" in h[0]:  # mesh optimiser, a point per pass
            ax.semilogy(t, floor("max_aspect_ratio"), "o-", label="max aspect ratio")
            ax.semilogy(t, floor("max_skewness"), "s-", label="max skewness")
            ax.semilogy(t, floor("max_non_orthogonality_deg"), "^-", label="max non-orthogonality (deg)")
            ax.semilogy(t, [p["cells_failing_gate"] + 1e-1 for p in h], "x--", label="cells failing the gate (+0.1)")
        else:  # flow solve
            ax.semilogy(t, floor("residual_U"), label="initial residual U")
            ax.semilogy(t, floor("residual_p"), label="initial residual p")
            final = h[-1].get("pressure_gradient_bed_pa_m")
            if final:
                ax.semilogy(t, [max(abs(p.get("pressure_gradient_bed_pa_m", final) / final - 1), 1e-12) for p in h],
                            label="|dp/L / final - 1|")
        ax.set_title(name, fontsize=9), ax.set_xlabel("elapsed time (s)"), ax.legend(fontsize=7), ax.grid(alpha=0.3)
    fig.tight_layout(), fig.savefig(path, dpi=110), plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
