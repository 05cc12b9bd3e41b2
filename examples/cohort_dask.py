#!/usr/bin/env python3
"""Mesh a cohort with Dask: one task per subject, one mesh and one JSON report per subject, and
a summary CSV.

    python examples/cohort_dask.py subj01.stl subj02.stl ... -o meshes/            # LocalCluster
    python examples/cohort_dask.py subjects/*.stl -o meshes/ --workers 8 --size 2
    python examples/cohort_dask.py subjects/*.stl -o meshes/ --scheduler tcp://host:8786
    python examples/cohort_dask.py seg/*.nii.gz -o meshes/ --keep-labels 2,41 --min-component-voxels 20

A subject is a closed surface file or a label image (a segmentation: .nii, .nii.gz, .mgz, .nrrd,
.mha, .vti...), meshed as ``biotet mesh FILE`` would.

Each task meshes with ``threads=1`` so that workers do not oversubscribe the cores: run one
worker process per core (the default here). biotet releases the GIL while it meshes, so threaded
workers work too. A subject that fails (an invalid surface, say) is recorded in the summary with
its message; the others go on. On a Slurm cluster, pass the address of a ``dask-jobqueue``
``SLURMCluster`` scheduler (see the README) or run this script inside an allocation.

Needs: pip install biotet "dask[distributed]".
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import time
from pathlib import Path

import biotet

SUMMARY_FIELDS = [
    "subject", "status", "seconds", "points", "tets", "min_dihedral_deg", "max_dihedral_deg",
    "tets_under_10deg", "steiner_points", "max_region_volume_error", "max_region_distance", "mesh",
    "report", "error",
]


def subject_name(path: str) -> str:
    """The subject's name: the file name without its extension(s)."""
    name = Path(path).name
    for ext in (".gz",):
        name = name.removesuffix(ext)
    return Path(name).stem


def subject_names(paths: list[str]) -> list[str]:
    """One distinct name per input, for its output files: the file name without its
    extension(s); where two inputs share it (``s1/brain.stl``, ``s2/brain.stl``), their folder's
    name before it (``s1_brain``), and where that is shared too, the input's position after it.
    Two subjects never write to the same file."""
    names = [subject_name(p) for p in paths]
    names = [f"{Path(p).parent.name}_{n}" if names.count(n) > 1 else n for p, n in zip(paths, names)]
    return [f"{n}_{i}" if names.count(n) > 1 else n for i, n in enumerate(names)]


def mesh_one(path: str, name: str, out_dir: str, options: dict) -> dict:
    """Mesh one subject, write ``<name>.vtu`` and ``<name>.json``, return its summary row.
    Never raises for a subject's own failure: the row says what went wrong."""
    row = {k: "" for k in SUMMARY_FIELDS}
    row["subject"] = name
    start = time.perf_counter()
    try:
        m = biotet.mesh_file(path, threads=1, **options)
    except (biotet.BiotetError, ValueError, OSError) as e:
        row.update(status="failed", error=str(e), seconds=f"{time.perf_counter() - start:.3f}")
        return row
    mesh_path = Path(out_dir) / f"{name}.vtu"
    report_path = Path(out_dir) / f"{name}.json"
    m.write(mesh_path)
    tmp = report_path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(m.report, indent=1))
    os.replace(tmp, report_path)
    q = m.report["quality"]
    row.update(
        status="ok",
        seconds=f"{time.perf_counter() - start:.3f}",
        points=m.n_points,
        tets=m.n_tets,
        min_dihedral_deg=f"{q['min_dihedral_deg']:.3f}",
        max_dihedral_deg=f"{q['max_dihedral_deg']:.3f}",
        tets_under_10deg=q["n_dihedral_lt_10"],
        steiner_points=(m.report["pipeline"].get("recover") or {}).get("steiner_points", 0),
        # A label image: the largest relative difference of a region's mesh and voxel volumes.
        max_region_volume_error=max(
            (abs(r["relative_error"]) for r in m.report.get("image_regions") or []
             if r["relative_error"] is not None),
            default="",
        ),
        # And the largest distance between a region's boundary and its voxel boundary (either
        # way; at most half a voxel with the default surface stage).
        max_region_distance=max(
            (max(r["hausdorff_in_to_out"], r["hausdorff_out_to_in"])
             for r in m.report.get("image_regions") or []),
            default="",
        ),
        mesh=str(mesh_path),
        report=str(report_path),
    )
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("inputs", nargs="+", help="surface files or label images, one subject each")
    ap.add_argument("-o", "--out", required=True, help="output folder")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                    help="LocalCluster worker processes (default: one per core)")
    ap.add_argument("--size", type=float, help="uniform size (default: from each surface)")
    ap.add_argument("--keep-labels", help="label images: keep only these labels, as L,L,...")
    ap.add_argument("--min-component-voxels", type=int, default=0,
                    help="label images: merge smaller islands into their surroundings")
    a = ap.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    # Absolute paths: workers of a remote scheduler run elsewhere (another directory, another
    # node of a shared file system), where the client's relative paths mean nothing.
    out = Path(a.out).resolve()
    inputs = [str(Path(p).resolve()) for p in a.inputs]
    out.mkdir(parents=True, exist_ok=True)
    options: dict = {"size": a.size} if a.size else {}
    if a.keep_labels:
        options["keep_labels"] = [int(x) for x in a.keep_labels.split(",")]
    if a.min_component_voxels:
        options["min_component_voxels"] = a.min_component_voxels
    if a.scheduler:
        client = Client(a.scheduler)
        cluster = None
    else:
        cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        futures = [client.submit(mesh_one, p, name, str(out), options, key=f"mesh-{i}-{name}")
                   for i, (p, name) in enumerate(zip(inputs, subject_names(inputs)))]
        rows = client.gather(futures)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    summary = out / "summary.csv"
    with open(summary, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=SUMMARY_FIELDS)
        w.writeheader()
        w.writerows(rows)
    failed = [r for r in rows if r["status"] != "ok"]
    print(f"{len(rows) - len(failed)} of {len(rows)} subjects meshed; summary: {summary}")
    for r in failed:
        print(f"  {r['subject']}: {r['error']}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
