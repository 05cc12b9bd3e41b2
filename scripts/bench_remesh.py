#!/usr/bin/env python3
"""Remeshing in place (issue 23) beside MMG3D with the tets outside the zone required.

    cargo build --release -p biotet-cli
    pip install pymmg numpy scipy                 # pymmg ships the mmg3d_O3 binary
    python3 scripts/bench_remesh.py [--repeat 3] [--fine-size 1.7] [--skip-fine] [--json out.json]

On the nested brain/white-matter model meshed with defaults (and, unless --skip-fine, at --fine-size, above 1M
tets): the white matter (region 2) at half and twice its median edge length, a 20 mm ball in the grey matter at a
third of it, a 10 mm ellipsoid lesion inserted inside the grey matter (label 3) and one across the grey/white
interface (refused: crossing is not handled yet), the 20 mm ball again with --allow-shell-changes, a 16 mm ball at a
sixth of the grey matter's size (far finer than its shell), and a ball holding about 1% of the tets refilled at the grey
matter's size (the cost against meshing the whole model). For each: seconds (median of --repeat runs of the library's
`seconds_total`, reading and writing aside), tets removed and added, the new tets' and the whole mesh's dihedral
angles, and `biotet check` against the model's surface (and the lesion's).

MMG3D gets the same zone: the input tets biotet replaced are left free, every other tet is written as a
RequiredTetrahedra, and `mmg3d_O3 -hsiz H -nosurf` remeshes the free ones at the same size (-nosurf keeps the
boundary and interface triangles, as biotet keeps the cavity's shell). MMG writes coordinates rounded to about 15
digits: its points within 1e-9 of the bounding-box diagonal of an input point are put back on it before its kept tets
are counted and its output checked. MMG has no way to embed a triangulated surface into a volume mesh (its -ls mode
cuts the mesh along the zero level set of a function given at its vertices instead), so the insert rows have
no MMG figures.

Also the cost of a zone of about 1% of the fine mesh refilled at the mesh's own size, against meshing the whole model.
"""
import argparse, json, os, shutil, statistics, subprocess, sys, tempfile, time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchlib import ROOT, find_biotet, mmg3d, require  # noqa: E402

SURFACE = os.path.join(ROOT, "tests/data/nested_brain_wm_20k.stl")
SURFACE_LABELS = "nested_brain_wm_20k.stl=1,2"


def run(args, ok=(0,)):
    r = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    if r.returncode not in ok:
        raise RuntimeError(f"{' '.join(map(str, args))}: {r.stderr.strip() or r.stdout.strip()}")
    return r


def read_medit(path):
    """Points (n, 3), tets (m, 4, 0-based) and tet refs of a Medit .mesh file."""
    with open(path) as f:
        tokens = f.read().split()
    out, i = {}, 0
    while i < len(tokens):
        key = tokens[i]
        if key in ("Vertices", "Tetrahedra"):
            n = int(tokens[i + 1])
            width = 4 if key == "Vertices" else 5
            a = np.array(tokens[i + 2:i + 2 + n * width], dtype=float).reshape(n, width)
            out[key] = a
            i += 2 + n * width
        else:
            i += 1
    p = out["Vertices"][:, :3]
    t = out["Tetrahedra"]
    return p, t[:, :4].astype(np.int64) - 1, t[:, 4].astype(np.int64)


def write_medit(path, p, t, refs, required=None):
    """A Medit .mesh with tets (0-based in) and, optionally, the 0-based indices of required tets."""
    with open(path, "w") as f:
        f.write("MeshVersionFormatted 2\nDimension 3\n")
        f.write(f"Vertices\n{len(p)}\n")
        f.writelines(f"{q[0]!r} {q[1]!r} {q[2]!r} 0\n" for q in p.tolist())
        f.write(f"Tetrahedra\n{len(t)}\n")
        f.writelines(f"{a + 1} {b + 1} {c + 1} {d + 1} {r}\n" for (a, b, c, d), r in zip(t.tolist(), refs.tolist()))
        if required is not None and len(required):
            f.write(f"RequiredTetrahedra\n{len(required)}\n")
            f.writelines(f"{k + 1}\n" for k in required.tolist())
        f.write("End\n")


def point_ids(p_in, p_out):
    """For each output point, the index of the input point with exactly the same coordinates, or -1."""
    index = {row.tobytes(): i for i, row in enumerate(np.ascontiguousarray(p_in))}
    return np.array([index.get(row.tobytes(), -1) for row in np.ascontiguousarray(p_out)], dtype=np.int64)


