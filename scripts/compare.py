#!/usr/bin/env python3
"""How biotet compares: biotet `mesh` beside TetGen, Gmsh, fTetWild and MMG on the same closed surfaces, in one run.

Installs nothing. The anchors come from PyPI (each is skipped, and said so, when it is missing):

    pip install tetgen gmsh pytetwild meshio trimesh   # meshio (and numpy) are needed by every Python anchor
    pip install pymmg                                  # MMG: ships the mmg3d_O3 binary
    pip install matplotlib                             # only for --svg
    pip install pyacvd pyvista                         # only for --tolerance (pyacvd + TetGen)
    cargo build --release -p biotet-cli
    python3 scripts/compare.py [SURFACE ...] [--repeat 3] [--svg docs/compare.svg] [--csv compare.csv]

(pytetwild 0.4 imports pyvista at import time without declaring it: `pip install pyvista` too if it complains.)

(CGAL: `apt install libcgal-dev g++`. TetGen's own command line: `apt install tetgen`.)

Tools, each on every surface (default: the real surfaces bundled in tests/data, brain_20k.stl and wm_20k.stl):
  biotet        `biotet mesh SURFACE` with its default options (the full pipeline; surface kept exactly)
  tetgen        TetGen 1.6 (pip `tetgen`) `pq1.2Y`: quality refinement, surface kept (no point added on it)
  tetgen-O      TetGen `pq1.2YO`, with its mesh optimisation
  tetgen-cli    TetGen's command line (`tetgen -pq1.2YQ`, Debian's build of 1.5.0) on the surface written as OFF by
                `biotet convert`; faster than the wheel on the brain models (brain_20k 0.66 s as a whole process,
                against 0.82 s for the wheel's meshing call alone), and it adds more points
  gmsh          Gmsh's 3D Delaunay (Mesh.Algorithm3D = 1) in a volume bounded by the surface as a discrete surface,
                which is kept as it is (no reparametrisation, no remeshing); interior sizes from the surface's
                edges (Gmsh's default), Gmsh's default 3D optimisation, one thread
  ftetwild      fTetWild through pytetwild, its default ideal edge length (bounding-box diagonal / 20), one thread:
                the surface is approximated within fTetWild's envelope, not kept
  cgal          CGAL 5.5 Mesh_3 (scripts/cgal/mesh3.cpp, built on first use with g++ against Debian's libcgal-dev): the
                surface as a polyhedral domain with its sharp edges protected, every size the mean input edge, facet
                distance an eighth of it, perturb and exude; the surface is resampled, not kept
  mmg           MMG3D `-optim -nosurf` on the TetGen `pq1.2Y` mesh (surface untouched); MMG rescales the mesh to a
                unit box and writes 15 digits, so its points within 1e-9 of the bounding-box diagonal of an input
                point are snapped back onto it before measuring (the count is in the notes)

Every tool runs in a child process, `--repeat` times; the table gives medians. `seconds` is the meshing alone: biotet's
sizing and pipeline seconds from its --json (reading and writing excluded), the Python anchors' meshing call timed inside the
child, MMG's and TetGen's command line's process wall time (their reading and writing included). `wall` is the child process's wall time.
`peak MB` is the peak RSS during meshing minus the RSS before it (biotet and the Python children reset the peak after
reading the surface); for MMG it is the whole process's peak (/usr/bin/time).

Quality comes from ONE routine for every output, never from a tool's own report: `biotet quality --surface S --json`
(points, tets, dihedral and solid angles, q, tets below 5/10/20 degrees, and the split by placement: tets with an input
triangle as a face, touching the surface at points only, interior; tets forced poor by the input, a face that is an
input triangle with an angle under 10 degrees or an input edge where the surface folds under 10 degrees) and
`biotet check --surface S --json` (validity, input triangles missing from the mesh). Placement is by exact
coordinates, so for fTetWild, which moves the surface, nearly every tet counts as interior.

With `--tolerance D[,D...]` the run is the surface-tolerance comparison instead (scripts/compare_tolerance.py: biotet
`--surface-tolerance D` beside MMG `-hausd D`, fTetWild with its envelope D, and pyacvd + TetGen), on brain_20k, wm_20k
and the nested model by default; `--tools` then picks among biotet, mmg, ftetwild, acvd+tetgen.

Outputs: the markdown tables on stdout (with the command, the machine and the ratios to TetGen `pq1.2Y` measured in
the same run), a CSV (--csv), the same markdown block in a file (--markdown) or in place of the block between
`<!-- compare:begin -->` and `<!-- compare:end -->` of a file (--update-readme README.md), and with --svg the
dihedral-angle histograms of all tools overlaid (matplotlib).
"""
import argparse, csv, importlib.util, json, os, platform, shutil, sys, tempfile, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib  # noqa: E402
from benchlib import ROOT, biotet_json, measure, median, run_binary, run_child  # noqa: E402

