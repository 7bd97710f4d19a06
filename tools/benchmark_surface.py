#!/usr/bin/python3
"""Speed, memory and accuracy of the surface stage against N, for every contact treatment;
writes docs/surface_benchmark.md and .json.

    /usr/bin/python3 tools/benchmark_surface.py                 # N = 500, 2000, 10000
    /usr/bin/python3 tools/benchmark_surface.py --counts 500 2000
    /usr/bin/python3 tools/benchmark_surface.py --counts 10000 --keep   # adds N = 1e4 to the rows there
    /usr/bin/python3 tools/benchmark_surface.py --treatments enlarge --keep   # redoes the enlarge rows
    /usr/bin/python3 tools/benchmark_surface.py --counts 10000 --aspect-ratio 14 --keep   # N = 1e4 in a wider tube

Beds: `bedforge pack --aspect-ratio A --count N --seed 1` (soft sphere, accelerated; A = 5 unless --aspect-ratio). Each
treatment is a real `bedforge surface DIR --contacts T` (surface edge 0.1 d, 0.033 d at contacts, no refinement
across gaps) on a copy of the bed, timed from outside
(wall clock and peak resident memory from /usr/bin/time) with the stage's own split (build,
checks) and accuracy from report.json. Linear scaling shows as a flat time per sphere; the
ratio column is time per sphere over that at the smallest N (same script, same machine).
Targets from the issues: a = 5, N = 500 with bridges under 10 s; N = 1e4 under 3 min and 4 GB; and
the surface stage at N = 1e4 under 60 s for every treatment with the full validity check (issue 26).
"""
import argparse
import json
import os
import shutil
import subprocess
import tempfile

from bedforge_files import BEDFORGE, DOCS, commit_and_date

# The surface settings every row was measured at (the scene defaults until 2026-11-28): a 0.1 d
# edge, 0.033 d at contacts, no refinement across gaps.
SURFACE = ["--edge-length-d", "0.1", "--contact-edge-length-d", "0.033", "--cells-per-gap", "0"]


def made(row):
    """A row's commit and date, or that it is older than the stamps."""
    return f"{row['commit']}, {row['date']}" if "commit" in row else "before stamps"

TREATMENTS = ["shrink", "bridge", "cap", "enlarge"]


