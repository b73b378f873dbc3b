"""collide.dask: one scene split across Dask workers by its islands, or many
scenes solved and measured across them.

A scene's islands (:func:`collide.islands`: the groups of contacts joined by
shared movable bodies) never see each other's results, so each can be solved
anywhere, and the result is bit for bit that of :func:`collide.solve` on one
machine. :func:`solve` groups the islands into partitions balanced by contact
count and solves each partition on a worker with the ordinary solver;
:func:`solve_scenes` solves many scenes, one task each, and returns a pandas
table of speed, error and conservation. One island is one sequential chain of
dependencies: a scene whose largest island holds most of the contacts is
solved mostly on one worker, and :func:`solve` warns (:class:`IslandWarning`).

Dask (``distributed``) and pandas are imported when a function needs them,
so ``import collide`` and ``import collide.dask`` work without them.
docs/distributed.md describes when distribution helps, the API and the
command (``python -m collide.dask``).
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
import uuid
import warnings
from typing import NamedTuple

import numpy as np

import collide

from ._files import MappedImpulses
from ._partition import partition_islands, single_contact_ends
from . import _cluster, _tasks

__all__ = ["GIANT_ISLAND_SHARE", "IslandWarning", "SCENE_COLUMNS", "Solution", "partition_islands", "solve",
           "solve_scenes"]

#: The share of a scene's contacts in its largest island above which
#: :func:`solve` warns that distribution cannot help much.
GIANT_ISLAND_SHARE = 0.5


class IslandWarning(UserWarning):
    """The largest island holds most of the scene's contacts: it is solved on
    one worker, in its solve order, whatever the number of workers."""


class Solution(NamedTuple):
    """What :func:`solve` returns. For a scene of arrays, ``v`` and ``w`` are
    the caller's ``bodies.v`` and ``bodies.w``, updated in place as
    :func:`collide.solve` updates them; for scene files, read-only maps of
    the output files ``J.npy``, ``v.npy`` and ``w.npy``."""

    J: np.ndarray
    v: np.ndarray
    w: np.ndarray
    stats: dict


def _need(module):
    """Imports a Dask module (or pandas), or raises ImportError saying what to install."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise ImportError(f"collide.dask needs {module.split('.')[0]} (Debian: python3-dask python3-distributed "
                          f"python3-pandas; pip: dask distributed pandas): {e}") from e


@contextlib.contextmanager
def _connected(client, workers=None):
    """The client to run on: ``client`` itself, a new Client to a scheduler
    address, the default client of this process, or a new LocalCluster
    (``workers`` processes of one thread; all cores by default), closed
    afterwards. That cluster runs in a process of its own (_cluster.py), so
    that its workers do not import the caller's script: a script that calls
    collide.dask at its top level, without an ``if __name__ ==
    "__main__":`` guard, runs as it does with one."""
    distributed = _need("distributed")
    if isinstance(client, distributed.Client):
        yield client
        return
    if isinstance(client, str):
        with distributed.Client(client) as c:
            yield c
        return
    if client is not None:
        raise TypeError(f"client must be a distributed.Client, a scheduler address or None, got "
                        f"{type(client).__name__}")
    try:
        yield distributed.default_client()
        return
    except ValueError:
        pass
    n = workers or os.cpu_count() or 1
    with _cluster.local_cluster(n) as address, distributed.Client(address) as c:
        yield c


def _wait(futures, progress, what):
    """Waits for every future and returns their results in order. With
    ``progress``, a bar on stderr (dask.distributed.progress) when stderr is
    a terminal, else a line per finished task."""
    distributed = _need("distributed")
    if progress and futures:
        if sys.stderr.isatty():
            with contextlib.redirect_stdout(sys.stderr):
                distributed.progress(futures)
            print(file=sys.stderr)
        else:
            for done, _ in enumerate(distributed.as_completed(futures), start=1):
                print(f"collide-dask: {done}/{len(futures)} {what} done", file=sys.stderr, flush=True)
    return [f.result() for f in futures]