def tet_keys(t):
    """Each tet as the sorted tuple of its point indices."""
    return [tuple(r) for r in np.sort(t, axis=1).tolist()]


def kept_split(p_in, t_in, p_out, t_out):
    """(input tets kept, as a bool mask; output tets that are input tets, as a mask): tets as sets of input points."""
    ids = point_ids(p_in, p_out)
    mapped = ids[t_out]
    old = set(tet_keys(t_in))
    out_old = np.array([(-1 not in k) and (k in old) for k in tet_keys(mapped)], dtype=bool)
    kept = set(k for k, o in zip(tet_keys(mapped), out_old) if o)
    in_kept = np.array([k in kept for k in tet_keys(t_in)], dtype=bool)
    return in_kept, out_old


def dihedrals(p, t):
    """Min and max dihedral angle (degrees) of each tet."""
    c = p[t]
    faces = [(1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1)]
    n = []
    for a, b, d in faces:
        v = np.cross(c[:, b] - c[:, a], c[:, d] - c[:, a])
        n.append(v / np.linalg.norm(v, axis=1, keepdims=True))
    angs = []
    for i in range(4):
        for j in range(i + 1, 4):
            cosv = np.clip(np.einsum("ij,ij->i", n[i], n[j]), -1, 1)
            angs.append(180.0 - np.degrees(np.arccos(cosv)))
    a = np.stack(angs, axis=1)
    return a.min(axis=1), a.max(axis=1)


def quality(p, t):
    lo, hi = dihedrals(p, t)
    return {"min_dihedral": float(lo.min()) if len(t) else None, "max_dihedral": float(hi.max()) if len(t) else None,
            "lt10": int((lo < 10).sum())}


def snap(p_out, p_in, rel=1e-9):
    """MMG's rounded coordinates put back on the input points within rel × the bounding-box diagonal."""
    from scipy.spatial import cKDTree
    tol = rel * float(np.linalg.norm(p_in.max(axis=0) - p_in.min(axis=0)))
    d, k = cKDTree(p_in).query(p_out, distance_upper_bound=tol)
    out = p_out.copy()
    hit = np.isfinite(d)
    out[hit] = p_in[k[hit]]
    return out


def ellipsoid_off(path, centre, axes, levels=3):
    """An icosphere subdivided `levels` times, scaled to semi-axes `axes` along rotated axes, centred at `centre`."""
    g = (1 + 5 ** 0.5) / 2
    p = [[-1, g, 0], [1, g, 0], [-1, -g, 0], [1, -g, 0], [0, -1, g], [0, 1, g], [0, -1, -g], [0, 1, -g],
         [g, 0, -1], [g, 0, 1], [-g, 0, -1], [-g, 0, 1]]
    t = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6],
         [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
         [8, 6, 7], [9, 8, 1]]
    p = [list(np.array(q) / np.linalg.norm(q)) for q in p]
    for _ in range(levels):
        mid, nt = {}, []

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                q = (np.array(p[a]) + np.array(p[b])) / 2
                p.append(list(q / np.linalg.norm(q)))
                mid[k] = len(p) - 1
            return mid[k]
        for a, b, c in t:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nt += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        t = nt
    # A fixed tilt so that the ellipsoid is not axis-aligned.
    ca, sa = np.cos(0.5), np.sin(0.5)
    rot = np.array([[ca, -sa, 0], [sa, ca, 0], [0, 0, 1]])
    q = (np.array(p) * np.array(axes)) @ rot.T + np.array(centre)
    with open(path, "w") as f:
        f.write(f"OFF\n{len(q)} {len(t)} 0\n")
        f.writelines(f"{x!r} {y!r} {z!r}\n" for x, y, z in q.tolist())
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in t)


def region_edge(p, t, refs, label):
    """Median edge length of the tets of a region."""
    sel = t[refs == label]
    e = [np.linalg.norm(p[sel[:, i]] - p[sel[:, j]], axis=1) for i, j in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]]
    return float(np.median(np.concatenate(e)))


