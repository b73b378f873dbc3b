"""Call overhead of the Python module over the C++ solve (issue 14's targets).

    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_overhead.py [--quick]

For each size it times R calls of Solver.solve (prebuilt Solver and Schedule,
J written into a preallocated `out`, the frame-loop use) and reads the C++
solve's own time from stats["kernel_seconds"] of the same calls (steady_clock
around Solver::solve, as `collide solve --stats` reports it). Velocities are
restored before each call, untimed. Medians of the per-call figures:

    overhead  = wall - kernel_seconds   (validation, model check, stats dict, GIL)
    ratio     = wall / kernel_seconds - 1

Targets: ratio <= 5% at 1M pairs, overhead <= 20 us per call at 1k contacts.
Three ways to call, each a row:
    frame          Solver.solve(..., model=M, schedule=S, out=J, check=False):
                   the frame loop; layouts and indices checked, values not
    checked        the same with check=True and model="auto" (the default):
                   validate() and the model choice are passes over every array
    collide.solve  the one-shot call: also builds a Solver and a Schedule Prints the ISA next to every figure.
"""

import argparse
import statistics
import time

import numpy as np

import collide


def measure(n, runs, dtype, model, mode):
    bodies, contacts = collide.generate("pairs", n, dtype=dtype, model=model)
    v0, w0 = bodies.v.copy(), bodies.w.copy()
    solver = collide.Solver()
    schedule = collide.Schedule(bodies, contacts)
    out = np.empty((3, n), dtype=dtype)
    walls, kernels = [], []
    stats = None
    for _ in range(runs):
        np.copyto(bodies.v, v0)
        np.copyto(bodies.w, w0)
        t0 = time.perf_counter()
        if mode == "collide.solve":
            _, stats = collide.solve(bodies, contacts, out=out)
        elif mode == "checked":
            _, stats = solver.solve(bodies, contacts, schedule=schedule, out=out)
        else:
            _, stats = solver.solve(bodies, contacts, model=model, schedule=schedule, out=out, check=False)
        walls.append(time.perf_counter() - t0)
        kernels.append(stats["kernel_seconds"])
    overheads = [w - k for w, k in zip(walls, kernels)]
    return statistics.median(walls), statistics.median(kernels), statistics.median(overheads), stats


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer runs")
    args = ap.parse_args()
    big_runs, small_runs = (5, 200) if args.quick else (15, 2000)
    print(f"collide {collide.__version__}; SIMD float lanes {collide.simd_width('auto', np.float32)}")
    rows = []
    for label, n, runs, model in (
        ("1M pairs rigid", 1_000_000, big_runs, "rigid"),
        ("1M pairs particle", 1_000_000, big_runs, "particle"),
        ("1k contacts rigid", 1000, small_runs, "rigid"),
    ):
        for mode in ("frame", "checked", "collide.solve"):
            wall, kernel, over, stats = measure(n, runs, np.float32, model, mode)
            rows.append((label, mode, stats["isa"], stats["threads"], wall, kernel, over))
    print(f"{'scene (float32)':20} {'call':14} {'isa':6} {'thr':>3} {'wall':>11} {'kernel':>11} "
          f"{'overhead':>11} {'ratio':>8}")
    for label, call, isa, threads, wall, kernel, over in rows:
        print(f"{label:20} {call:14} {isa:6} {threads:3d} {wall * 1e6:9.1f}us {kernel * 1e6:9.1f}us "
              f"{over * 1e6:9.1f}us {100 * over / kernel:7.2f}%")


if __name__ == "__main__":
    main()
