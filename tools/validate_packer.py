#!/usr/bin/python3
"""Validation and speed benchmark of the soft-sphere packer; writes docs/validation.md,
docs/validation.json and the PNG figures beside them.

    /usr/bin/python3 tools/validate_packer.py            # the full set (about an hour on 2 cores)
    /usr/bin/python3 tools/validate_packer.py --quick    # fewer seeds and sizes, for a look
    /usr/bin/python3 tools/validate_packer.py --only paper speed   # rerun some sections, keep the rest

Every case is a real `build/bedforge pack` run followed by `bedforge analyse`; both modes run
single-threaded side by side (two at a time on two cores), so their time ratio is measured in
the same conditions. Reference values are those of docs/reference.md (Salvat et al. 2005 and the
correlations collected there).
"""
import argparse
import concurrent.futures as cf
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from bedforge_files import BEDFORGE, DOCS, commit_and_date, made_line, read_csv  # noqa: E402
from references import benyahia, de_klerk, dixon, jeschar, zou_yu_dense, zou_yu_loose  # noqa: E402,F401



SECTIONS = ["paper", "eps0", "by_a", "contacts", "speed", "periodic"]
N_1E5_LIMIT_S = 240.0  # issue 25: every seed of the N = 1e5 bed under this, on this 2-core machine
# Independent frictionless DEM run of a = 7.99, N = 1111 (central slab, gaps below 1e-3 d), made
# outside this project and reported in issue 25; not reproducible here.
DEM_7_99 = dict(eps=0.398, z=5.42, rattlers=12)
TIGHTER_FORCE_TOLERANCES = [0.1, 0.05]  # accelerated stopping tests beside the default 0.2


def count_for(a, height_d):
    """Spheres filling a tube of aspect ratio a to about height_d diameters at eps ~ 0.42."""
    return int(round(0.58 * (math.pi / 4 * a * a * height_d) / (math.pi / 6)))


def run(case):
    """One pack + analyse; returns the case with its measured results."""
    out = tempfile.mkdtemp(prefix="bedforge_val_")
    shape = [] if "box_d" in case else ["--aspect-ratio", str(case["a"])]  # a box comes from the scene file
    cmd = [BEDFORGE, "--quiet", "pack", *shape, "--count", str(case["n"]),
           "--seed", str(case["seed"]), "--mode", case["mode"],
           "--initial-void-fraction", str(case.get("eps0", 0.47)), "-o", os.path.join(out, "bed")]
    if "force_tolerance" in case or "period_d" in case:  # no command-line option: a scene file sets them
        scene = os.path.join(out, "scene.toml")
        text = f"[packing.soft_sphere]\nforce_tolerance = {case['force_tolerance']}\n" if "force_tolerance" in case else ""
        if "period_d" in case:  # a periodic section: a tube, or a box periodic on every side (box_d)
            text += f"[container]\nperiod_z_d = {case['period_d']}\n"
            if "box_d" in case:
                text += (f"type = \"box\"\nsize_x_d = {case['box_d']}\nsize_y_d = {case['box_d']}\n"
                         "periodic_x = true\nperiodic_y = true\n")
        open(scene, "w").write(text)
        cmd += ["--scene", scene]
    env = dict(os.environ, OMP_NUM_THREADS=str(case.get("threads", 1)))
    t0 = time.time()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.time() - t0
    if p.returncode != 0:
        return dict(case, error=p.stdout + p.stderr, wall_s=wall)
    bed = os.path.join(out, "bed")
    if case.get("analyse", True):
        subprocess.run([BEDFORGE, "--quiet", "analyse", "--contact-tolerance-d", str(case.get("contact_tol", 1e-4)), bed],
                       env=env, check=True)
    rep = json.load(open(os.path.join(bed, "report.json")))
    pack = rep["stages"]["pack"]
    res = dict(case, wall_s=wall, time_s=pack["time_s"], iterations=pack["iterations"],
               eps_whole=pack["void_fraction"]["whole_bed"], eps_central=pack["void_fraction"]["central_slab"],
               max_overlap=pack["max_pair_overlap_d"], residual=pack["force_residual_rms"],
               recoveries=len(pack["recoveries"]))
    if "analysis" in rep["stages"]:
        an = rep["stages"]["analysis"]
        res["z_bulk"] = an["coordination"]["bulk_mean_without_rattlers"]
        slab = an["coordination"]["central_slab"]
        res.update(z_slab=slab["mean_all"], rattlers_slab=slab["rattlers"], spheres_slab=slab["spheres"])
        if os.path.exists(os.path.join(bed, "radial_profile.csv")):  # a box has none
            prof = read_csv(os.path.join(bed, "radial_profile.csv"))
            res["radial"] = [prof["wall_distance_d"].tolist(), prof["void_fraction"].tolist()]
            cen = read_csv(os.path.join(bed, "centre_distribution.csv"))
            res["centres"] = [cen["wall_distance_d"].tolist(), cen["fraction"].tolist()]
        res["z_no_rattlers"] = an["coordination"]["mean_without_rattlers"]
        res["rattlers"] = an["coordination"]["rattlers"]
    subprocess.run(["rm", "-rf", out])
    return res