DEFAULT_SURFACES = [os.path.join(ROOT, "tests", "data", n) for n in ("brain_20k.stl", "wm_20k.stl")]

# key -> (table label, Python modules needed)
TOOLS = {
    "biotet": ("biotet mesh (defaults)", []),
    "tetgen": ("TetGen 1.6 `pq1.2Y`", ["numpy", "meshio", "tetgen"]),
    "tetgen-O": ("TetGen 1.6 `pq1.2YO`", ["numpy", "meshio", "tetgen"]),
    "tetgen-cli": ("TetGen command line `-pq1.2Y`", []),
    "gmsh": ("Gmsh 3D Delaunay (surface kept)", ["numpy", "meshio", "gmsh"]),
    "ftetwild": ("fTetWild (pytetwild)", ["numpy", "meshio", "pytetwild"]),
    "mmg": ("MMG3D `-optim -nosurf` on TetGen `pq1.2Y`", ["numpy", "meshio", "tetgen"]),
    "cgal": ("CGAL 5.5 Mesh_3 (features protected)", []),
}
BEGIN, END = "<!-- compare:begin -->", "<!-- compare:end -->"

CSV_COLUMNS = ["surface", "tool", "status", "seconds", "wall", "peak_mb", "points", "tets", "min_dihedral",
               "max_dihedral", "min_solid_sr", "mean_q", "lt5", "lt10", "lt20", "missing", "valid", "forced",
               "unforced_lt10", "face_tets", "face_lt10", "face_min_dihedral", "face_mean_q", "vertex_tets",
               "vertex_lt10", "vertex_min_dihedral", "vertex_mean_q", "interior_tets", "interior_lt10",
               "interior_min_dihedral", "interior_mean_q", "note"]


def missing_requirement(tool):
    """Why `tool` cannot run here (a missing module or binary), or None."""
    for m in TOOLS[tool][1]:
        if importlib.util.find_spec(m) is None:
            return f"Python module `{m}` not installed"
    if tool == "tetgen-cli" and not shutil.which("tetgen"):
        return "the tetgen command not found (apt install tetgen)"
    if tool == "mmg" and not benchlib.mmg3d():
        return "mmg3d not found (pip install pymmg)"
    if tool == "cgal" and not benchlib.cgal_mesh3():
        return "CGAL's driver could not be built (apt install libcgal-dev g++)"
    return None