def _options(model, sample=0, warm_start=False, **solve):
    """The options of the tasks: ``model``, ``sample``, ``threads`` (the
    task's share of the machine, _tasks.on_its_threads), ``warm_start``
    (whether a warm start is given) and ``solve``, the keywords every task
    passes to collide.solve (accuracy, order, passes, iteration, threads,
    isa), checked and normalised by the library as collide.solve checks
    them, with its messages (the ISA's name only: the workers' CPUs decide
    whether they have it; a warm start with iteration="repeat" gets
    collide.solve's refusal)."""
    if model not in ("auto", "rigid", "sphere", "particle"):
        raise ValueError(f"model must be 'auto', 'rigid', 'sphere' or 'particle', got {model!r}")
    checked = collide._collide.solve_options(warm_start=warm_start, **solve)
    del checked["path"]
    warm_start = checked.pop("warm_start")  # collide.solve takes warm=, the J itself, not this flag
    return {"model": model, "sample": int(sample), "threads": checked["threads"], "warm_start": warm_start,
            "solve": checked}


def _scene_model(bodies, contacts, model, loaded):
    """The model the whole scene runs, after every value of it is checked by
    the library's validate() (ValueError naming the array and the element;
    ``loaded``: the arrays come from collide.load, whose reader checked
    every value, so only the indices are checked again): the model
    collide.solve would run. Partitions run this model, not their own
    cheapest, which could differ from the whole scene's."""
    chosen = collide._collide.choose_model(bodies, contacts, check=not loaded)
    if model == "auto":
        return chosen
    misfit = collide._collide.model_misfit(bodies, contacts, model)
    if misfit:
        raise ValueError(f"model '{model}' does not fit the scene: {misfit}")
    return model


def _prepare(bodies, contacts, options, loaded=False):
    """What the client does before any task: checks the scene and chooses
    its model, computes its islands, warns about a giant one, and in the
    colour order finds the whole scene's solve order. Returns the options of
    the tasks, the islands, their figures, their time and the solve order
    (None: the input order).

    A partition's contacts are solved in input order, in the sequence its
    rows are given: the scene's order, or in the colour order the whole
    scene's solve order (Schedule.solve_order). A colour order of the
    partition alone would differ wherever an island spans other windows of
    contacts than in the whole scene; the whole scene's sequence solved in
    input order is the colour-order solve, bit for bit (the law applied
    sequentially, docs/collision-law.md, "The solve order")."""
    task = dict(options, model=_scene_model(bodies, contacts, options["model"], loaded))
    t = time.perf_counter()
    isl = collide.islands(bodies, contacts)
    islands_seconds = time.perf_counter() - t
    m = len(contacts)
    share = isl.largest / m if m else 0.0
    figures = {"islands": isl.count, "largest_island": isl.largest, "largest_island_share": share}
    _warn_if_giant(figures, m, stacklevel=5)
    solve_order = None
    if options["solve"]["order"] != "input":
        task["solve"] = dict(options["solve"], order="input")
        if isl.largest > 1:  # else no two contacts share a movable body: every order is the input's
            solve_order = collide.Schedule(bodies, contacts, order=options["solve"]["order"]).solve_order()
    return task, isl, figures, islands_seconds, solve_order


def _warn_if_giant(figures, contacts, stacklevel):
    if contacts and figures["largest_island_share"] > GIANT_ISLAND_SHARE:
        warnings.warn(IslandWarning(
            f"collide.dask.solve: the largest island holds {figures['largest_island']:,} of {contacts:,} contacts "
            f"({100 * figures['largest_island_share']:.0f}%; {figures['islands']:,} islands): it is solved on one "
            "worker, in its solve order, so distributing this scene gains little"), stacklevel=stacklevel)


