"""Shared fixtures: the repository's data and the CLI binary to compare with."""

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / "tests" / "data"
SHAPES = DATA / "shapes"


def cube(origin=(0.0, 0.0, 0.0), side=1.0):
    """A closed outward cube of 12 triangles (points, triangles)."""
    o = np.asarray(origin, float)
    p = np.array([[(i >> 0) & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], float) * side + o
    t = np.array([
        [0, 2, 1], [1, 2, 3],  # z = 0
        [4, 5, 6], [5, 7, 6],  # z = 1
        [0, 1, 4], [1, 5, 4],  # y = 0
        [2, 6, 3], [3, 6, 7],  # y = 1
        [0, 4, 2], [2, 4, 6],  # x = 0
        [1, 3, 5], [3, 7, 5],  # x = 1
    ])
    return p, t


@pytest.fixture(scope="session")
def cli():
    """The biotet CLI: $BIOTET_CLI, else the workspace's release or debug build (built by the
    test command before pytest runs)."""
    env = os.environ.get("BIOTET_CLI")
    candidates = [Path(env)] if env else [ROOT / "target" / k / "biotet" for k in ("release", "debug")]
    for c in candidates:
        if c.is_file():
            return c
    found = shutil.which("biotet")
    if found:
        return Path(found)
    pytest.fail("no biotet CLI binary: build it (cargo build -p biotet-cli) or set BIOTET_CLI")


def run_cli(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)
