"""`scripts/compare.py --tolerance D[,D...]`: meshers that may move the surface, each within a distance D, side by
side in one run (the surface-tolerance issue's comparison).

    pip install tetgen pytetwild pymmg pyacvd pyvista meshio numpy matplotlib
    cargo build --release -p biotet-cli
    python3 scripts/compare.py --tolerance 0.25,0.5,1.0 [SURFACE ...] [--svg docs/compare_tolerance.svg]

Default surfaces: tests/data/brain_20k.stl, wm_20k.stl and the nested model nested_brain_wm_20k.stl. Tools, each at
every D, each in a child process:
  biotet       `biotet mesh SURFACE --surface-tolerance D` (the surface stage, then the pipeline with the improved
               surface kept). Seconds: the stage's plus the pipeline's, from its --json.
  mmg          TetGen `pq1.2YA` on the raw surface (regions labelled), then MMG3D `mmg3d -hausd D` on that mesh
               (surface remeshing allowed, MMG's defaults otherwise). Seconds: TetGen's meshing plus MMG's process.
  ftetwild     fTetWild (pytetwild) with its envelope set to D (epsilon = D / bounding-box diagonal), its default
               edge length, one thread.
  acvd+tetgen  The surface remeshed by pyacvd to as many points as the input, then TetGen `pq1.2YA`: a smoother
               surface with no distance bound; it does not depend on D and runs once per surface.

The distance is measured on each mesh's boundary and the faces between its labels: a mesher that does not keep a
nested model's interface as faces between two labels (fTetWild fills the outer shell as one region) is measured
without it, and its input → output distance is then the inner shell's distance to the outer boundary.

Every output is measured by one routine: `biotet quality OUT --surface SURFACE --distance --json` (tets, dihedral
angles, tets under 10° and 5°, and the two-sided distance between the mesh's boundary and interface faces and the
input surface, sampled with a Lipschitz bound, the same way for every tool) and the volume the mesh encloses against
the input's (`biotet validate --json`). Peak MB is the whole child process (/usr/bin/time, or the Python child's own).
"""
import json, os, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib  # noqa: E402
from benchlib import ROOT, biotet_json, run_binary, run_child  # noqa: E402

DEFAULT_SURFACES = [os.path.join(ROOT, "tests", "data", n)
                    for n in ("brain_20k.stl", "wm_20k.stl", "nested_brain_wm_20k.stl")]
TOOLS = {"biotet": "biotet mesh --surface-tolerance D", "mmg": "TetGen `pq1.2YA` + MMG3D `-hausd D`",
         "ftetwild": "fTetWild, envelope D", "acvd+tetgen": "pyacvd + TetGen `pq1.2YA` (no bound)"}


def input_volume(exe, surface):
    """The volume the input's shells enclose (every region's, summed)."""
    j = biotet_json(exe, "validate", surface, ok=(0,))
    return sum(r["volume"] for f in j["surfaces"] for r in f["report"]["regions"])


def measure(exe, mesh, surface, vin):
    """Quality, distance and volume of a tet mesh by one routine for every tool."""
    q = biotet_json(exe, "quality", mesh, "--surface", surface, "--distance", ok=(0,))
    d = q["surface_distance"]
    vol = sum(r["volume"] for r in q.get("regions") or [])
    return {"tets": q["n_tets"], "min_dihedral": q["min_dihedral_deg"], "max_dihedral": q["max_dihedral_deg"],
            "lt10": q["n_dihedral_lt_10"], "lt5": q["n_dihedral_lt_5"], "h_in_out": d["in_to_out"],
            "h_out_in": d["out_to_in"], "h_bound": d["bound"], "volume_change": (vol - vin) / vin,
            "dihedral_histogram": q.get("dihedral_histogram"),
            "min_dihedral_histogram": q.get("min_dihedral_histogram")}


