"""The GIL is released while biotet computes: another Python thread runs meanwhile."""

import sys
import threading
import time

import biotet
from conftest import DATA


def test_a_python_thread_runs_while_meshing():
    """With the switch interval made huge, a thread holding the GIL keeps it until it blocks:
    had biotet held the GIL through the call, this (main) thread could not wake up before the
    meshing thread ended, and would count nothing while it runs. No timing threshold: one
    iteration while the meshing runs shows the release."""
    s = biotet.read_surface(DATA / "brain_20k.stl")
    started, done = threading.Event(), threading.Event()

    def mesh():
        try:
            biotet.mesh(s.points, s.triangles, threads=1, progress=lambda stage: started.set())
        finally:
            started.set()
            done.set()

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        worker = threading.Thread(target=mesh)
        worker.start()
        started.wait()
        ticks = 0
        while not done.is_set():
            ticks += 1
            time.sleep(0)  # releases the GIL, so the meshing thread's progress calls get it
        worker.join()
    finally:
        sys.setswitchinterval(interval)
    assert ticks > 0
