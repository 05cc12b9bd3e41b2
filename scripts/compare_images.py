#!/usr/bin/env python3
"""Label images in, tet meshes out: biotet beside CGAL Mesh_3 and surface nets + TetGen, in one run.

    apt install libcgal-dev g++                    # CGAL (scripts/cgal/mesh3.cpp is built on first use)
    pip install nibabel numpy meshio pyvista tetgen
    cargo build --release -p biotet-cli
    python3 scripts/compare_images.py [IMAGE ...] [--markdown FILE]

Default images: tests/data/mni_brain.nii.gz (grey and white matter) and mni_head.nii.gz (5 tissues), 1 mm.

Tools, each in a child process:
  biotet       `biotet mesh IMAGE` with its defaults (the voxel faces remeshed within half a voxel by the surface
               stage, then meshed).
  biotet-exact `biotet mesh IMAGE --exact-surface` (the voxel faces kept exactly: a staircase boundary).
  cgal         CGAL 5.5 Mesh_3 on the labelled image (Labeled_mesh_domain_3), criteria as the label-image issue
               sets them: facet angle 30°, facet size and cell size biotet's median edge on the same image, facet
               distance half a voxel, radius-edge ratio 3, perturb and exude. It meshes in the image's voxel frame
               (origin at voxel 0); angles and volumes do not depend on it.
  nets+tetgen  pyvista's `contour_labels` (VTK surface nets, smoothed) then TetGen `pq1.2YA` (pip `tetgen`) on the
               labelled surface; TetGen is given no region seeds, so per-region volumes are not measured for it.

Measures, from one routine for every output (`biotet quality --json`): seconds (the meshing alone when the tool
reports it; wall time of the child otherwise), peak MB (the whole process, /usr/bin/time), tets, smallest and largest
dihedral angle, tets under 10° and 5°, the worst relative difference between a region's mesh volume and its voxel
volume (count × voxel volume), and the two-sided distance between the mesh's boundary and interface faces and the
labels' voxel boundary (`biotet quality MESH --surface VOXELS --distance --distance-spacing 0.5`, VOXELS being
`biotet surface IMAGE`: the voxel faces between labels after biotet's manifold repair, which relabels about 0.1% of the
voxels; CGAL's and TetGen's outputs, made in the voxel frame, are moved to world by the image's affine first).
"""
import argparse, json, os, subprocess, sys, tempfile, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib  # noqa: E402
from benchlib import ROOT, biotet_json, run_binary  # noqa: E402

DEFAULT = [os.path.join(ROOT, "tests", "data", n) for n in ("mni_brain.nii.gz", "mni_head.nii.gz")]


def voxel_volumes(img):
    """Label -> voxel volume (mm³) of a nibabel image, and the voxel sizes."""
    import numpy as np
    a = np.asarray(img.dataobj)
    z = [float(x) for x in img.header.get_zooms()[:3]]
    labels, counts = np.unique(a, return_counts=True)
    return {int(l): float(c) * z[0] * z[1] * z[2] for l, c in zip(labels, counts) if l != 0}, z, a


def quality(exe, mesh):
    """The one routine: biotet quality --json."""
    q = biotet_json(exe, "quality", mesh, ok=(0,))
    regions = {int(r["label"]): r["volume"] for r in q.get("regions", [])}
    return {"tets": q["n_tets"], "min_dihedral": q["min_dihedral_deg"], "max_dihedral": q["max_dihedral_deg"],
            "lt5": q["n_dihedral_lt_5"], "lt10": q["n_dihedral_lt_10"], "regions": regions}


def to_world(mesh, affine, zooms, tmp):
    """A copy of a Medit .mesh or TetGen .node/.ele made in the voxel frame (voxel i at i·zoom), its points moved to
    the image's world coordinates (text only: the file's other sections are kept as they are)."""
    import numpy as np
    A = np.asarray(affine, dtype=float)

    def world(xyz):
        v = np.array([float(c) / z for c, z in zip(xyz, zooms)] + [1.0])
        return [repr(float(c)) for c in (A @ v)[:3]]

    if mesh.endswith(".mesh"):
        lines = open(mesh).read().split("\n")
        i = next(k for k, l in enumerate(lines) if l.strip() == "Vertices")
        n = int(lines[i + 1].split()[0])
        for k in range(i + 2, i + 2 + n):
            f = lines[k].split()
            lines[k] = " ".join(world(f[:3]) + f[3:])
        out = os.path.join(tmp, "world.mesh")
        open(out, "w").write("\n".join(lines))
        return out
    base = mesh[: -len(".node")]
    lines = open(mesh).read().split("\n")
    n = int(lines[0].split()[0])
    for k in range(1, 1 + n):
        f = lines[k].split()
        lines[k] = " ".join([f[0]] + world(f[1:4]) + f[4:])
    out = os.path.join(tmp, "world")
    open(out + ".node", "w").write("\n".join(lines))
    with open(base + ".ele") as src, open(out + ".ele", "w") as dst:
        dst.write(src.read())
    return out + ".node"


