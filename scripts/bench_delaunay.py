#!/usr/bin/env python3
"""Delaunay speed and memory: biotet beside TetGen, CGAL and Qhull, on the same points, in one run.

    apt-get install tetgen; pip install numpy cgal scipy   # the anchors (each skipped if absent)
    cargo build --release -p biotet-cli
    python3 scripts/bench_delaunay.py --n 1000000 --repeat 3 [--lattice 100] [--json out.json]

Each tool runs in its own process on the same point file; a row gives the median of the repeats
of the triangulation time alone (TetGen 1.5's binary, its own "Delaunay seconds"; CGAL's insert; scipy's Delaunay;
biotet's `--json` seconds, without file I/O), points per second, finite tets, and the process's
peak RSS (and its RSS before triangulating, so the difference is the triangulation's).
"""
import argparse, json, os, statistics, subprocess, sys, tempfile, textwrap

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIOTET = os.path.join(ROOT, "target", "release", "biotet")

CHILD = textwrap.dedent(r'''
    import json, resource, sys, time, re, io, os
    import numpy as np
    tool, path = sys.argv[1], sys.argv[2]
    p = np.load(path)
    def rss_kb():
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmRSS"):
                    return int(line.split()[1])
    out = {}
    if False:
        pass
    elif tool == "cgal":
        from CGAL.CGAL_Kernel import Point_3
        from CGAL.CGAL_Triangulation_3 import Delaunay_triangulation_3
        pts = [Point_3(float(x), float(y), float(z)) for x, y, z in p]
        before = rss_kb()
        dt = Delaunay_triangulation_3()
        t = time.perf_counter()
        dt.insert(pts)
        out = {"seconds": time.perf_counter() - t, "n_tets": dt.number_of_finite_cells()}
    elif tool == "qhull":
        from scipy.spatial import Delaunay
        before = rss_kb()
        t = time.perf_counter()
        d = Delaunay(p)
        out = {"seconds": time.perf_counter() - t, "n_tets": int(d.simplices.shape[0])}
    out["rss_before_kb"] = before
    out["peak_rss_kb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(json.dumps(out))
''')


def run_anchor(tool, npy):
    r = subprocess.run([sys.executable, "-c", CHILD, tool, npy], capture_output=True, text=True)
    if r.returncode != 0:
        return {"error": (r.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(r.stdout.strip().splitlines()[-1])


def run_tetgen(node):
    """TetGen's own binary (Debian package `tetgen`); -NEF writes no output, -V prints timings."""
    import re, shutil
    exe = shutil.which("tetgen")
    if not exe:
        return {"error": "tetgen binary not found (apt-get install tetgen)"}
    r = subprocess.run(["/usr/bin/time", "-f", "PEAK %M", exe, "-NEFV", node], capture_output=True, text=True)
    if r.returncode != 0:
        return {"error": r.stderr.strip()[-200:]}
    sec = re.search(r"Delaunay seconds:\s*([0-9.e-]+)", r.stdout)
    tets = re.search(r"Mesh tetrahedra:\s*(\d+)", r.stdout)
    peak = re.search(r"PEAK (\d+)", r.stderr)
    return {"seconds": float(sec.group(1)), "n_tets": int(tets.group(1)), "peak_rss_kb": int(peak.group(1)),
            "rss_before_kb": None}


def run_biotet(xyz):
    r = subprocess.run(["/usr/bin/time", "-f", "%M", BIOTET, "delaunay", xyz, "--json"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        return {"error": r.stderr.strip()}
    j = json.loads(r.stdout)
    peak = int(r.stderr.strip().splitlines()[-1])
    return {"seconds": j["seconds"], "n_tets": j["n_tets"], "peak_rss_kb": peak,
            "rss_before_kb": j.get("rss_before_kb"), "triangulation_peak_kb": j.get("peak_rss_kb")}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=1_000_000, help="uniform random points in the unit cube")
    ap.add_argument("--lattice", type=int, default=0, help="use a K×K×K integer lattice instead")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tools", default="biotet,tetgen,cgal,qhull")
    ap.add_argument("--json", help="write the results here too")
    a = ap.parse_args()
    import numpy as np
    if a.lattice:
        k = a.lattice
        g = np.stack(np.meshgrid(np.arange(k), np.arange(k), np.arange(k), indexing="ij"), -1)
        pts = g.reshape(-1, 3).astype(np.float64)
        name = f"{k}^3 lattice"
    else:
        pts = np.random.default_rng(1).random((a.n, 3))
        name = f"{a.n} uniform random points"
    d = tempfile.mkdtemp()
    npy, xyz = os.path.join(d, "p.npy"), os.path.join(d, "p.xyz")
    np.save(npy, pts)
    np.savetxt(xyz, pts, fmt="%.17g")
    node = os.path.join(d, "p.node")
    with open(node, "w") as f:
        f.write(f"{len(pts)} 3 0 0\n")
        np.savetxt(f, np.column_stack([np.arange(1, len(pts) + 1), pts]), fmt=["%d", "%.17g", "%.17g", "%.17g"])
    rows = {}
    for rep in range(a.repeat):
        for tool in a.tools.split(","):
            if tool == "biotet":
                r = run_biotet(xyz)
            elif tool == "tetgen":
                r = run_tetgen(node)
            else:
                r = run_anchor(tool, npy)
            rows.setdefault(tool, []).append(r)
    n = len(pts)
    print(f"# {name}, {a.repeat} runs each, median; machine: {os.cpu_count()} cores")
    print(f"{'tool':8} {'seconds':>9} {'points/s':>11} {'tets':>10} {'peak RSS MB':>12} {'RSS before MB':>14} {'B/point':>8}")
    summary = {"dataset": name, "n_points": n, "tools": {}}
    for tool, rs in rows.items():
        ok = [r for r in rs if "error" in r and False or "seconds" in r]
        if not ok:
            print(f"{tool:8} skipped: {rs[0].get('error')}")
            summary["tools"][tool] = {"error": rs[0].get("error")}
            continue
        s = statistics.median(r["seconds"] for r in ok)
        peak = statistics.median(r["peak_rss_kb"] for r in ok)
        before = ok[0].get("rss_before_kb") or 0
        bpp = (peak - before) * 1024 / n
        print(f"{tool:8} {s:9.3f} {n / s:11.0f} {ok[0]['n_tets']:10d} {peak / 1024:12.1f} {before / 1024:14.1f} {bpp:8.0f}")
        summary["tools"][tool] = {"seconds": s, "points_per_second": n / s, "n_tets": ok[0]["n_tets"],
                                  "peak_rss_kb": peak, "rss_before_kb": before, "bytes_per_point": bpp,
                                  "runs": [r["seconds"] for r in ok]}
    if "biotet" in summary["tools"] and "seconds" in summary["tools"]["biotet"]:
        b = summary["tools"]["biotet"]["seconds"]
        for tool, r in summary["tools"].items():
            if tool != "biotet" and "seconds" in r:
                print(f"biotet is {r['seconds'] / b:.2f}x {tool}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(summary, f, indent=1)


if __name__ == "__main__":
    main()
