#!/usr/bin/env python3
"""Figures of collide.dask (docs/distributed.md, "Figures").

(a) One scene: N independent pairs (16M by default) written once as a binary
    scene file pair into a temporary directory, then
      * in-process: collide.load + collide.solve with --threads threads +
        np.save of J, v and w renamed over the previous ones (file to file,
        as the distributed run, with its guarantee);
      * distributed: collide.dask.solve of the file pair on a LocalCluster of
        --workers single-threaded processes, everything included (the load
        and check on the client, the islands, the partitions, the workers'
        reads and their in-place writes of J, v and w);
    and the outputs compared byte for byte (exit 1 if they differ).
(b) Many scenes: collide.dask.solve_scenes over --scenes generated scenes
    (pairs and debris of --scene-n contacts, generated on the workers) on a
    LocalCluster of 1 worker and then of --workers workers.

Prints each time and the ratios, and the rows of the figures table of
docs/distributed.md. The clusters are started (and their workers warmed up:
collide imported, the instruction-set choice measured) before anything is
timed. Memory: the 16M-pair scene is about 2.8 GB on disk in float and the
in-process solve holds it in memory, the comparison a second copy of v, w
and J.

    PYTHONPATH=build/python /usr/bin/python3 scripts/dask_bench.py              # the full run
    PYTHONPATH=build/python /usr/bin/python3 scripts/dask_bench.py --n 100000 --scenes 10   # a smoke run
"""

import argparse
import os
import platform
import shutil
import sys
import tempfile
import time

import numpy as np

import collide
import collide.dask as cd


def cluster(workers):
    import distributed

    c = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
    client = distributed.Client(c)
    # Warm-up, untimed: every worker imports collide and measures its ISA choice.
    cd.solve_scenes([{"kind": "pairs", "n": 1000, "seed": s} for s in range(2 * workers)], client, sample=100)
    return c, client


def one_scene(args, tmp):
    bp, cp = os.path.join(tmp, "bodies.npz"), os.path.join(tmp, "contacts.npz")
    t = time.perf_counter()
    bodies, contacts = collide.generate("pairs", args.n, seed=1, dtype=np.dtype(args.dtype))
    collide.save(bp, cp, bodies, contacts)
    del bodies, contacts
    print(f"(a) {args.n:,} pairs written to {tmp} in {time.perf_counter() - t:.1f} s", flush=True)

    def in_process():
        t = time.perf_counter()
        bodies, contacts = collide.load(bp, cp)
        load = time.perf_counter() - t
        t = time.perf_counter()
        J, stats = collide.solve(bodies, contacts, threads=args.threads)
        solve = time.perf_counter() - t
        # The same job as the distributed one, file to file: J, v and w
        # saved as .npy files (what collide.dask.solve writes), under
        # temporary names renamed over the previous outputs, the guarantee
        # collide.dask.solve gives (a failed run leaves them as they were).
        # np.save straight over the old files would reuse their page-cache
        # pages, which on a VM that hands free memory back to its host is
        # several times faster than writing new pages.
        t = time.perf_counter()
        os.makedirs(os.path.join(tmp, "in-process"), exist_ok=True)
        for name, array in (("J", J), ("v", bodies.v), ("w", bodies.w)):
            path = os.path.join(tmp, "in-process", f"{name}.npy")
            np.save(path + ".tmp.npy", array)
            os.replace(path + ".tmp.npy", path)
        save = time.perf_counter() - t
        return {"load": load, "solve": solve, "save": save, "file_to_file": load + solve + save,
                "kernel": stats["kernel_seconds"]}, (J.tobytes(), bodies.v.tobytes(), bodies.w.tobytes())

    # Both sides alternated, each side's best run kept: a VM hands back
    # memory its guest has not touched for a while, and whichever run first
    # touches it pays for that, not for its own work.
    c, client = cluster(args.workers)
    runs, dask_runs = [], []
    try:
        for _ in range(args.runs):
            # Both sides write into an empty directory: the previous run's
            # outputs are removed before the clock starts, so that neither
            # pays for freeing them in its rename.
            shutil.rmtree(os.path.join(tmp, "in-process"), ignore_errors=True)
            figures, expected = in_process()
            runs.append(figures)
            shutil.rmtree(os.path.join(tmp, "out"), ignore_errors=True)
            t = time.perf_counter()
            solution = cd.solve((bp, cp), client, out_dir=os.path.join(tmp, "out"), threads=1)
            seconds = time.perf_counter() - t
            same = all(np.ascontiguousarray(x).tobytes() == y for x, y in zip(solution[:3], expected))
            dask_runs.append((seconds, solution.stats, same))
            del solution, expected
    finally:
        client.close()
        c.close()
    a = min(runs, key=lambda r: r["file_to_file"])
    dask_seconds, s, _ = min(dask_runs, key=lambda r: r[0])
    load_seconds, solve_seconds, save_seconds, file_to_file = a["load"], a["solve"], a["save"], a["file_to_file"]
    stats = {"kernel_seconds": a["kernel"]}
    same = all(r[2] for r in dask_runs)
    print(f"    in-process collide.solve, {args.threads} threads: {solve_seconds:.3f} s "
          f"(kernel {stats['kernel_seconds']:.3f} s; collide.load before it {load_seconds:.3f} s)")
    print(f"    collide.dask.solve, {args.workers} workers: {dask_seconds:.3f} s (client load and check "
          f"{s['read_seconds']:.3f} s, islands {s['islands_seconds']:.3f} s, partitions {s['partitions']}, "
          f"kernels {s['kernel_seconds']:.3f} s summed, partition tasks "
          f"{', '.join(f'{x:.3f}' for x in s['partition_seconds'])} s)")
    print(f"    in-process file to file (load + solve + np.save of J, v, w, renamed into place): {file_to_file:.3f} s "
          f"(save {save_seconds:.3f} s)")
    print(f"    throughput, dask / in-process: {solve_seconds / dask_seconds:.3f} of the solve alone, "
          f"{file_to_file / dask_seconds:.2f} of file to file")
    print(f"    same bytes (J, v, w), every run: {'yes' if same else 'NO'}", flush=True)
    print("    every run (in-process file to file / dask): " +
          ", ".join(f"{r['file_to_file']:.3f} / {d[0]:.3f} s" for r, d in zip(runs, dask_runs)))
    return same, {"solve": solve_seconds, "load": load_seconds, "save": save_seconds, "file_to_file": file_to_file,
                  "dask": dask_seconds}


