#!/usr/bin/env python3
"""biotet `mesh` beside TetGen `pq1.2Y` on the shape corpus (tests/data/shapes, see its README): does every valid
closed surface mesh, how fast, how well.

    pip install tetgen meshio numpy            # TetGen (pip `tetgen`) and the surface reader of its child
    cargo build --release -p biotet-cli
    python3 scripts/bench_shapes.py [SURFACE ...] [--biotet PATH] [--repeat 3] [--timeout 60] [--csv shapes.csv]
                                    [--brains] [--invalid] [--only NAME,NAME] [--no-tetgen]

Surfaces: every tests/data/shapes/*.off (invalid_* only with --invalid), plus tests/data/brain_20k.stl and
wm_20k.stl with --brains, or the SURFACE arguments. On each, `--repeat` times, alternating in the same run:

  biotet   `biotet mesh SURFACE -o TMP/biotet.vtu --json` (defaults) in a child process. `seconds` is the meshing from
           its JSON (pipeline.seconds_total + seconds_sizing: reading and writing excluded), `wall` the process's wall
           time, `exit` its exit code (the last run's). Steiner points: pipeline.recover.steiner_points (or
           points_added, the name may change); missing: pipeline.missing_triangles.
  tetgen   TetGen 1.6 `pq1.2Y` through pip `tetgen`, in a child process (scripts/benchlib.py's child: the meshing call
           alone is timed). `added` = its output points minus the input's points (refinement and Steiner points).

Every output (biotet's, also a failed run's when one was written, marked `fail`; TetGen's .node/.ele) is measured by
one routine, benchlib.measure: `biotet quality --surface SURFACE --json` (tets, dihedral angles, tets under 10°) and
`biotet check --surface SURFACE --json` (validity, input triangles missing). Seconds are medians over the repeats;
quality comes from the last run (both tools are deterministic). A run past --timeout seconds is killed and marked
`timeout`. The table goes to stdout (markdown), every field to --csv.
"""
import argparse, csv, glob, json, os, platform, subprocess, sys, tempfile, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib  # noqa: E402
from benchlib import ROOT, find_biotet, measure, median, require  # noqa: E402

SHAPES = os.path.join(ROOT, "tests", "data", "shapes")
BRAINS = [os.path.join(ROOT, "tests", "data", n) for n in ("brain_20k.stl", "wm_20k.stl")]

CSV_COLUMNS = [
    "surface", "triangles", "points",
    "biotet_status", "biotet_exit", "biotet_seconds", "biotet_wall", "biotet_tets", "biotet_lt10", "biotet_min_dihedral",
    "biotet_max_dihedral", "biotet_steiner", "biotet_polish_points", "biotet_missing", "biotet_missing_check",
    "biotet_valid", "biotet_forced", "biotet_unforced_lt10", "biotet_message",
    "tetgen_status", "tetgen_seconds", "tetgen_wall", "tetgen_tets", "tetgen_lt10", "tetgen_min_dihedral",
    "tetgen_max_dihedral", "tetgen_added", "tetgen_missing", "tetgen_valid", "tetgen_forced", "tetgen_unforced_lt10",
    "tetgen_message",
]


def dig(d, *keys):
    """d[k0][k1]... or None."""
    for k in keys:
        if not isinstance(d, dict) or k not in d:
            return None
        d = d[k]
    return d


def count_surface(path):
    """(triangles, points) of a surface as the meshers see it (exactly equal points welded)."""
    p, t = benchlib.read_surface(path)
    return len(t), len(p)


def last_line(text):
    lines = [x for x in (text or "").strip().splitlines() if x.strip()]
    return lines[0][:200] if lines else ""


def run_biotet(exe, surface, tmp, timeout):
    """One `biotet mesh` run; the measures of its JSON and (when it wrote one) its output mesh path."""
    out = os.path.join(tmp, "biotet.vtu")
    for f in glob.glob(os.path.join(tmp, "biotet*")):
        os.remove(f)
    start = time.perf_counter()
    try:
        r = subprocess.run([exe, "mesh", surface, "-o", out, "--json"], capture_output=True, text=True,
                           timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"status": "timeout", "wall": time.perf_counter() - start, "message": f"killed after {timeout} s"}, None
    wall = time.perf_counter() - start
    row = {"exit": r.returncode, "wall": wall, "status": "ok" if r.returncode == 0 else "fail"}
    try:
        j = json.loads(r.stdout)
    except ValueError:
        j = {}
    if "pipeline" in j:
        pipe = j["pipeline"]
        row["seconds"] = (pipe.get("seconds_total") or 0.0) + (j.get("seconds_sizing") or 0.0)
        rec = pipe.get("recover") or {}
        steiner = rec.get("steiner_points", rec.get("points_added"))
        row["steiner"] = steiner
        row["polish_points"] = dig(pipe, "polish", "points_added")
        row["missing"] = pipe.get("missing_triangles")
    if r.returncode != 0:
        msg = last_line(r.stderr) or j.get("error", "")
        for prefix in ("error: ", surface + ": "):
            msg = msg[len(prefix):] if msg.startswith(prefix) else msg
        row["message"] = msg
    # The output as written, or (a later binary) the partial mesh a failed run keeps beside it.
    written = [f for f in sorted(glob.glob(os.path.join(tmp, "biotet*"))) if f.endswith((".vtu", ".mesh", ".msh"))]
    return row, (out if os.path.exists(out) else (written[0] if written else None))