def run_all(cases, workers=2):
    """Runs the cases, two at a time by default, printing each result as it comes."""
    results = []
    with cf.ProcessPoolExecutor(max_workers=workers) as pool:
        for r in pool.map(run, cases):
            tag = f"{r['mode']:11s} a={r['a']:<5} N={r['n']:<6} seed={r['seed']} eps0={r.get('eps0', 0.47)}"
            if "error" in r:
                print(f"FAILED {tag}: {r['error'].strip()}", flush=True)
            else:
                print(f"{tag}: eps {r['eps_whole']:.4f} / central {r['eps_central']:.4f}, "
                      f"{r['iterations']} it, {r['time_s']:.1f} s", flush=True)
            results.append(r)
    return results


def stats(rs, key):
    v = [r[key] for r in rs if key in r and r[key] is not None]
    if not v:
        return float("nan"), float("nan"), 0
    return statistics.mean(v), (statistics.stdev(v) if len(v) > 1 else 0.0), len(v)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="fewer seeds and sizes")
    ap.add_argument("--only", nargs="+", choices=SECTIONS, default=SECTIONS,
                    help="sections to run; the others are kept from docs/validation.json")
    args = ap.parse_args()
    if not os.path.exists(BEDFORGE):
        sys.exit("build/bedforge is missing: run `bash tools/setup.sh` first")
    quick = args.quick
    seeds10 = range(1, 4 if quick else 11)
    seeds5 = range(1, 3 if quick else 6)
    previous = os.path.join(DOCS, "validation.json")
    results = json.load(open(previous)) if os.path.exists(previous) and args.only != SECTIONS else {}
    want = set(args.only)

    # Each section: its cases, run and timed.
    a_small, a_large = [7.99, 10], ([15, 20] if quick else [15, 20, 30])
    sizes = [(1000, 7), (10000, 14)] + ([] if quick else [(100000, 40)])
    sections = {
        # 1. The paper's case, both modes.
        "paper": lambda: run_all([dict(a=5, n=500, seed=s, mode=m) for s in seeds10
                                  for m in ("faithful", "accelerated")]),
        # 2. eps_0 sensitivity (Sec. 4.1 of the paper).
        "eps0": lambda: run_all([dict(a=5, n=500, seed=s, mode=m, eps0=e, analyse=False) for e in (0.30, 0.40, 0.55)
                                 for s in seeds5 for m in ("faithful", "accelerated")]),
        # 3. eps_F against a: both modes up to a = 10 (beds about 20 d tall), accelerated beyond.
        "by_a": lambda: run_all([dict(a=a, n=count_for(a, 20), seed=s, mode=m) for a in a_small for s in seeds5
                                 for m in ("faithful", "accelerated")] +
                                [dict(a=a, n=count_for(a, 12), seed=s, mode="accelerated") for a in a_large
                                 for s in range(1, 3 if quick else 4)]),
        # 4. Contacts at a = 7.99, N = 1111 (gaps below 1e-3 d), the bed of the DEM comparison:
        # faithful, accelerated, and accelerated with the tighter stopping test.
        "contacts": lambda: run_all([dict(a=7.99, n=1111, seed=s, mode=m, contact_tol=1e-3, **extra)
                                     for s in seeds5 for m, extra in [("faithful", {}), ("accelerated", {})] +
                                     [("accelerated", {"force_tolerance": ft}) for ft in TIGHTER_FORCE_TOLERANCES]]),
        # 5. Speed against N (accelerated, both cores); N = 1e5 at a = 40 as the issue asks (a bed
        # about 70 d tall, three seeds: its iteration count is chaotic), the smaller ones about 20 d tall.
        "speed": lambda: run_all([dict(a=a, n=n, seed=s, mode="accelerated", threads=2, analyse=False)
                                  for n, a in sizes for s in (range(1, 4) if n == 100000 else (1,))], workers=1),
        # 6. Periodic sections (issue 56): a = 5 sections 10 d tall at the full beds' central void
        # fraction, beside full a = 5, N = 500 beds of the same run; a box periodic on every side
        # compressed towards random close packing.
        "periodic": lambda: run_all([dict(a=5, n=500, seed=s, mode="accelerated") for s in seeds5] +
                                    [dict(a=5, n=n, seed=s, mode="accelerated", period_d=10) for n in (210, 212)
                                     for s in range(1, 5 if quick else 9)] +
                                    [dict(a=6, n=n, seed=s, mode="accelerated", period_d=6, box_d=6)
                                     for n in (260, 264) for s in range(1, 3 if quick else 5)]),
    }
    results.setdefault("minutes", {})
    for name in SECTIONS:
        if name in want:
            t0 = time.time()
            results[name] = sections[name]()
            results["minutes"][name] = (time.time() - t0) / 60
            results.setdefault("made", {})[name] = commit_and_date()
    results["quick"] = quick
    json.dump(results, open(os.path.join(DOCS, "validation.json"), "w"), indent=1)
    write_report(results)


