"""The GIL is released while biotet computes: another Python thread runs meanwhile, and a
long call can be stopped."""

import _thread
import signal
import sys
import threading
import time

import pytest

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


def test_an_exception_from_the_progress_callable_stops_the_call():
    """It is raised in the call's place, at the stage it was raised in (it was ignored, and
    meshing went on to the end)."""
    s = biotet.read_surface(DATA / "brain_20k.stl")
    seen = []

    class Enough(Exception):
        pass

    def progress(stage):
        seen.append(stage)
        if len(seen) == 2:
            raise Enough(stage)

    with pytest.raises(Enough):
        biotet.mesh(s.points, s.triangles, progress=progress)
    assert len(seen) == 2, seen


def test_ctrl_c_stops_a_long_call():
    """Ctrl-C (here `_thread.interrupt_main`, what the signal handler does) during a call stops
    it at its next stage with KeyboardInterrupt; the waiting thread looks at the signals every
    100 ms, so the first progress call waits long enough to be seen."""
    s = biotet.read_surface(DATA / "brain_20k.stl")
    seen = []

    def progress(stage):
        seen.append(stage)
        if len(seen) == 1:
            _thread.interrupt_main()
            time.sleep(0.5)

    # Python's own Ctrl-C handler, as in a terminal (a run started in the background inherits
    # SIGINT ignored, and then interrupt_main does nothing).
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            biotet.mesh(s.points, s.triangles, surface_tolerance=0.5, progress=progress)
    finally:
        signal.signal(signal.SIGINT, before)
    assert len(seen) == 1, seen