def _partitions(isl, requested, client, solve_order=None):
    """The contacts grouped by partition, each group in the sequence its
    partition solves them (ascending, the scene's order, or the whole
    scene's ``solve_order``), and the contacts of each partition and where
    its group ends: ``(order, counts, ends)``. ``order`` is None when the
    groups are already in the scene's order (partition 0 the first contacts,
    and so on: a scene of many small islands in input order), so that
    positions in it are contact rows."""
    p = requested if requested is not None else max(1, sum(client.nthreads().values()))
    if int(p) < 1:
        raise ValueError(f"partitions must be >= 1, got {p}")
    m = len(isl.labels)
    if isl.count == m and isl.largest <= 1:
        # Every contact an island of its own, labelled by its row: the
        # partitions are ranges, found without arrays the length of the scene.
        ends = single_contact_ends(m, int(p))
        if ends is not None:
            return None, np.diff(ends, prepend=np.int64(0)), ends
    island_part = partition_islands(isl.sizes, int(p))
    used = int(island_part.max()) + 1 if len(island_part) else 1
    # Small integers, so that NumPy's stable sort of them is a radix sort.
    dtype = np.uint8 if used <= 256 else np.uint16 if used <= 65536 else np.uint32
    contact_part = island_part.astype(dtype)[isl.labels]
    counts = np.bincount(contact_part, minlength=used)
    ends = np.cumsum(counts)
    if solve_order is not None:
        return solve_order[np.argsort(contact_part[solve_order], kind="stable")].astype(np.int64), counts, ends
    if len(contact_part) < 2 or bool(np.all(contact_part[1:] >= contact_part[:-1])):
        return None, counts, ends
    return np.argsort(contact_part, kind="stable"), counts, ends


def _rows(order, count, end):
    """The contact rows of the partition whose group ends at position
    ``end`` of ``order``, in the sequence they are solved: a slice where
    they are consecutive and ascending, else an int64 array."""
    if order is None:
        return slice(int(end - count), int(end))
    rows = order[end - count:end]
    if int(rows[-1]) - int(rows[0]) == count - 1 and (count < 2 or bool(np.all(np.diff(rows) == 1))):
        return slice(int(rows[0]), int(rows[0]) + int(count))
    return rows


def _is_scene_files(scene):
    return isinstance(scene, (tuple, list)) and len(scene) == 2 and all(
        isinstance(x, (str, os.PathLike)) for x in scene)


