#!/usr/bin/env python3
"""2D meshes at a million triangles: biotet beside Triangle (the pip package `triangle`) in one run (issue 9).

    pip install triangle numpy
    cargo build --release -p biotet-cli
    python3 scripts/bench_2d.py [--triangles 1000000] [--repeat 3] [--json out.json]

Two inputs, written to a temporary directory:
1. disk.poly: the unit disk as a polygon of N boundary points (spacing h), N chosen so that a mesh of size h has about
   --triangles triangles. biotet: `mesh disk.poly --size h` (template deployment, Delaunay, segment recovery,
   outside removal, smoothing with the boundary fixed). Triangle: `pq20.7Ya<A>` on the same PSLG (quality mesh: min
   angle 20.7°, no Steiner point on the boundary, area bound A = h², about as many triangles), and `pY` (the
   constrained Delaunay triangulation) of biotet's own node set, so both triangulate exactly the same points.
2. square.poly: the unit square (boundary split into 4·64 segments) plus random interior points, the Table 4.1 set-up
   at scale. biotet: `mesh square.poly --no-deploy` (Delaunay + recovery of the PSLG's own points), then
   `smooth` (boundary fixed, 5 sweeps). Triangle: `pY` on the same PSLG.

Times are medians over --repeat runs: biotet's stage seconds from its --json (and the process wall time, which also
reads, checks, measures and writes); Triangle's `triangulate` call (numpy arrays in, out). Quality of every output
from one routine: `biotet quality --json` on a .node/.ele file. Set BIOTET to the binary if it is not
target/release/biotet.
"""
import argparse, json, math, os, statistics, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIOTET = os.environ.get("BIOTET", os.path.join(ROOT, "target", "release", "biotet"))


def run(*args):
    t = time.perf_counter()
    r = subprocess.run([BIOTET, *args, "--json"], capture_output=True, text=True)
    wall = time.perf_counter() - t
    if r.returncode != 0:
        sys.exit(f"biotet {' '.join(args)} failed ({r.returncode}): {r.stderr}")
    return json.loads(r.stdout), wall


def write_poly(path, pts, segs):
    with open(path, "w") as f:
        f.write(f"{len(pts)} 2 0 0\n")
        for i, (x, y) in enumerate(pts):
            f.write(f"{i + 1} {float(x)!r} {float(y)!r}\n")
        f.write(f"{len(segs)} 0\n")
        for i, (a, b) in enumerate(segs):
            f.write(f"{i + 1} {a + 1} {b + 1}\n")
        f.write("0\n")


def read_node(path):
    import numpy as np
    with open(path) as f:
        n = int(f.readline().split()[0])
        data = np.loadtxt(f, max_rows=n)
    return data[:, 1:3]


def write_node_ele(base, verts, tris):
    with open(base + ".node", "w") as f:
        f.write(f"{len(verts)} 2 0 0\n")
        for i, (x, y) in enumerate(verts):
            f.write(f"{i + 1} {float(x)!r} {float(y)!r}\n")
    with open(base + ".ele", "w") as f:
        f.write(f"{len(tris)} 3 0\n")
        for i, (a, b, c) in enumerate(tris):
            f.write(f"{i + 1} {a + 1} {b + 1} {c + 1}\n")


def quality(path):
    q, _ = run("quality", path)
    return {"triangles": q["n_triangles"], "min_angle": q["min_angle_deg"], "max_angle": q["max_angle_deg"],
            "mean_q": q.get("mean_q") or q.get("q_mean")}


def tri_run(pslg, flags, repeat):
    import triangle
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = triangle.triangulate(pslg, flags)
        times.append(time.perf_counter() - t)
    return statistics.median(times), out


