"""Call overhead of the Python module over the C++ solve.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_overhead.py [--quick]

For each scene it times R calls of every way to call, round-robin (call 1 of
every way, then call 2 of every way, ...), so that the load of other
processes falls on all of them alike, and reads the C++ solve's own time from
stats["kernel_seconds"] of the same calls (steady_clock around
Solver::solve, as `collide solve --stats` reports it). Velocities are
restored before each call, untimed. Per call:

    overhead = wall - kernel_seconds   (checks, model choice, stats dict, GIL)
    ratio    = overhead / kernel_seconds

and the table shows medians. At the end each is compared with the value
docs/decisions/0013-python-call-overhead.md measures it against:
    * ratio <= 5% at 1M pairs, for the frame-loop call;
    * overhead <= 20 us per call at 1k contacts, for the default (checked) call.

The ways to call, each a row:
    frame          Solver.solve(..., model=M, schedule=S, out=J, check=False,
                   impacts=False): the frame loop; layouts and indices
                   checked (memory safety), values not, no count over J
    frame+impacts  the same with the default impacts=True (a pass over J)
    checked        Solver.solve(..., schedule=S, out=J): the default check=True
                   and model="auto" (validate() and the model choice)
    collide.solve  the one-shot call: also builds a Solver and a Schedule
    packed frame   the frame call on PackedBodies (collide.pack) of the scene
The ISA is printed next to every figure.
"""

import argparse
import statistics
import time

import numpy as np

import collide

# The values of docs/decisions/0013-python-call-overhead.md.
LIMIT_RATIO = 0.05
LIMIT_SMALL_US = 20.0


def ways(bodies, contacts, model, dtype):
    """(name, call, restore) for every way to call on this scene."""
    n = len(contacts)
    solver = collide.Solver()
    schedule = collide.Schedule(bodies, contacts)
    out = np.empty((3, n), dtype=dtype)
    v0, w0 = bodies.v.copy(), bodies.w.copy()

    def restore():
        np.copyto(bodies.v, v0)
        np.copyto(bodies.w, w0)

    packed = collide.pack(bodies, model, contacts=contacts)
    packed_schedule = collide.Schedule(packed, contacts)
    r0 = packed.records.copy()

    def restore_packed():
        np.copyto(packed.records, r0)

    return [
        ("frame", lambda: solver.solve(bodies, contacts, model=model, schedule=schedule, out=out, check=False,
                                       impacts=False), restore),
        ("frame+impacts", lambda: solver.solve(bodies, contacts, model=model, schedule=schedule, out=out,
                                               check=False), restore),
        ("checked", lambda: solver.solve(bodies, contacts, schedule=schedule, out=out), restore),
        ("collide.solve", lambda: collide.solve(bodies, contacts, out=out), restore),
        ("packed frame", lambda: solver.solve(packed, contacts, schedule=packed_schedule, out=out, check=False,
                                              impacts=False), restore_packed),
    ]


def measure(n, runs, model, dtype=np.float32):
    bodies, contacts = collide.generate("pairs", n, dtype=dtype, model=model)
    calls = ways(bodies, contacts, model, dtype)
    samples = {name: ([], []) for name, _, _ in calls}
    isa = threads = None
    for _ in range(runs):
        for name, call, restore in calls:
            restore()
            t0 = time.perf_counter()
            _, stats = call()
            wall = time.perf_counter() - t0
            samples[name][0].append(wall)
            samples[name][1].append(stats["kernel_seconds"])
            isa, threads = stats["isa"], stats["threads"]
    rows = []
    for name, (walls, kernels) in samples.items():
        overheads = [w - k for w, k in zip(walls, kernels)]
        ratios = [o / k for o, k in zip(overheads, kernels)]
        rows.append((name, isa, threads, statistics.median(walls), statistics.median(kernels),
                     statistics.median(overheads), statistics.median(ratios)))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer calls (a smoke run)")
    args = ap.parse_args()
    big_runs, small_runs = (5, 300) if args.quick else (21, 3000)
    print(f"collide {collide.__version__}; best ISA {collide.best_isa()}; "
          f"SIMD float lanes {collide.simd_width('auto', np.float32)}; float32 scenes")
    results = {}
    for label, n, runs, model in (
        ("1M pairs rigid", 1_000_000, big_runs, "rigid"),
        ("1M pairs particle", 1_000_000, big_runs, "particle"),
        ("1k contacts rigid", 1000, small_runs, "rigid"),
    ):
        results[label] = measure(n, runs, model)
    print(f"{'scene':18} {'call':14} {'isa':6} {'thr':>3} {'wall':>11} {'kernel':>11} {'overhead':>11} {'ratio':>8}")
    for label, rows in results.items():
        for name, isa, threads, wall, kernel, over, ratio in rows:
            print(f"{label:18} {name:14} {isa:6} {threads:3d} {wall * 1e6:9.1f}us {kernel * 1e6:9.1f}us "
                  f"{over * 1e6:9.1f}us {100 * ratio:7.2f}%")
    verdicts = []
    for label in ("1M pairs rigid", "1M pairs particle"):
        for name in ("frame", "packed frame"):
            row = next(r for r in results[label] if r[0] == name)
            verdicts.append((f"{label}, {name}: overhead / C++ solve = {100 * row[6]:.2f}% ({row[1]})",
                             row[6] <= LIMIT_RATIO, f"<= {100 * LIMIT_RATIO:.0f}%"))
    row = next(r for r in results["1k contacts rigid"] if r[0] == "checked")
    verdicts.append((f"1k contacts rigid, checked (the default call): overhead = {row[5] * 1e6:.1f} us ({row[1]})",
                     row[5] * 1e6 <= LIMIT_SMALL_US, f"<= {LIMIT_SMALL_US:.0f} us"))
    print()
    for text, ok, limit in verdicts:
        print(f"{'within' if ok else 'OVER  '} {text}   limit {limit}")


if __name__ == "__main__":
    main()