def solve(scene, client=None, *, partitions=None, model="auto", accuracy="fast", order="input", passes=1,
          iteration="repeat", warm=None, dtype=None, threads=1, isa=None, out_dir=None, workers=None,
          progress=False):
    """Solves one scene on Dask workers, island by island; the same bytes as
    :func:`collide.solve` on one machine. Returns a :class:`Solution` ``(J,
    v, w, stats)``.

    ``scene`` is ``(bodies, contacts)``, either :class:`collide.Bodies` and
    :class:`collide.Contacts` (their ``v`` and ``w`` updated in place, as
    collide.solve does; the partitions travel to the workers through the
    scheduler), or the paths of a binary scene file pair (``.npz``, what
    :func:`collide.save` writes) on storage every worker can read. For files
    the client checks the whole scene (:func:`collide.load`) and computes
    its islands; each worker maps the files and reads only its partition's
    rows, and writes its J and its movable bodies' v and w in place into
    ``out_dir``'s ``J.npy`` (3, M), ``v.npy`` and ``w.npy`` (3, N), which the
    client preallocates (v and w hold the input's for bodies no contact
    moves) and renames into place once every partition is done: bodies and
    contacts never travel through the scheduler. ``dtype`` (files only)
    converts, as collide.load does; default: the file's precision.

    The islands are grouped into ``partitions`` partitions (default: the
    cluster's threads) balanced by contact count (:func:`partition_islands`);
    the grouping never changes the result. Each partition runs
    :func:`collide.solve` with the model chosen for the whole scene
    (``model``: "auto", "rigid", "sphere", "particle"), ``accuracy``
    ("fast" or "accurate"), ``passes``, ``iteration`` ("repeat" or
    "accumulate"), ``threads`` solver threads per task
    (default 1: one per Dask thread) and ``isa``, in the whole scene's
    ``order`` ("input" or "colour": for the colour order the client finds
    the scene's solve order and each partition solves its contacts in it).
    Bad values of these raise collide.solve's errors. A task lost with its
    worker is run again by Dask, writing the same bytes.

    ``warm`` (with iteration="accumulate", as collide.solve's ``warm``) is a
    warm start, the J of a solve before of the same contacts in the same
    order; each partition starts from the columns of its contacts. For
    arrays it is a (3, M) array of the scene's dtype; for scene files the
    path of an impulses file every worker can read: an ``.npz`` with members
    jx, jy, jz (``collide solve --out-impulses x.npz``) or a (3, M) ``.npy``,
    such as the ``J.npy`` of an earlier solve, ``out_dir``'s own included
    (the outputs replace it only once every partition is done), converted to
    the scene's precision as a scene file is. The client checks it with
    collide.solve's rules and messages before any task runs (the contact
    named by its row in the scene; for a file, the file named too).

    ``client``: a ``distributed.Client``, a scheduler address, or None (the
    default client of this process, else a LocalCluster of ``workers``
    single-threaded processes, all cores by default, for this call).
    ``progress=True`` shows the tasks' progress on stderr.

    Raises TypeError or ValueError for bad input (naming the array and
    element, or the file, row and column) before anything is written, and
    warns with :class:`IslandWarning` when the largest island holds more than
    ``GIANT_ISLAND_SHARE`` of the contacts. ``stats``: collisions, bodies,
    islands, largest_island, largest_island_share, partitions (their contact
    counts), model, precision, accuracy, order, passes, iteration,
    warm_start (True or False), call_seconds (the
    whole call, wall time), kernel_seconds (the partitions' solves, summed),
    collisions_per_second (collisions / kernel_seconds: the kernels'
    throughput, as collide.solve reports it), allocate_seconds (the allocate
    phases of those solves, summed: each task's one-shot solver grows its
    buffers and touches their pages before its kernels run, time
    kernel_seconds leaves out), partition_seconds (each partition's task on
    its worker, read to write), islands_seconds, and for files read_seconds
    (the load and check on the client) and outputs (the three paths)."""
    started = time.perf_counter()
    options = _options(model, warm_start=warm is not None, accuracy=accuracy, order=order, passes=passes,
                       iteration=iteration, threads=threads, isa=isa)
    if _is_scene_files(scene):
        if out_dir is None:
            raise ValueError("collide.dask.solve: scene files need out_dir, where the workers write J, v and w")
        if warm is not None and not isinstance(warm, (str, os.PathLike)):
            raise TypeError(f"collide.dask.solve: for scene files, warm is the path of an impulses file every "
                            f"worker can read (.npz with jx, jy, jz, or a (3, M) .npy such as a J.npy this "
                            f"function wrote), got {type(warm).__name__}")
        return _solve_files(scene, client, partitions, options, dtype, os.fspath(out_dir), warm, workers, progress,
                            started)
    if not (isinstance(scene, (tuple, list)) and len(scene) == 2):
        raise TypeError("collide.dask.solve: scene must be (bodies, contacts): collide.Bodies and collide.Contacts, "
                        "or the paths of a binary scene file pair")
    bodies, contacts = scene
    if not isinstance(bodies, collide.Bodies) or not isinstance(contacts, collide.Contacts):
        raise TypeError(f"collide.dask.solve: scene must be (collide.Bodies, collide.Contacts) or two paths, got "
                        f"({type(bodies).__name__}, {type(contacts).__name__})")
    if dtype is not None and np.dtype(dtype) != bodies.dtype:
        raise TypeError(f"collide.dask.solve: dtype={np.dtype(dtype)} but the arrays are {bodies.dtype}: arrays are "
                        "solved in their own precision")
    if out_dir is not None:
        raise ValueError("collide.dask.solve: out_dir is for scene files; arrays are updated in place")
    return _solve_arrays(bodies, contacts, warm, client, partitions, options, workers, progress, started)


