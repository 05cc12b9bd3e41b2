#!/usr/bin/env python3
"""Random marching-cubes surfaces for robustness runs: the level sets segmentation pipelines write, of fields nobody chose.

    pip install scikit-image==0.26.0 trimesh==5.2.0 scipy numpy
    python3 scripts/random_fields.py --out DIR [--count 30] [--seed 1] [--biotet PATH]
    python3 scripts/bench_shapes.py DIR/*.off          # then: biotet beside TetGen on each

Each surface is scikit-image's marching cubes (Lewiner) of a random field on a grid of 28 to 44 voxels a side, the
voxels 1 x 1 x s with s one of 1, 1.5, 2.5 and 3 (a scanner's slices), the field one of
  blobs   a sum of 5 to 30 Gaussian blobs of random centres and widths, at level 0.3 (unions of rounded lobes, thin
          necks where two lobes barely meet, and sometimes a shape star-shaped from its centroid);
  noise   white noise smoothed by a Gaussian of 2 to 4 voxels, faded out beyond a ball, at a random level (porous,
          genus, pinches where the level set nearly touches itself);
  mask    the same noise thresholded to a binary mask inside a ball, smoothed by 0 to 1 voxel (the staircase of a
          segmentation);
then its largest closed component, coordinates rounded to float32 as an STL export stores them, turned outward. A
field whose largest component has fewer than 500 triangles is dropped, and so is any surface `biotet validate`
refuses; the rest are written as DIR/field_SEED_K_KIND.off. The same seed gives the same files with the pinned
packages. Nothing here is tuned: a union of blobs on voxels of 1 x 1 x 2.5 found by this script took 19 s (the cones
of a star-shaped region that took back none of the nodes) before session 39, and is in the corpus as mc_blobs_aniso.
"""
import os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchlib import find_biotet  # noqa: E402
from make_shapes import random_args, write_random  # noqa: E402

import numpy as np  # noqa: E402

KINDS = ["blobs", "noise", "mask"]


def field(kind, n, rng):
    """The field on an n^3 grid (inside: above the returned level)."""
    from scipy.ndimage import gaussian_filter
    x, y, z = np.mgrid[0:n, 0:n, 0:n].astype(float)
    r = np.sqrt(((x - n / 2) ** 2 + (y - n / 2) ** 2 + (z - n / 2) ** 2)) / n
    if kind == "blobs":
        f = np.zeros_like(x)
        for c in rng.uniform(0.2 * n, 0.8 * n, (int(rng.integers(5, 31)), 3)):
            s = rng.uniform(n / 24, n / 8)
            f += np.exp(-((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) / (2 * s * s))
        return f, 0.3
    noise = gaussian_filter(rng.standard_normal((n, n, n)), sigma=float(rng.uniform(2, 4)))
    noise /= noise.std()
    if kind == "noise":
        return noise - 6 * np.maximum(0, r - 0.35), float(rng.uniform(0.2, 0.8))
    mask = (noise > 0.1) & (r < 0.4)
    return gaussian_filter(mask.astype(float), sigma=float(rng.choice([0.0, 0.7, 1.0]))), 0.5


def surface(kind, rng):
    """A random field's largest closed level-set component (points, triangles), or None."""
    import trimesh
    from skimage.measure import marching_cubes
    n = int(rng.integers(28, 45))
    dz = float(rng.choice([1.0, 1.5, 2.5, 3.0]))
    f, level = field(kind, n, rng)
    # Padded below the level, so every component is closed.
    f = np.pad(f, 2, constant_values=min(float(f.min()), level - 1.0))
    try:
        v, t, _, _ = marching_cubes(f, level, spacing=(1.0, 1.0, dz))
    except (ValueError, RuntimeError):
        return None
    m = trimesh.Trimesh(np.asarray(v, np.float32).astype(float), t, process=True)
    parts = m.split(only_watertight=True)
    if not parts:
        return None
    m = max(parts, key=lambda c: len(c.faces))
    if len(m.faces) < 500:
        return None
    if m.volume < 0:
        m.invert()
    return np.asarray(m.vertices), np.asarray(m.faces)


def main():
    a = random_args(__doc__, 30, "surfaces")
    rng = np.random.default_rng(a.seed)

    def make(k):
        kind = KINDS[k % len(KINDS)]
        return f"field_{a.seed}_{k}_{kind}", surface(kind, rng)

    write_random(find_biotet(a.biotet), a.out, a.count, make, "surfaces")


if __name__ == "__main__":
    main()
