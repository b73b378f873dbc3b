"""What runs on a worker: one partition of a scene, or one whole scene of
``solve_scenes``. NumPy and collide only, so that the functions can be
called (and tested) without Dask; the workers import them by name.

A partition is a set of whole islands. It is solved as a scene of its own:
its contacts in input order, in the sequence the client gives them (the
scene's order, or the whole scene's colour order), its bodies (every body its contacts name,
immovable ones included) in ascending index order, the contacts' indices
remapped to them. Islands never see each other's results, so the impulses
and the velocities of its movable bodies are bit for bit those of one solve
of the whole scene (collide/islands.hpp). An immovable body may be named by
several partitions; the solver never changes it, so a partition sent as
arrays returns its movable bodies only, and one of a file writes every body
it names (an immovable one with its input values, whoever writes it).

A warm start (collide.solve's ``warm=``) goes with its contacts: a partition
solves from the columns of the scene's J for its contacts, in the sequence
it solves them. A contact's warm impulse is applied to its own bodies only
(docs/collision-law.md, "The warm start"), so islands stay independent and
the bits those of one warm solve of the whole scene.
"""

from __future__ import annotations

import contextlib
import functools
import os
import time

import numpy as np

import collide

from ._files import MappedImpulses, MappedNpz, write_columns


def local_bodies(a, b):
    """The bodies contacts ``a``, ``b`` (uint32) name, ascending, and the
    contacts' indices into that list (uint32): ``(bodies, a_local,
    b_local)``. ``bodies`` is a slice when the named bodies are a range of
    consecutive indices (independent pairs: then a worker's body rows are
    views, and its v and w are solved in place), else an int64 array."""
    m = len(a)
    if m == 0:
        return slice(0, 0), a, b
    first = int(min(a.min(), b.min()))
    span = int(max(a.max(), b.max())) + 1 - first
    if m * 8 < span:
        # A few contacts spread over many bodies: sort what is named.
        bodies, inverse = np.unique(np.concatenate([a, b]), return_inverse=True)
        inverse = inverse.astype(np.uint32)
        return bodies.astype(np.int64), inverse[:m], inverse[m:]
    # Linear in the span of the indices: mark, list, number.
    a0, b0 = a - np.uint32(first), b - np.uint32(first)
    named = np.zeros(span, dtype=bool)
    named[a0] = True
    named[b0] = True
    if named.all():
        return slice(first, first + span), a0, b0
    bodies = np.flatnonzero(named)
    number = np.empty(span, dtype=np.uint32)
    number[bodies] = np.arange(len(bodies), dtype=np.uint32)
    return bodies + first, number[a0], number[b0]


def sub_scene(bodies, contacts, rows):
    """Contacts ``rows`` (in that order) of a scene of arrays and the bodies
    they name, as a new scene over copies: ``(Bodies, Contacts, body_ids)``."""
    a, b = contacts.a[rows], contacts.b[rows]
    ids, la, lb = local_bodies(a, b)
    if isinstance(ids, slice):
        ids = np.arange(ids.start, ids.stop, dtype=np.int64)
    sub_bodies = collide.Bodies(*(np.ascontiguousarray(getattr(bodies, f)[..., ids])
                                  for f in ("inv_mass", "inv_inertia", "q", "p", "v", "w")))
    optional = {k: (None if getattr(contacts, k) is None else np.ascontiguousarray(getattr(contacts, k)[rows]))
                for k in ("e", "mu")}
    sub_contacts = collide.Contacts(la, lb, np.ascontiguousarray(contacts.c[:, rows]),
                                    np.ascontiguousarray(contacts.n[:, rows]), optional["e"], contacts.uniform_e,
                                    optional["mu"])
    return sub_bodies, sub_contacts, ids


def checked_warm(warm, bodies, contacts):
    """Checks ``warm``, a warm start for the scene ``bodies``, ``contacts``
    (itself checked), as collide.solve checks it, with collide.solve's
    errors: the array's type, dtype, shape and layout (TypeError), its
    length, memory shared with what a solve writes, and every J finite and
    within 120 degrees of its normal (ValueError naming ``warm[:, k]``, k the
    contact's row in the scene). The tasks solve with check=False, so these
    are checked once, on the whole scene, where the message can name the
    scene's row and not the partition's."""
    check_warm_array(warm, bodies, contacts)
    refusal = first_refused_warm(warm, bodies, contacts)
    if refusal is not None:
        raise ValueError(refusal)