def _stats(scene_model, precision, collisions, body_count, figures, counts, options, results, started, **extra):
    """The stats of a distributed solve (see :func:`solve`): as in
    collide.solve's, collisions_per_second is the kernels' throughput,
    collisions / kernel_seconds; the whole call's wall time is
    call_seconds."""
    kernel_seconds = sum(r["kernel_seconds"] for r in results)
    return {"collisions": collisions, "bodies": body_count, **figures, "partitions": [int(c) for c in counts if c],
            "model": scene_model, "precision": "float" if precision == np.float32 else "double",
            "accuracy": options["solve"]["accuracy"], "order": options["solve"]["order"],
            "passes": options["solve"]["passes"], "iteration": options["solve"]["iteration"],
            "warm_start": options["warm_start"], "call_seconds": time.perf_counter() - started,
            "kernel_seconds": kernel_seconds,
            "collisions_per_second": collisions / kernel_seconds if kernel_seconds > 0 else 0.0,
            "allocate_seconds": sum(r["allocate_seconds"] for r in results),
            "partition_seconds": [r["seconds"] for r in results], **extra}


def _solve_arrays(bodies, contacts, warm, client, partitions, options, workers, progress, started):
    if bodies.dtype != contacts.dtype:
        raise TypeError(f"bodies are {bodies.dtype} but contacts are {contacts.dtype}: one precision per solve")
    if warm is not None:
        # collide.solve's order: the array before the scene's values, its
        # values after them.
        _tasks.check_warm_array(warm, bodies, contacts)
    task, isl, figures, islands_seconds, solve_order = _prepare(bodies, contacts, options)
    refusal = None if warm is None else _tasks.first_refused_warm(warm, bodies, contacts)
    if refusal is not None:
        raise ValueError(refusal)
    with _connected(client, workers) as c:
        order, counts, ends = _partitions(isl, partitions, c, solve_order)
        parts, futures = [], []
        key = f"collide-dask-part-{uuid.uuid4().hex}"
        with warnings.catch_warnings():
            # The partitions go with their tasks, through the scheduler, so
            # that a task lost with its worker can run again elsewhere.
            warnings.filterwarnings("ignore", message="Large object of size")
            for p, count in enumerate(counts):
                if count == 0:
                    continue
                rows = _rows(order, count, ends[p])
                sub_bodies, sub_contacts, ids = _tasks.sub_scene(bodies, contacts, rows)
                payload = {"bodies": [getattr(sub_bodies, f) for f in ("inv_mass", "inv_inertia", "q", "p", "v", "w")],
                           "contacts": [sub_contacts.a, sub_contacts.b, sub_contacts.c, sub_contacts.n, sub_contacts.e,
                                        sub_contacts.uniform_e, sub_contacts.mu]}
                if warm is not None:
                    # The warm start's columns for the partition's contacts, in its sequence.
                    payload["warm"] = np.ascontiguousarray(warm[:, rows])
                parts.append((rows, ids))
                futures.append(c.submit(_tasks.solve_part_arrays, payload, task, key=f"{key}-{p}", pure=False))
        results = _wait(futures, progress, "partitions")
    # Every partition is solved: only now is anything of the caller's written.
    J = np.empty((3, len(contacts)), dtype=bodies.dtype)
    for (rows, ids), (j, v, w, movable, _) in zip(parts, results):
        J[:, rows] = j
        bodies.v[:, ids[movable]] = v
        bodies.w[:, ids[movable]] = w
    stats = _stats(task["model"], bodies.dtype, len(contacts), len(bodies), figures, counts, options,
                   [r[4] for r in results], started, islands_seconds=islands_seconds)
    return Solution(J, bodies.v, bodies.w, stats)


