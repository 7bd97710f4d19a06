#!/usr/bin/python3
"""Plots the analysis of a run directory as PNG files beside its CSVs.

    /usr/bin/python3 tools/plot_bed.py DIR

DIR holds what `bedforge run` or `bedforge analyse` wrote: radial_profile.csv,
centre_distribution.csv, axial_profile.csv and report.json. Writes DIR/radial_profile.png,
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
    if os.path.exists(os.path.join(d, "radial_profile.csv")):
        rad, cen = read_csv(os.path.join(d, "radial_profile.csv")), read_csv(os.path.join(d, "centre_distribution.csv"))
        fig, ax = plt.subplots(1, 2, figsize=(10, 4))
        ax[0].plot(rad["wall_distance_d"], rad["void_fraction"], "b-")
        ax[0].set_xlabel("distance from the wall (R - r)/d"), ax[0].set_ylabel("void fraction"), ax[0].grid(alpha=0.3)
        ax[1].bar(cen["wall_distance_d"], cen["fraction"], width=np.diff(cen["wall_distance_d"]).mean())
        ax[1].set_xlabel("distance from the wall (R - r)/d"), ax[1].set_ylabel("fraction of centres"), ax[1].grid(alpha=0.3)
        fig.suptitle(title, fontsize=8), fig.tight_layout()
        fig.savefig(os.path.join(d, "radial_profile.png"), dpi=110), plt.close(fig)
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
        ax.semilogy(t, [max(h["max_pair_overlap_d"], 1e-9) for h in history], label="max pair overlap / d_min")
        ax.semilogy(t, [max(h["max_wall_overlap_d"], 1e-9) for h in history], label="max wall overlap / d_min")
        if "force_residual_rms" in history[0]:
            ax.semilogy(t, [max(h["force_residual_rms"], 1e-9) for h in history], label="rms force residual / weight")
        ax.set_xlabel("elapsed time (s)"), ax.legend(fontsize=8), ax.grid(alpha=0.3)
        fig.tight_layout(), fig.savefig(os.path.join(d, "convergence.png"), dpi=110), plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