class Runner:
    """Runs the tools on one surface in a scratch directory and measures their outputs."""

    def __init__(self, biotet, surface, tmp, repeat, ftetwild_threads):
        self.biotet, self.surface, self.tmp, self.repeat = biotet, surface, tmp, repeat
        self.ftetwild_threads = ftetwild_threads
        self.tetgen_base = None  # the TetGen pq1.2Y mesh, MMG's input

    def path(self, name):
        """A file in the scratch directory."""
        return os.path.join(self.tmp, name)

    def biotet_mesh(self):
        """`biotet mesh` with its defaults; seconds and memory from its --json (reading excluded)."""
        out, rows = self.path("biotet.vtu"), []
        for _ in range(self.repeat):
            start = time.perf_counter()
            j = biotet_json(self.biotet, "mesh", self.surface, "-o", out, ok=(0,))
            rows.append({"seconds": j["pipeline"]["seconds_total"] + j.get("seconds_sizing", 0.0), "wall": time.perf_counter() - start,
                         "kb": j["peak_rss_kb"] - j["rss_before_kb"]})
        return out, rows, ""

    def child(self, tool, base, **opts):
        """A Python mesher child `--repeat` times; its output is base.node/.ele."""
        rows = []
        for _ in range(self.repeat):
            j = run_child(tool, self.surface, base, **opts)
            rows.append({"seconds": j["seconds"], "wall": j["wall"], "kb": j["peak_rss_kb"] - j["rss_before_kb"]})
        return base + ".node", rows

    def tetgen(self, switches):
        """pip TetGen with `switches`; the `pq1.2Y` mesh is kept as MMG's input."""
        base = self.path("tetgen_" + switches)
        out, rows = self.child("tetgen", base, switches=switches)
        if switches == "pq1.2Y":
            self.tetgen_base = base
        return out, rows, ""

    def tetgen_cli(self):
        """TetGen's own command line (`tetgen -pq1.2YQ`, Debian's build) on the surface as OFF; its seconds are
        the whole process's, reading and writing its .node/.ele/.face/.edge included."""
        off = self.path("tetgen_cli.off")
        biotet_json(self.biotet, "convert", self.surface, "-o", off, ok=(0,))
        rows = []
        for _ in range(self.repeat):
            wall, peak, r = run_binary([shutil.which("tetgen"), "-pq1.2YQ", off])
            if r.returncode != 0:
                raise RuntimeError(f"tetgen: {(r.stderr or r.stdout).strip()[-300:]}")
            rows.append({"seconds": wall, "wall": wall, "kb": peak})
        return self.path("tetgen_cli.1.node"), rows, "whole process (reading and writing included)"

    def gmsh(self):
        """Gmsh's 3D Delaunay inside the kept surface."""
        return (*self.child("gmsh", self.path("gmsh")), "")

    def ftetwild(self):
        """fTetWild through pytetwild."""
        out, rows = self.child("ftetwild", self.path("ftetwild"), threads=self.ftetwild_threads)
        return out, rows, "surface approximated (not kept)"

    def mmg(self):
        """MMG3D `-optim -nosurf` on the TetGen `pq1.2Y` mesh (made here if the tetgen tool did not run)."""
        if self.tetgen_base is None:
            self.tetgen_base = self.path("tetgen_pq1.2Y")
            run_child("tetgen", self.surface, self.tetgen_base, switches="pq1.2Y")
        src, out = self.path("mmg_input.mesh"), self.path("mmg.mesh")
        biotet_json(self.biotet, "convert", self.tetgen_base + ".node", "-o", src, ok=(0,))
        rows = []
        for _ in range(self.repeat):
            wall, peak, r = run_binary([benchlib.mmg3d(), "-in", src, "-out", out, "-optim", "-nosurf", "-v", "-1"])
            if r.returncode != 0:
                raise RuntimeError(f"mmg3d: {(r.stderr or r.stdout).strip()[-300:]}")
            rows.append({"seconds": wall, "wall": wall, "kb": peak})
        # Back onto the input's exact surface points (see the module doc), as .node/.ele.
        raw = self.path("mmg_raw")
        biotet_json(self.biotet, "convert", out, "-o", raw + ".node", ok=(0,))
        p, _ = benchlib.read_surface(self.surface)
        points, moved = benchlib.snap_to_surface(benchlib.read_node(raw + ".node"), p)
        final = self.path("mmg_snapped")
        shutil.copyfile(raw + ".ele", final + ".ele")
        write_node_like(raw + ".node", final + ".node", points)
        return final + ".node", rows, f"{moved} points snapped onto the input surface"

    def cgal(self):
        """CGAL Mesh_3 on the surface as a polyhedral domain with its sharp edges protected: every size the mean
        input edge, facet distance an eighth of it, facet angle 25°, radius-edge ratio 3, perturb and exude."""
        off = self.path("cgal_input.off")
        biotet_json(self.biotet, "convert", self.surface, "-o", off, ok=(0,))
        p, t = benchlib.read_surface(self.surface)
        import numpy as np
        e = np.concatenate([p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 1]], p[t[:, 0]] - p[t[:, 2]]])
        h = float(np.linalg.norm(e, axis=1).mean())
        out, rows = self.path("cgal.mesh"), []
        for _ in range(self.repeat):
            wall, peak, r = run_binary([benchlib.cgal_mesh3(), "surface", off, out, repr(h), repr(h), repr(h / 8), repr(h)])
            if r.returncode != 0:
                raise RuntimeError(f"mesh3: {(r.stderr or r.stdout).strip()[-300:]}")
            j = json.loads(r.stdout.strip().splitlines()[-1])
            rows.append({"seconds": j["seconds"], "wall": wall, "kb": peak})
        return out, rows, f"surface resampled (sizes {h:.2f}, facet distance {h / 8:.2f}); peak MB is the whole process"

    def run(self, tool):
        """Run `tool`: returns (output mesh, one dict per run with seconds, wall and kb, a note)."""
        if tool == "biotet":
            return self.biotet_mesh()
        if tool == "tetgen":
            return self.tetgen("pq1.2Y")
        if tool == "tetgen-O":
            return self.tetgen("pq1.2YO")
        if tool == "tetgen-cli":
            return self.tetgen_cli()
        return getattr(self, tool)()