def distance(exe, mesh, voxels):
    """Two-sided distance between the mesh's boundary and interface faces and the voxel boundary (mm)."""
    q = biotet_json(exe, "quality", mesh, "--surface", voxels, "--distance", "--distance-spacing", "0.5", ok=(0,))
    d = q["surface_distance"]
    return d["in_to_out"], d["out_to_in"], d["bound"]


def median_edge(mesh):
    """The median edge length of a tet mesh (meshio)."""
    import meshio, numpy as np
    m = meshio.read(mesh)
    t = m.cells_dict["tetra"]
    e = np.concatenate([t[:, [i, j]] for i, j in ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))])
    e = np.unique(np.sort(e, axis=1), axis=0)
    return float(np.median(np.linalg.norm(m.points[e[:, 0]] - m.points[e[:, 1]], axis=1)))


def run_biotet(exe, image, tmp, *args):
    out = os.path.join(tmp, "biotet.vtu")
    wall, peak, r = run_binary([exe, "mesh", image, "-o", out, "--json", "--quiet", *args])
    if r.returncode != 0:
        raise RuntimeError(r.stderr.strip()[-300:])
    j = json.loads(r.stdout)
    stage = j["surface"]["seconds"] if j.get("surface") else 0.0
    return out, {"seconds": stage + j["pipeline"]["seconds_total"] + j.get("seconds_sizing", 0.0), "wall": wall,
                 "peak_mb": peak / 1024 if peak else None}


def run_cgal(exe_cgal, arr, zooms, h, tmp):
    import numpy as np
    raw = os.path.join(tmp, "labels.raw")
    np.asarray(arr, dtype="<u2").ravel(order="F").tofile(raw)
    out = os.path.join(tmp, "cgal.mesh")
    nx, ny, nz = arr.shape[:3]
    wall, peak, r = run_binary([exe_cgal, "image", raw, str(nx), str(ny), str(nz), *map(repr, zooms), out,
                                repr(h), repr(0.5 * min(zooms)), repr(h)])
    if r.returncode != 0:
        raise RuntimeError(r.stderr.strip()[-300:])
    j = json.loads(r.stdout.strip().splitlines()[-1])
    return out, {"seconds": j["seconds"], "wall": wall, "peak_mb": peak / 1024 if peak else None}


CHILD = r'''
import json, resource, sys, time
import numpy as np, nibabel, pyvista as pv, tetgen
img = nibabel.load(sys.argv[1]); a = np.asarray(img.dataobj)
z = [float(x) for x in img.header.get_zooms()[:3]]
grid = pv.ImageData(dimensions=a.shape, spacing=z)
grid.point_data["labels"] = a.ravel(order="F")
t0 = time.perf_counter()
surf = grid.contour_labels(smoothing=True, output_mesh_type="triangles").clean().triangulate()
tg = tetgen.TetGen(surf.points, surf.faces.reshape(-1, 4)[:, 1:])
nodes, elems, *_ = tg.tetrahedralize(switches="pq1.2YAQ")
s = time.perf_counter() - t0
with open(sys.argv[2] + ".node", "w") as f:
    f.write(f"{len(nodes)} 3 0 0\n")
    for i, p in enumerate(nodes):
        f.write(f"{i} {float(p[0])!r} {float(p[1])!r} {float(p[2])!r}\n")
with open(sys.argv[2] + ".ele", "w") as f:
    f.write(f"{len(elems)} 4 0\n")
    for i, e in enumerate(elems):
        f.write(f"{i} {e[0]} {e[1]} {e[2]} {e[3]}\n")
print(json.dumps({"seconds": s, "surface_triangles": int(surf.n_cells)}))
'''


