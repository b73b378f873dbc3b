"""The GIL is released while solving, and a loop of solves leaks nothing."""

import gc
import sys
import threading
import time
import tracemalloc

import numpy as np
import pytest

import collide


def test_other_thread_runs_during_a_long_solve():
    bodies, contacts = collide.generate("debris", 1_000_000, dtype=np.float64)
    solver = collide.Solver(path="scalar", threads=1)
    schedule = collide.Schedule(bodies, contacts)
    ticks = []
    solving = threading.Event()
    done = threading.Event()

    def counter():
        solving.wait()
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.0005)

    t = threading.Thread(target=counter)
    t.start()
    start = time.perf_counter()
    solving.set()
    _, stats = solver.solve(bodies, contacts, schedule=schedule)
    end = time.perf_counter()
    done.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    # The solve is long enough to tell (a held GIL would leave at most the
    # switch-interval tick or two), and the other thread ticked all along.
    assert stats["kernel_seconds"] > 0.05, stats
    assert len(during) >= 10, (len(during), stats["kernel_seconds"])


def test_no_reference_or_memory_leaks():
    bodies, contacts = collide.generate("pairs", 2000, dtype=np.float32)
    solver = collide.Solver(threads=1)
    schedule = collide.Schedule(bodies, contacts)
    out = np.empty((3, len(contacts)), dtype=np.float32)
    arrays = [bodies.v, bodies.w, contacts.a, out]

    def loop(k):
        for _ in range(k):
            J, stats = collide.solve(bodies, contacts)
            solver.solve(bodies, contacts, schedule=schedule, out=out)
            ref = collide.reference_solve(bodies, contacts)
            collide.impulse_error(J, ref)
            del J, stats, ref

    loop(20)  # warm-up: caches, interned strings
    gc.collect()
    counts = [sys.getrefcount(a) for a in arrays]
    objects = len(gc.get_objects())
    loop(200)
    gc.collect()
    assert [sys.getrefcount(a) for a in arrays] == counts
    assert len(gc.get_objects()) <= objects + 5  # a leaked dict or array per call would be 200+
    tracemalloc.start()
    snap0 = tracemalloc.take_snapshot()
    loop(200)
    gc.collect()
    snap1 = tracemalloc.take_snapshot()
    tracemalloc.stop()
    growth = sum(s.size_diff for s in snap1.compare_to(snap0, "filename"))
    # 200 iterations of a J of 24 kB each: a leaked array per call would be 4.8 MB.
    assert growth < 100_000, growth


def test_thread_limit_keeps_the_results():
    # collide.dask runs each task under ThreadLimit(its threads): generate,
    # islands and solve on one thread give the bytes they give on all.
    def run():
        bodies, contacts = collide.generate("debris", 200_000, friction=True, dtype=np.float32)
        labels = collide.islands(bodies, contacts).labels.copy()
        J, _ = collide.solve(bodies, contacts)
        return bodies.v.tobytes(), bodies.w.tobytes(), J.tobytes(), labels.tobytes()

    everywhere = run()
    with collide._collide.ThreadLimit(1):
        assert run() == everywhere
    assert run() == everywhere
    for bad in (0, -1):
        with pytest.raises(ValueError, match="threads must be >= 1"):
            collide._collide.ThreadLimit(bad)
