#!/usr/bin/python3
"""Plots the analysis of a run directory as PNG files beside its CSVs.

    /usr/bin/python3 tools/plot_bed.py DIR

DIR holds what `bedforge run` or `bedforge analyse` wrote: the wall profiles (radial_profile*.csv,
wall_profile_*.csv, with their centre distributions and line-intersection versions),
axial_profile.csv and report.json. Writes a PNG per wall profile,
DIR/axial_profile.png and, when the report has a packer history, DIR/convergence.png.
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
    history = report.get("stages", {}).get("pack", {}).get("history", [])
    if history:
        fig, ax = plt.subplots(figsize=(7, 4))
        t = [h["time_s"] for h in history]
        if "mass_centre_d" in history[0]:  # Monte Carlo: settling of the mass centre
            ax.plot(t, [h["mass_centre_d"] for h in history], label="mass centre / d")
            ax.plot(t, [h["acceptance"] for h in history], label="acceptance")
            ax.set_yscale("log")
        else:
            ax.semilogy(t, [max(h["max_pair_overlap_d"], 1e-9) for h in history], label="max pair overlap / d_min")
            ax.semilogy(t, [max(h["max_wall_overlap_d"], 1e-9) for h in history], label="max wall overlap / d_min")
            if "force_residual_rms" in history[0]:
                ax.semilogy(t, [max(h["force_residual_rms"], 1e-9) for h in history],
                            label="rms force residual / weight")
        ax.set_xlabel("elapsed time (s)"), ax.legend(fontsize=8), ax.grid(alpha=0.3)
        fig.tight_layout(), fig.savefig(os.path.join(d, "convergence.png"), dpi=110), plt.close(fig)

if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
