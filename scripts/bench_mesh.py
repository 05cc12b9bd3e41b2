#!/usr/bin/env python3
"""Surface to tet mesh: biotet `mesh` beside TetGen (surface kept, `pq1.2Y`) on the same surface, in one run.

    pip install tetgen meshio numpy        # the anchor (pip tetgen wraps TetGen 1.6); apt-get install tetgen for 1.5
    cargo build --release -p biotet-cli
    python3 scripts/bench_mesh.py [SURFACE.stl ...] [--repeat 3] [--scaling] [--json out.json]

Every tool runs in its own process. Times are medians of the repeats: biotet's meshing seconds (its `--json`:
`seconds_sizing` + `pipeline.seconds_total`, without reading and writing files) and the process wall time; TetGen's time of the `tetrahedralize` call (pip) or its
own "Total running seconds" (binary). Peak memory is the process's peak RSS minus its RSS before meshing (biotet
resets the peak after reading the surface; the pip child records its RSS before the call). Quality comes from one
routine for all tools: `biotet quality --json` on each output; missing input triangles from `biotet check --surface`.

--scaling meshes the first surface at several uniform sizes with the deployment stages only (template, Delaunay,
outside removal; `--no-recover --no-improve --no-smooth`) and prints seconds per tet (dissertation fig. 2.16).
"""
import argparse, json, os, shutil, subprocess, sys, tempfile, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib  # noqa: E402  (shared: the biotet calls, the one quality routine, the pip TetGen child)
from benchlib import ROOT, median as med  # noqa: E402

BIOTET = benchlib.find_biotet()
DEFAULT = [os.path.join(ROOT, "tests", "data", "brain_20k.stl")]


def biotet_json(*args):
    return benchlib.biotet_json(BIOTET, *args)


def measure(mesh, surface):
    return benchlib.measure(BIOTET, mesh, surface)


def run_biotet(surface, out, extra, repeat):
    rows = []
    for _ in range(repeat):
        start = time.perf_counter()
        j = biotet_json("mesh", surface, "-o", out, *extra)
        wall = time.perf_counter() - start
        rows.append({"seconds": j["pipeline"]["seconds_total"] + j.get("seconds_sizing", 0.0), "wall": wall,
                     "mem_kb": j["peak_rss_kb"] - j["rss_before_kb"], "mesh_bytes": j["mesh_bytes"],
                     "stages": {st["name"]: st["seconds"] for st in j["pipeline"].get("stages", [])}})
    return rows


def stage_medians(rows):
    names = list(rows[0]["stages"])
    return {n: med([{"s": r["stages"][n]} for r in rows], "s") for n in names}


def run_pip_tetgen(surface, switches, base, repeat):
    rows = []
    for _ in range(repeat):
        try:
            j = benchlib.run_child("tetgen", surface, base, switches=switches)
        except RuntimeError as e:
            return None, str(e)
        rows.append({"seconds": j["seconds"], "wall": j["wall"], "mem_kb": j["peak_rss_kb"] - j["rss_before_kb"]})
    return rows, None


def run_tetgen_binary(surface, switches, tmp, repeat):
    exe = shutil.which("tetgen")
    if not exe:
        return None, "tetgen binary not found (apt-get install tetgen)", None
    # TetGen 1.5's STL reader aborts on these files; hand it the same surface as OFF.
    src = os.path.join(tmp, "tg_input.off")
    r = subprocess.run([BIOTET, "convert", surface, "-o", src, "--quiet"], capture_output=True, text=True)
    if r.returncode != 0:
        return None, r.stderr.strip(), None
    rows = []
    import re
    for _ in range(repeat):
        start = time.perf_counter()
        r = subprocess.run(["/usr/bin/time", "-f", "PEAK %M", exe, "-" + switches + "V", src],
                           capture_output=True, text=True)
        wall = time.perf_counter() - start
        if r.returncode != 0:
            return None, r.stderr.strip()[-200:], None
        sec = re.search(r"Total running seconds:\s*([0-9.e-]+)", r.stdout)
        peak = re.search(r"PEAK (\d+)", r.stderr)
        rows.append({"seconds": float(sec.group(1)) if sec else wall, "wall": wall,
                     "mem_kb": int(peak.group(1)) if peak else None})
    return rows, None, os.path.join(tmp, "tg_input.1.node")