def many_scenes(args):
    kinds = ("pairs", "debris")
    specs = [{"kind": kinds[i % 2], "n": args.scene_n, "seed": i + 1, "dtype": args.dtype} for i in range(args.scenes)]
    seconds = {}
    for workers in (1, args.workers):
        c, client = cluster(workers)
        try:
            t = time.perf_counter()
            table = cd.solve_scenes(specs, client, sample=args.sample)
            seconds[workers] = time.perf_counter() - t
        finally:
            client.close()
            c.close()
        print(f"(b) solve_scenes, {args.scenes} scenes of {args.scene_n:,} contacts, {workers} worker(s): "
              f"{seconds[workers]:.2f} s; max error {table['max_error_eps'].max():.2f} eps", flush=True)
    print(f"    1 worker / {args.workers} workers: {seconds[1] / seconds[args.workers]:.2f}")
    return seconds


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--n", type=int, default=16_000_000, help="pairs of the one-scene run (default 16M)")
    p.add_argument("--scenes", type=int, default=200, help="scenes of the many-scene run (default 200)")
    p.add_argument("--scene-n", type=int, default=100_000, help="contacts per scene (default 100k)")
    p.add_argument("--sample", type=int, default=10_000, help="contacts per scene compared with the reference")
    p.add_argument("--workers", type=int, default=2, help="Dask worker processes, one thread each (default 2)")
    p.add_argument("--threads", type=int, default=2, help="threads of the in-process solve (default 2)")
    p.add_argument("--dtype", default="float32", choices=("float32", "float64"))
    p.add_argument("--runs", type=int, default=2, help="runs of each side of (a), alternated; the best is kept")
    p.add_argument("--tmp", default=None, help="directory for the scene files (default: a new one in $TMPDIR)")
    args = p.parse_args()
    tmp = tempfile.mkdtemp(prefix="collide-dask-bench-", dir=args.tmp)
    try:
        same, a = one_scene(args, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    b = many_scenes(args)
    print(f"\nFigures rows ({platform.processor() or platform.machine()}, {os.cpu_count()} hardware threads, "
          f"{args.dtype}):\n")
    print("| run | reference | collide.dask | ratio |")
    print("| --- | ---: | ---: | ---: |")
    print(f"| one scene, {args.n:,} pairs, binary file to files | {a['file_to_file']:.3f} s (load {a['load']:.3f} + "
          f"solve {a['solve']:.3f} on {args.threads} threads + save {a['save']:.3f}) | {a['dask']:.3f} s "
          f"({args.workers} workers, all included) | {a['file_to_file'] / a['dask']:.2f} of in-process throughput "
          f"({a['solve'] / a['dask']:.3f} of the solve alone) |")
    print(f"| {args.scenes} scenes of {args.scene_n:,} contacts | {b[1]:.2f} s (1 worker) | {b[args.workers]:.2f} s "
          f"({args.workers} workers) | {b[1] / b[args.workers]:.2f} (1 worker / {args.workers}) |")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
