"""What runs on a worker: one partition of a scene, or one whole scene of
``solve_scenes``. NumPy and collide only, so that the functions can be
called (and tested) without Dask; the workers import them by name.

A partition is a set of whole islands. It is solved as a scene of its own:
its contacts in input order, its bodies (every body its contacts name,
immovable ones included, as read-only copies) in ascending index order, the
contacts' indices remapped to them. Islands never see each other's results,
so the impulses and the velocities of its movable bodies are bit for bit
those of one solve of the whole scene (collide/islands.hpp). Only movable
bodies are written back: an immovable body may be named by several
partitions, and the solver never changes it.
"""

from __future__ import annotations

import time

import numpy as np

import collide

from ._files import npz_columns

BODY_COLUMNS = ("m", "Ix", "Iy", "Iz", "qw", "qx", "qy", "qz", "px", "py", "pz", "vx", "vy", "vz", "wx", "wy", "wz")
CONTACT_REALS = ("cx", "cy", "cz", "nx", "ny", "nz", "e", "mu")


def local_bodies(a, b, body_count):
    """The bodies contacts ``a``, ``b`` name, ascending, and the contacts'
    indices into that list (uint32): ``(bodies, a_local, b_local)``."""
    m = len(a)
    if m * 8 < body_count:
        # A few contacts among many bodies: sort what is named.
        bodies, inverse = np.unique(np.concatenate([a, b]), return_inverse=True)
        inverse = inverse.astype(np.uint32)
        return bodies, inverse[:m], inverse[m:]
    # Linear in the body count: mark, list, number.
    named = np.zeros(body_count, dtype=bool)
    named[a] = True
    named[b] = True
    bodies = np.flatnonzero(named)
    number = np.empty(body_count, dtype=np.uint32)
    number[bodies] = np.arange(len(bodies), dtype=np.uint32)
    return bodies, number[a], number[b]


def take(column, rows):
    """column[rows], as a slice when the rows are consecutive (a sequential
    read of a mapped file) and as a gather otherwise."""
    if len(rows) and int(rows[-1]) - int(rows[0]) + 1 == len(rows):
        return np.array(column[int(rows[0]):int(rows[-1]) + 1])
    return np.asarray(column[rows])


def sub_scene(bodies, contacts, rows):
    """Contacts ``rows`` (ascending) of a scene of arrays and the bodies they
    name, as a new scene over copies: ``(Bodies, Contacts, body_ids)``."""
    a, b = contacts.a[rows], contacts.b[rows]
    ids, la, lb = local_bodies(a, b, len(bodies))
    sub_bodies = collide.Bodies(*(np.ascontiguousarray(getattr(bodies, f)[..., ids])
                                  for f in ("inv_mass", "inv_inertia", "q", "p", "v", "w")))
    optional = {k: (None if getattr(contacts, k) is None else np.ascontiguousarray(getattr(contacts, k)[rows]))
                for k in ("e", "mu")}
    sub_contacts = collide.Contacts(la, lb, np.ascontiguousarray(contacts.c[:, rows]),
                                    np.ascontiguousarray(contacts.n[:, rows]), optional["e"], contacts.uniform_e,
                                    optional["mu"])
    return sub_bodies, sub_contacts, ids


def _solve(bodies, contacts, options):
    """collide.solve of an already checked scene (the client ran the checks
    on the whole scene and chose the model there)."""
    return collide.solve(bodies, contacts, model=options["model"], accuracy=options["accuracy"],
                         threads=options["threads"], isa=options["isa"], check=False, impacts=False)


def _part_stats(stats, contacts, bodies, started, read_seconds):
    return {"contacts": contacts, "bodies": bodies, "kernel_seconds": stats["kernel_seconds"],
            "schedule_seconds": stats["schedule_seconds"], "batches": stats["batches"], "isa": stats["isa"],
            "read_seconds": read_seconds, "seconds": time.perf_counter() - started}


def solve_part_arrays(part, options):
    """A partition sent as arrays (``solve`` of a scene in memory): returns
    ``(J, v, w, movable, stats)``, v and w of its movable bodies only, whose
    indices in the partition's body list are ``movable``."""
    started = time.perf_counter()
    bodies = collide.Bodies(*part["bodies"])
    contacts = collide.Contacts(*part["contacts"])
    J, stats = _solve(bodies, contacts, options)
    movable = np.flatnonzero(bodies.inv_mass != 0)
    return J, bodies.v[:, movable], bodies.w[:, movable], movable, _part_stats(stats, len(contacts), len(bodies),
                                                                             started, 0.0)


