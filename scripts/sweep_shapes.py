#!/usr/bin/env python3
"""Robustness sweep: does every valid shape of the corpus mesh at any size, in any position?

    cargo build --release -p biotet-cli
    python3 scripts/sweep_shapes.py [--fractions 0.5,0.2,0.1,0.05,0.03,0.02] [--turned 2] [--seed 7]
                                    [--biotet PATH] [--timeout 120] [--only NAME,NAME]

Every tests/data/shapes/*.off that `biotet validate` accepts (invalid_* skipped), and `--turned` copies of each turned
by a random rotation, scaled by 10^U(-2, 3) and shifted by U(-100, 100) per axis (seeded: the same copies every run),
is meshed by `biotet mesh` with the defaults and with `--size` at each fraction of its bounding-box diagonal; each
output must exist and pass `biotet check --surface`. No timing: this looks for failures (exit code, check). Prints one
line per failure and a summary; exits 1 if any run failed. Pure Python (no numpy).
"""
import argparse, glob, math, os, random, subprocess, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchlib import ROOT, find_biotet  # noqa: E402

SHAPES = os.path.join(ROOT, "tests", "data", "shapes")


def read_off(path):
    with open(path) as f:
        words = f.read().split()
    assert words[0] == "OFF", path
    n, m = int(words[1]), int(words[2])
    pts = [tuple(float(x) for x in words[4 + 3 * i: 7 + 3 * i]) for i in range(n)]
    tris, k = [], 4 + 3 * n
    for _ in range(m):
        c = int(words[k])
        tris.append(tuple(int(x) for x in words[k + 1: k + 1 + c]))
        k += 1 + c
    return pts, tris


def write_off(path, pts, tris):
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(pts), len(tris)))
        for p in pts:
            f.write("%.17g %.17g %.17g\n" % p)
        for t in tris:
            f.write("%d %s\n" % (len(t), " ".join(map(str, t))))


def turned(pts, rng):
    """pts turned by a uniformly random rotation, scaled and shifted."""
    q = [rng.gauss(0, 1) for _ in range(4)]
    s = math.sqrt(sum(x * x for x in q))
    a, b, c, d = (x / s for x in q)
    r = [[a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)],
         [2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)],
         [2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d]]
    scale = 10 ** rng.uniform(-2, 3)
    shift = [rng.uniform(-100, 100) for _ in range(3)]
    return [tuple(scale * sum(r[i][j] * p[j] for j in range(3)) + shift[i] for i in range(3)) for p in pts]


def diagonal(pts):
    return math.dist([min(p[k] for p in pts) for k in range(3)], [max(p[k] for p in pts) for k in range(3)])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fractions", default="0.5,0.2,0.1,0.05,0.03,0.02")
    ap.add_argument("--turned", type=int, default=2, help="turned, scaled and shifted copies of each shape")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--biotet", default=None)
    ap.add_argument("--timeout", type=float, default=120)
    ap.add_argument("--only", default=None, help="comma-separated shape names (file stems)")
    a = ap.parse_args()
    biotet = a.biotet or find_biotet()
    fractions = [float(x) for x in a.fractions.split(",") if x]
    only = set(a.only.split(",")) if a.only else None
    rng = random.Random(a.seed)
    tmp = tempfile.mkdtemp(prefix="biotet_sweep_")
    runs, failures = 0, []
    for path in sorted(glob.glob(os.path.join(SHAPES, "*.off"))):
        name = os.path.basename(path)[:-4]
        if name.startswith("invalid_"):
            continue
        pts, tris = read_off(path)
        copies = [(name, path)]
        for k in range(a.turned):
            q = turned(pts, rng)  # drawn for every shape, so --only keeps the same copies
            copies.append((f"{name}_turned{k}", os.path.join(tmp, f"{name}_turned{k}.off")))
            write_off(copies[-1][1], q, tris)
        if only is not None and name not in only:
            continue
        for cname, cpath in copies:
            d = diagonal(read_off(cpath)[0])
            for frac in [None] + fractions:
                args = [] if frac is None else ["--size", repr(d * frac)]
                label = f"{cname} " + ("defaults" if frac is None else f"--size {frac} × diagonal")
                out = os.path.join(tmp, "out.vtu")
                if os.path.exists(out):
                    os.remove(out)
                runs += 1
                try:
                    p = subprocess.run([biotet, "mesh", cpath, "-o", out, "--quiet", *args],
                                       capture_output=True, text=True, timeout=a.timeout)
                except subprocess.TimeoutExpired:
                    failures.append(f"{label}: timeout after {a.timeout} s")
                    continue
                if p.returncode != 0:
                    failures.append(f"{label}: exit {p.returncode}: {p.stderr.strip().splitlines()[0][:200]}")
                    continue
                c = subprocess.run([biotet, "check", out, "--surface", cpath, "--quiet"], capture_output=True, text=True)
                if c.returncode != 0:
                    failures.append(f"{label}: check fails")
            print(f"{cname}: done", file=sys.stderr, flush=True)
    for f in failures:
        print("FAIL", f)
    print(f"{runs - len(failures)} of {runs} runs meshed and passed check")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