def run_tetgen(surface, tmp, timeout, switches="pq1.2Y"):
    """One TetGen child run (benchlib's); its measures and output .node path."""
    base = os.path.join(tmp, "tetgen")
    for f in glob.glob(base + ".*"):
        os.remove(f)
    start = time.perf_counter()
    cmd = [sys.executable, benchlib.HERE, "tetgen", os.path.abspath(surface), base, json.dumps({"switches": switches})]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=tmp)
    except subprocess.TimeoutExpired:
        return {"status": "timeout", "wall": time.perf_counter() - start, "message": f"killed after {timeout} s"}, None
    wall = time.perf_counter() - start
    if r.returncode != 0:
        msg = last_line((r.stderr or "").strip().splitlines()[-1] if r.stderr.strip() else f"exit {r.returncode}")
        return {"status": "error", "wall": wall, "message": msg or f"exit {r.returncode}"}, None
    j = json.loads(r.stdout.strip().splitlines()[-1])
    return {"status": "ok", "wall": wall, "seconds": j["seconds"]}, base + ".node"


def measured(exe, mesh, surface):
    """benchlib.measure, or a note of why it could not measure."""
    try:
        return measure(exe, mesh, surface), ""
    except Exception as e:  # noqa: BLE001 — a broken output is a result to report
        return None, f"measure: {str(e)[:150]}"


def bench(exe, surface, repeat, timeout, tetgen):
    """All runs on one surface; one flat row."""
    name = os.path.basename(surface)
    tris, pts = count_surface(surface)
    row = {"surface": name, "triangles": tris, "points": pts}
    with tempfile.TemporaryDirectory(prefix="bench_shapes_") as tmp:
        b_runs, t_runs, b_mesh, t_mesh = [], [], None, None
        for _ in range(repeat):
            b, b_mesh = run_biotet(exe, surface, tmp, timeout)
            b_runs.append(b)
            b_q = measured(exe, b_mesh, surface) if b_mesh else None  # measured now: the next run replaces it
            if tetgen:
                t, t_mesh = run_tetgen(surface, tmp, timeout)
                t_runs.append(t)
                t_q = measured(exe, t_mesh, surface) if t_mesh else None
            if b["status"] == "timeout" and (not tetgen or t_runs[-1]["status"] == "timeout"):
                break  # one timeout is enough
        last = b_runs[-1]
        row.update({f"biotet_{k}": last.get(k) for k in ("status", "exit", "steiner", "polish_points", "missing",
                                                          "message")})
        row["biotet_seconds"], row["biotet_wall"] = median(b_runs, "seconds"), median(b_runs, "wall")
        if b_q:
            q, note = b_q
            if q:
                row.update({"biotet_tets": q["tets"], "biotet_lt10": q["lt10"], "biotet_min_dihedral": q["min_dihedral"],
                            "biotet_max_dihedral": q["max_dihedral"], "biotet_missing_check": q["missing"],
                            "biotet_valid": q["valid"], "biotet_forced": q["forced"],
                            "biotet_unforced_lt10": q["unforced_lt10"]})
            elif note:
                row["biotet_message"] = (row.get("biotet_message") or "") + " " + note
        if tetgen:
            last = t_runs[-1]
            row["tetgen_status"], row["tetgen_message"] = last.get("status"), last.get("message")
            row["tetgen_seconds"], row["tetgen_wall"] = median(t_runs, "seconds"), median(t_runs, "wall")
            if t_q:
                q, note = t_q
                if q:
                    row.update({"tetgen_tets": q["tets"], "tetgen_lt10": q["lt10"],
                                "tetgen_min_dihedral": q["min_dihedral"], "tetgen_max_dihedral": q["max_dihedral"],
                                "tetgen_added": q["points"] - pts, "tetgen_missing": q["missing"],
                                "tetgen_valid": q["valid"], "tetgen_forced": q["forced"],
                                "tetgen_unforced_lt10": q["unforced_lt10"]})
                else:
                    row["tetgen_message"] = note
    return row


# ---------------------------------------------------------------------------------------------------------------------
# table


num = benchlib.cell


def deg(v, digits=1):
    return "–" if v is None else f"{v:.{digits}f}"


