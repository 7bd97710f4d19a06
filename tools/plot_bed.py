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
(docs/reference.md). From bed.csv, DIR/bed.png: the bed seen from the side, spheres coloured by
their contacts; and when DIR/case holds a mesh, DIR/mesh_section.png: the cells cut by the
horizontal plane through the contact nearest the bed's middle, coloured by non-orthogonality,
with a zoom onto that contact's gap.
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from bedforge_files import read_bed, read_csv, read_poly_mesh  # noqa: E402

CONTACT_GAP_D = 1e-3  # surfaces nearer than this (in d) count as touching in the pictures


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
    if os.path.exists(os.path.join(d, "bed.csv")):
        centres, diameters, container = read_bed(os.path.join(d, "bed.csv"))
        if len(diameters):
            pairs, count = contacts(centres, diameters, container)
            plot_bed_picture(centres, diameters, count, os.path.join(d, "bed.png"))
            mesh = os.path.join(d, "case", "constant", "polyMesh")
            if os.path.exists(os.path.join(mesh, "owner")):
                plot_mesh_section(mesh, centres, diameters, pairs, os.path.join(d, "mesh_section.png"))
    case = report.get("stages", {}).get("case", {})
    if "convergence" in case:
        plot_mesh_convergence(case, os.path.join(d, "mesh_convergence.png"))


def contacts(centres, diameters, container):
    """Touching pairs (i, j) and each sphere's contact count, walls and floor included."""
    from scipy.spatial import cKDTree
    tol = CONTACT_GAP_D * diameters.mean()
    r = 0.5 * diameters
    pairs = np.array(sorted(cKDTree(centres).query_pairs(diameters.max() + tol)), dtype=int).reshape(-1, 2)
    gap = np.linalg.norm(centres[pairs[:, 0]] - centres[pairs[:, 1]], axis=1) - r[pairs[:, 0]] - r[pairs[:, 1]]
    pairs = pairs[gap < tol]
    count = np.bincount(pairs.ravel(), minlength=len(r)) + (centres[:, 2] - r < tol)
    radial = np.hypot(centres[:, 0], centres[:, 1])
    if container.get("type") in ("cylinder", "annulus"):
        count += 0.5 * container["diameter"] - radial - r < tol
    if container.get("type") == "annulus":
        count += radial - 0.5 * container["inner_diameter"] - r < tol
    if container.get("type") == "box":
        for axis, size in ((0, container.get("length_x", 0)), (1, container.get("length_y", 0))):
            count += (0.5 * size - np.abs(centres[:, axis]) - r < tol)
    return pairs, count


def plot_bed_picture(centres, diameters, count, path):
    """The bed seen from the side, each sphere shaded as lit from the upper left and coloured by
    its number of contacts (`count`); spheres are painted far to near, so the near ones hide the rest."""
    from matplotlib.patches import Circle
    d = diameters.mean()
    cmap = plt.get_cmap("viridis", max(2, count.max() + 1))
    height = (centres[:, 2].max() + diameters.max()) / d
    width = 2 * np.abs(centres[:, 0]).max() / d + 1
    fig, ax = plt.subplots(figsize=(min(12, 2 + 0.9 * width), min(14, 1 + 0.9 * height)))
    for i in np.argsort(-centres[:, 1]):  # the viewer looks along +y
        x, z, r = centres[i, 0] / d, centres[i, 2] / d, 0.5 * diameters[i] / d
        base = np.array(cmap(count[i])[:3])
        for k, f in enumerate(np.linspace(1.0, 0.2, 10)):  # dark rim to a light spot up and to the left
            shade = base * (0.45 + 0.55 * k / 9) + (1 - base) * 0.5 * (k / 9) ** 3
            ax.add_patch(Circle((x - 0.35 * r * (1 - f), z + 0.35 * r * (1 - f)), r * f, color=np.clip(shade, 0, 1),
                                lw=0))
    ax.set_xlim(-width / 2, width / 2), ax.set_ylim(0, height), ax.set_aspect("equal")
    ax.set_xlabel("x / d"), ax.set_ylabel("height z / d")
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(-0.5, count.max() + 0.5))
    fig.colorbar(sm, ax=ax, shrink=0.6, label=f"contacts per sphere (gap < {CONTACT_GAP_D:g} d, walls included)")
    ax.set_title(f"{len(diameters)} spheres, side view", fontsize=9)
    fig.tight_layout(), fig.savefig(path, dpi=110), plt.close(fig)