def check_warm_array(warm, bodies, contacts):
    """The checks of :func:`checked_warm` that read no value of ``warm``:
    type, dtype, shape, layout, length and memory shared with bodies.v or
    bodies.w, as collide.solve makes them before it reads the scene's
    values."""
    dtype = bodies.dtype

    def none(rows):
        return np.zeros((rows, 0), dtype)

    # collide.solve's own checks of the array, on a scene of no contacts:
    # a TypeError is about the array itself; its one ValueError, the length
    # against no contacts, is judged below against the scene's.
    probe = collide.Bodies(np.zeros(0, dtype), none(3), none(4), none(3), none(3), none(3)), collide.Contacts(
        np.zeros(0, np.uint32), np.zeros(0, np.uint32), none(3), none(3))
    try:
        collide.Solver(iteration="accumulate", warm_start=True).solve(*probe, warm=warm, check=False, impacts=False)
    except ValueError:
        pass
    if warm.shape[1] != len(contacts):  # collide.solve's words
        raise ValueError(f"solve.warm has {warm.shape[1]} elements, contacts.a has {len(contacts)}")
    for name in ("v", "w"):
        # collide.solve refuses it; the tasks' copies would not notice.
        if np.may_share_memory(warm, getattr(bodies, name)):
            raise ValueError(f"bodies.{name} and solve.warm share memory: the solve writes bodies.{name} while it "
                             "reads solve.warm")


#: Contacts screened at a time by first_refused_warm (float64 temporaries).
_SCREEN_BLOCK = 1 << 20


def first_refused_warm(warm, bodies, contacts):
    """collide.solve's message for the first contact (by row) whose J in
    ``warm`` it refuses, or None. The library's rule (finite, and
    J . n >= warm_start_least_cosine |J| |n| in double) is screened here in
    NumPy, block by block, a little tighter, so that every J it refuses is a
    suspect whatever the last bits of the screen's sums; each suspect,
    in row order, is then judged by collide.solve itself, on that contact
    alone, whose message (naming it ``warm[:, 0]``) is the scene's with its
    row put back."""
    slack = collide.warm_start_least_cosine * (1 - 1e-6)
    with np.errstate(all="ignore"):
        for start in range(0, warm.shape[1], _SCREEN_BLOCK):
            j = warm[:, start:start + _SCREEN_BLOCK].astype(np.float64)
            n = contacts.n[:, start:start + _SCREEN_BLOCK].astype(np.float64)
            along = j[0] * n[0] + j[1] * n[1] + j[2] * n[2]
            size = np.sqrt(j[0] * j[0] + j[1] * j[1] + j[2] * j[2]) * np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
            suspects = ~(along >= slack * size) | ~np.isfinite(j).all(axis=0)
            for k in np.flatnonzero(suspects) + start:
                sub_bodies, sub_contacts, _ = sub_scene(bodies, contacts, np.array([k]))
                try:
                    collide.solve(sub_bodies, sub_contacts, iteration="accumulate",
                                  warm=np.ascontiguousarray(warm[:, k:k + 1]), impacts=False)
                except ValueError as e:
                    head = "solve: warm[:, 0] = "
                    if not str(e).startswith(head):
                        raise
                    return f"solve: warm[:, {k}] = {str(e)[len(head):]}"
    return None


def on_its_threads(task):
    """A task ``task(x, options)`` run on its share of the machine: at most
    ``options["threads"]`` threads in every parallel loop of the library
    (generate, load, islands, the solvers) while it runs; 0: all of them.
    A Dask worker of one thread then keeps to one core instead of competing
    with its neighbours for every core."""

    @functools.wraps(task)
    def run(x, options):
        threads = options["threads"]
        with collide._collide.ThreadLimit(threads) if threads > 0 else contextlib.nullcontext():
            return task(x, options)

    return run


def _solve(bodies, contacts, options, warm=None):
    """collide.solve of an already checked scene and warm start (the client
    ran the checks on the whole scene and chose the model there) with the
    task's solve keywords."""
    return collide.solve(bodies, contacts, model=options["model"], **options["solve"], warm=warm, check=False,
                         impacts=False)


def _part_stats(stats, contacts, bodies, started, read_seconds):
    return {"contacts": contacts, "bodies": bodies, "kernel_seconds": stats["kernel_seconds"],
            "allocate_seconds": stats["allocate_seconds"],
            "schedule_seconds": stats["schedule_seconds"], "batches": stats["batches"], "isa": stats["isa"],
            "read_seconds": read_seconds, "seconds": time.perf_counter() - started}


