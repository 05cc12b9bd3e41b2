#!/usr/bin/env python3
"""Solid-angle smoothing: biotet `smooth` beside MMG3D (`-optim -nosurf`) and TetGen's own optimisation (`pq1.2YO`)
on the same TetGen `pq1.2Y` mesh of a surface, in one run (issue 7).

    pip install tetgen meshio numpy pymmg      # pymmg ships the mmg3d_O3 binary
    cargo build --release -p biotet-cli
    python3 scripts/bench_smooth.py [SURFACE.stl] [--repeat 3] [--json out.json]

The input mesh is TetGen `pq1.2Y` of the surface (STL points welded with numpy.unique first). biotet smooths it with
the surface fixed and sliding; MMG3D optimises it without touching the surface; TetGen's `pq1.2YO` meshes the surface
again with its own optimisation on (its time includes meshing; the `pq1.2Y` time is listed so the difference is the
optimisation). Times are medians of the repeats: biotet's smoothing seconds from its --json and the process wall time;
MMG's process wall time; TetGen's `tetrahedralize` call. Quality comes from one routine for every output:
`biotet quality --json` (min solid angle, min/max dihedral, tets under 10°, share of solid angles under 0.2 sr).
Set BIOTET to the binary if it is not target/release/biotet.
"""
import argparse, json, os, shutil, statistics, subprocess, sys, tempfile, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib  # noqa: E402  (shared: the biotet calls, the pip TetGen child, MMG's binary)
from benchlib import ROOT, mmg3d  # noqa: E402

BIOTET = benchlib.find_biotet()
DEFAULT = os.path.join(ROOT, "tests", "data", "brain_20k.stl")


def biotet_json(*args):
    return benchlib.biotet_json(BIOTET, *args, ok=(0,))


def measure(mesh):
    q = biotet_json("quality", mesh)
    h = q["solid_angle_histogram"]
    below = h["below"] + sum(h["counts"][:4])  # 0.05 sr bins: [0, 0.2)
    c = subprocess.run([BIOTET, "check", mesh, "--json"], capture_output=True, text=True)
    c = json.loads(c.stdout) if c.stdout.strip() else {}
    return {
        "points": q["n_points"], "tets": q["n_tets"],
        "min_solid_sr": q["min_solid_angle_sr"],
        "min_dihedral": q["min_dihedral_deg"], "max_dihedral": q["max_dihedral_deg"],
        "lt10": q["n_dihedral_lt_10"], "mean_q": q["mean_q"],
        "share_lt_0_2_sr": below / max(1, 4 * q["n_tets"]),
        "valid": c.get("valid"),
    }


def tetgen(surface, switches, out, repeat):
    return statistics.median(
        benchlib.run_child("tetgen", surface, out, switches=switches)["seconds"] for _ in range(repeat))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("surface", nargs="?", default=DEFAULT)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", help="write the rows to this file")
    a = ap.parse_args()
    if not os.path.exists(BIOTET):
        sys.exit(f"{BIOTET}: build it with `cargo build --release -p biotet-cli` or set BIOTET")
    tmp = tempfile.mkdtemp(prefix="bench_smooth_")
    rows = []
    base = os.path.join(tmp, "tetgen")
    t_mesh = tetgen(a.surface, "pq1.2Y", base, a.repeat)
    node = base + ".node"
    rows.append({"tool": "TetGen pq1.2Y (input)", "seconds": t_mesh, **measure(node)})
    print(f"input: {rows[0]['tets']} tets, TetGen pq1.2Y {t_mesh:.3f} s", file=sys.stderr)

    for boundary in ["fixed", "slide"]:
        out = os.path.join(tmp, f"biotet_{boundary}.vtu")
        secs, walls, j = [], [], None
        for _ in range(a.repeat):
            start = time.perf_counter()
            j = biotet_json("smooth", node, "--boundary", boundary, "-o", out)
            walls.append(time.perf_counter() - start)
            secs.append(j["seconds"])
        rows.append({"tool": f"biotet smooth --boundary {boundary}", "seconds": statistics.median(secs),
                     "wall_seconds": statistics.median(walls), "sweeps": j["sweeps"],
                     "seconds_per_sweep": j["seconds_per_sweep"],
                     "max_surface_distance": j["max_surface_distance"], **measure(out)})

    exe = mmg3d()
    if exe:
        medit = os.path.join(tmp, "input.mesh")
        subprocess.run([BIOTET, "convert", node, "-o", medit, "--quiet"], check=True)
        out = os.path.join(tmp, "mmg.mesh")
        walls = []
        for _ in range(a.repeat):
            start = time.perf_counter()
            r = subprocess.run([exe, "-in", medit, "-out", out, "-optim", "-nosurf", "-v", "-1"],
                               capture_output=True, text=True)
            walls.append(time.perf_counter() - start)
            if r.returncode != 0:
                raise RuntimeError(f"mmg3d: {r.stderr.strip() or r.stdout.strip()}")
        rows.append({"tool": "MMG3D -optim -nosurf", "seconds": statistics.median(walls), **measure(out)})
    else:
        print("mmg3d not found (pip install pymmg); MMG skipped", file=sys.stderr)

    base_o = os.path.join(tmp, "tetgen_O")
    t_o = tetgen(a.surface, "pq1.2YO", base_o, a.repeat)
    rows.append({"tool": "TetGen pq1.2YO (meshing + optimisation)", "seconds": t_o, **measure(base_o + ".node")})

    head = f"{'tool':<42} {'seconds':>8} {'tets':>8} {'min solid sr':>13} {'min dih°':>9} {'max dih°':>9} {'<10°':>6} {'<0.2 sr':>8} valid"
    print(head)
    for r in rows:
        print(f"{r['tool']:<42} {r['seconds']:>8.3f} {r['tets']:>8} {r['min_solid_sr']:>13.4e} {r['min_dihedral']:>9.4f} "
              f"{r['max_dihedral']:>9.3f} {r['lt10']:>6} {100 * r['share_lt_0_2_sr']:>7.2f}% {r['valid']}")
    for r in rows:
        if "sweeps" in r:
            print(f"{r['tool']}: {r['sweeps']} sweeps, {r['seconds_per_sweep']:.3f} s per sweep, "
                  f"wall {r['wall_seconds']:.3f} s, surface distance {r['max_surface_distance']:.2e}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=2)
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
