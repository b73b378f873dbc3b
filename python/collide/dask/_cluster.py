"""The LocalCluster that collide.dask starts when it is given no client: in
a process of its own, so that its workers never import the caller's script.

Why a process of its own: Dask starts worker processes with
multiprocessing's "spawn", and a spawned process first imports the main
module of the process that started it. Started from the caller's process,
the workers would run the caller's script again; a script that calls
``collide.dask.solve(..., workers=2)`` at its top level, without an ``if
__name__ == "__main__":`` guard, would then start a cluster again in every
worker, and those workers would do the same, for ever. Started from here,
the workers import this module instead (guarded below), so the caller's
script runs the same with or without the guard, and a worker restarted by
its nanny is as safe.

    python -m collide.dask._cluster N

starts a LocalCluster of N single-threaded worker processes, prints the
scheduler's address on one line of stdout and serves until its stdin closes
(the caller closes it when done, or dies), then closes the cluster.
"""

from __future__ import annotations

import contextlib
import os
import select
import subprocess
import sys

# How long the cluster may take to start (a loaded machine spawning many workers).
START_SECONDS = 300


@contextlib.contextmanager
def local_cluster(workers):
    """Starts the cluster process; yields the scheduler's address; closes
    the cluster when the block ends. RuntimeError when it does not start."""
    package_root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ)
    env["PYTHONPATH"] = package_root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    proc = subprocess.Popen([sys.executable, "-m", "collide.dask._cluster", str(int(workers))], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, env=env, text=True)
    try:
        ready, _, _ = select.select([proc.stdout], [], [], START_SECONDS)
        address = proc.stdout.readline().strip() if ready else ""
        if not address:
            proc.kill()
            raise RuntimeError(f"collide.dask: the LocalCluster of {workers} worker processes did not start "
                               f"(exit status {proc.wait()}; its messages are above)")
        yield address
    finally:
        if proc.stdin and not proc.stdin.closed:
            proc.stdin.close()
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def main():
    import distributed

    with distributed.LocalCluster(n_workers=int(sys.argv[1]), threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        print(cluster.scheduler_address, flush=True)
        sys.stdin.read()  # until the caller closes it


if __name__ == "__main__":
    main()