def _solve_files(paths, client, partitions, options, dtype, out_dir, warm, workers, progress, started):
    bodies_path, contacts_path = (os.path.abspath(os.fspath(p)) for p in paths)
    for path in (bodies_path, contacts_path):
        if not path.endswith(".npz"):
            raise ValueError(f"collide.dask.solve: {path}: workers map their rows of a binary scene file (.npz); "
                             "`collide convert` writes one from CSV")
    t = time.perf_counter()
    bodies, contacts = collide.load(bodies_path, contacts_path, dtype=dtype)
    warm_path = None if warm is None else _check_warm_file(warm, bodies, contacts, contacts_path)
    read_seconds = time.perf_counter() - t
    task, isl, figures, islands_seconds, solve_order = _prepare(bodies, contacts, options, loaded=True)
    os.makedirs(out_dir, exist_ok=True)
    out_dir = os.path.abspath(out_dir)
    final = {k: os.path.join(out_dir, f"{k}.npy") for k in ("J", "v", "w")}
    partial = {k: os.path.join(out_dir, f".{k}.npy.partial") for k in final}
    order_path = os.path.join(out_dir, ".contact-order.npy")
    n, m = len(bodies), len(contacts)
    precision = bodies.dtype
    try:
        # The outputs, allocated here. The workers write J and the v, w of
        # every body a contact names; the client writes the input values of
        # the bodies in no island (no contact names them, or they are
        # immovable: their values, whoever writes them), if there are any.
        j = np.lib.format.open_memmap(partial["J"], mode="w+", dtype=precision, shape=(3, m))
        del j
        unnamed = np.flatnonzero(isl.body_labels == collide.Islands.NONE)
        for k in ("v", "w"):
            out = np.lib.format.open_memmap(partial[k], mode="w+", dtype=precision, shape=(3, n))
            if len(unnamed):
                out[:, unnamed] = getattr(bodies, k)[:, unnamed]
            out.flush()
            del out
        common = {"bodies_path": bodies_path, "contacts_path": contacts_path, "body_count": n, "dtype": precision.name,
                  "friction": contacts.mu is not None, "outputs": partial, "client_machine": _tasks.machine(),
                  "warm": warm_path}
        with _connected(client, workers) as c:
            order, counts, ends = _partitions(isl, partitions, c, solve_order)
            # A partition of consecutive contacts (a scene of independent
            # pairs: all of them) is sent as its range of rows; the others
            # read their rows from an order file beside the outputs.
            rows = [_rows(order, count, e) if count else None for count, e in zip(counts, ends)]
            if any(isinstance(r, np.ndarray) for r in rows):
                np.save(order_path, order.astype(np.uint32))
            del bodies, contacts, isl, order, unnamed, solve_order
            key = f"collide-dask-part-{uuid.uuid4().hex}"
            futures = []
            for p, (count, e, r) in enumerate(zip(counts, ends, rows)):
                if count == 0:
                    continue
                if isinstance(r, slice):
                    part = dict(common, order=None, first=r.start, end=r.stop)
                else:
                    part = dict(common, order=order_path, first=int(e - count), end=int(e))
                futures.append(c.submit(_tasks.solve_part_files, part, task, key=f"{key}-{p}", pure=False))
            results = _wait(futures, progress, "partitions")
        for k in final:
            os.replace(partial[k], final[k])
    finally:
        for path in (*partial.values(), order_path):
            with contextlib.suppress(FileNotFoundError):
                os.remove(path)
    stats = _stats(task["model"], precision, m, n, figures, counts, options, results, started,
                   islands_seconds=islands_seconds, read_seconds=read_seconds, outputs=final)
    return Solution(*(np.load(final[k], mmap_mode="r") for k in ("J", "v", "w")), stats)


def _check_warm_file(warm, bodies, contacts, contacts_path):
    """The absolute path of the warm start file ``warm`` for the loaded
    scene, after the checks collide.solve makes of an array (the scene's
    values were checked by collide.load), the file and the contact named:
    the workers then read their columns of it unchecked."""
    path = os.path.abspath(os.fspath(warm))
    impulses = MappedImpulses(path)
    if impulses.count != len(contacts):  # `collide solve --warm-start`'s words
        raise ValueError(f"{path}: warm holds {impulses.count} impulses but {contacts_path} holds {len(contacts)} "
                         "contacts: a warm start gives one J per contact, in the same order")
    refusal = _tasks.first_refused_warm(impulses.columns(slice(None), bodies.dtype), bodies, contacts)
    if refusal is not None:
        raise ValueError(f"{path}: {refusal.removeprefix('solve: ')}")
    return path


