#!/usr/bin/env python3
"""Shared pieces of the benchmark scripts (bench_mesh.py, bench_smooth.py, compare.py).

- Finding and calling the biotet binary (`find_biotet`, `biotet_json`) and measuring any tool's output with one routine
  (`measure`: `biotet quality --surface --json` and `biotet check --surface --json`).
- The Python mesher children: every Python tool runs in its own process so that its peak RSS is its own. Run as

      python3 scripts/benchlib.py TOOL SURFACE OUT_BASE [JSON_OPTIONS]

  with TOOL one of `tetgen` (pip `tetgen`, options `{"switches": "pq1.2Y"}`), `gmsh` (3D Delaunay inside the surface,
  kept as it is) or `ftetwild` (`pytetwild`). The child reads the surface (STL points welded exactly, as biotet
  does), imports the tool, resets its peak RSS, times the meshing call alone, writes OUT_BASE.node/.ele (coordinates printed with Python's
  shortest round-trip repr, so points on the surface stay bit-identical) and prints one JSON line:
  `{"seconds", "rss_before_kb", "peak_rss_kb"}`.
- Binaries run under /usr/bin/time for their peak RSS (`run_binary`); `mmg3d` finds MMG's binary from `pymmg`.
"""
import json, os, re, resource, shutil, statistics, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HERE = os.path.abspath(__file__)


# ---------------------------------------------------------------------------------------------------------------------
# biotet


def find_biotet(path=None):
    """The biotet binary: PATH if given, else $BIOTET, else $CARGO_TARGET_DIR/release/biotet, else
    target/release/biotet under the repository root."""
    if path:
        return os.path.abspath(path)
    if os.environ.get("BIOTET"):
        return os.environ["BIOTET"]
    target = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
    return os.path.join(target, "release", "biotet")


def require(exe, hint="cargo build --release -p biotet-cli"):
    """Exit with a clear message when the biotet binary is missing."""
    if not os.path.exists(exe):
        sys.exit(f"{exe} not found: {hint}")


def biotet_json(exe, *args, ok=(0, 1)):
    """Run `biotet ARGS --json` and return its JSON object (exit 1, an invalid mesh, still reports)."""
    r = subprocess.run([exe, *args, "--json"], capture_output=True, text=True)
    if r.returncode not in ok or not r.stdout.strip():
        raise RuntimeError(f"biotet {' '.join(map(str, args))}: {r.stderr.strip() or r.stdout.strip()}")
    return json.loads(r.stdout)


def measure(exe, mesh, surface):
    """Quality of a tet mesh by one routine for every tool: biotet's `quality` with the placement split and forcing
    against `surface`, and `check --surface` for validity and the input triangles missing from the mesh."""
    q = biotet_json(exe, "quality", mesh, "--surface", surface, ok=(0,))
    c = biotet_json(exe, "check", mesh, "--surface", surface)
    conf = c.get("surface") or {}
    place = q.get("placement") or {}
    row = {
        "points": q["n_points"], "tets": q["n_tets"],
        "min_dihedral": q["min_dihedral_deg"], "max_dihedral": q["max_dihedral_deg"],
        "min_solid_sr": q["min_solid_angle_sr"], "mean_q": q["mean_q"],
        "lt5": q["n_dihedral_lt_5"], "lt10": q["n_dihedral_lt_10"], "lt20": q["n_dihedral_lt_20"],
        "missing": conf["n_triangles"] - conf["n_found"] if conf else None,
        "valid": c.get("valid"),
        "forced": q.get("n_forced"), "unforced_lt10": q.get("n_unforced_dihedral_lt_10"),
        "unforced_cause": (q.get("forcing") or {}).get("unforced_lt_10_by_cause"),
    }
    for cls in ("face", "vertex", "interior"):
        p = place.get(cls) or {}
        row[f"{cls}_tets"] = p.get("n_tets")
        row[f"{cls}_lt10"] = p.get("n_dihedral_lt_10")
        row[f"{cls}_min_dihedral"] = p.get("min_dihedral_deg")
        row[f"{cls}_mean_q"] = p.get("mean_q")
    row["dihedral_histogram"] = q.get("dihedral_histogram")
    row["min_dihedral_histogram"] = q.get("min_dihedral_histogram")
    return row