@on_its_threads
def solve_part_arrays(part, options):
    """A partition sent as arrays (``solve`` of a scene in memory), with
    the columns of the warm start for its contacts when there is one:
    returns ``(J, v, w, movable, stats)``, v and w of its movable bodies
    only, whose indices in the partition's body list are ``movable``."""
    started = time.perf_counter()
    bodies = collide.Bodies(*part["bodies"])
    contacts = collide.Contacts(*part["contacts"])
    J, stats = _solve(bodies, contacts, options, part.get("warm"))
    movable = np.flatnonzero(bodies.inv_mass != 0)
    return J, bodies.v[:, movable], bodies.w[:, movable], movable, _part_stats(stats, len(contacts), len(bodies),
                                                                             started, 0.0)


def machine():
    """What names the running kernel (Linux's boot id), or None where
    there is none: processes that give the same name share one page cache,
    so what one writes into a file is what the other reads, unflushed."""
    try:
        with open("/proc/sys/kernel/random/boot_id", encoding="ascii") as f:
            return f.read().strip() or None
    except OSError:
        return None


def contact_rows(part):
    """The contact rows of a partition of a scene file: a slice, or rows of
    the order file the client wrote (int64)."""
    if part["order"] is None:
        return slice(part["first"], part["end"])
    order = np.load(part["order"], mmap_mode="r")
    return np.array(order[part["first"]:part["end"]], dtype=np.int64)


@on_its_threads
def solve_part_files(part, options):
    """A partition of a scene file: reads its rows from the mapped scene
    files, solves them, and writes its J and the v, w of every body it names
    in place into the output .npy files the client allocated (an immovable
    body named by several partitions is written by each with its input
    values: the same bytes). Where the partition's contacts, or its bodies,
    are a range of rows (independent pairs), they are read as views of the
    mapping, and J, or v and w, written back by one positioned write per
    row; scattered rows are written through a mapping of the output. A
    warm start file (``part["warm"]``, checked by the client) is read the
    same way, the columns of the partition's contacts only. Writing the
    same values again (a task run again after its worker was
    lost) gives the same bytes. Returns stats."""
    started = time.perf_counter()
    dtype = np.dtype(part["dtype"])
    rows = contact_rows(part)
    cfile, bfile = MappedNpz(part["contacts_path"]), MappedNpz(part["bodies_path"])
    a = np.asarray(cfile["a"][rows]).astype(np.uint32, copy=False)
    b = np.asarray(cfile["b"][rows]).astype(np.uint32, copy=False)
    ids, la, lb = local_bodies(a, b)
    contacts = collide.Contacts(la, lb, cfile.stacked(("cx", "cy", "cz"), rows, dtype),
                                cfile.stacked(("nx", "ny", "nz"), rows, dtype), cfile.stacked(("e",), rows, dtype)[0],
                                mu=cfile.stacked(("mu",), rows, dtype)[0] if part["friction"] else None)
    # The inverses as collide.load computes them (the readers' own code).
    inv_mass, inv_inertia = collide._collide.inverses(bfile.stacked(("m",), ids, dtype)[0],
                                                      bfile.stacked(("Ix", "Iy", "Iz"), ids, dtype))
    vw = {k: bfile.stacked(tuple(k + axis for axis in "xyz"), ids, dtype) for k in ("v", "w")}
    # The solve writes v and w: a view of the read-only input is copied.
    vw = {k: x if x.flags.writeable else np.array(x) for k, x in vw.items()}
    bodies = collide.Bodies(inv_mass, inv_inertia, bfile.stacked(("qw", "qx", "qy", "qz"), ids, dtype),
                            bfile.stacked(("px", "py", "pz"), ids, dtype), vw["v"], vw["w"])
    warm = None if part.get("warm") is None else MappedImpulses(part["warm"]).columns(rows, dtype)
    read_seconds = time.perf_counter() - started
    J, stats = _solve(bodies, contacts, options, warm)
    # Ranges of rows by positioned writes, scattered rows through a mapping.
    out = {}
    for k, x, where in (("J", J, rows), ("v", vw["v"], ids), ("w", vw["w"], ids)):
        if isinstance(where, slice):
            write_columns(part["outputs"][k], where.start, x)
        else:
            out[k] = np.load(part["outputs"][k], mmap_mode="r+")
            out[k][:, where] = x
    if part["client_machine"] is None or part["client_machine"] != machine():
        # Another kernel reads the outputs: the writes go to the shared
        # storage before the task ends. On the client's own kernel they
        # are in the page cache the client reads, a synchronous write to
        # the disk would only cost time.
        for array in out.values():
            array.flush()
        for k in ("J", "v", "w"):
            if k not in out:
                with open(part["outputs"][k], "rb") as f:
                    os.fsync(f.fileno())
    return _part_stats(stats, len(contacts), len(bodies), started, read_seconds)