fmt = benchlib.cell


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("surfaces", nargs="*", default=DEFAULT)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--switches", default="pq1.2Y")
    ap.add_argument("--scaling", action="store_true")
    ap.add_argument("--json")
    a = ap.parse_args()
    benchlib.require(BIOTET)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for s in a.surfaces:
            name = os.path.basename(s)
            out = os.path.join(tmp, "biotet.vtu")
            rows = run_biotet(s, out, [], a.repeat)
            r = {"surface": name, "tool": "biotet mesh", "seconds": med(rows, "seconds"), "wall": med(rows, "wall"),
                 "mem_mb": med(rows, "mem_kb") / 1024, "mesh_mb": rows[0]["mesh_bytes"] / 2**20,
                 "stages": stage_medians(rows), **measure(out, s)}
            results.append(r)
            base = os.path.join(tmp, "pip_tetgen")
            rows, err = run_pip_tetgen(s, a.switches, base, a.repeat)
            if rows:
                results.append({"surface": name, "tool": f"TetGen {a.switches} (pip tetgen)",
                                "seconds": med(rows, "seconds"), "wall": med(rows, "wall"),
                                "mem_mb": med(rows, "mem_kb") / 1024, **measure(base + ".node", s)})
            else:
                print(f"pip tetgen skipped: {err}", file=sys.stderr)
            rows, err, node = run_tetgen_binary(s, a.switches, tmp, a.repeat)
            if rows:
                results.append({"surface": name, "tool": f"TetGen 1.5 {a.switches} (Debian binary)",
                                "seconds": med(rows, "seconds"), "wall": med(rows, "wall"),
                                "mem_mb": med(rows, "mem_kb") / 1024, **measure(node, s)})
            else:
                print(f"tetgen binary skipped: {err}", file=sys.stderr)
        print("| surface | tool | seconds (median) | wall s | peak MB | points | tets | min dihedral ° | max dihedral ° "
              "| mean q | tets <5° | <10° | <20° | missing triangles | valid |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in results:
            print(f"| {r['surface']} | {r['tool']} | {fmt(r['seconds'], '.3f')} | {fmt(r['wall'], '.3f')} "
                  f"| {fmt(r['mem_mb'], '.1f')} | {r['points']} | {r['tets']} | {fmt(r['min_dihedral'], '.4f')} "
                  f"| {fmt(r['max_dihedral'], '.2f')} | {fmt(r['mean_q'], '.3f')} | {r['lt5']} | {r['lt10']} "
                  f"| {r['lt20']} | {r['missing']} | {r['valid']} |")
        for r in results:
            if r.get("stages"):
                st = ", ".join(f"{n} {v:.3f}" for n, v in r["stages"].items())
                print(f"\n{r['surface']}: biotet stage seconds (medians): {st}")
        if results and results[0].get("mesh_mb"):
            r = results[0]
            print(f"\nbiotet: peak memory {r['mem_mb']:.1f} MB for an output mesh of {r['mesh_mb']:.1f} MB in memory "
                  f"({r['mem_mb'] / r['mesh_mb']:.2f}×)")
        scaling = []
        if a.scaling:
            s = a.surfaces[0]
            print("\n| uniform size | points | tets | seconds (median) | µs per tet | template MB | peak MB |")
            print("|---|---|---|---|---|---|---|")
            for h in ["4", "3", "2", "1.5"]:
                out = os.path.join(tmp, "scale.vtu")
                rows = []
                for _ in range(a.repeat):
                    j = biotet_json("mesh", s, "--size", h, "--no-recover", "--no-improve", "--no-smooth")
                    rows.append({"seconds": j["pipeline"]["seconds_total"] + j.get("seconds_sizing", 0.0), "tets": j["pipeline"]["n_tets"],
                                 "points": j["pipeline"]["n_points"], "tmpl": j["pipeline"]["template"]["bytes"],
                                 "mem_kb": j["peak_rss_kb"] - j["rss_before_kb"]})
                sec = med(rows, "seconds")
                row = {"size": float(h), "points": rows[0]["points"], "tets": rows[0]["tets"], "seconds": sec,
                       "us_per_tet": sec / rows[0]["tets"] * 1e6, "template_mb": rows[0]["tmpl"] / 1e6,
                       "mem_mb": med(rows, "mem_kb") / 1024}
                scaling.append(row)
                print(f"| {h} | {row['points']} | {row['tets']} | {sec:.3f} | {row['us_per_tet']:.3f} "
                      f"| {row['template_mb']:.1f} | {row['mem_mb']:.1f} |")
        if a.json:
            with open(a.json, "w") as f:
                json.dump({"results": results, "scaling": scaling}, f, indent=1)


if __name__ == "__main__":
    main()