# ---------------------------------------------------------------------------------------------------------------------
# processes


def rss_kb():
    """This process's resident set size now (kB, Linux)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS"):
                return int(line.split()[1])
    return None


def reset_peak_rss():
    """Reset this process's peak RSS to its current RSS (Linux `clear_refs`); False where that is not possible."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def peak_rss_kb():
    """This process's peak resident set size (kB): VmHWM, which `reset_peak_rss` resets, else the rusage peak."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM"):
                return int(line.split()[1])
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def run_child(tool, surface, base, **options):
    """Run one Python mesher child (see the module doc) in the directory of `base`; returns its JSON with `wall`
    (process seconds) added."""
    # In the output's directory: fTetWild leaves a __tracked_surface.stl in its working directory.
    surface, base = os.path.abspath(surface), os.path.abspath(base)
    start = time.perf_counter()
    r = subprocess.run([sys.executable, HERE, tool, surface, base, json.dumps(options)],
                       capture_output=True, text=True, cwd=os.path.dirname(base))
    wall = time.perf_counter() - start
    if r.returncode != 0:
        raise RuntimeError(f"{tool}: {(r.stderr.strip().splitlines() or ['exit %d' % r.returncode])[-1]}")
    out = json.loads(r.stdout.strip().splitlines()[-1])
    out["wall"] = wall
    return out


def run_binary(args):
    """Run a binary under /usr/bin/time (when present) for its peak RSS; returns (wall seconds, peak kB, result)."""
    timer = shutil.which("time") or ("/usr/bin/time" if os.path.exists("/usr/bin/time") else None)
    cmd = [timer, "-f", "PEAK %M", *args] if timer else list(args)
    start = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    peak = re.search(r"PEAK (\d+)", r.stderr or "")
    return wall, int(peak.group(1)) if peak else None, r


def mmg3d():
    """The mmg3d binary: pymmg installs mmg3d_O3 inside its package (`mmg3d`) and a wrapper on PATH."""
    try:
        import mmg3d as pkg  # pymmg's package
        exe = os.path.join(os.path.dirname(pkg.__file__), "mmg3d_O3")
        if os.path.exists(exe):
            return exe
    except ImportError:
        pass
    return shutil.which("mmg3d_O3") or shutil.which("mmg3d")


def cgal_mesh3():
    """CGAL Mesh_3's driver (scripts/cgal/mesh3.cpp), built on first use into $CARGO_TARGET_DIR (or target/)/cgal
    with g++ against Debian's libcgal-dev; None (and why, on stderr) when it cannot be built here."""
    target = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
    exe = os.path.join(target, "cgal", "mesh3")
    src = os.path.join(ROOT, "scripts", "cgal", "mesh3.cpp")
    if os.path.exists(exe) and os.path.getmtime(exe) >= os.path.getmtime(src):
        return exe
    if not (os.path.isdir("/usr/include/CGAL") and shutil.which("g++")):
        return None
    os.makedirs(os.path.dirname(exe), exist_ok=True)
    r = subprocess.run(["g++", "-O2", "-DNDEBUG", "-std=c++17", src, "-o", exe, "-lgmp", "-lmpfr"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        print(f"building {src} failed: {r.stderr.strip()[-500:]}", file=sys.stderr)
        return None
    return exe


def cell(v, spec=","):
    """A markdown table cell: '–' for a missing value (None or ''), else `format(v, spec)` (thousands separators
    by default)."""
    return "–" if v is None or v == "" else format(v, spec)


def median(rows, key):
    """Median of `key` over the rows that have it (None if none has)."""
    vals = [r[key] for r in rows if r.get(key) is not None]
    return statistics.median(vals) if vals else None


# ---------------------------------------------------------------------------------------------------------------------
# the children


def read_surface(path):
    """Points and triangles of a surface file (meshio), exactly equal points welded as every mesher does."""
    import numpy as np, meshio
    m = meshio.read(path)
    p = np.asarray(m.points, dtype=float)
    t = np.asarray(m.cells_dict["triangle"], dtype=np.int64)
    p, inv = np.unique(p, axis=0, return_inverse=True)
    return p, inv.reshape(-1)[t].astype(np.int32)


def write_node_ele(base, points, tets, labels=None):
    """TetGen .node/.ele (0-based), coordinates with the shortest repr that reads back to the same double; `labels`
    (one per tet) become the .ele's region attribute."""
    with open(base + ".node", "w") as f:
        f.write(f"{len(points)} 3 0 0\n")
        f.writelines(f"{i} {float(q[0])!r} {float(q[1])!r} {float(q[2])!r}\n" for i, q in enumerate(points))
    with open(base + ".ele", "w") as f:
        if labels is None:
            f.write(f"{len(tets)} 4 0\n")
            f.writelines(f"{i} {e[0]} {e[1]} {e[2]} {e[3]}\n" for i, e in enumerate(tets))
        else:
            f.write(f"{len(tets)} 4 1\n")
            f.writelines(f"{i} {e[0]} {e[1]} {e[2]} {e[3]} {int(a)}\n" for i, (e, a) in enumerate(zip(tets, labels)))


def read_node(path):
    """Points of a TetGen .node file (3D, any first index) as an (n, 3) array, in file order."""
    import numpy as np
    with open(path) as f:
        rows = [line.split("#")[0].split() for line in f]
    rows = [r for r in rows if r]
    n = int(rows[0][0])
    return np.array([[float(x) for x in r[1:4]] for r in rows[1:1 + n]])


def snap_to_surface(points, surface_points, rel_tol=1e-9):
    """Move every point within rel_tol x (bounding-box diagonal) of a surface point onto it exactly; returns the new
    points and how many moved. For tools that keep the surface but print or rescale coordinates with round-off (MMG
    writes 15 digits after scaling the mesh to a unit box), so that `biotet check --surface` matches their surface
    points; a point farther away than the tolerance is left as the tool wrote it."""
    import numpy as np
    sp = np.asarray(surface_points, dtype=float)
    tol = rel_tol * float(np.linalg.norm(sp.max(axis=0) - sp.min(axis=0)))
    cells = {}
    for i, key in enumerate(map(tuple, np.floor(sp / tol).astype(np.int64))):
        cells.setdefault(key, []).append(i)
    out = np.array(points, dtype=float)
    moved = 0
    offsets = [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)]
    for k, key in enumerate(map(tuple, np.floor(out / tol).astype(np.int64))):
        best, best_d = None, tol
        for o in offsets:
            for i in cells.get((key[0] + o[0], key[1] + o[1], key[2] + o[2]), ()):
                d = float(np.max(np.abs(sp[i] - out[k])))
                if d <= best_d:
                    best, best_d = i, d
        if best is not None and not np.array_equal(out[k], sp[best]):
            out[k] = sp[best]
            moved += 1
    return out, moved


def mesh_tetgen(p, t, opts):
    """TetGen (pip `tetgen`) with `switches`."""
    import tetgen
    g = tetgen.TetGen(p, t)
    return tetgen_result(g.tetrahedralize(switches=opts.get("switches", "pq1.2Y")))


def tetgen_result(res):
    """pip TetGen's (nodes, tets, attributes, ...) as (nodes, tets) or, with region attributes (`A`), (nodes, tets,
    labels)."""
    import numpy as np
    attrib = res[2] if len(res) > 2 else None
    if attrib is not None and len(attrib) == len(res[1]):
        return res[0], res[1], np.asarray(attrib).reshape(len(res[1]), -1)[:, 0]
    return res[0], res[1]


def mesh_gmsh(p, t, opts):
    """Gmsh's 3D Delaunay inside the surface, kept: the triangles become a discrete surface, a volume (its surface
    loop) is bounded by it and meshed in 3D without touching the surface mesh (no reparametrisation, no remeshing). Interior
    sizes come from the surface's edges (Gmsh's default size from the boundary), capped at `size_max` if given.
    Gmsh's default optimisation of the 3D mesh stays on."""
    import numpy as np, gmsh
    gmsh.initialize(["-noenv"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay
        gmsh.option.setNumber("Mesh.MaxNumThreads3D", 1)
        if opts.get("size_max"):
            gmsh.option.setNumber("Mesh.MeshSizeMax", float(opts["size_max"]))
        gmsh.model.add("surface")
        s = gmsh.model.addDiscreteEntity(2)
        tags = np.arange(1, len(p) + 1, dtype=np.uint64)
        gmsh.model.mesh.addNodes(2, s, tags, p.reshape(-1).tolist())
        gmsh.model.mesh.addElementsByType(s, 2, [], (t.reshape(-1) + 1).tolist())
        # A discrete volume counts as already meshed: bound a geometric volume by the discrete surface instead.
        gmsh.model.geo.addVolume([gmsh.model.geo.addSurfaceLoop([s])])
        gmsh.model.geo.synchronize()
        gmsh.model.mesh.generate(3)
        node_tags, coords, _ = gmsh.model.mesh.getNodes()
        _, elem_nodes = gmsh.model.mesh.getElementsByType(4)
        index = np.zeros(int(node_tags.max()) + 1, dtype=np.int64)
        index[node_tags.astype(np.int64)] = np.arange(len(node_tags))
        return np.asarray(coords).reshape(-1, 3), index[np.asarray(elem_nodes, dtype=np.int64)].reshape(-1, 4)
    finally:
        gmsh.finalize()


def mesh_ftetwild(p, t, opts):
    """fTetWild through `pytetwild` (the surface is approximated within its envelope), single-threaded unless
    `threads` is given; `edge_length` is the ideal edge length (fTetWild's default: bounding-box diagonal / 20)."""
    import pytetwild
    kw = {"num_threads": int(opts.get("threads", 1)), "quiet": True}
    if opts.get("edge_length"):
        kw["edge_length_abs"] = float(opts["edge_length"])
    if opts.get("envelope"):
        # fTetWild's envelope is relative to the bounding-box diagonal.
        import numpy as np
        diag = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))
        kw["epsilon"] = float(opts["envelope"]) / diag
    return pytetwild.tetrahedralize(p, t, **kw)


def mesh_acvd_tetgen(p, t, opts):
    """The surface remeshed by pyacvd (Voronoi clustering into `points` points, after subdividing each triangle into
    nine), then TetGen `pq1.2Y` on it: the route users take to a better surface without a distance bound."""
    import numpy as np, pyvista as pv, pyacvd, tetgen
    faces = np.hstack([np.full((len(t), 1), 3), t]).astype(np.int64).ravel()
    c = pyacvd.Clustering(pv.PolyData(p, faces))
    c.subdivide(3)
    c.cluster(int(opts["points"]))
    m = c.create_mesh()
    q = np.asarray(m.points, dtype=float)
    f = np.asarray(m.faces).reshape(-1, 4)[:, 1:]
    g = tetgen.TetGen(q, f)
    return tetgen_result(g.tetrahedralize(switches=opts.get("switches", "pq1.2Y")))


# tool -> (meshing function, the Python module it needs)
CHILDREN = {"tetgen": (mesh_tetgen, "tetgen"), "gmsh": (mesh_gmsh, "gmsh"), "ftetwild": (mesh_ftetwild, "pytetwild"),
            "acvd_tetgen": (mesh_acvd_tetgen, "pyacvd")}


def child_main(argv):
    """One meshing in this process: the surface read and the tool's module imported first, the peak RSS reset, then
    only the meshing call timed and its memory measured."""
    import importlib
    tool, surface, base = argv[:3]
    opts = json.loads(argv[3]) if len(argv) > 3 else {}
    func, module = CHILDREN[tool]
    importlib.import_module(module)
    p, t = read_surface(surface)
    reset_peak_rss()
    before = rss_kb()
    start = time.perf_counter()
    points, tets, *labels = func(p, t, opts)
    seconds = time.perf_counter() - start
    peak = peak_rss_kb()
    write_node_ele(base, points, tets, labels[0] if labels else None)
    print(json.dumps({"seconds": seconds, "rss_before_kb": before, "peak_rss_kb": peak}))


if __name__ == "__main__":
    if len(sys.argv) < 4 or sys.argv[1] not in CHILDREN:
        sys.exit(__doc__)
    child_main(sys.argv[1:])