def places(p, t, refs, clearance):
    """A point of the grey matter (region 1) at least `clearance` from the outer boundary and the interface, as far
    as possible from both (tet centroids against the boundary and interface points); and a point on the interface."""
    from scipy.spatial import cKDTree
    faces = np.concatenate([t[:, [1, 2, 3]], t[:, [0, 3, 2]], t[:, [0, 1, 3]], t[:, [0, 2, 1]]])
    owner = np.tile(refs, 4)
    key = np.sort(faces, axis=1)
    order = np.lexsort(key.T[::-1])
    key, owner = key[order], owner[order]
    same = np.all(key[1:] == key[:-1], axis=1)
    paired = np.zeros(len(key), dtype=bool)
    paired[1:] |= same
    paired[:-1] |= same
    boundary = key[~paired]
    first = np.where(same)[0]
    interface = key[first][owner[first] != owner[first + 1]]
    bpts = np.unique(np.concatenate([boundary.ravel(), interface.ravel()]))
    tree = cKDTree(p[bpts])
    gm = t[refs == 1]
    cent = p[gm].mean(axis=1)
    d, _ = tree.query(cent)
    best = cent[np.argmax(d)]
    # The interface point nearest to the grey-matter spot: a lesion centred there crosses the interface.
    ipts = np.unique(interface.ravel())
    across = p[ipts[np.argmin(np.linalg.norm(p[ipts] - best, axis=1))]]
    return best, float(d.max()), across


def biotet_remesh(exe, mesh, args, out, repeat):
    secs, walls, j = [], [], None
    for _ in range(repeat):
        start = time.perf_counter()
        r = run([exe, "remesh", mesh, *args, "-o", out, "--json"])
        walls.append(time.perf_counter() - start)
        j = json.loads(r.stdout)
        secs.append(j["remesh"]["seconds_total"])
    return statistics.median(secs), statistics.median(walls), j


def check(exe, mesh, extra=()):
    r = run([exe, "check", mesh, "-s", SURFACE, *extra, "--json"], ok=(0, 1))
    return json.loads(r.stdout)["valid"]


def whole(exe, mesh):
    q = json.loads(run([exe, "quality", mesh, "--json"]).stdout)
    return {"tets": q["n_tets"], "min_dihedral": q["min_dihedral_deg"], "max_dihedral": q["max_dihedral_deg"],
            "lt10": q["n_dihedral_lt_10"]}