def run_tool(exe, tool, surface, d, tmp, n_points):
    """Mesh `surface` with `tool` at tolerance `d`: (output mesh, seconds, wall, peak kB, note)."""
    path = lambda name: os.path.join(tmp, name)  # noqa: E731
    if tool == "biotet":
        out = path("biotet.vtu")
        wall, peak, r = run_binary([exe, "mesh", surface, "--surface-tolerance", repr(d), "-o", out, "--json"])
        if r.returncode != 0:
            raise RuntimeError((r.stderr or r.stdout).strip().splitlines()[-1][:200])
        j = json.loads(r.stdout)
        seconds = j["surface"]["seconds"] + j["pipeline"]["seconds_total"] + j.get("seconds_sizing", 0.0)
        return out, seconds, wall, peak, ""
    if tool == "mmg":
        base = path("tetgen")
        # `A`: each region labelled, so a nested model's interface is measured as one.
        t = run_child("tetgen", surface, base, switches="pq1.2YA")
        src, out = path("mmg_input.mesh"), path("mmg.mesh")
        biotet_json(exe, "convert", base + ".node", "-o", src, ok=(0,))
        wall, peak, r = run_binary([benchlib.mmg3d(), "-in", src, "-out", out, "-hausd", repr(d), "-v", "-1"])
        if r.returncode != 0:
            raise RuntimeError(f"mmg3d: {(r.stderr or r.stdout).strip()[-200:]}")
        return out, t["seconds"] + wall, t["wall"] + wall, peak, f"TetGen {t['seconds']:.2f} s + MMG {wall:.2f} s"
    if tool == "ftetwild":
        base = path("ftetwild")
        j = run_child("ftetwild", surface, base, threads=1, envelope=d)
        return base + ".node", j["seconds"], j["wall"], j["peak_rss_kb"], ""
    if tool == "acvd+tetgen":
        base = path("acvd")
        j = run_child("acvd_tetgen", surface, base, points=n_points, switches="pq1.2YA")
        return base + ".node", j["seconds"], j["wall"], j["peak_rss_kb"], f"{n_points} points"
    raise ValueError(tool)


fmt = benchlib.cell


def table(rows):
    lines = ["| surface | D | tool | seconds | peak MB | tets | min / max dihedral | <10° | <5° | "
             "Hausdorff in→out / out→in (bound) | volume change |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"| {r['surface']} | {r['d']} | {r['label']} | {r['note']} | | | | | | | |")
            continue
        lines.append(
            f"| {r['surface']} | {r['d']} | {r['label']} | {fmt(r['seconds'], '.2f')} | "
            f"{fmt(r['peak_kb'] and r['peak_kb'] / 1024, '.0f')} | {r['tets']:,} | "
            f"{r['min_dihedral']:.2f}° / {r['max_dihedral']:.2f}° | {r['lt10']:,} | {r['lt5']:,} | "
            f"{r['h_in_out']:.3f} / {r['h_out_in']:.3f} ({r['h_bound']:.3f}) | {100 * r['volume_change']:+.2f}% |")
    return "\n".join(lines)


def main(exe, surfaces, tolerances, tools, svg=None, json_out=None, command=""):
    """Run every tool on every surface at every tolerance; print the markdown table; optionally the figure."""
    surfaces = surfaces or DEFAULT_SURFACES
    rows = []
    with tempfile.TemporaryDirectory(prefix="compare_tol_") as tmp:
        for surface in surfaces:
            surface = os.path.abspath(surface)
            name = os.path.basename(surface)
            vin = input_volume(exe, surface)
            n_points = len(benchlib.read_surface(surface)[0])
            for d in tolerances:
                for tool in tools:
                    if tool == "acvd+tetgen" and d != tolerances[0]:
                        continue  # no tolerance: once per surface
                    row = {"surface": name, "d": "–" if tool == "acvd+tetgen" else d, "tool": tool,
                           "label": TOOLS[tool], "status": "ok", "note": ""}
                    print(f"{name} D={d}: {tool} ...", file=sys.stderr, flush=True)
                    try:
                        out, seconds, wall, peak, note = run_tool(exe, tool, surface, d, tmp, n_points)
                        row.update(seconds=seconds, wall=wall, peak_kb=peak, note=note,
                                   **measure(exe, out, surface, vin))
                    except Exception as e:  # an anchor's failure is a row of the table, not fatal
                        msg = str(e).strip().splitlines()[-1][:200] if str(e).strip() else type(e).__name__
                        row.update(status="failed", note=f"failed: {msg}")
                        print(f"{name} D={d}: {tool} failed: {msg}", file=sys.stderr)
                    rows.append(row)
    block = "\n".join([f"`{command}`", "", table(rows)])
    print(block)
    if json_out:
        with open(json_out, "w") as f:
            json.dump(rows, f, indent=1)
    if svg:
        import compare
        fig_rows = [dict(r, surface=f"{r['surface']} D={r['d']}") for r in rows if r["tool"] != "acvd+tetgen"]
        for r in rows:  # the bound-free route beside every D
            if r["tool"] == "acvd+tetgen":
                fig_rows += [dict(r, surface=f"{r['surface']} D={d}") for d in tolerances]
        compare.write_svg(svg, fig_rows)
    return rows