def fmt(m, s, n, digits=4):
    return f"{m:.{digits}f} ± {s:.{digits}f} (n={n})"


def made(R, section):
    """Which commit made a section's runs, and when."""
    return made_line(R.get("made", {}).get(section))


def write_report(R):
    ok = lambda rs: [r for r in rs if "error" not in r]
    lines = ["# Soft-sphere packer: validation and speed", "",
             "Generated by `/usr/bin/python3 tools/validate_packer.py"
             + (" --quick" if R["quick"] else "") + "` on this 2-core machine ("
             + ", ".join(f"{k}: {v:.0f} min" for k, v in R.get("minutes", {}).items()) + "). "
             "Void fractions: *whole* = floor to the top of the highest sphere, *central* = the slab that leaves out "
             "2 d at the floor and below the top. Times are single-threaded for both modes (they ran side by side), "
             "so their ratio compares the algorithms.", ""]
    # The periodic section reports its own jams (some of its runs ask for more than can be reached).
    failed = [r for k in SECTIONS if k != "periodic" for r in R.get(k, []) if "error" in r]
    if failed:
        lines += ["**Failed runs:** " + "; ".join(f"{r['mode']} a={r['a']} N={r['n']} seed={r['seed']}" for r in failed), ""]

    # 1. Paper case.
    lines += ["## a = 5, N = 500, eps_0 = 0.47 (Salvat et al. 2005: eps_F = 0.433)", "", made(R, "paper"), "",
              "| mode | eps central | eps whole | iterations | time (s) | rms force residual | max overlap (d) |",
              "|---|---|---|---|---|---|---|"]
    per_mode = {}
    for m in ("faithful", "accelerated"):
        rs = [r for r in ok(R["paper"]) if r["mode"] == m]
        per_mode[m] = rs
        ec, ew, it, tm, rr, mo = (stats(rs, k) for k in ("eps_central", "eps_whole", "iterations", "time_s", "residual",
                                                         "max_overlap"))
        lines.append(f"| {m} | {fmt(*ec)} | {fmt(*ew)} | {it[0]:.0f} | {tm[0]:.2f} ± {tm[1]:.2f} | {rr[0]:.3f} | "
                     f"{mo[0]:.1e} |")
    tf, ta = stats(per_mode["faithful"], "time_s")[0], stats(per_mode["accelerated"], "time_s")[0]
    ecf, eca = stats(per_mode["faithful"], "eps_central"), stats(per_mode["accelerated"], "eps_central")
    ewf, ewa = stats(per_mode["faithful"], "eps_whole"), stats(per_mode["accelerated"], "eps_whole")
    itf, ita = stats(per_mode["faithful"], "iterations")[0], stats(per_mode["accelerated"], "iterations")[0]
    lines += ["", f"Speed-up of the accelerated mode: **{tf / ta:.1f}x** in time and {itf / ita:.1f}x in iterations "
              f"(means over seeds); an iteration costs {1e6 * tf / itf:.0f} µs faithful and {1e6 * ta / ita:.0f} µs "
              "accelerated, both through the same contact-force loop (packer/contact_forces.cpp). "
              f"Difference of the means: central {eca[0] - ecf[0]:+.4f}, whole {ewa[0] - ewf[0]:+.4f}, against a "
              f"seed-to-seed standard deviation of {ecf[1]:.4f} (central) and {ewf[1]:.4f} (whole) for the faithful mode.",
              ""]

    # 2. eps0.
    lines += ["## Sensitivity to eps_0 (paper, Sec. 4.1: eps_F in [0.43, 0.44] for eps_0 in [0.30, 0.55])", "", made(R, "eps0"), "",
              "| eps_0 | faithful central | faithful whole | accelerated central | accelerated whole |", "|---|---|---|---|---|"]
    for e in (0.30, 0.40, 0.47, 0.55):
        src = R["paper"] if e == 0.47 else R["eps0"]
        row = [f"{e:.2f}"]
        for m in ("faithful", "accelerated"):
            rs = [r for r in ok(src) if r["mode"] == m and abs(r.get("eps0", 0.47) - e) < 1e-9]
            row += [fmt(*stats(rs, "eps_central")), fmt(*stats(rs, "eps_whole"))]
        lines.append("| " + " | ".join(row) + " |")
    lines.append("")

    # 3. eps against a, with the correlations.
    lines += ["## Void fraction against aspect ratio", "", made(R, "by_a"), "",
              "| a | N | mode | eps central | eps whole | Z bulk | time (s) | Benyahia | Dixon | Zou-Yu dense..loose |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    groups = {}
    for r in ok(R["paper"]) + ok(R["by_a"]):
        groups.setdefault((r["a"], r["mode"]), []).append(r)
    for (a, m), rs in sorted(groups.items()):
        lines.append(f"| {a} | {rs[0]['n']} | {m} | {fmt(*stats(rs, 'eps_central'))} | {fmt(*stats(rs, 'eps_whole'))} | "
                     f"{stats(rs, 'z_bulk')[0]:.2f} | {stats(rs, 'time_s')[0]:.1f} | {benyahia(a):.3f} | "
                     f"{float(dixon(a)):.3f} | {zou_yu_dense(a):.3f}..{zou_yu_loose(a):.3f} |")
    lines += ["", "![eps against a](validation_eps_vs_a.png)", ""]
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    aa = np.linspace(4, 32, 200)
    ax.plot(aa, benyahia(aa), "k-", lw=1, label="Benyahia & O'Neill (2005)")
    ax.plot(aa, dixon(aa), "k--", lw=1, label="Dixon (1988)")
    ax.plot(aa, jeschar(aa), "k:", lw=1, label="Jeschar (1975)")
    ax.fill_between(aa, zou_yu_dense(aa), zou_yu_loose(aa), color="0.9", label="Zou & Yu dense..loose")
    for m, mk, off in (("faithful", "o", -0.15), ("accelerated", "s", 0.15)):
        for key, fill in (("eps_whole", "none"), ("eps_central", None)):
            xs, ys, es = [], [], []
            for (a, mm), rs in sorted(groups.items()):
                if mm == m:
                    mu, sd, _ = stats(rs, key)
                    xs.append(a + off), ys.append(mu), es.append(sd)
            ax.errorbar(xs, ys, es, fmt=mk, mfc=fill, capsize=3,
                        label=f"{m}, {'whole bed' if key == 'eps_whole' else 'central slab'}")
    ax.plot([5], [0.433], "r*", ms=12, label="Salvat et al. (2005), a = 5")
    ax.set_xlabel("a = D/d"), ax.set_ylabel("void fraction"), ax.legend(fontsize=7), ax.grid(alpha=0.3)
    fig.tight_layout(), fig.savefig(os.path.join(DOCS, "validation_eps_vs_a.png"), dpi=120), plt.close(fig)

    # Radial profile at a = 7.99.
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    feats = []
    for m, style in (("faithful", "b-"), ("accelerated", "r--")):
        rs = [r for r in ok(R["by_a"]) if r["a"] == 7.99 and r["mode"] == m and "radial" in r]
        if not rs:
            continue
        z = np.array(rs[0]["radial"][0])
        eps = np.mean([r["radial"][1] for r in rs], axis=0)
        ax[0].plot(z, eps, style, label=f"{m} (mean of {len(rs)})")
        cz = np.array(rs[0]["centres"][0])
        ax[1].plot(cz, np.mean([r["centres"][1] for r in rs], axis=0), style, label=m)
        near = z < 0.8
        i_min = np.argmin(np.where(near, eps, 9))
        after = (z > 0.7) & (z < 1.3)
        i_max = np.where(after)[0][np.argmax(eps[after])]
        bulk = eps[(z > 2.5) & (z < 3.5)].mean()
        within = z[np.where(np.abs(eps - bulk) > 0.02)[0].max()] if np.any(np.abs(eps - bulk) > 0.02) else 0
        feats.append(f"| {m} | {eps[0]:.3f} | {eps[i_min]:.3f} at {z[i_min]:.3f} | {eps[i_max]:.3f} at {z[i_max]:.2f} | "
                     f"{bulk:.3f} | {within:.2f} |")
    bulk_ref = np.mean([f for f in [stats([r for r in ok(R['by_a']) if r['a'] == 7.99], 'eps_central')[0]]])
    zz = np.linspace(0, 4, 400)
    ax[0].plot(zz, de_klerk(zz, bulk_ref), "k:", label="de Klerk (2003) [C]")
    ax[0].set_xlabel("(R - r)/d"), ax[0].set_ylabel("void fraction"), ax[0].legend(fontsize=8), ax[0].grid(alpha=0.3)
    ax[1].set_xlabel("(R - r)/d"), ax[1].set_ylabel("fraction of centres per 0.05 d"), ax[1].legend(fontsize=8)
    ax[1].grid(alpha=0.3)
    fig.tight_layout(), fig.savefig(os.path.join(DOCS, "validation_radial_7_99.png"), dpi=120), plt.close(fig)
    lines += ["## Radial structure at a = 7.99 (central slab, bins of 0.05 d)", "", made(R, "by_a"), "",
              "Reference [A]: eps = 1 at the wall; first minimum near 0.5 d, about 0.20-0.26; first maximum at "
              "0.9-1.05 d, about 0.5-0.6; within ±0.02 of the bulk by 4-5 d.", "",
              "| mode | bin at the wall (0-0.05 d) | first minimum | first maximum | bulk (2.5-3.5 d) | "
              "last bin off the bulk by > 0.02 (d) |",
              "|---|---|---|---|---|---|"] + feats + ["", "![radial profile](validation_radial_7_99.png)", ""]

    # 4. Contacts.
    if R.get("contacts"):
        lines += ["## Contacts at a = 7.99, N = 1111 (central slab, gaps below 1e-3 d)", "", made(R, "contacts"), "",
                  "Contacts per sphere count spheres only and include rattlers (fewer than 4 contacts with spheres, "
                  "walls and floor). Reference: an independent frictionless DEM run of the same scene (overlaps "
                  f"about 2e-4 d), reported in issue 25: eps {DEM_7_99['eps']}, {DEM_7_99['z']} contacts per sphere, "
                  f"{DEM_7_99['rattlers']} rattlers in the slab. Means ± standard errors over seeds.", "",
                  "| mode | force tolerance | eps central | contacts per sphere | rattlers in the slab | iterations | "
                  "time (s) |", "|---|---|---|---|---|---|---|"]
        groups = {}
        for r in ok(R["contacts"]):
            groups.setdefault((r["mode"], r.get("force_tolerance")), []).append(r)
        se = lambda rs, k: stats(rs, k)[1] / math.sqrt(max(1, stats(rs, k)[2]))
        for (m, ft), rs in groups.items():
            lines.append(f"| {m} | {'' if m == 'faithful' else ft or 0.2} | {stats(rs, 'eps_central')[0]:.4f} | "
                         f"{stats(rs, 'z_slab')[0]:.3f} ± {se(rs, 'z_slab'):.3f} | "
                         f"{stats(rs, 'rattlers_slab')[0]:.1f} ± {se(rs, 'rattlers_slab'):.1f} of "
                         f"{stats(rs, 'spheres_slab')[0]:.0f} | {stats(rs, 'iterations')[0]:.0f} | "
                         f"{stats(rs, 'time_s')[0]:.2f} |")
        f = groups.get(("faithful", None), [])
        for ft in [None] + TIGHTER_FORCE_TOLERANCES:
            a = groups.get(("accelerated", ft), [])
            if not (f and a):
                continue
            dz = stats(a, "z_slab")[0] - stats(f, "z_slab")[0]
            dr = stats(a, "rattlers_slab")[0] - stats(f, "rattlers_slab")[0]
            cost = stats(a, "iterations")[0] / stats(groups[("accelerated", None)], "iterations")[0]
            lines += ["", f"Accelerated at force tolerance {ft or '0.2 (the default)'} against faithful: contacts per "
                      f"sphere {dz:+.3f} ({dz / math.hypot(se(a, 'z_slab'), se(f, 'z_slab')):+.1f} standard errors of "
                      f"the difference), rattlers {dr:+.1f} "
                      f"({dr / math.hypot(se(a, 'rattlers_slab'), se(f, 'rattlers_slab')):+.1f})"
                      + (f", at {cost:.1f}x the default's iterations." if ft else ".")]
        lines += ["", "Why, and what the stopping test trades: [findings.md](findings.md) (dated, not regenerated).", ""]

    # 5. Speed.
    lines += ["## Time against N (accelerated, 2 threads)", "", made(R, "speed"), "",
              "| N | a | seed | iterations | time (s) | iterations per second | eps central |",
              "|---|---|---|---|---|---|---|"]
    for r in ok(R["speed"]):
        lines.append(f"| {r['n']} | {r['a']} | {r['seed']} | {r['iterations']} | {r['time_s']:.1f} | "
                     f"{r['iterations'] / r['time_s']:.0f} | {r['eps_central']:.4f} |")
    big = [r for r in ok(R["speed"]) if r["n"] == 100000]
    if big:
        # Issue 25: every seed under the bar, not their mean (a mean hid a seed with a 2 % margin).
        under = [r for r in big if r["time_s"] < N_1E5_LIMIT_S]
        lines += ["", f"The target for N = 1e5 (a = 40), every seed under {N_1E5_LIMIT_S:.0f} s on this machine, is "
                  f"**{'met' if len(under) == len(big) else 'not met'}**: {len(under)} of {len(big)} seeds under it ("
                  + ", ".join(f"seed {r['seed']} {r['time_s']:.0f} s, {r['iterations']} iterations" for r in big)
                  + f"; {1000 * sum(r['time_s'] for r in big) / sum(r['iterations'] for r in big):.1f} ms per "
                  "iteration). Why the iteration count varies from seed to seed, where the time goes, and what was "
                  "tried: [findings.md](findings.md) (dated, not regenerated)."]
    lines.append("")
    if R.get("periodic"):
        lines += periodic_report(R)
    open(os.path.join(DOCS, "validation.md"), "w").write("\n".join(lines))
    print("\n".join(lines))


def wall_features(radial):
    """A radial profile's bin at the wall and its first minimum within 1 d: (value, at d), and the
    mean void fraction in the bands 0-0.5, 0.5-1, 1-1.5 and 1.5-2.5 d from the wall."""
    z, eps = np.array(radial[0]), np.array(radial[1])
    near = z < 1.0
    k = int(np.argmin(eps[near]))
    bands = [float(eps[(z >= lo) & (z < hi)].mean()) for lo, hi in ((0, 0.5), (0.5, 1), (1, 1.5), (1.5, 2.5))]
    return float(eps[0]), (float(eps[near][k]), float(z[near][k])), bands


def periodic_report(R):
    """Section 6: periodic sections against full beds, and a periodic box against random close packing."""
    rs = R["periodic"]
    lines = ["## Periodic sections (a = 5, period 10 d) against full beds (a = 5, N = 500)", "", made(R, "periodic"), "",
             "Sections: `container.period_z_d = 10`, no floor or top, compressed without gravity (with taps where they "
             "jam first); their void fraction is set by the count. Full beds: floor and gravity, central slab 2 d "
             "from floor and top. Profiles: bins of 0.05 d, over the central slab (full) or the whole period "
             "(section). Reached: seeds whose section reached its period (the rest jammed first, and say so).", "",
             "| bed | N | reached | eps central | wall bin | first minimum (at d) | eps 0-0.5 / 0.5-1 / 1-1.5 / "
             "1.5-2.5 d | Z bulk (no rattlers) | rattlers | time (s) |", "|---|---|---|---|---|---|---|---|---|---|"]
    groups = [("full", 500, [r for r in rs if "period_d" not in r])] + [
        ("section", n, [r for r in rs if r.get("period_d") == 10 and r["n"] == n]) for n in (210, 212)]
    for name, n, group in groups:
        ok = [r for r in group if "error" not in r]
        if not ok:
            continue
        feats = [wall_features(r["radial"]) for r in ok]
        rng = lambda vals, d=3: f"{min(vals):.{d}f}-{max(vals):.{d}f}"
        bands = " / ".join(rng([f[2][b] for f in feats]) for b in range(4))
        lines.append(f"| {name} | {n} | {len(ok)}/{len(group)} | {rng([r['eps_central'] for r in ok], 4)} | "
                     f"{rng([f[0] for f in feats])} | {rng([f[1][0] for f in feats])} "
                     f"({rng([f[1][1] for f in feats], 2)}) | {bands} | "
                     f"{rng([r['z_bulk'] for r in ok if r['z_bulk'] is not None], 2)} | "
                     f"{rng([100 * r['rattlers'] / r['n'] for r in ok], 1)} % | "
                     f"{rng([r['time_s'] for r in ok], 1)} |")
    box = [r for r in rs if "box_d" in r]
    lines += ["", "A box 6 d wide periodic on every side (period 6 d), compressed towards random close packing "
              "(void fraction 0.36-0.3634, Scott & Kilgour; docs/reference.md); where it jams first, the error says "
              "at which void fraction:", "", "| N | asked eps | seed | reached | eps at the end | Z (no rattlers) | "
              "rattlers |", "|---|---|---|---|---|---|---|"]
    for r in box:
        asked = 1 - r["n"] * math.pi / 6 / r["box_d"] ** 3
        if "error" in r:
            m = re.search(r"void fraction ([0-9.]+)", r["error"])
            lines.append(f"| {r['n']} | {asked:.4f} | {r['seed']} | no | {m.group(1) if m else '?'} (jammed) | | |")
        else:
            lines.append(f"| {r['n']} | {asked:.4f} | {r['seed']} | yes | {r['eps_central']:.4f} | "
                         f"{r['z_no_rattlers']:.2f} | {r['rattlers']} |")
    return lines + [""]


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--report-only":
        write_report(json.load(open(os.path.join(DOCS, "validation.json"))))
    else:
        main()
