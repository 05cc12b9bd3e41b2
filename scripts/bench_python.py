#!/usr/bin/env python3
"""The Python package's overhead and parallelism, beside the CLI and the Python anchors.

    pip install ./crates/biotet-py tetgen            # (pytetwild too, if it installs)
    cargo build --release -p biotet-cli
    python3 scripts/bench_python.py [--repeat 3] [--surface tests/data/brain_20k.stl] [--wheel WHEEL]
        [--pip-install] [--pip-source] [--cases biotet,cli,tetgen,pytetwild,serial,parallel]

Each figure is measured in a child process (its own peak RSS), the cases alternating, `--repeat`
times; medians are printed:

  biotet.mesh     numpy arrays in (read before the clock), biotet.mesh(...) in the same process
  biotet CLI      `biotet mesh SURFACE --json -o TMP.vtu`: pipeline seconds and the whole process
  tetgen          pyvista's tetgen, `pq1.2Y`, from numpy in the same process
  pytetwild       its tetrahedralize call with its defaults (if installed)
  two threads     two meshings of the surface, one after the other, then in two Python threads at
                  once (threads=1 each): the speed-up says whether the GIL is released

Peak memory: the process's peak RSS (ru_maxrss; for the CLI, its own peak while meshing) and the
part of it above the RSS before the meshing call (the input already in memory).

With --wheel, the wheel's size is printed too; with --pip-install also the time of
`pip install WHEEL` into a new virtual environment (numpy fetched from the index), and with
--pip-source the time of `pip install ./crates/biotet-py` into a new one with an empty cargo
target directory (a cold build, as on a fresh machine).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, resource, sys, time, threading
import numpy as np
case, surface = sys.argv[1], sys.argv[2]
import biotet
s = biotet.read_surface(surface)
pts, tris = np.ascontiguousarray(s.points), np.ascontiguousarray(s.triangles)
rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
cpu = lambda: sum(resource.getrusage(resource.RUSAGE_SELF)[:2])
c0 = cpu()
t = time.perf_counter()
out = {}
if case == "biotet":
    m = biotet.mesh(pts, tris)
    out["tets"] = m.n_tets
elif case == "tetgen":
    import tetgen
    g = tetgen.TetGen(pts, tris)
    nodes, elems = g.tetrahedralize(switches="pq1.2Y")[:2]
    out["tets"] = len(elems)
elif case == "pytetwild":
    import pytetwild
    v, tt = pytetwild.tetrahedralize(pts, tris)
    out["tets"] = len(tt)
    out["points_dtype"] = str(v.dtype)
elif case == "serial":
    for _ in range(2):
        biotet.mesh(pts, tris, threads=1)
elif case == "parallel":
    ts = [threading.Thread(target=biotet.mesh, args=(pts, tris), kwargs={"threads": 1}) for _ in range(2)]
    [x.start() for x in ts]
    [x.join() for x in ts]
out["seconds"] = time.perf_counter() - t
out["cpu_seconds"] = cpu() - c0
out["peak_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
out["peak_above_start_mb"] = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss0) / 1024
print(json.dumps(out))
"""


def child(case: str, surface: str) -> dict | None:
    # In a scratch directory: fTetWild (pytetwild) leaves a __tracked_surface.stl in its working
    # directory.
    with tempfile.TemporaryDirectory() as scratch:
        r = subprocess.run([sys.executable, "-c", CHILD, case, os.path.abspath(surface)],
                           capture_output=True, text=True, cwd=scratch)
    if r.returncode != 0:
        print(f"  {case}: failed: {r.stderr.strip().splitlines()[-1] if r.stderr.strip() else r.returncode}",
              file=sys.stderr)
        return None
    lines = r.stdout.strip().splitlines()
    out = json.loads(lines[-1])
    # What the tool printed on its own (biotet prints nothing).
    out["stdout_lines"] = len(lines) - 1
    return out


def cli(biotet: str, surface: str) -> dict:
    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        r = subprocess.run([biotet, "mesh", surface, "-o", os.path.join(d, "m.vtu"), "--json"],
                           capture_output=True, text=True, check=True)
        wall = time.perf_counter() - t
    j = json.loads(r.stdout)
    return {
        "seconds": j["pipeline"]["seconds_total"] + j["seconds_sizing"],
        "wall": wall,
        "tets": j["pipeline"]["n_tets"],
        "peak_mb": j["peak_rss_meshing_kb"] / 1024,
        "peak_above_start_mb": (j["peak_rss_meshing_kb"] - j["rss_before_kb"]) / 1024,
    }