def plot_mesh_section(mesh_dir, centres, diameters, pairs, path):
    """The solved mesh cut by the horizontal plane through the contact nearest the bed's middle:
    every cell the plane crosses, drawn as its cut and coloured by the largest non-orthogonality
    of its faces (checkMesh's measure; above 70 degrees checkMesh warns); the right panel zooms
    onto that contact. `pairs`: the touching pairs of `contacts`."""
    from matplotlib.collections import PolyCollection
    d = diameters.mean()
    points, offsets, labels, owner, neighbour = read_poly_mesh(mesh_dir)
    middle = 0.5 * (centres[:, 2].min() + centres[:, 2].max())
    spots = 0.5 * (centres[pairs[:, 0]] + centres[pairs[:, 1]]) if len(pairs) else centres
    spot = spots[np.argmin(np.abs(spots[:, 2] - middle))]
    z0 = spot[2] + 1e-9 * d  # off any vertex exactly on the plane
    # Face centres and area vectors by fans from the vertex average; cell centres from them.
    sizes = np.diff(offsets)
    face = np.repeat(np.arange(len(sizes)), sizes)
    nxt = np.arange(len(labels)) + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    p, q = points[labels], points[labels[nxt]]
    mid = np.add.reduceat(p, offsets[:-1]) / sizes[:, None]
    tri = 0.5 * np.cross(p - mid[face], q - mid[face])
    area = np.add.reduceat(tri, offsets[:-1])
    w = np.linalg.norm(tri, axis=1)
    centre = np.add.reduceat((mid[face] + p + q) / 3 * w[:, None], offsets[:-1]) / \
        np.maximum(np.add.reduceat(w, offsets[:-1]), 1e-300)[:, None]
    cells = owner.max() + 1
    beyond = np.concatenate([neighbour, -np.ones(len(owner) - len(neighbour), int)])  # -1 on boundary faces
    fa = np.linalg.norm(area, axis=1)
    cell_centre = np.zeros((cells, 3))
    weight = np.zeros(cells)
    for c in (owner, beyond):
        ok = c >= 0
        np.add.at(cell_centre, c[ok], centre[ok] * fa[ok, None])
        np.add.at(weight, c[ok], fa[ok])
    cell_centre /= weight[:, None]
    internal = len(neighbour)
    link = cell_centre[neighbour] - cell_centre[owner[:internal]]
    cosine = np.einsum("ij,ij->i", link, area[:internal]) / (np.linalg.norm(link, axis=1) * fa[:internal])
    non_ortho = np.degrees(np.arccos(np.clip(cosine, -1, 1)))
    worst = np.zeros(cells)
    np.maximum.at(worst, owner[:internal], non_ortho)
    np.maximum.at(worst, neighbour, non_ortho)
    # The plane's cut of each crossed cell: where its faces' edges cross z0.
    crossing = (p[:, 2] - z0) * (q[:, 2] - z0) < 0
    t = (z0 - p[crossing, 2]) / (q[crossing, 2] - p[crossing, 2])
    cut = p[crossing, :2] + t[:, None] * (q[crossing, :2] - p[crossing, :2])
    faces_cut = face[crossing]
    by_cell = {}
    for cell_of in (owner, beyond):
        cs = cell_of[faces_cut]
        for c, xy in zip(cs[cs >= 0], cut[cs >= 0]):
            by_cell.setdefault(c, []).append(xy)
    polys, colours = [], []
    for c, xy in by_cell.items():
        xy = np.unique(np.round(np.array(xy) / d, 9), axis=0)
        if len(xy) < 3:
            continue
        o = xy.mean(axis=0)
        polys.append(xy[np.argsort(np.arctan2(xy[:, 1] - o[1], xy[:, 0] - o[0]))])
        colours.append(worst[c])
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.6))
    for ax, zoom in zip(axes, (False, True)):
        pc = PolyCollection(polys, array=np.array(colours), cmap="plasma", clim=(0, 80), edgecolors="k",
                            linewidths=0.1 if not zoom else 0.3)
        ax.add_collection(pc)
        ax.set_aspect("equal")
        if zoom:
            ax.set_xlim(spot[0] / d - 0.4, spot[0] / d + 0.4), ax.set_ylim(spot[1] / d - 0.4, spot[1] / d + 0.4)
            ax.set_title("around the contact", fontsize=9)
        else:
            ax.autoscale()
            ax.plot(spot[0] / d, spot[1] / d, "c+", ms=14, mew=2)
            ax.set_title(f"{len(polys)} cells cut by z = {z0 / d:.3f} d (+: the contact zoomed on)", fontsize=9)
        ax.set_xlabel("x / d"), ax.set_ylabel("y / d")
    fig.colorbar(pc, ax=axes, shrink=0.8, label="largest face non-orthogonality of the cell (deg)")
    fig.savefig(path, dpi=110), plt.close(fig)


def plot_mesh_convergence(case, path):
    """dp/L against cell size h = (V/N)^(1/3) over d on every level that gave a value; the
    extrapolation to h = 0 with the finest level's GCI as its band, when the study concluded one;
    the least-squares power law over all levels, when there were four or more;
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
    fit = study.get("least_squares", {})
    if fit.get("fitted"):
        hs = [h[-1] * k / 100 for k in range(101)]  # from h = 0 to the coarsest level
        ax.plot(hs, [fit["extrapolated"] + fit["coefficient"] * (x / h[0]) ** fit["order"] for x in hs], "b--", lw=1,
                label=f"least squares over {fit['levels']} levels, order {fit['order']:.2f}"
                      + ("" if fit.get("asymptotic", True) else " (outside 1-3: not trusted)"))
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
    mesh = stages.get("mesh", {})
    # A mesh made in slabs has each slab's attempts; the first slab's stand for the rest.
    for attempt in (mesh["slabs"][0] if "slabs" in mesh else mesh).get("attempts", []):
        if attempt.get("history"):
            slab = f", slab 1 of {len(mesh['slabs'])}" if "slabs" in mesh else ""
            panels.append((f"mesh optimiser ({attempt['algorithm']}, {attempt.get('optimiser', 'gmsh')}'s{slab})",
                           attempt["history"]))
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