#: The columns of the table :func:`solve_scenes` returns, in order.
SCENE_COLUMNS = ("scene", "model", "precision", "accuracy", "contacts", "islands", "largest_island",
                 "collisions_per_second", "max_error_eps", "momentum_drift", "angular_momentum_drift", "error_sample")

_SPEC_KEYS = {"kind", "n", "seed", "model", "friction", "shuffle", "dtype", "name", "accuracy"}
_FILE_KEYS = {"bodies", "contacts", "dtype", "name", "accuracy"}


def _entry(i, item):
    """One solve_scenes entry as a dict a worker can act on, checked here so
    that a mistake is named before anything runs."""
    where = f"collide.dask.solve_scenes: scene {i}"
    if _is_scene_files(item):
        item = {"bodies": item[0], "contacts": item[1]}
    if not isinstance(item, dict):
        raise TypeError(f"{where}: a (bodies, contacts) pair of paths or a dict, got {type(item).__name__}")
    entry = dict(item)
    if "dtype" in entry and entry["dtype"] is not None:
        entry["dtype"] = np.dtype(entry["dtype"]).name
    if "bodies" in entry:
        unknown = set(entry) - _FILE_KEYS
        if unknown or "contacts" not in entry:
            raise ValueError(f"{where}: a file entry has 'bodies' and 'contacts' (and 'dtype', 'name', 'accuracy'), "
                             f"got {sorted(entry)}")
        for k in ("bodies", "contacts"):
            entry[k] = os.path.abspath(os.fspath(entry[k]))
            if not os.path.isfile(entry[k]):
                raise FileNotFoundError(2, f"{where}: no such scene file", entry[k])
        entry.setdefault("name", os.path.basename(entry["bodies"]))
    else:
        unknown = set(entry) - _SPEC_KEYS
        if unknown or "kind" not in entry or "n" not in entry:
            raise ValueError(f"{where}: a generated scene has 'kind' and 'n' and may have "
                             f"{sorted(_SPEC_KEYS - {'kind', 'n'})}; got {sorted(entry)}")
        if entry["kind"] not in ("pairs", "debris", "pile"):
            raise ValueError(f"{where}: kind must be 'pairs', 'debris' or 'pile', got {entry['kind']!r}")
        entry.setdefault("name", " ".join(f"{k}={entry[k]}" for k in ("kind", "n", "seed", "model", "friction",
                                                                       "shuffle", "dtype") if k in entry))
    if "accuracy" in entry:
        try:
            entry["accuracy"] = collide._collide.solve_options(accuracy=entry["accuracy"])["accuracy"]
        except (TypeError, ValueError) as e:
            raise type(e)(f"{where}: {e}") from None
    return entry


def _scene_warm(i, item):
    """One warm start of solve_scenes as its worker takes it: an array, or
    the absolute path of a file; the scene's worker checks it against the
    scene, which only it holds."""
    where = f"collide.dask.solve_scenes: scene {i}"
    if isinstance(item, np.ndarray):
        return item
    if isinstance(item, (str, os.PathLike)):
        path = os.path.abspath(os.fspath(item))
        if not os.path.isfile(path):
            raise FileNotFoundError(2, f"{where}: no such warm start file", path)
        return path
    raise TypeError(f"{where}: a warm start is None, a (3, M) array or the path of an impulses file, got "
                    f"{type(item).__name__}")