def write_node_like(src, dst, points):
    """Rewrite the .node file `src` to `dst` with new coordinates, keeping its header and point indices."""
    with open(src) as f:
        lines = [line for line in f if line.split("#")[0].strip()]
    with open(dst, "w") as f:
        f.write(lines[0])
        for line, q in zip(lines[1:1 + len(points)], points):
            f.write(f"{line.split()[0]} {float(q[0])!r} {float(q[1])!r} {float(q[2])!r}\n")


# ---------------------------------------------------------------------------------------------------------------------
# tables


num = benchlib.cell


def angle(v, digits):
    """An angle cell in degrees."""
    return "–" if v is None else f"{v:.{digits}f}°"


def main_table(rows):
    """The markdown table of the main measures, one row per surface and tool."""
    out = ["| surface | tool | seconds | wall s | peak MB | points | tets | min dihedral | max dihedral "
           "| min solid sr | mean q | tets <5° | <10° | <20° | missing triangles | valid |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["status"] != "ok":
            out.append(f"| {r['surface']} | {r['label']} | {r['status']} |" + " |" * 13)
            continue
        out.append(
            f"| {r['surface']} | {r['label']} | {num(r['seconds'], '.2f')} | {num(r['wall'], '.2f')} "
            f"| {num(r['peak_mb'], '.1f')} | {num(r['points'])} | {num(r['tets'])} "
            f"| {angle(r['min_dihedral'], 4)} | {angle(r['max_dihedral'], 2)} | {num(r['min_solid_sr'], '.2e')} "
            f"| {num(r['mean_q'], '.3f')} | {num(r['lt5'])} | {num(r['lt10'])} | {num(r['lt20'])} "
            f"| {num(r['missing'])} | {'yes' if r['valid'] else 'no'} |")
    return "\n".join(out)


def placement_table(rows):
    """The markdown table of quality by placement and of forced tets."""
    out = ["| surface | tool | tets face / vertex / interior | <10° face | <10° vertex | <10° interior "
           "| min dihedral interior | mean q face / interior | forced | unforced <10° |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["status"] != "ok":
            continue
        out.append(
            f"| {r['surface']} | {r['label']} | {num(r['face_tets'])} / {num(r['vertex_tets'])} / "
            f"{num(r['interior_tets'])} | {num(r['face_lt10'])} | {num(r['vertex_lt10'])} | {num(r['interior_lt10'])} "
            f"| {angle(r['interior_min_dihedral'], 3)} | {num(r['face_mean_q'], '.3f')} / "
            f"{num(r['interior_mean_q'], '.3f')} | {num(r['forced'])} | {num(r['unforced_lt10'])} |")
    return "\n".join(out)


def ratios(rows):
    """One line per surface: biotet against TetGen pq1.2Y measured in the same run."""
    lines = []
    for surface in dict.fromkeys(r["surface"] for r in rows):
        by = {r["tool"]: r for r in rows if r["surface"] == surface and r["status"] == "ok"}
        b, t = by.get("biotet"), by.get("tetgen")
        if not (b and t):
            continue
        parts = [f"time {b['seconds'] / t['seconds']:.1f}× TetGen's" if t["seconds"] else None,
                 f"peak memory {b['peak_mb'] / t['peak_mb']:.2f}×" if b["peak_mb"] and t["peak_mb"] else None,
                 f"tets under 10° {b['lt10']:,} vs {t['lt10']:,}"
                 + (f" ({b['lt10'] / t['lt10']:.2f}×)" if t["lt10"] else ""),
                 f"unforced under 10° {num(b['unforced_lt10'])} vs {num(t['unforced_lt10'])}",
                 f"missing triangles {num(b['missing'])} vs {num(t['missing'])}"]
        lines.append(f"- {surface}: biotet vs TetGen `pq1.2Y`: " + "; ".join(p for p in parts if p) + ".")
    return "\n".join(lines)


def machine():
    """The machine in one line: cores, CPU model, Python, and the load average now."""
    model = platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    load = " / ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "?"
    return f"{os.cpu_count()} cores ({model}), {platform.system()}, Python {platform.python_version()}; load average " \
           f"{load}"


def versions():
    """Versions of the anchors that ran."""
    import importlib.metadata as md
    out = []
    for name, dist in [("tetgen", "tetgen"), ("gmsh", "gmsh"), ("pytetwild", "pytetwild"), ("pymmg", "pymmg"),
                       ("meshio", "meshio")]:
        try:
            out.append(f"{name} {md.version(dist)}")
        except md.PackageNotFoundError:
            pass
    return ", ".join(out)


def markdown_block(rows, command, machine_start, machine_end, repeat):
    """The block for the README: how it was made, the machine, both tables, the ratios and the notes."""
    notes = [f"- {r['surface']}, {r['label']}: {r['note']}" for r in rows if r.get("note")]
    return "\n".join([
        f"Made by `{command}` (median of {repeat} run{'s' if repeat != 1 else ''} per tool, each in a child "
        f"process; quality for every tool from one routine, `biotet quality --surface` and `biotet check "
        f"--surface`).",
        f"Machine: {machine_start} at the start, {machine_end.split('; load average ')[-1]} at the end. "
        f"Anchors: {versions()}.",
        "",
        main_table(rows),
        "",
        "By placement (a face on the input surface, a vertex only, interior) and forced tets (a face that is an "
        "input triangle with an angle under 10°, or an input edge where the surface folds under 10°):",
        "",
        placement_table(rows),
        "",
        ratios(rows),
        *(["", "Notes:", *notes] if notes else []),
    ])


def write_csv(path, rows):
    """One CSV row per surface and tool (the columns of CSV_COLUMNS; histograms only in --json)."""
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: "" if r.get(k) is None else r[k] for k in CSV_COLUMNS})


