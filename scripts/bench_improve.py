#!/usr/bin/env python3
"""Sliver removal (dissertation Table 3.2): `biotet improve` on a raw biotet mesh and on TetGen meshes of the same
surface, beside TetGen's own `pq1.2Y` and `pq1.2YO` and the full `biotet mesh` pipeline, in one run.

    pip install tetgen meshio numpy        # the anchor (pip tetgen wraps TetGen 1.6)
    cargo build --release -p biotet-cli
    python3 scripts/bench_improve.py [SURFACE.stl] [--repeat 3] [--json out.json]

Meshes improved (each `biotet improve MESH --surface SURFACE --json`, surface and points kept):
- `biotet mesh --no-improve --no-smooth`: template nodes, Delaunay, recovery only;
- TetGen `pq1.2Y` and `pq1.2YO` (pip tetgen) of the same surface.
Table 3.2's columns for each: tets under 10° before and after ("slivers"), searches ("calls"), the median and largest
milliseconds per search, the mean (seconds over calls), the seconds of the whole improvement (median of the
repeats) and milliseconds per tet under 10° before (the seed's seconds per sliver). Beside them, the quality
of the meshes as the tools leave them (TetGen `pq1.2Y`, `pq1.2YO` and the full `biotet mesh` pipeline): smallest
dihedral angle, tets under 5°, 10° and 20°, and the unforced tets under 10° by what bounds them
(`forcing.unforced_lt_10_by_cause`: opposite an edge of an input triangle with an angle under 10°, with a corner on
one, neither). Every output is checked with `biotet check --surface`.
"""
import argparse, json, os, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib  # noqa: E402
from benchlib import ROOT, median as med  # noqa: E402

BIOTET = benchlib.find_biotet()
DEFAULT = os.path.join(ROOT, "tests", "data", "brain_20k.stl")
# Dissertation Table 3.2 (the seed's runs): slivers, calls, seconds per sliver.
SEED = [("seed, breast", 148, 104, "1.08–1.22"), ("seed, brain", 310, 241, "1.08–1.22")]


def improve(mesh, surface, out, repeat):
    rows = [benchlib.biotet_json(BIOTET, "improve", mesh, "--surface", surface, "-o", out, "--quiet")
            for _ in range(repeat)]
    j = rows[0]
    return {"seconds": med([{"s": r["improve"]["seconds"]} for r in rows], "s"), "calls": j["calls"],
            "ms_median": j["call_ms_median"], "ms_max": j["call_ms_max"],
            "before": j["slivers_before"], "after": j["slivers_after"],
            "unforced_before": j["forcing_before"]["n_unforced_dihedral_lt_10"],
            "unforced_after": j["forcing_after"]["n_unforced_dihedral_lt_10"],
            "cause_after": j["forcing_after"].get("unforced_lt_10_by_cause"),
            "valid": benchlib.measure(BIOTET, out, surface)["valid"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("surface", nargs="?", default=DEFAULT)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json")
    a = ap.parse_args()
    benchlib.require(BIOTET)
    s = a.surface
    made, improved = [], []
    with tempfile.TemporaryDirectory() as tmp:
        raw = os.path.join(tmp, "raw.vtu")
        benchlib.biotet_json(BIOTET, "mesh", s, "--no-improve", "--no-smooth", "-o", raw, "--quiet")
        meshes = [("biotet mesh --no-improve --no-smooth", raw)]
        full = os.path.join(tmp, "full.vtu")
        benchlib.biotet_json(BIOTET, "mesh", s, "-o", full, "--quiet")
        for sw in ("pq1.2Y", "pq1.2YO"):
            base = os.path.join(tmp, "tetgen_" + sw)
            try:
                benchlib.run_child("tetgen", s, base, switches=sw)
            except RuntimeError as e:
                print(f"pip tetgen {sw} skipped: {e}", file=sys.stderr)
                continue
            made.append({"tool": f"TetGen {sw}", **benchlib.measure(BIOTET, base + ".node", s)})
            meshes.append((f"TetGen {sw}", base + ".node"))
        made.append({"tool": "biotet mesh (defaults)", **benchlib.measure(BIOTET, full, s)})
        for name, mesh in meshes:
            r = improve(mesh, s, os.path.join(tmp, "improved.vtu"), a.repeat)
            r["mesh"] = name
            improved.append(r)
    name = os.path.basename(s)
    print(f"Sliver removal on {name} (`biotet improve`, dihedral threshold 10°; medians of {a.repeat}):\n")
    print("| mesh | tets <5° | <10° (slivers) | <20° | unforced <10° | calls | median ms | mean ms | max ms | seconds "
          "| ms per sliver | unforced left by cause | valid |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in improved:
        b, f = r["before"], r["after"]
        print(f"| {r['mesh']} → improved | {b['lt_5']:,} → {f['lt_5']:,} | {b['lt_10']:,} → {f['lt_10']:,} "
              f"| {b['lt_20']:,} → {f['lt_20']:,} | {r['unforced_before']:,} → {r['unforced_after']:,} "
              f"| {r['calls']:,} | {r['ms_median']:.4f} | {r['seconds'] / r['calls'] * 1e3:.4f} | {r['ms_max']:.1f} "
              f"| {r['seconds']:.3f} | {r['seconds'] / b['lt_10'] * 1e3:.3f} | {r['cause_after']} "
              f"| {r['valid']} |")
    for n, sl, calls, per in SEED:
        print(f"| {n} (Table 3.2) | | {sl} | | | {calls} | | | | | {per} s | | |")
    print(f"\nMeshes as the tools leave them ({name}):\n")
    print("| tool | tets | min dihedral ° | tets <5° | <10° | <20° | unforced <10° | by cause | valid |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in made:
        print(f"| {r['tool']} | {r['tets']:,} | {r['min_dihedral']:.4f} | {r['lt5']:,} | {r['lt10']:,} "
              f"| {r['lt20']:,} | {r['unforced_lt10']:,} | {r['unforced_cause']} | {r['valid']} |")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"surface": name, "improved": improved, "meshes": made}, fh, indent=1)


if __name__ == "__main__":
    main()