def main():
    import numpy as np
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--triangles", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", help="write the figures here")
    a = ap.parse_args()
    res = {"triangles_target": a.triangles, "repeat": a.repeat}
    with tempfile.TemporaryDirectory() as d:
        # 1. The disk. The template's Euclidean zones put nodes on a square-ish lattice: about 2/h² triangles per unit
        # area, so h = sqrt(2π / T).
        h = math.sqrt(2 * math.pi / a.triangles)
        n = int(round(2 * math.pi / h))
        pts = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n)]
        segs = [(k, (k + 1) % n) for k in range(n)]
        poly = os.path.join(d, "disk.poly")
        write_poly(poly, pts, segs)
        out = os.path.join(d, "disk.node")
        runs = [run("mesh", poly, "--size", repr(h), "-o", out) for _ in range(a.repeat)]
        rep = [r[0]["report"] for r in runs]
        med = lambda k: statistics.median(r[k] for r in rep)
        b = {"h": h, "boundary_points": n, "walls": statistics.median(r[1] for r in runs),
             "template": med("seconds_template"), "delaunay": med("seconds_delaunay"),
             "recover": med("seconds_recover"), "smooth": med("seconds_smooth"),
             "valid": runs[0][0]["check"]["valid"], **quality(out)}
        b["pipeline"] = b["template"] + b["delaunay"] + b["recover"] + b["smooth"]
        res["disk_biotet"] = b
        pslg = {"vertices": np.array(pts), "segments": np.array(segs)}
        area = h * h  # Triangle's area bound is a maximum: this gives about as many triangles as biotet's h
        t, o = tri_run(pslg, f"pq20.7Ya{area:.12f}", a.repeat)
        base = os.path.join(d, "tri_q")
        write_node_ele(base, o["vertices"], o["triangles"])
        res["disk_triangle_quality"] = {"flags": f"pq20.7Ya{area:.12f}", "seconds": t, **quality(base + ".node")}
        nodes = read_node(out)
        t, o = tri_run({"vertices": nodes, "segments": np.array(segs)}, "pY", a.repeat)
        base = os.path.join(d, "tri_p")
        write_node_ele(base, o["vertices"], o["triangles"])
        res["disk_triangle_cdt_same_points"] = {"flags": "pY", "points": len(nodes), "seconds": t,
                                                **quality(base + ".node")}

        # 2. The square with random points (Table 4.1 at scale).
        m = a.triangles // 2
        k = 64
        side = [(i / k, 0.0) for i in range(k)] + [(1.0, i / k) for i in range(k)] + \
               [(1.0 - i / k, 1.0) for i in range(k)] + [(0.0, 1.0 - i / k) for i in range(k)]
        rng = np.random.default_rng(44)
        inner = 0.001 + 0.998 * rng.random((m - len(side), 2))
        spts = side + [tuple(p) for p in inner]
        ssegs = [(i, (i + 1) % len(side)) for i in range(len(side))]
        spoly = os.path.join(d, "square.poly")
        write_poly(spoly, spts, ssegs)
        sout = os.path.join(d, "square.mesh")
        runs = [run("mesh", spoly, "--no-deploy", "--no-smooth", "-o", sout) for _ in range(a.repeat)]
        rep = [r[0]["report"] for r in runs]
        sm_out = os.path.join(d, "square_smooth.node")
        sruns = [run("smooth", sout, "--max-sweeps", "5", "-o", sm_out) for _ in range(a.repeat)]
        res["square_biotet"] = {"points": len(spts), "delaunay": statistics.median(r["seconds_delaunay"] for r in rep),
                                "recover": statistics.median(r["seconds_recover"] for r in rep),
                                "wall": statistics.median(r[1] for r in runs), **quality(sout)}
        res["square_biotet_smooth"] = {
            "sweeps": sruns[0][0]["smooth"]["sweeps"].__len__(),
            "wall": statistics.median(r[1] for r in sruns),
            "min_angle_before": sruns[0][0]["before"]["min_angle_deg"], **quality(sm_out)}
        t, o = tri_run({"vertices": np.array(spts), "segments": np.array(ssegs)}, "pY", a.repeat)
        base = os.path.join(d, "tri_s")
        write_node_ele(base, o["vertices"], o["triangles"])
        res["square_triangle_cdt"] = {"flags": "pY", "seconds": t, **quality(base + ".node")}

    print(json.dumps(res, indent=2))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(res, f, indent=2)


if __name__ == "__main__":
    main()