def update_readme(path, block):
    """Replace the text between the compare markers of `path` with `block`."""
    with open(path) as f:
        text = f.read()
    if BEGIN not in text or END not in text:
        sys.exit(f"{path}: no {BEGIN} ... {END} block to replace")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    with open(path, "w") as f:
        f.write(f"{head}{BEGIN}\n{block}\n{END}{tail}")


# ---------------------------------------------------------------------------------------------------------------------
# histograms


def write_svg(path, rows):
    """Overlaid dihedral-angle histograms of every tool, one row of two panels per surface: all six dihedral angles
    of every tet (10° bins) and each tet's smallest (5° bins), as a share of the tool's total, log scale."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("--svg needs matplotlib (pip install matplotlib)")
    surfaces = list(dict.fromkeys(r["surface"] for r in rows))
    labels = list(dict.fromkeys(r["label"] for r in rows if r["status"] == "ok"))
    styles = {label: ("-", "--", "-.", ":")[i % 4] for i, label in enumerate(labels)}
    fig, axes = plt.subplots(len(surfaces), 2, figsize=(12, 4.2 * len(surfaces) + 0.8), squeeze=False)
    for row_axes, surface in zip(axes, surfaces):
        for ax, key, title in [(row_axes[0], "dihedral_histogram", "all dihedral angles"),
                               (row_axes[1], "min_dihedral_histogram", "smallest dihedral angle per tet")]:
            floor = 1.0
            for r in rows:
                h = r.get(key)
                if r["surface"] != surface or r["status"] != "ok" or not h:
                    continue
                total = max(1, sum(h["counts"]) + h["below"] + h["above"])
                edges = [h["lo"] + i * h["width"] for i in range(len(h["counts"]) + 1)]
                share = [100 * c / total for c in h["counts"]]
                floor = min([floor, *(x for x in share if x > 0)])
                # Empty bins drop below the axis instead of showing as a small share.
                ax.stairs([x if x > 0 else 1e-12 for x in share], edges, label=r["label"], linewidth=1.6,
                          linestyle=styles[r["label"]])
            for x in (5, 10, 20):
                ax.axvline(x, color="0.75", linewidth=0.8, linestyle=":")
            ax.set_yscale("log")
            ax.set_ylim(bottom=floor / 3)
            ax.set_xlabel("degrees")
            ax.set_ylabel("% of angles" if key == "dihedral_histogram" else "% of tets")
            ax.set_title(f"{surface}: {title}")
    handles, names = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, names, loc="lower center", ncol=3, fontsize=9, frameon=False)
    fig.tight_layout(rect=(0, 0.8 / (4.2 * len(surfaces) + 0.8), 1, 1))
    fig.savefig(path)


# ---------------------------------------------------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("surfaces", nargs="*", metavar="SURFACE",
                    help="closed surfaces (default: tests/data/brain_20k.stl and wm_20k.stl)")
    ap.add_argument("--repeat", type=int, default=3, help="runs per tool; the table gives medians (default 3)")
    ap.add_argument("--tools", default=",".join(TOOLS),
                    help=f"comma-separated tools to run, of {', '.join(TOOLS)} (default: all; missing ones skipped)")
    ap.add_argument("--biotet", metavar="PATH",
                    help="the biotet binary (default: $BIOTET, else $CARGO_TARGET_DIR or target/ + release/biotet)")
    ap.add_argument("--csv", metavar="FILE", default="compare.csv", help="the CSV to write (default compare.csv)")
    ap.add_argument("--svg", metavar="FILE", help="overlaid dihedral-angle histograms of all tools (matplotlib)")
    ap.add_argument("--markdown", metavar="FILE", help="also write the markdown block to this file")
    ap.add_argument("--update-readme", metavar="FILE",
                    help=f"replace the block between {BEGIN} and {END} in this file with the markdown block")
    ap.add_argument("--json", metavar="FILE", help="also write every row (histograms included) as JSON")
    ap.add_argument("--ftetwild-threads", type=int, default=1, help="fTetWild's threads (default 1, as the others)")
    ap.add_argument("--tolerance", metavar="D[,D...]",
                    help="the surface-tolerance comparison instead (scripts/compare_tolerance.py): biotet "
                         "--surface-tolerance D beside MMG -hausd D, fTetWild with envelope D and pyacvd + TetGen")
    ap.add_argument("--list-tools", action="store_true",
                    help="print which tools can run here (JSON: tool -> null or why not) and exit")
    a = ap.parse_args()

    if a.tolerance:
        import compare_tolerance
        exe = benchlib.find_biotet(a.biotet)
        tols = [float(x) for x in a.tolerance.split(",") if x.strip()]
        tools = list(compare_tolerance.TOOLS) if a.tools == ",".join(TOOLS) else \
            [t.strip() for t in a.tools.split(",") if t.strip()]
        command = " ".join(["python3", os.path.relpath(os.path.abspath(__file__), os.getcwd()), *sys.argv[1:]])
        compare_tolerance.main(exe, a.surfaces, tols, tools, svg=a.svg, json_out=a.json, command=command)
        return
    tools = [t.strip() for t in a.tools.split(",") if t.strip()]
    unknown = [t for t in tools if t not in TOOLS]
    if unknown:
        ap.error(f"unknown tools {unknown}; known: {', '.join(TOOLS)}")
    if a.list_tools:
        print(json.dumps({t: missing_requirement(t) for t in TOOLS}))
        return
    if a.repeat < 1:
        ap.error("--repeat must be at least 1")
    exe = benchlib.find_biotet(a.biotet)
    if not os.path.exists(exe):
        sys.exit(f"{exe} not found: cargo build --release -p biotet-cli, or give --biotet PATH")
    surfaces = a.surfaces or DEFAULT_SURFACES
    command = " ".join(["python3", os.path.relpath(os.path.abspath(__file__), os.getcwd()), *sys.argv[1:]])
    machine_start = machine()
    rows = []
    with tempfile.TemporaryDirectory(prefix="compare_") as tmp:
        for surface in surfaces:
            name = os.path.basename(surface)
            runner = Runner(exe, os.path.abspath(surface), tmp, a.repeat, a.ftetwild_threads)
            for tool in tools:
                row = {"surface": name, "tool": tool, "label": TOOLS[tool][0], "status": "ok", "note": ""}
                why = missing_requirement(tool) if tool != "biotet" else None
                if why:
                    print(f"{name}: {tool} skipped: {why}", file=sys.stderr)
                    continue
                print(f"{name}: {tool} ...", file=sys.stderr, flush=True)
                try:
                    out, runs, note = runner.run(tool)
                    row.update(seconds=median(runs, "seconds"), wall=median(runs, "wall"),
                               peak_mb=None if median(runs, "kb") is None else median(runs, "kb") / 1024,
                               note=note, **measure(exe, out, runner.surface))
                except Exception as e:  # a crashing anchor is reported in the table, not fatal
                    msg = str(e).strip().splitlines()[-1][:200] if str(e).strip() else type(e).__name__
                    row.update(status="failed", note=f"failed: {msg}")
                    print(f"{name}: {tool} failed: {msg}", file=sys.stderr)
                rows.append(row)
    block = markdown_block(rows, command, machine_start, machine(), a.repeat)
    print(block)
    if a.csv:
        write_csv(a.csv, rows)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(block + "\n")
    if a.update_readme:
        update_readme(a.update_readme, block)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    if a.svg:
        write_svg(a.svg, rows)


if __name__ == "__main__":
    main()