def yes(v):
    return "–" if v is None else ("yes" if v else "**no**")


def table(rows, tetgen):
    head = ("| shape | tris | biotet | s | wall s | tets | <10° | min° | max° | Steiner | missing | valid |")
    sep = "|---|---|---|---|---|---|---|---|---|---|---|---|"
    if tetgen:
        head += " TetGen s | tets | <10° | min° | max° | added | valid |"
        sep += "---|---|---|---|---|---|---|"
    out = [head, sep]
    for r in rows:
        st = r.get("biotet_status")
        status = "ok" if st == "ok" else (f"**{st}**" + (f" ({r['biotet_exit']})" if r.get("biotet_exit") else ""))
        line = (f"| {r['surface']} | {num(r['triangles'])} | {status} | {num(r.get('biotet_seconds'), '.2f')} "
                f"| {num(r.get('biotet_wall'), '.2f')} | {num(r.get('biotet_tets'))} | {num(r.get('biotet_lt10'))} "
                f"| {deg(r.get('biotet_min_dihedral'), 2)} | {deg(r.get('biotet_max_dihedral'))} "
                f"| {num(r.get('biotet_steiner'))} | {num(r.get('biotet_missing_check', r.get('biotet_missing')))} "
                f"| {yes(r.get('biotet_valid'))} |")
        if tetgen:
            ts = r.get("tetgen_status")
            secs = num(r.get("tetgen_seconds"), ".2f") if ts == "ok" else f"**{ts}**"
            line += (f" {secs} | {num(r.get('tetgen_tets'))} | {num(r.get('tetgen_lt10'))} "
                     f"| {deg(r.get('tetgen_min_dihedral'), 2)} | {deg(r.get('tetgen_max_dihedral'))} "
                     f"| {num(r.get('tetgen_added'))} | {yes(r.get('tetgen_valid'))} |")
        out.append(line)
    return "\n".join(out)


def summary(rows):
    ok = [r for r in rows if r.get("biotet_status") == "ok" and r.get("biotet_valid") and not r.get("biotet_missing_check")]
    lines = [f"biotet: {len(ok)} of {len(rows)} shapes meshed (exit 0, valid, every triangle kept)."]
    bad = [r for r in rows if r not in ok]
    for r in bad:
        lines.append(f"- {r['surface']}: {r.get('biotet_status')}, {r.get('biotet_message') or ''}".rstrip(", "))
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("surfaces", nargs="*", metavar="SURFACE", help="surfaces (default: tests/data/shapes/*.off)")
    ap.add_argument("--biotet", metavar="PATH", help="the biotet binary (default target/release/biotet, or $BIOTET)")
    ap.add_argument("--repeat", type=int, default=1, help="runs per tool, alternating; seconds are medians (default 1)")
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds per run before it is killed (default 120)")
    ap.add_argument("--csv", metavar="FILE", help="write every field to this CSV")
    ap.add_argument("--brains", action="store_true", help="also tests/data/brain_20k.stl and wm_20k.stl")
    ap.add_argument("--invalid", action="store_true", help="also the invalid_* shapes (expected to be refused)")
    ap.add_argument("--only", help="comma-separated substrings: only the shapes whose file name contains one")
    ap.add_argument("--no-tetgen", action="store_true", help="biotet only")
    args = ap.parse_args()
    exe = find_biotet(args.biotet)
    require(exe)
    surfaces = args.surfaces or sorted(f for f in glob.glob(os.path.join(SHAPES, "*.off"))
                                       if args.invalid or not os.path.basename(f).startswith("invalid_"))
    if args.brains:
        surfaces += BRAINS
    if args.only:
        keys = args.only.split(",")
        surfaces = [s for s in surfaces if any(k in os.path.basename(s) for k in keys)]
    tetgen = not args.no_tetgen
    if tetgen:
        import importlib.util
        for m in ("tetgen", "meshio", "numpy"):
            if importlib.util.find_spec(m) is None:
                sys.exit(f"Python module `{m}` not installed (pip install tetgen meshio numpy), or --no-tetgen")
    rows = []
    start = time.perf_counter()
    for s in surfaces:
        row = bench(exe, s, args.repeat, args.timeout, tetgen)
        rows.append(row)
        print(f"{row['surface']:32s} biotet {row.get('biotet_status')} {num(row.get('biotet_wall'), '.2f')} s"
              + (f"   tetgen {row.get('tetgen_status')} {num(row.get('tetgen_wall'), '.2f')} s" if tetgen else ""),
              file=sys.stderr, flush=True)
    print(f"python3 {' '.join(sys.argv)}  # {platform.node()}, {os.cpu_count()} cores, "
          f"{time.perf_counter() - start:.0f} s\n")
    print(table(rows, tetgen))
    print()
    print(summary(rows))
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=CSV_COLUMNS, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)


if __name__ == "__main__":
    main()