def pip_install(what: list[str], env: dict | None = None) -> float:
    """Seconds of `pip install WHAT` into a new virtual environment (its creation not counted)."""
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([sys.executable, "-m", "venv", os.path.join(d, "venv")], check=True)
        py = os.path.join(d, "venv", "bin", "python")
        t = time.perf_counter()
        subprocess.run([py, "-m", "pip", "install", "-q", "--no-cache-dir", *what], check=True,
                       env={**os.environ, **(env or {})})
        seconds = time.perf_counter() - t
        subprocess.run([py, "-c", "import biotet"], check=True, cwd=d)
    return seconds


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--surface", default=str(ROOT / "tests/data/brain_20k.stl"))
    ap.add_argument("--biotet", default=str(ROOT / "target/release/biotet"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--wheel", help="a built wheel whose size to report")
    ap.add_argument("--pip-install", action="store_true",
                    help="time `pip install WHEEL` into a new virtual environment")
    ap.add_argument("--pip-source", action="store_true",
                    help="time `pip install ./crates/biotet-py` with a cold cargo target")
    ap.add_argument("--cases", default="biotet,cli,tetgen,pytetwild,serial,parallel",
                    help="which cases to run, comma-separated")
    a = ap.parse_args()
    cases = a.cases.split(",")
    runs: dict[str, list[dict]] = {c: [] for c in cases}
    for _ in range(a.repeat):
        for c in cases:
            r = cli(a.biotet, a.surface) if c == "cli" else child(c, a.surface)
            if r is not None:
                runs[c].append(r)
    print(f"{Path(a.surface).name}, medians of {a.repeat}, {time.strftime('%Y-%m-%d')}, {os.cpu_count()} cores")
    print("| case | seconds | tets | peak RSS MB | above start MB | lines printed |")
    print("|---|---|---|---|---|---|")
    for c in cases:
        rs = runs[c]
        if not rs:
            print(f"| {c} | not run | | | | |")
            continue
        med = lambda k: statistics.median(r[k] for r in rs) if k in rs[0] else float("nan")
        tets = rs[0].get("tets", "")
        printed = rs[0].get("stdout_lines", "")
        print(f"| {c} | {med('seconds'):.2f} | {tets} | {med('peak_mb'):.0f} | "
              f"{med('peak_above_start_mb'):.0f} | {printed} |")
    if runs.get("pytetwild"):
        print(f"pytetwild's points: {runs['pytetwild'][0].get('points_dtype')}")
    if runs.get("serial") and runs.get("parallel"):
        s = statistics.median(r["seconds"] for r in runs["serial"])
        p = statistics.median(r["seconds"] for r in runs["parallel"])
        print(f"two meshings in two threads: {s / p:.2f}× faster than one after the other")
        par = runs["parallel"]
        busy = statistics.median(r["cpu_seconds"] / r["seconds"] for r in par)
        print(f"  CPU seconds per wall second in the two threads: {busy:.2f} (at most 1 with "
              "the GIL held; 2 when both threads have a core)")
    load = os.getloadavg()
    print(f"load average at the end: {load[0]:.2f} / {load[1]:.2f} / {load[2]:.2f}")
    if runs.get("biotet") and runs.get("cli"):
        b = statistics.median(r["seconds"] for r in runs["biotet"])
        c = statistics.median(r["seconds"] for r in runs["cli"])
        print(f"binding / CLI meshing time: {b / c:.2f}")
    if a.wheel:
        print(f"wheel {Path(a.wheel).name}: {os.path.getsize(a.wheel) / 1e6:.1f} MB")
        if a.pip_install:
            print(f"pip install of the wheel into a new venv: {pip_install([a.wheel]):.1f} s")
    if a.pip_source:
        with tempfile.TemporaryDirectory() as target:
            s = pip_install([str(ROOT / "crates" / "biotet-py")], {"CARGO_TARGET_DIR": target})
        print(f"pip install ./crates/biotet-py into a new venv, cold build: {s:.0f} s")


if __name__ == "__main__":
    main()
