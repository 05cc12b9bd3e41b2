#!/usr/bin/env python3
"""Random CAD solids for robustness runs: booleans of OpenCASCADE primitives nobody chose.

    pip install gmsh==4.15.2 numpy
    python3 scripts/random_cad.py --out DIR [--count 60] [--seed 1] [--biotet PATH]
    python3 scripts/bench_shapes.py DIR/*.off          # then: biotet beside TetGen on each

Each solid is a random primitive (box, cylinder, sphere, cone, torus or wedge, random size and place) combined with
two to five more by random booleans (fuse, cut, intersect), a few of its edges filleted at random (one in three), then
surface-meshed by gmsh (a random algorithm among MeshAdapt, Delaunay and Frontal, a random size from 0.03 to 3, so
from fine to very coarse facets) exactly as scripts/make_shapes.py meshes the corpus's CAD shapes. A boolean that
leaves more or fewer than one volume is dropped, and so is any surface `biotet validate` refuses; the rest are written
as DIR/occ_SEED_K.off. The same seed gives the same files with the pinned gmsh. Nothing here is tuned: the point is
shapes the corpus lacks (saddles, slivers of cut solids, coarse facets on curved faces).
"""
import os, random, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchlib import find_biotet  # noqa: E402
from make_shapes import Gmsh, random_args, write_random  # noqa: E402


def primitive(occ, rng):
    """One random primitive's volume tag."""
    x, y, z = (rng.uniform(-0.5, 0.5) for _ in range(3))
    kind = rng.choice(["box", "cylinder", "sphere", "cone", "torus", "wedge"])
    if kind == "box":
        return occ.addBox(x, y, z, rng.uniform(0.2, 1.2), rng.uniform(0.05, 1.0), rng.uniform(0.1, 1.0))
    if kind == "cylinder":
        return occ.addCylinder(x, y, z, rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0.1, 1),
                               rng.uniform(0.05, 0.5))
    if kind == "sphere":
        return occ.addSphere(x, y, z, rng.uniform(0.1, 0.6))
    if kind == "cone":
        return occ.addCone(x, y, z, 0, 0, rng.uniform(0.3, 1), rng.uniform(0.1, 0.5), rng.uniform(0.0, 0.3))
    if kind == "torus":
        return occ.addTorus(x, y, z, rng.uniform(0.3, 0.6), rng.uniform(0.05, 0.2))
    return occ.addWedge(x, y, z, rng.uniform(0.2, 1), rng.uniform(0.2, 1), rng.uniform(0.2, 1), -1, rng.uniform(0, 0.5))


def solid(name, rng):
    """A random solid's outward surface (points, triangles), or None when its booleans or mesh fail."""
    with Gmsh(name) as s:
        occ = s.g.model.occ
        a = primitive(occ, rng)
        for _ in range(rng.randint(2, 5)):
            b = primitive(occ, rng)
            op = rng.choice([occ.fuse, occ.cut, occ.fuse, occ.intersect])
            try:
                out, _ = op([(3, a)], [(3, b)])
            except Exception:
                continue
            vols = [t for d, t in out if d == 3]
            if len(vols) != 1:
                return None
            a = vols[0]
        occ.synchronize()
        if rng.random() < 1 / 3:
            edges = [t for d, t in s.g.model.getBoundary([(3, a)], combined=False, oriented=False, recursive=True)
                     if d == 1]
            try:
                occ.fillet([a], edges[: rng.randint(1, 4)], [rng.uniform(0.01, 0.08)])
            except Exception:
                pass
        size = rng.choice([0.03, 0.1, 0.3, 1.0, 3.0])
        s.g.option.setNumber("Mesh.Algorithm", rng.choice([1, 5, 6]))
        try:
            return s.surface_mesh(size_min=size / 10, size_max=size)
        except Exception:
            return None


def main():
    a = random_args(__doc__, 60, "solids")
    rng = random.Random(a.seed)

    def make(k):
        name = f"occ_{a.seed}_{k}"
        got = solid(name, rng)
        return name, None if got is None or len(got[1]) > 40000 else got

    write_random(find_biotet(a.biotet), a.out, a.count, make, "solids")


if __name__ == "__main__":
    main()
