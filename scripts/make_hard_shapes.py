#!/usr/bin/env python3
"""Write tests/data/shapes/hard/: valid closed surfaces that LAST RESORT recovery does not finish on, which mesh only
through the pipeline's fallbacks: the cubes as cones from their centre (`biotet::star`), the lattice through points
just behind the triangles left (`biotet::inset`), slowly (found in session 35's hunt on shapes nobody tuned for;
tests/data/shapes/hard/README.md).

    pip install numpy manifold3d==3.5.4
    python3 scripts/make_hard_shapes.py [--out DIR]

  gen_cube_strips35  a unit cube, each side face cut into 35 strips parallel to z (two triangles each); the top and
                     bottom faces cut into 35 strips parallel to y, the two end strips of each fanned over the 36
                     collinear points of the side face beside them. Pure Python.
  gen_cube_strips100 the same with 100 strips a face (1,596 triangles).
  tm_lattice2_f64    manifold3d's union of 2 × 2 × 2 crossing bars (twelve 12-sided cylinders, radius 0.08, length
                     4), its float64 mesh (`to_mesh64`): genus 5, 1,296 triangles.

All are written as OFF with Python's repr coordinates (exactly equal points welded), as scripts/make_shapes.py does.
"""
import argparse, os, sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_shapes import clean, write_off  # noqa: E402
from benchlib import ROOT  # noqa: E402


def gen_cube_strips(n=35):
    s = np.linspace(0.0, 1.0, n + 1)
    index = {}

    def pid(x, y, z):
        return index.setdefault((float(x), float(y), float(z)), len(index))

    tris = []
    for i in range(n):
        a, b = s[i], s[i + 1]
        # Side faces, outward: y = 0, y = 1, x = 0, x = 1.
        tris += [[pid(a, 0, 0), pid(b, 0, 0), pid(b, 0, 1)], [pid(a, 0, 0), pid(b, 0, 1), pid(a, 0, 1)]]
        tris += [[pid(a, 1, 0), pid(b, 1, 1), pid(b, 1, 0)], [pid(a, 1, 0), pid(a, 1, 1), pid(b, 1, 1)]]
        tris += [[pid(0, a, 0), pid(0, b, 1), pid(0, b, 0)], [pid(0, a, 0), pid(0, a, 1), pid(0, b, 1)]]
        tris += [[pid(1, a, 0), pid(1, b, 0), pid(1, b, 1)], [pid(1, a, 0), pid(1, b, 1), pid(1, a, 1)]]
    for z, up in ((0.0, False), (1.0, True)):
        for i in range(n):
            a, b = s[i], s[i + 1]
            # The strip's outline counter-clockwise from +z; the end strips take the side face's points.
            ring = [(a, 0.0), (b, 0.0)]
            if i == n - 1:
                ring += [(1.0, y) for y in s[1:-1]]
            ring += [(b, 1.0), (a, 1.0)]
            if i == 0:
                ring += [(0.0, y) for y in s[::-1][1:-1]]
            ids = [pid(x, y, z) for x, y in ring]
            # A fan from a corner off the long collinear run.
            start = 1 if i == 0 else 0
            ids = ids[start:] + ids[:start]
            for k in range(1, len(ids) - 1):
                t = [ids[0], ids[k], ids[k + 1]]
                tris.append(t if up else t[::-1])
    points = np.array(sorted(index, key=index.get))
    return clean(points, tris)


def tm_lattice(k=2, sections=12, radius=0.08):
    import manifold3d as mf

    bars = []
    o = (k - 1) / 2
    for i in range(k):
        for j in range(k):
            bar = mf.Manifold.cylinder(4, radius, radius, sections)
            bars.append(bar.translate([i - o, j - o, -2]))
            bars.append(bar.rotate([90, 0, 0]).translate([i - o, 2, j - o]))
            bars.append(bar.rotate([0, 90, 0]).translate([-2, i - o, j - o]))
    mesh = mf.Manifold.batch_boolean(bars, mf.OpType.Add).to_mesh64()
    return clean(np.asarray(mesh.vert_properties)[:, :3], np.asarray(mesh.tri_verts))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(ROOT, "tests", "data", "shapes", "hard"))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    shapes = (
        ("gen_cube_strips35", gen_cube_strips),
        ("gen_cube_strips100", lambda: gen_cube_strips(100)),
        ("tm_lattice2_f64", tm_lattice),
    )
    for name, make in shapes:
        p, t = make()
        write_off(os.path.join(args.out, name + ".off"), p, t)
        print(f"{name}: {len(t)} triangles, {len(p)} points")


if __name__ == "__main__":
    main()
