"""Ctrl-C during a solve of many passes: a SIGINT (here from a timer
thread, as the terminal sends it) stops the solve after the pass in
progress, within a bounded time, with KeyboardInterrupt saying how many
passes ran; v, w (or the records) and out= are bitwise a solve of that many
passes. The module's SIGINT handler is installed only for the main thread's
solves and while Python's default handler is in place, and the one it
replaced is back afterwards."""

import ctypes
import os
import re
import signal
import threading
import time

import numpy as np
import pytest

import collide

FIELDS = ("inv_mass", "inv_inertia", "q", "p", "v", "w")
STOPPED = re.compile(r"collide: Ctrl-C stopped the solve after (\d+) of (\d+) passes; "
                     r"v, w \(or the records\) and out= are as those passes left them")


def copy_bodies(bodies):
    return collide.Bodies(*(np.array(getattr(bodies, f), copy=True) for f in FIELDS))


def bits(a):
    a = np.ascontiguousarray(a)
    return a.view(np.uint32 if a.dtype == np.float32 else np.uint64)


def sigint_after(seconds):
    """SIGINT to this process in `seconds`, from another thread: what a
    terminal's Ctrl-C does."""
    timer = threading.Timer(seconds, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def sigint_handler_address():
    """The C handler of SIGINT (struct sigaction's first member on Linux)."""
    libc = ctypes.CDLL(None, use_errno=True)
    buf = ctypes.create_string_buffer(512)
    assert libc.sigaction(signal.SIGINT, None, buf) == 0, ctypes.get_errno()
    return ctypes.c_void_p.from_buffer(buf).value


def seconds_per_pass(bodies, contacts, order):
    _, stats = collide.solve(copy_bodies(bodies), contacts, order=order, passes=20)
    return max(stats["kernel_seconds"] / 20, 1e-6)


@pytest.mark.parametrize("order", ["input", "colour"])
@pytest.mark.parametrize("layout", ["soa", "packed"])
def test_ctrl_c_stops_a_long_solve_on_a_whole_pass(order, layout):
    bodies, contacts = collide.generate("pile", 20, friction=True, dtype=np.float32)
    before = copy_bodies(bodies)
    target = collide.pack(bodies, "rigid") if layout == "packed" else bodies
    out = np.full((3, len(contacts)), np.nan, dtype=np.float32)
    solver = collide.Solver(passes=1_000_000)  # tens of minutes to the end
    timer = sigint_after(0.3)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt) as stop:
        solver.solve(target, contacts, order=order, out=out)
    elapsed = time.monotonic() - start
    timer.join()
    assert elapsed < 5, elapsed
    m = STOPPED.fullmatch(str(stop.value))
    assert m, str(stop.value)
    done = int(m.group(1))
    assert 1 <= done < 1_000_000 and m.group(2) == "1000000"
    after = target.unpack() if layout == "packed" else target
    assert np.isfinite(out).all() and np.isfinite(after.v).all() and np.isfinite(after.w).all()
    # Bitwise the passes done, run to their end.
    J, stats = collide.solve(before, contacts, order=order, passes=done)
    assert stats["passes"] == done
    for x, y in ((out, J), (after.v, before.v), (after.w, before.w)):
        np.testing.assert_array_equal(bits(x), bits(y))


def test_a_solver_stopped_once_solves_every_pass_next_time():
    bodies, contacts = collide.generate("pile", 16, dtype=np.float32)
    passes = max(50, int(2.0 / seconds_per_pass(bodies, contacts, "colour")))  # about two seconds
    solver = collide.Solver(passes=passes)
    timer = sigint_after(0.1)
    with pytest.raises(KeyboardInterrupt, match=STOPPED.pattern):
        solver.solve(copy_bodies(bodies), contacts, order="colour")
    timer.join()
    _, stats = solver.solve(copy_bodies(bodies), contacts, order="colour")
    assert stats["passes"] == passes


def test_a_program_that_handles_sigint_itself_keeps_its_handler():
    bodies, contacts = collide.generate("pile", 12, dtype=np.float32)
    passes = max(50, int(0.5 / seconds_per_pass(bodies, contacts, "colour")))  # about half a second
    seen = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: seen.append(signum))
    try:
        timer = sigint_after(0.1)
        _, stats = collide.solve(bodies, contacts, order="colour", passes=passes)
        timer.join()
        for _ in range(200):  # the handler runs between bytecodes of this thread
            if seen:
                break
            time.sleep(0.01)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert stats["passes"] == passes, "the solve was not stopped"
    assert seen == [signal.SIGINT], "the program's handler saw the signal"


def test_the_handler_is_the_modules_only_during_a_main_thread_solve():
    bodies, contacts = collide.generate("pile", 12, dtype=np.float32)
    passes = max(50, int(0.5 / seconds_per_pass(bodies, contacts, "colour")))
    python = sigint_handler_address()

    def handlers_during(solve_on_main_thread):
        """The SIGINT handlers seen from another thread while the solve ran,
        sampled every few milliseconds from its call to its return (a
        sample of the moment before it installs its own handler included)."""
        seen = {"handlers": set()}
        solving = threading.Event()
        solved = threading.Event()

        def look():
            solving.wait()
            while not solved.is_set():
                seen["handlers"].add(sigint_handler_address())
                time.sleep(0.005)

        def solve():
            solving.set()
            try:
                stats = collide.solve(copy_bodies(bodies), contacts, order="colour", passes=passes)[1]
                seen["passes"] = stats["passes"]
            finally:
                solved.set()

        if solve_on_main_thread:
            looker = threading.Thread(target=look)
            looker.start()
            solve()
            looker.join()
        else:
            solver = threading.Thread(target=solve)
            solver.start()
            look()
            solver.join()
        assert seen["passes"] == passes
        return seen["handlers"]

    assert handlers_during(solve_on_main_thread=True) - {python}, "the module's handler was never seen"
    assert sigint_handler_address() == python, "Python's handler is back"
    assert handlers_during(solve_on_main_thread=False) == {python}
    # One pass has nothing to stop between: nothing is installed.
    seen = []
    looker = threading.Thread(target=lambda: (time.sleep(0.05), seen.append(sigint_handler_address())))
    one_pass = collide.generate("debris", 1_000_000, dtype=np.float32)
    looker.start()
    collide.solve(*one_pass)
    looker.join()
    assert seen == [python]
    # And Ctrl-C after a solve is Python's own KeyboardInterrupt, as before.
    with pytest.raises(KeyboardInterrupt) as e:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(5)
    assert str(e.value) == ""