def bench_mesh(exe, mmg, tmp, name, mesh_args, repeat, own_size):
    """Every case on one base mesh (`own_size`: its --size, None for the default sizing); returns the rows."""
    base = os.path.join(tmp, f"{name}.vtu")
    start = time.perf_counter()
    j = json.loads(run([exe, "mesh", SURFACE, *mesh_args, "-o", base, "--json"]).stdout)
    mesh_wall = time.perf_counter() - start
    # Sizing plus the pipeline: reading and validating the surface aside, as for remesh.
    mesh_secs = j["pipeline"]["seconds_total"] + (j.get("seconds_sizing") or 0.0)
    medit = os.path.join(tmp, f"{name}.mesh")
    run([exe, "convert", base, "-o", medit, "--quiet"])
    p, t, refs = read_medit(medit)
    h = region_edge(p, t, refs, 2)
    hg = region_edge(p, t, refs, 1)
    print(f"{name}: {len(t)} tets, meshed in {mesh_secs:.2f} s; median edge: white {h:.3f}, grey {hg:.3f}",
          file=sys.stderr)
    rows = [{"mesh": name, "case": "whole model (biotet mesh)", "tets": len(t), "seconds": mesh_secs,
             "whole": whole(exe, base)}]
    axes = (5.0, 3.5, 3.0)
    spot, clear, across = places(p, t, refs, max(axes))
    lesion = os.path.join(tmp, f"{name}_lesion.off")
    ellipsoid_off(lesion, spot, axes)
    crossing = os.path.join(tmp, f"{name}_crossing.off")
    ellipsoid_off(crossing, across, axes)
    print(f"{name}: lesion at {spot.round(2).tolist()} (clearance {clear:.2f} mm), crossing one at "
          f"{across.round(2).tolist()}", file=sys.stderr)
    margin = min(hg, max(0.0, clear - max(axes)) * 0.9)
    cases = [
        ("white matter at half its size", ["--region", "2", "--size", f"{h / 2:.4g}"], h / 2, None),
        ("white matter at twice its size", ["--region", "2", "--size", f"{2 * h:.4g}"], 2 * h, None),
        ("20 mm ball in grey matter, a third of the size",
         ["--sphere", ",".join(f"{x:.4g}" for x in spot) + ",10", "--size", f"{hg / 3:.4g}"], hg / 3, None),
        ("the same ball, sliver removal across its shell",
         ["--sphere", ",".join(f"{x:.4g}" for x in spot) + ",10", "--size", f"{hg / 3:.4g}",
          "--allow-shell-changes"], None, None),
        # A refill six times finer than the shell's triangles (recovery failed here before 2026-12-02).
        ("16 mm ball in grey matter, a sixth of the size",
         ["--sphere", ",".join(f"{x:.4g}" for x in spot) + ",8", "--size", f"{hg / 6:.4g}"], hg / 6, None),
        # Sizes from the cavity's surface (the lesion's edges and the shell's): a uniform size far above the
        # lesion's edges leaves poor tets at it.
        ("10 mm ellipsoid lesion inside grey matter",
         ["--insert", lesion, "--label", "3", "--margin", f"{margin:.4g}"], None, lesion),
    ]
    # The ball around the lesion's spot holding about 1% of the tets (by centroid), at the mesh's --size.
    r = float(np.sort(np.linalg.norm(p[t].mean(axis=1) - spot, axis=1))[len(t) // 100])
    cases.append(("about 1% of the tets (ball), the mesh's own size",
                  ["--sphere", ",".join(f"{x:.4g}" for x in spot) + f",{r:.4g}", "--size", f"{own_size or hg:.4g}"],
                  None, None))
    for label, args, hsiz, les in cases:
        out = os.path.join(tmp, f"{name}_out.vtu")
        secs, wall, j = biotet_remesh(exe, base, args, out, repeat)
        out_medit = os.path.join(tmp, f"{name}_out.mesh")
        run([exe, "convert", out, "-o", out_medit, "--quiet"])
        po, to, ro = read_medit(out_medit)
        in_kept, out_old = kept_split(p, t, po, to)
        extra = ("-s", les, "--label", SURFACE_LABELS, "--label", f"{os.path.basename(les)}=3") if les else ()
        row = {"mesh": name, "case": label, "tool": "biotet", "args": " ".join(os.path.basename(a) for a in args),
               "seconds": secs, "wall": wall, "removed": int((~in_kept).sum()), "added": int((~out_old).sum()),
               "new": quality(po, to[~out_old]), "whole": whole(exe, out), "valid": check(exe, out, extra),
               "share_of_mesh": secs / mesh_secs}
        if les:
            row["lesion_tets"] = int((ro == 3).sum())
        rows.append(row)
        print(json.dumps(row), file=sys.stderr)
        if mmg and hsiz:
            required = np.where(in_kept)[0]
            mmg_in = os.path.join(tmp, f"{name}_mmg_in.mesh")
            mmg_out = os.path.join(tmp, f"{name}_mmg_out.mesh")
            write_medit(mmg_in, p, t, refs, required)
            walls = []
            for _ in range(repeat):
                start = time.perf_counter()
                r = subprocess.run([mmg, "-in", mmg_in, "-out", mmg_out, "-hsiz", f"{hsiz:.4g}", "-nosurf",
                                    "-v", "-1"], capture_output=True, text=True)
                walls.append(time.perf_counter() - start)
            mrow = {"mesh": name, "case": label, "tool": "MMG3D", "args": f"-hsiz {hsiz:.4g} -nosurf, "
                    f"{len(required)} tets required", "seconds": statistics.median(walls)}
            if r.returncode != 0 or not os.path.exists(mmg_out):
                mrow["error"] = (r.stderr.strip() or r.stdout.strip()).splitlines()[-1:] or [f"exit {r.returncode}"]
            else:
                pm, tm, rm = read_medit(mmg_out)
                pm = snap(pm, p)
                snapped = os.path.join(tmp, f"{name}_mmg_snapped.mesh")
                write_medit(snapped, pm, tm, rm)
                m_kept, m_old = kept_split(p, t, pm, tm)
                mrow.update({"removed": int((~m_kept).sum()), "added": int((~m_old).sum()),
                             "required_kept": int(m_kept[required].sum()),
                             "new": quality(pm, tm[~m_old]), "whole": whole(exe, snapped),
                             "valid": check(exe, snapped)})
            rows.append(mrow)
            print(json.dumps(mrow), file=sys.stderr)
    # Across the interface: refused (one line naming where), timed.
    start = time.perf_counter()
    r = subprocess.run([exe, "remesh", base, "--insert", crossing, "--label", "3", "--size", f"{hg / 2:.4g}",
                        "-o", os.path.join(tmp, "never.vtu")], capture_output=True, text=True)
    rows.append({"mesh": name, "case": "10 mm lesion across the grey/white interface", "tool": "biotet",
                 "refused": r.returncode != 0, "message": r.stderr.strip(), "seconds": time.perf_counter() - start})
    print(json.dumps(rows[-1]), file=sys.stderr)
    return rows


def cost(exe, tmp, size, repeat):
    """Meshing the whole model at --size `size` against refilling a ball holding about 1% of its tets at the same
    size: medians of `repeat` runs each (library seconds: reading and writing aside)."""
    base = os.path.join(tmp, "cost.vtu")
    mesh_secs = []
    for _ in range(repeat):
        j = json.loads(run([exe, "mesh", SURFACE, "--size", str(size), "-o", base, "--json"]).stdout)
        mesh_secs.append(j["pipeline"]["seconds_total"] + (j.get("seconds_sizing") or 0.0))
    medit = os.path.join(tmp, "cost.mesh")
    run([exe, "convert", base, "-o", medit, "--quiet"])
    p, t, refs = read_medit(medit)
    spot, _, _ = places(p, t, refs, 0.0)
    r = float(np.sort(np.linalg.norm(p[t].mean(axis=1) - spot, axis=1))[len(t) // 100])
    args = ["--sphere", ",".join(f"{x:.4g}" for x in spot) + f",{r:.4g}", "--size", str(size)]
    secs, wall, j = biotet_remesh(exe, base, args, os.path.join(tmp, "cost_out.vtu"), repeat)
    rem = j["remesh"]
    row = {"case": "cost", "tets": len(t), "mesh_seconds": statistics.median(mesh_secs), "mesh_runs": mesh_secs,
           "zone": " ".join(args), "removed": rem["tets_before"] - rem["tets_kept"],
           "added": rem["tets_after"] - rem["tets_kept"], "remesh_seconds": secs, "remesh_wall": wall,
           "seconds_select": rem["seconds_select"], "seconds_splice": rem["seconds_splice"]}
    row["share"] = row["remesh_seconds"] / row["mesh_seconds"]
    print(json.dumps(row))
    return [row]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--biotet")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--fine-size", type=float, default=1.7, help="--size of the fine mesh (above 1M tets)")
    ap.add_argument("--fine-repeat", type=int, default=1)
    ap.add_argument("--skip-fine", action="store_true")
    ap.add_argument("--skip-default", action="store_true")
    ap.add_argument("--cost-only", action="store_true",
                    help="only the 1%% zone against meshing the whole model at --fine-size, --repeat runs each")
    ap.add_argument("--no-mmg", action="store_true")
    ap.add_argument("--json")
    a = ap.parse_args()
    exe = find_biotet(a.biotet)
    require(exe)
    mmg = None if a.no_mmg else mmg3d()
    if not mmg and not a.no_mmg:
        print("mmg3d not found (pip install pymmg); MMG skipped", file=sys.stderr)
    tmp = tempfile.mkdtemp(prefix="bench_remesh_")
    try:
        if a.cost_only:
            rows = cost(exe, tmp, a.fine_size, a.repeat)
            if a.json:
                with open(a.json, "w") as f:
                    json.dump(rows, f, indent=2)
            return
        rows = [] if a.skip_default else bench_mesh(exe, mmg, tmp, "default", [], a.repeat, None)
        if not a.skip_fine:
            rows += bench_mesh(exe, mmg, tmp, "fine", ["--size", str(a.fine_size)], a.fine_repeat, a.fine_size)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"{'mesh':<8} {'case':<52} {'tool':<7} {'s':>8} {'removed':>8} {'added':>9} "
          f"{'new min°':>8} {'new <10°':>8} {'all min°':>8} {'all <10°':>8} valid")
    for r in rows:
        if "new" not in r:
            print(f"{r['mesh']:<8} {r['case']:<52} {r.get('tool', ''):<7} {r['seconds']:>8.3f} "
                  f"{r.get('tets', '')!s:>8} {r.get('message', r.get('error', ''))}")
            continue
        print(f"{r['mesh']:<8} {r['case']:<52} {r['tool']:<7} {r['seconds']:>8.3f} {r['removed']:>8} {r['added']:>9} "
              f"{r['new']['min_dihedral'] or 0:>8.2f} {r['new']['lt10']:>8} {r['whole']['min_dihedral']:>8.2f} "
              f"{r['whole']['lt10']:>8} {r['valid']}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=2)


if __name__ == "__main__":
    main()