def run_nets(image, tmp):
    base = os.path.join(tmp, "nets")
    wall, peak, r = run_binary([sys.executable, "-c", CHILD, image, base])
    if r.returncode != 0:
        err = "\n".join(l for l in (r.stderr or "").splitlines() if not l.startswith("PEAK "))
        raise RuntimeError((err or r.stdout).strip()[-300:] or f"exit status {r.returncode}")
    j = json.loads(r.stdout.strip().splitlines()[-1])
    return base + ".node", {"seconds": j["seconds"], "wall": wall, "peak_mb": peak / 1024 if peak else None}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("images", nargs="*", metavar="IMAGE")
    ap.add_argument("--tools", default="biotet,cgal,nets+tetgen,biotet-exact")
    ap.add_argument("--markdown", metavar="FILE")
    a = ap.parse_args()
    import nibabel
    exe = benchlib.find_biotet()
    tools = a.tools.split(",")
    rows = []
    for image in a.images or DEFAULT:
        name = os.path.basename(image)
        img = nibabel.load(image)
        vox, zooms, arr = voxel_volumes(img)
        with tempfile.TemporaryDirectory(prefix="images_") as tmp:
            h = None
            voxels = os.path.join(tmp, "voxels.vtu")
            subprocess.run([exe, "surface", image, "-o", voxels, "--quiet"], check=True)
            for tool in tools:
                print(f"{name}: {tool} ...", file=sys.stderr, flush=True)
                row = {"image": name, "tool": tool}
                try:
                    if tool in ("biotet", "biotet-exact"):
                        out, t = run_biotet(exe, image, tmp, *(["--exact-surface"] if tool == "biotet-exact" else []))
                        e = median_edge(out)
                        h = h or e
                        row["note"] = f"median edge {e:.2f} mm"
                    elif tool == "cgal":
                        cg = benchlib.cgal_mesh3()
                        if not cg:
                            raise RuntimeError("CGAL's driver could not be built (apt install libcgal-dev g++)")
                        size = h if h else 2.0 * max(zooms)
                        out, t = run_cgal(cg, arr, zooms, size, tmp)
                        row["note"] = f"facet and cell size {size:.2f} mm, facet distance {0.5 * min(zooms):.2f} mm"
                    else:
                        out, t = run_nets(image, tmp)
                    row.update(t)
                    q = quality(exe, out)
                    row.update({k: v for k, v in q.items() if k != "regions"})
                    if tool != "nets+tetgen":
                        errs = [abs(q["regions"].get(l, 0.0) - v) / v for l, v in vox.items()]
                        row["volume_error"] = max(errs)
                    world = out if tool.startswith("biotet") else to_world(out, img.affine, zooms, tmp)
                    row["distance"] = distance(exe, world, voxels)
                except Exception as e:
                    row["failed"] = str(e).strip().splitlines()[-1][:200] if str(e).strip() else type(e).__name__
                    print(f"{name}: {tool} failed: {row['failed']}", file=sys.stderr)
                rows.append(row)
    f = benchlib.cell
    dist = lambda d: "–" if d is None else f"{d[0]:.3f} / {d[1]:.3f} ({d[2]:.3f})"
    lines = ["| image | tool | seconds | wall s | peak MB | tets | min dihedral | max dihedral | <10° | <5° "
             "| worst region volume error | distance to the voxel boundary: in→out / out→in (bound), mm | note |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "failed" in r:
            lines.append(f"| {r['image']} | {r['tool']} | failed: {r['failed']} |" + " |" * 10)
            continue
        lines.append(f"| {r['image']} | {r['tool']} | {f(r['seconds'], '.1f')} | {f(r['wall'], '.1f')} "
                     f"| {f(r.get('peak_mb'), ',.0f')} | {r['tets']:,} | {r['min_dihedral']:.2f}° "
                     f"| {r['max_dihedral']:.2f}° | {r['lt10']:,} | {r['lt5']:,} "
                     f"| {f(r.get('volume_error'), '.2%')} | {dist(r.get('distance'))} | {r.get('note', '')} |")
    block = "\n".join(lines)
    print(block)
    if a.markdown:
        with open(a.markdown, "w") as fh:
            fh.write(block + "\n")


if __name__ == "__main__":
    main()