def contact_rows(part):
    """The contact rows of a partition of a scene file: a range, or a slice
    of the order file the client wrote."""
    if part["order"] is None:
        return np.arange(part["first"], part["end"], dtype=np.int64)
    order = np.load(part["order"], mmap_mode="r")
    return np.array(order[part["first"]:part["end"]], dtype=np.int64)


def read_part(part):
    """The partition's scene read from the mapped scene files: ``(Bodies,
    Contacts, rows, body_ids)``."""
    dtype = np.dtype(part["dtype"])
    rows = contact_rows(part)
    cols = npz_columns(part["contacts_path"])
    a = take(cols["a"], rows).astype(np.uint32, copy=False)
    b = take(cols["b"], rows).astype(np.uint32, copy=False)
    ids, la, lb = local_bodies(a, b, part["body_count"])
    real = {k: take(cols[k], rows).astype(dtype, copy=False) for k in CONTACT_REALS}
    contacts = collide.Contacts(la, lb, np.stack([real["cx"], real["cy"], real["cz"]]),
                                np.stack([real["nx"], real["ny"], real["nz"]]), real["e"],
                                mu=real["mu"] if part["friction"] else None)
    bcols = npz_columns(part["bodies_path"])
    x = [take(bcols[k], ids).astype(dtype, copy=False) for k in BODY_COLUMNS]
    # The inverses as collide.load computes them (the readers' own code).
    bodies = collide.from_physical(x[0], np.stack(x[1:4]), np.stack(x[4:8]), np.stack(x[8:11]), np.stack(x[11:14]),
                                   np.stack(x[14:17]), dtype=dtype)
    return bodies, contacts, rows, ids


def solve_part_files(part, options):
    """A partition of a scene file: reads its rows, solves them, and writes
    its J and the v, w of its movable bodies in place into the output .npy
    files the client allocated. Writing the same values again (a task run
    again after its worker was lost) gives the same bytes. Returns stats."""
    started = time.perf_counter()
    bodies, contacts, rows, ids = read_part(part)
    read_seconds = time.perf_counter() - started
    J, stats = _solve(bodies, contacts, options)
    out = {k: np.load(part["outputs"][k], mmap_mode="r+") for k in ("J", "v", "w")}
    consecutive = len(rows) and int(rows[-1]) - int(rows[0]) + 1 == len(rows)
    out["J"][:, slice(int(rows[0]), int(rows[-1]) + 1) if consecutive else rows] = J
    movable = bodies.inv_mass != 0
    out["v"][:, ids[movable]] = bodies.v[:, movable]
    out["w"][:, ids[movable]] = bodies.w[:, movable]
    for array in out.values():
        array.flush()
    return _part_stats(stats, len(contacts), len(bodies), started, read_seconds)


# ---------------------------------------------------------------------------
# One scene of solve_scenes.
# ---------------------------------------------------------------------------


def scene_of(entry):
    """The scene of a solve_scenes entry: files loaded, or generated."""
    if "bodies" in entry:
        return collide.load(entry["bodies"], entry["contacts"], dtype=entry.get("dtype"))
    spec = {k: v for k, v in entry.items() if k not in ("name", "accuracy")}
    kind, n = spec.pop("kind"), spec.pop("n")
    if "dtype" in spec:
        spec["dtype"] = np.dtype(spec["dtype"])
    return collide.generate(kind, n, **spec)


def scene_row(entry, options):
    """Solves one scene on the worker and measures it: the row of
    ``solve_scenes``. The error and the drifts are measured on the scene's
    first ``sample`` contacts, as ``collide report`` measures its rows: the
    law applies contacts in input order, so those contacts' impulses are the
    same with or without the ones after them. The sample is solved on its
    own with the model the whole scene ran (its impulses equal the whole
    solve's first ones) and compared with the long double reference."""
    accuracy = entry.get("accuracy", options["accuracy"])
    bodies, contacts = scene_of(entry)
    isl = collide.islands(bodies, contacts, threads=options["threads"])
    k = min(options["sample"], len(contacts))
    sample_bodies, sample_contacts, _ = sub_scene(bodies, contacts, np.arange(k))
    J, stats = collide.solve(bodies, contacts, model=options["model"], accuracy=accuracy, threads=options["threads"],
                             isa=options["isa"])
    ref = collide.reference_solve(sample_bodies, sample_contacts)
    J_sample, _ = collide.solve(sample_bodies, sample_contacts, model=stats["model"], accuracy=accuracy,
                                threads=options["threads"], isa=options["isa"])
    if J_sample.tobytes() != np.ascontiguousarray(J[:, :k]).tobytes():
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