def solve_scenes(scenes, client=None, *, model="auto", accuracy="fast", order="input", passes=1,
                 iteration="repeat", warm=None, sample=10_000, threads=1, isa=None, workers=None, progress=False):
    """Solves many scenes, one task each, and measures each against the
    reference; returns a pandas DataFrame, one row per scene in the order
    given, columns ``SCENE_COLUMNS``: scene (its name), model (the one that
    ran), precision, accuracy, contacts, islands, largest_island,
    collisions_per_second (the solve's, from its stats), max_error_eps (the
    largest impulse error on the sample, in eps units of the impulse scale,
    bound ``collide.error_bound_eps``), momentum_drift and
    angular_momentum_drift (:func:`collide.conservation_drift` on the
    sample) and error_sample (contacts in the sample).

    Each entry of ``scenes`` is a scene file pair (a tuple of two paths, or a
    dict with "bodies", "contacts" and optionally "dtype", "name",
    "accuracy"), read by the worker, or the parameters of
    :func:`collide.generate` as a dict ("kind", "n", and optionally "seed",
    "model", "friction", "shuffle", "dtype", "name", "accuracy"), generated
    on the worker, so nothing is stored. Each scene is solved whole by
    :func:`collide.solve` with ``model``, ``accuracy``, ``order``,
    ``passes``, ``iteration``, ``threads`` (solver threads per task) and ``isa``; the
    sample is the scene's first ``sample`` contacts, as ``collide report``
    samples, solved alone with the same options and compared with
    :func:`collide.reference_solve` replaying them. In input order with one
    pass the sample's impulses are the whole solve's first ones (checked);
    in the colour order, or with several passes, the contacts after the
    sample change them, and the sample measures the solver on a scene of
    its own. ``client``, ``workers`` and ``progress`` as for :func:`solve`.

    ``warm`` (with iteration="accumulate") is a list with one warm start per
    scene, in the order of ``scenes``: None (a cold start), a (3, M) array
    of the scene's dtype, or the path of an impulses file (.npz with jx, jy,
    jz, or a (3, M) .npy) the workers read. The scene's worker checks it
    with collide.solve's rules and messages, naming the scene by its
    number; the sample starts from its first columns, and the reference
    from the same (the sample is then a scene of its own: a warm start's
    visit applies every contact's J before the first pass).

    An entry that is not understood raises before anything runs (naming the
    entry); a scene file that is bad raises the reader's error (file, row,
    column)."""
    pandas = _need("pandas")
    if warm is not None and (isinstance(warm, (np.ndarray, str, os.PathLike, dict)) or not hasattr(warm, "__iter__")):
        raise TypeError(f"collide.dask.solve_scenes: warm is a list, one warm start (or None) per scene, got "
                        f"{type(warm).__name__}")
    warm = None if warm is None else list(warm)
    options = _options(model, sample, warm_start=warm is not None and any(w is not None for w in warm),
                       accuracy=accuracy, order=order, passes=passes, iteration=iteration, threads=threads, isa=isa)
    if options["sample"] < 0:
        raise ValueError(f"sample must be >= 0, got {sample}")
    entries = [_entry(i, item) for i, item in enumerate(scenes)]
    if warm is not None:
        if len(warm) != len(entries):
            raise ValueError(f"collide.dask.solve_scenes: warm has {len(warm)} entries for {len(entries)} scenes: "
                             "one per scene, in their order (None for a cold start)")
        entries = [entry if w is None else dict(entry, warm=_scene_warm(i, w), index=i)
                   for i, (entry, w) in enumerate(zip(entries, warm))]
    with _connected(client, workers) as c:
        key = f"collide-dask-scene-{uuid.uuid4().hex}"
        with warnings.catch_warnings():
            # A warm start given as an array goes with its task, as a
            # partition's arrays do.
            warnings.filterwarnings("ignore", message="Large object of size")
            futures = [c.submit(_tasks.scene_row, entry, options, key=f"{key}-{i}", pure=False)
                       for i, entry in enumerate(entries)]
        rows = _wait(futures, progress, "scenes")
    return pandas.DataFrame(rows, columns=list(SCENE_COLUMNS))
