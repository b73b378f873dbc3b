"""The LocalCluster that collide.dask starts when it is given no client: in
a process of its own, so that its workers never import the caller's script.

Why a process of its own: Dask starts worker processes with
multiprocessing's "spawn", and a spawned process first imports the main
module of the process that started it. Started from the caller's process,
the workers would run the caller's script again; a script that calls
``collide.dask.solve(..., workers=2)`` at its top level, without an ``if
__name__ == "__main__":`` guard, would then start a cluster again in every
worker, and those workers would do the same, for ever. Started from a
process whose main program is the ``-c`` line below, the workers import no
main module at all, so the caller's script runs the same with or without the
guard, and a worker restarted by its nanny is as safe.

    python -c "from collide.dask._cluster import main; main()" N

starts a LocalCluster of N single-threaded worker processes, prints the
scheduler's address on one line of stdout and serves until its stdin closes
(the caller closes it when done, or dies), then closes the cluster.

Why ``-c`` and not ``python -m collide.dask._cluster``: ``-m`` runs this
module through runpy after its package, which imports it, so Python warns
("'collide.dask._cluster' found in sys.modules after import of package
'collide.dask', but prior to execution"), and a spawned worker runs the main
module of its parent again, the same way, warning once more per worker. A
``-c`` program is no module: nothing runs twice, and the workers import
nothing of it.
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
    program = "from collide.dask._cluster import main; main()"
    proc = subprocess.Popen([sys.executable, "-c", program, str(int(workers))], stdin=subprocess.PIPE,
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
    """The cluster process (see the module's notes): serves until stdin closes."""
    import distributed

    # No dashboard; the scheduler's HTTP server (health, metrics) on a free
    # port, not on 8787, which another cluster may hold (Dask then warns).
    with distributed.LocalCluster(n_workers=int(sys.argv[1]), threads_per_worker=1, processes=True,
                                  dashboard_address=None, scheduler_kwargs={"dashboard_address": ":0"}) as cluster:
        print(cluster.scheduler_address, flush=True)
        sys.stdin.read()  # until the caller closes it