# ---------------------------------------------------------------------------
# One scene of solve_scenes.
# ---------------------------------------------------------------------------


def scene_of(entry):
    """The scene of a solve_scenes entry: files loaded, or generated."""
    if "bodies" in entry:
        return collide.load(entry["bodies"], entry["contacts"], dtype=entry.get("dtype"))
    spec = {k: v for k, v in entry.items() if k not in ("name", "accuracy", "warm", "index")}
    kind, n = spec.pop("kind"), spec.pop("n")
    if "dtype" in spec:
        spec["dtype"] = np.dtype(spec["dtype"])
    return collide.generate(kind, n, **spec)


def scene_warm(entry, bodies, contacts):
    """The warm start of a solve_scenes entry (None, an array, or the path
    of an impulses file read here), checked against its scene as
    collide.solve checks it; the error names the entry."""
    warm = entry.get("warm")
    if warm is None:
        return None
    try:
        if not isinstance(warm, np.ndarray):
            impulses = MappedImpulses(warm)
            if impulses.count != len(contacts):
                raise ValueError(f"{warm}: warm holds {impulses.count} impulses but the scene holds {len(contacts)} "
                                 "contacts: a warm start gives one J per contact, in the same order")
            warm = impulses.columns(slice(None), bodies.dtype)
        checked_warm(warm, bodies, contacts)
    except (TypeError, ValueError) as e:
        kind = TypeError if isinstance(e, TypeError) else ValueError
        raise kind(f"collide.dask.solve_scenes: scene {entry['index']}: {e}") from None
    return warm


@on_its_threads
def scene_row(entry, options):
    """Solves one scene on the worker and measures it: the row of
    ``solve_scenes``. The error and the drifts are measured on the scene's
    first ``sample`` contacts, as ``collide report`` measures its rows,
    solved on their own with the model and the options the whole scene ran
    (and the first columns of its warm start) and compared with the long
    double reference replaying its order, passes and warm start. In input
    order with one pass and no warm start the law applies contacts in input
    order, so the sample's impulses are the same with or without the
    contacts after them: they equal the whole solve's first ones (checked).
    In the colour order, with several passes, or from a warm start (whose
    visit applies every contact's J before the first pass), the contacts
    after the sample change those, and the sample is a scene of its own."""
    solve = dict(options["solve"], accuracy=entry.get("accuracy", options["solve"]["accuracy"]))
    bodies, contacts = scene_of(entry)
    warm = scene_warm(entry, bodies, contacts)
    isl = collide.islands(bodies, contacts, threads=options["threads"])
    k = min(options["sample"], len(contacts))
    sample_bodies, sample_contacts, _ = sub_scene(bodies, contacts, np.arange(k))
    sample_warm = None if warm is None else np.ascontiguousarray(warm[:, :k])
    J, stats = collide.solve(bodies, contacts, model=options["model"], warm=warm, **solve)
    ref = collide.reference_solve(sample_bodies, sample_contacts, order=solve["order"], passes=solve["passes"],
                                  iteration=solve["iteration"], warm=sample_warm)
    J_sample, _ = collide.solve(sample_bodies, sample_contacts, model=stats["model"], warm=sample_warm, **solve)
    alone_is_whole = solve["order"] == "input" and solve["passes"] == 1 and warm is None
    if alone_is_whole and J_sample.tobytes() != np.ascontiguousarray(J[:, :k]).tobytes():
        raise RuntimeError(f"{entry['name']}: the sample's impulses differ from the whole solve's")
    error = collide.impulse_error(J_sample, ref)
    drift = collide.conservation_drift(sample_bodies, ref)
    return {
        "scene": entry["name"],
        "model": stats["model"],
        "precision": stats["precision"],
        "accuracy": stats["accuracy"],
        "contacts": len(contacts),
        "islands": isl.count,
        "largest_island": isl.largest,
        "collisions_per_second": stats["collisions_per_second"],
        "max_error_eps": float(np.max(error)) if k else 0.0,
        "momentum_drift": drift["momentum_drift"],
        "angular_momentum_drift": drift["angular_momentum_drift"],
        "error_sample": k,
    }
