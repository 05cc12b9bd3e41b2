#!/usr/bin/env python3
"""Cost per tet of a multi-material run beside single-region runs of the same tissues, in one session.

    cargo build --release -p biotet-cli
    python3 scripts/bench_materials.py [--repeat 3] [--threads N] [--json out.json]

Meshes with `biotet mesh` (defaults, the full pipeline) and `--json`:
- `brain_20k.stl`: the outer brain surface alone, one region;
- `wm_20k.stl`: the white matter alone, one region;
- `nested_brain_wm_20k.stl --label nested_brain_wm_20k.stl=1,0`: the grey matter alone, one region with the white
  matter a hole (the same two surfaces as the nested model, constrained on one side);
- `nested_brain_wm_20k.stl`: the multi-material model, grey and white matter in one conforming mesh.
The grey-matter and white-matter runs are the single-region runs of the nested model's tissues: together they mesh
the same two regions with the same surfaces, so the row `tissues one by one` (their seconds and tets added up) is
the single-region cost of the same model. Times are medians of the meshing seconds (`seconds_sizing` +
`pipeline.seconds_total`, without reading and writing); µs per tet divides them by the output tets. Every output is
checked with `biotet check --surface` (and the labels of the multi-material run) once.
"""
import argparse, json, os, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib  # noqa: E402
from benchlib import ROOT, median as med  # noqa: E402

BIOTET = benchlib.find_biotet()
DATA = os.path.join(ROOT, "tests", "data")
NESTED = os.path.join(DATA, "nested_brain_wm_20k.stl")
# (name, surface, labels): the labels as `--label`, for `mesh` and `check` alike.
CASES = [
    ("brain_20k (one region)", os.path.join(DATA, "brain_20k.stl"), []),
    ("wm_20k (one region)", os.path.join(DATA, "wm_20k.stl"), []),
    ("grey matter, white matter a hole (one region)", NESTED, ["--label", "nested_brain_wm_20k.stl=1,0"]),
    ("nested brain + white matter (two regions)", NESTED, []),
]


def run(surface, labels, out, repeat, threads):
    pre = ["--threads", str(threads)] if threads else []
    rows = []
    for _ in range(repeat):
        j = benchlib.biotet_json(BIOTET, *pre, "mesh", surface, *labels, "-o", out, "--quiet")
        p = j["pipeline"]
        rows.append({"seconds": p["seconds_total"] + j.get("seconds_sizing", 0.0), "tets": p["n_tets"],
                     "stages": {st["name"]: st["seconds"] for st in p["stages"]},
                     "unforced_lt10": j.get("forcing", {}).get("n_unforced_dihedral_lt_10")})
    stages = {n: med([{"s": r["stages"][n]} for r in rows], "s") for n in rows[0]["stages"]}
    return {"seconds": med(rows, "seconds"), "tets": rows[0]["tets"], "stages": stages,
            "unforced_lt10": rows[0]["unforced_lt10"]}


def check(out, surface, labels):
    c = benchlib.biotet_json(BIOTET, "check", out, "--surface", surface, *labels)
    return bool(c.get("valid"))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=0, help="biotet --threads (0: all cores)")
    ap.add_argument("--json")
    a = ap.parse_args()
    benchlib.require(BIOTET)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, surface, labels in CASES:
            out = os.path.join(tmp, "out.vtu")
            r = run(surface, labels, out, a.repeat, a.threads)
            r["case"] = name
            r["valid"] = check(out, surface, labels)
            results.append(r)
    tissues = results[1:3]
    parts = {"case": "tissues one by one (grey + white, added)", "seconds": sum(r["seconds"] for r in tissues),
             "tets": sum(r["tets"] for r in tissues), "valid": all(r["valid"] for r in tissues)}
    print("| run | seconds (median) | tets | µs per tet | unforced <10° | valid |")
    print("|---|---|---|---|---|---|")
    for r in results[:3] + [parts] + results[3:]:
        print(f"| {r['case']} | {r['seconds']:.3f} | {r['tets']:,} | {r['seconds'] / r['tets'] * 1e6:.1f} "
              f"| {r.get('unforced_lt10', '')} | {r['valid']} |")
    multi = results[3]
    ratio = (multi["seconds"] / multi["tets"]) / (parts["seconds"] / parts["tets"])
    print(f"\nmulti-material µs per tet / the tissues' single-region runs: {ratio:.2f}×; "
          f"/ brain_20k alone: {(multi['seconds'] / multi['tets']) / (results[0]['seconds'] / results[0]['tets']):.2f}×")
    for r in results:
        print(f"{r['case']}: " + ", ".join(f"{n} {v:.3f}" for n, v in r["stages"].items()))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"results": results, "tissues": parts, "ratio": ratio}, f, indent=1)


if __name__ == "__main__":
    main()
