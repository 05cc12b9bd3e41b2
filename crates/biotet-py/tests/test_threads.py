"""The GIL is released while biotet computes: a Python thread keeps running."""

import threading

import biotet
from conftest import DATA


def test_a_python_thread_runs_while_meshing():
    s = biotet.read_surface(DATA / "brain_20k.stl")
    done = threading.Event()
    ticks = []

    def count():
        while not done.is_set():
            ticks.append(1)

    def mesh():
        try:
            biotet.mesh(s.points, s.triangles, threads=1)
        finally:
            done.set()

    counter = threading.Thread(target=count)
    worker = threading.Thread(target=mesh)
    # Start the mesher first and count only while it runs: with the GIL held for the whole run
    # the counter would get (almost) no turns; switches every 5 ms would still give it some,
    # so compare with the loop's own speed over the same run.
    worker.start()
    counter.start()
    worker.join()
    counter.join()
    during = len(ticks)
    # A held GIL lets the counter run only at the interpreter's switch interval (5 ms), a few
    # hundred iterations per switch at most; released, it spins freely: millions.
    assert during > 100_000, during