def timed(cmd):
    out = subprocess.run(["/usr/bin/time", "-f", "TIME %e %M"] + cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{out.stderr}")
    wall, kb = out.stderr.strip().splitlines()[-1].split()[1:]
    return float(wall), int(kb) / 1024.0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--counts", type=int, nargs="+", default=[500, 2000, 10000])
    ap.add_argument("--aspect-ratio", type=float, default=5.0, help="tube diameter over sphere diameter of the beds")
    ap.add_argument("--treatments", nargs="+", choices=TREATMENTS, default=TREATMENTS)
    ap.add_argument("--keep", action="store_true",
                    help="keep the rows of docs/surface_benchmark.json for the counts and treatments not run now")
    args = ap.parse_args()
    rows = []
    if args.keep and os.path.exists(os.path.join(DOCS, "surface_benchmark.json")):
        rows = [r for r in json.load(open(os.path.join(DOCS, "surface_benchmark.json")))
                if r["n"] not in args.counts or r["treatment"] not in args.treatments
                or r.get("a", 5.0) != args.aspect_ratio]
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.counts:
            bed = os.path.join(tmp, f"bed{n}")
            subprocess.run([BEDFORGE, "--quiet", "pack", "--aspect-ratio", f"{args.aspect_ratio:g}", "--count", str(n),
                            "--seed", "1", "-o", bed],
                           check=True)
            for t in args.treatments:
                work = os.path.join(tmp, f"{t}{n}")
                shutil.copytree(bed, work)
                wall, mb = timed([BEDFORGE, "--quiet", "surface", work, "--contacts", t, *SURFACE])
                s = json.load(open(os.path.join(work, "report.json")))["stages"]["surface"]
                rows.append({**commit_and_date(), "a": args.aspect_ratio, "n": n, "treatment": t, "wall_s": wall, "peak_mb": mb,
                             "stage_s": s["time_s"], "build_s": s["time_build_s"],
                             "check_s": s["time_check_s"], "triangles": s["triangles"],
                             "self_intersections_checked": s["check"]["self_intersections"] != "not checked",
                             "tested_pairwise": s["check"].get("triangles_tested_pairwise"),
                             "volume_error": s["fluid_volume_relative_error"],
                             "chordal_d": s["chordal_deviation_d"], "min_angle_deg": s["min_angle_deg"],
                             "contacts": s["contacts_treated"]["particle_particle"] + s["contacts_treated"]["particle_wall"],
                             "smallest_gap_d": min(s["smallest_gap_d"]["particle_particle"],
                                                   s["smallest_gap_d"]["particle_wall"])})
                print(rows[-1], flush=True)
                shutil.rmtree(work)
                rows.sort(key=lambda r: (r["n"], r.get("a", 5.0), TREATMENTS.index(r["treatment"])))
                write(rows)


def allocator():
    """The shared libraries of the benchmarked program, as ldd lists them."""
    return subprocess.run(["ldd", BEDFORGE], capture_output=True, text=True).stdout


def write(rows):
    """The table so far (rewritten after every run, so a long sweep leaves its results as it goes)."""
    smallest = min(r["n"] for r in rows)
    base = {r["treatment"]: r["wall_s"] / r["n"] for r in rows if r["n"] == smallest and r.get("a", 5.0) == 5.0}
    lines = ["# Surface stage: speed, memory and accuracy against N", "",
             "Made by `/usr/bin/python3 tools/benchmark_surface.py` (soft-sphere beds in a tube of a = D/d as in the "
             "*a* column, seed 1, "
             "`[contacts]` defaults but the treatment, surface edge 0.1 d, 0.033 d at contacts, no refinement across gaps (the `[surface]` defaults until 2026-11-28), 2 cores). Wall time and peak memory of the whole "
             "`bedforge surface DIR` command, including writing the STL files; *ratio* = time per sphere "
             "over that at the smallest N (1 = linear scaling). The allocator matters here: bedforge is linked "
             "with tcmalloc when `libgoogle-perftools-dev` is installed (these rows: "
             f"{'tcmalloc' if 'tcmalloc' in allocator() else 'glibc malloc'}; what glibc's malloc cost, measured once: "
             "[findings.md](findings.md)). *made*: the commit and date of the run that made the row.", "",
             "*stage s*: the surface stage's own time (build and checks, report.json); *wall s* adds starting "
             "the program, reading the bed and writing the files (fluid.stl in ASCII is the largest). *pairwise*: "
             "the share of triangles CGAL's self-intersection test took pair by pair, the rest covered by the "
             "argument in meshing/README.md.", "",
             "| a | N | treatment | contacts treated | triangles | wall s | stage s | build s | checks s | pairwise | peak MB | "
             "ratio | volume error | chordal d | min angle | smallest gap d | made |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        stage = f"{r['stage_s']:.1f}" if "stage_s" in r else "-"
        pairwise = (f"{r['tested_pairwise'] / r['triangles']:.0%}" if r.get("tested_pairwise") is not None
                    else "all" if r["self_intersections_checked"] else "none")
        lines.append(f"| {r.get('a', 5.0):g} | {r['n']} | {r['treatment']} | {r['contacts']} | {r['triangles']} | {r['wall_s']:.1f} | {stage} | "
                     f"{r['build_s']:.1f} | {r['check_s']:.1f}{'' if r['self_intersections_checked'] else ' (no SI)'} | "
                     f"{pairwise} | "
                     f"{r['peak_mb']:.0f} | {r['wall_s'] / r['n'] / base.get(r['treatment'], r['wall_s'] / r['n']):.2f} | "
                     f"{r['volume_error']:.2e} | {r['chordal_d']:.1e} | {r['min_angle_deg']:.1f} | "
                     f"{r['smallest_gap_d']:.3g} | {made(r)} |")
    if not all(r["self_intersections_checked"] for r in rows):
        lines += ["", "(no SI): rows made before the test went by pieces, when it was skipped above 5e6 triangles "
                  "(the report said so); closedness and manifoldness were always checked."]
    lines += ["", "Rows at another a come from `--aspect-ratio` (why: [findings.md](findings.md)).",
              "", "Rows added with `--keep` come from another run; this machine's speed has varied by up to "
              "1.5x between sessions, so a ratio across runs is indicative only."]
    os.makedirs(DOCS, exist_ok=True)
    open(os.path.join(DOCS, "surface_benchmark.md"), "w").write("\n".join(lines) + "\n")
    json.dump(rows, open(os.path.join(DOCS, "surface_benchmark.json"), "w"), indent=1)


if __name__ == "__main__":
    main()
