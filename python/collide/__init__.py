"""collide: batched rigid-body collision impulses on NumPy arrays, in place.

The arrays are structure-of-arrays: ``inv_mass`` has shape (N,), every
vector array has shape (3, N) (row k is component k) and ``q`` has shape
(4, N) as (w, x, y, z). One dtype per scene, float32 or float64, C-contiguous.
Nothing is copied: :func:`solve` updates ``bodies.v`` and ``bodies.w`` of
the caller's arrays and returns the impulses J, shape (3, M).

Typical use::

    import collide
    bodies, contacts = collide.generate("pairs", 1_000_000, dtype=numpy.float32)
    ref = collide.reference_solve(bodies, contacts)   # before: it copies the inputs
    J, stats = collide.solve(bodies, contacts)
    err = collide.impulse_error(J, ref)               # eps * impulse_scale units

The law, the error measure and the bound (``error_bound_eps``) are those of
``collide solve --check``; docs/python.md describes the API.
"""

import os as _os
import sys as _sys


def _cannot_run(what, missing, fix_here, error):
    """ImportError saying what the module needs and which interpreter this
    build's extension is for (python/collide/_build.py.in, written when the
    build is configured): the fix is to run that one, or to build for this
    one."""
    try:
        from ._build import PYTHON, PYTHON_VERSION
    except ImportError:
        PYTHON, PYTHON_VERSION = "the interpreter of its build", "?"
    here = _sys.executable
    version = ".".join(str(x) for x in _sys.version_info[:2])
    if _os.path.exists(PYTHON) and _os.path.realpath(PYTHON) == _os.path.realpath(here):
        return ImportError(f"{what}: this module was built for {PYTHON}, this interpreter, which has {missing}: "
                           f"{fix_here} ({error})")
    return ImportError(f"{what}: this module was built for {PYTHON} (Python {PYTHON_VERSION}), and this is {here} "
                       f"(Python {version}), which has {missing}: run it with {PYTHON}, or build collide for this "
                       f"interpreter (pip install . here, or cmake -DPython3_EXECUTABLE={here}) ({error})")


try:
    import numpy as _np
except ImportError as _error:
    raise _cannot_run("collide needs NumPy", "no NumPy", "install it (Debian: python3-numpy; pip: numpy)",
                      _error) from _error
try:
    from . import _collide
except ImportError as _error:
    raise _cannot_run("collide's extension (collide._collide) cannot be loaded", "no build of it",
                      "build it again (scripts/build.sh, or pip install .)", _error) from _error
from ._collide import (
    Bodies,
    Contacts,
    Islands,
    MappedFile,
    PackedBodies,
    Reference,
    Schedule,
    Solver,
    accurate_error_ulps,
    error_bound_eps,
    error_target_eps,
    warm_start_least_cosine,
)

__all__ = [
    "Bodies",
    "Contacts",
    "Islands",
    "MappedFile",
    "PackedBodies",
    "Reference",
    "Schedule",
    "Solver",
    "Stats",
    "accurate_error_ulps",
    "error_bound_eps",
    "error_target_eps",
    "warm_start_least_cosine",
    "from_physical",
    "conservation_drift",
    "generate",
    "impulse_error",
    "islands",
    "load",
    "pack",
    "packed_dtype",
    "packed_empty",
    "read_scene",
    "reference_solve",
    "save",
    "report",
    "report_hard",
    "report_convergence",
    "best_isa",
    "isa_supported",
    "simd_width",
    "solve",
    "write_scene",
]

__version__ = "0.1.0"


def __dir__():
    """The API (``__all__``) and the version: not the modules the package
    imports for itself."""
    return sorted([*__all__, "__version__"])


class Stats(dict):
    """The statistics of a solve, as :func:`solve` and :meth:`Solver.solve`
    return them: a dict with the keys of ``collide solve --stats``, shown one
    key per line. Its times: ``kernel_seconds`` (the solve, less the two
    below), ``isa_calibration_seconds`` (the ISA measurement of the first
    solve of a kind in the process), ``allocate_seconds`` (growing the
    solver's buffers and touching their pages before the kernels run: the
    first solve of a size on a Solver, every one-shot :func:`solve`; 0 when
    they were sized) and ``schedule_seconds`` (the schedule the call built,
    0 for one given)."""

    __slots__ = ()

    def __repr__(self):
        return "Stats({" + ",\n       ".join(f"{k!r}: {v!r}" for k, v in self.items()) + "})"


def solve(bodies, contacts, *, model="auto", path="simd", threads=0, isa=None, accuracy="fast", order=None,
          passes=1, iteration="repeat", warm=None, schedule=None, out=None, check=True, impacts=True):
    """Resolves every contact in place; returns ``(J, stats)``.

    ``bodies.v`` and ``bodies.w`` are updated; J (shape (3, M), the dtype of
    the scene) is the impulse on body a of each contact. ``stats`` has the keys
    of ``collide solve --stats`` (collisions, impacts, bodies, kernel_seconds,
    collisions_per_second, precision, threads, model, path, isa, isa_choice,
    layout, accuracy, lanes, order, passes, iteration, warm_start, residual, batches,
    largest_batch, colours,
    overflow_contacts, schedule_seconds, isa_calibration_seconds,
    allocate_seconds; kernel_seconds is the solve less its ISA measurement
    and its allocate phase, the one-time growth of the solver's buffers,
    each reported on its own). ``model`` is "auto" (the
    cheapest that fits), "rigid", "sphere" or "particle"; ``path`` "simd" or
    "scalar"; ``threads`` 0 for all; ``isa`` None (automatic: COLLIDE_ISA,
    else the fastest on this CPU, measured once per process), "sse2", "avx2"
    or "avx512"; ``accuracy`` "fast" or "accurate". ``order`` is "input"
    (the law in input order; the default) or "colour" (an order collide
    chooses: windows of contacts coloured over their bodies, several times
    faster on piles, stacks and chains; docs/collision-law.md, "The solve
    order"): the order of the schedule the call builds. A ``schedule`` given
    instead runs in the order it was built in (give one or the other, not
    both). ``passes`` (an integer
    from 1 to 1000000, as ``collide solve --passes``) resolves the contacts
    that many times in that order. ``iteration`` says what the passes after
    the first do: "repeat" (the law again, J summed over the passes) or
    "accumulate" (each contact's total impulse moved towards rest and clamped,
    restitution once, J the totals: how physics engines iterate; fast
    accuracy only); ``stats["residual"]`` is the last pass's largest change
    of a J over the largest |J| (docs/collision-law.md, "Iteration"). ``warm``
    (shape (3, M), the scene's dtype; with iteration="accumulate") is a warm
    start: the J of a solve before, of the same contacts in the same places
    (the previous frame's), which the passes start from instead of zero
    (docs/collision-law.md, "The warm start"); it may be ``out`` itself,
    and a J that is not finite or points against its normal (J . n below
    ``warm_start_least_cosine`` |J| |n|: more than 120 degrees from it) is
    refused (ValueError
    naming ``warm[:, k]``). No array the solve writes (v, w
    or the records, and ``out``) may share memory with another of its arrays
    (ValueError naming both). For frame loops build a
    :class:`Solver` and a :class:`Schedule` once. The GIL is released while
    solving; Ctrl-C on the main thread stops a solve of several passes after
    the pass in progress with KeyboardInterrupt, v, w and ``out`` as the
    passes done left them (docs/python.md, "Stopping a long solve"). Bad
    input raises TypeError or ValueError and modifies nothing.

    ``check=False`` skips the full validation of the values (a pass over every
    array, about as long as the solve itself at 1M pairs) and the model-fit
    check, for a frame loop re-solving a scene it validated once: indices and
    array layouts are still checked (a bad index never reaches the kernel),
    but NaN, a negative inverse mass or a non-unit normal then give the
    law's garbage instead of an error.

    ``bodies`` may be :class:`Bodies` (structure of arrays) or
    :class:`PackedBodies` (records, solved in place; the record type is the
    model; rigid records' inverse masses are read from their ``inv_mass``
    array beside them). ``impacts=False`` skips the pass over J that counts the non-zero
    impulses (``stats["impacts"]`` is then None): at a million contacts that
    pass costs 5 to 10% of a particle solve.
    """
    solver = Solver(path=path, threads=threads, isa=isa, accuracy=accuracy, passes=passes, iteration=iteration,
                    warm_start=warm is not None)
    return solver.solve(bodies, contacts, model=model, order=order, schedule=schedule, out=out, warm=warm,
                        check=check, impacts=impacts)


def reference_solve(bodies, contacts, *, order=None, passes=1, iteration="repeat", warm=None, schedule=None):
    """The high-precision reference (long double) on an exact copy of the inputs.

    The caller's bodies are not modified. Returns a :class:`Reference` with
    ``J`` (float64 (3, M)), the bodies' ``v`` and ``w`` after it, and
    ``impulse_scale`` per contact. Call it before :func:`solve` (which
    updates the velocities) to compare the two with :func:`impulse_error`,
    with the solve's ``order`` (or its ``schedule``, whose order it is),
    ``passes``, ``iteration`` and ``warm``: the reference applies the law in
    the same sequence, from the same warm start. Packed bodies are
    unpacked first (an exact copy).
    """
    if isinstance(bodies, PackedBodies):
        bodies = bodies.unpack()
    return _collide.reference_solve(bodies, contacts, order=order, passes=passes, iteration=iteration,
                                    schedule=schedule, warm=warm)


def impulse_error(J, reference):
    """Per-contact error of J against the reference, float64 (M,), in units of
    eps(J.dtype) * impulse_scale (what ``collide solve --check`` bounds by
    ``error_bound_eps``). NaN for a NaN impulse."""
    return _collide.impulse_error(J, reference)


def conservation_drift(bodies, reference):
    """How far the momenta and energy of ``bodies`` after a solve are from
    the reference's after the same contacts (the columns of ``collide
    report``): a dict with ``momentum_drift`` (|P - Pref| / sum m|v|),
    ``angular_momentum_drift`` (|L - Lref| / sum (|p x m v| + |I w|)) and
    ``energy_drift`` (|E - Eref| / E), the scales taken before the solve.
    ``reference`` is :func:`reference_solve` of the same bodies before the
    solve; totals are summed in long double over movable bodies."""
    if isinstance(bodies, PackedBodies):
        bodies = bodies.unpack()
    return _collide.conservation_drift(bodies, reference)


def islands(bodies, contacts, *, threads=0):
    """The islands of a scene: the groups of contacts joined by shared
    movable bodies (immovable bodies, inverse mass 0, join nothing; a contact
    between two immovable bodies is an island of its own). Solving each
    island alone, its contacts in input order, gives the same bits as one
    solve of the whole scene. Returns an :class:`Islands` whose NumPy arrays
    (read-only uint32 views, no copy) are ``labels`` (M,), the island of each
    contact, islands numbered in the order of their first contact;
    ``body_labels`` (N,), the island of each body or ``Islands.NONE``
    (immovable, or without contacts); ``sizes``, the contacts of each island;
    and ``count``, ``largest`` (contacts of the largest island) and
    ``largest_label``. Computed by the library in parallel on ``threads``
    threads (0: all), the same labels for any number. A bad index raises
    ValueError naming the contact; only indices and inverse masses are
    read."""
    return _collide.islands(bodies, contacts, threads=threads)


def generate(kind, n, *, seed=1, model="rigid", friction=False, shuffle=False, dtype=_np.float32):
    """The scenes of ``collide gen``: ``kind`` "pairs" (n independent pairs,
    2n bodies), "debris" (n contacts on shared bodies), "pile" (n x n x n
    boxes on a lattice, each touching its neighbours, the bottom layer on an
    immovable ground; contacts in broadphase cell order, or in a seeded random
    order with ``shuffle=True``) or "chain" (n + 1 boxes in a staircase, each
    touching the next, n contacts in chain order, which run one after
    another). ``n`` takes the range of ``collide gen``: from 1 to what 32-bit
    body ids allow (ValueError outside it, TypeError for a non-integer).
    Returns ``(Bodies, Contacts)`` over new arrays."""
    return _collide.generate(kind, n, seed=seed, model=model, friction=friction, shuffle=shuffle, dtype=dtype)


def read_scene(bodies_csv, contacts_csv, dtype=_np.float64):
    """Reads a scene in the files of ``collide solve`` (physical units) and
    returns ``(Bodies, Contacts)`` with the inverses the solver takes. A bad
    file raises ValueError naming file, line, row and column; a file that
    cannot be read (missing, a directory, no permission) OSError naming the
    path (FileNotFoundError, IsADirectoryError, PermissionError...)."""
    return _collide.read_scene(str(bodies_csv), str(contacts_csv), dtype=dtype)


def load(bodies, contacts, *, dtype=None):
    """Reads a scene's bodies and contacts files and returns ``(Bodies,
    Contacts)`` for :func:`solve`. Each file is binary (NumPy's uncompressed
    ``.npz``, one array per column; docs/collision-law.md) when its name ends
    in ``.npz``, else CSV. A binary scene is mapped, not parsed: its arrays
    that the solver only reads (``q``, ``p`` and every contact array) are
    read-only views of the file's pages, whose ``base`` is a
    :class:`MappedFile`; the inverses are computed and ``v``, ``w`` copied,
    since a solve writes them. ``dtype`` defaults to a binary file's own
    precision (float64 for CSV); another one converts. Every value is checked
    with the rules of the CSV reader: ValueError naming file, row and column;
    OSError for a file that cannot be read."""
    return _collide.load(str(bodies), str(contacts), dtype=dtype)


def save(bodies_path, contacts_path, bodies, contacts):
    """Writes ``bodies`` and ``contacts`` as scene files, binary (``.npz``)
    or CSV by each name, as :func:`write_scene` does: both replaced
    atomically, or neither. ``numpy.load`` reads the binary files."""
    write_scene(bodies_path, contacts_path, bodies, contacts)


def write_scene(bodies_csv, contacts_csv, bodies, contacts):
    """Writes the scene in the file format (masses and moments as 1/inverse,
    inf for 0; every number the shortest text that reads back to the same
    value) with the library's writers, in parallel blocks, without the GIL.
    Both files are replaced atomically, or neither. Packed bodies are
    unpacked first (an exact copy)."""
    if isinstance(bodies, PackedBodies):
        bodies = bodies.unpack()
    _collide.write_scene(str(bodies_csv), str(contacts_csv), bodies, contacts)


def from_physical(m, inertia, q, p, v=None, w=None, *, dtype=_np.float64):
    """Bodies from physical units: mass m (N,) (inf = immovable), principal
    moments ``inertia`` (3, N) (inf = no rotation about that axis), any
    non-zero quaternion q (4, N) (stored as given; the law normalises it),
    p, v, w (3, N); v and w default to zero. Arrays of ``dtype`` are used as
    they are; anything else is taken as float64 scene values, which a
    float32 result holds as every scene file reader holds them: the float
    nearest each double (docs/collision-law.md, "Scene values"). The result
    owns new arrays.

    Every body must obey the input rules of the scene files, in ``dtype``
    (the library's collide/rules.hpp: no NaN, inf only in m and inertia,
    m and the moments > 0 with a finite inverse, |q|^2 a normal number),
    and a float32 result every value within float's range:
    ValueError("from_physical: body 3, column 'm': mass must be > 0, got -1"),
    the reason :func:`read_scene` gives for the same value in a file."""
    dt = _np.dtype(dtype)
    given = [x for x in (m, inertia, q, p, v, w) if x is not None]
    if not all(isinstance(x, _np.ndarray) and x.dtype == dt for x in given):
        dt_in = _np.dtype(_np.float64)  # scene values, rounded by the library
    else:
        dt_in = dt

    def arr(x, rows):
        if x is None:
            return _np.zeros((rows, len(_np.asarray(m))), dtype=dt_in)
        return _np.ascontiguousarray(x, dtype=dt_in)

    return _collide.from_physical(arr(m, 0), arr(inertia, 3), arr(q, 4), arr(p, 3), arr(v, 3), arr(w, 3), dt)


def report(*, n=1_000_000, debris_n=None, pile_n=None, threads=(1, 2), sample=100_000, runs=3, seed=1, quick=False):
    """The rows of ``collide report`` as a list of dicts (speed and error of
    every variant on the pairs, debris and pile scenes; docs/report.md has the
    columns). Takes minutes with the defaults; ``quick=True`` for a smoke run."""
    return _collide.report(n=n, debris_n=debris_n, pile_n=pile_n, threads=list(threads), sample=sample, runs=runs,
                           seed=seed, quick=quick)


def report_hard(*, n=1000, runs=5):
    """The hard section of ``collide report --hard`` as a list of dicts: every
    scene of the hard catalogue (huge mass ratios, immovable bodies, needle
    inertia, grazing contacts, tiny and huge scales, subnormals, chains of
    shared bodies) in float and double, fast and accurate mode, SIMD at one
    thread, with speed and error. ``n`` is the number of pairs of each pair
    family (the shared scenes have fixed sizes); ``runs`` the least number of
    timed runs. Keys: family, model, precision, mode ("fast" or "accurate"),
    shared, n, acting, threads, isa, runs, seconds, collisions_per_second,
    max_err_eps and p99_err_eps (the fast mode's unit, target
    ``error_target_eps``), max_err_ulps (the accurate mode's unit, bound
    ``accurate_error_ulps``; None where this build has no reference precise
    enough to judge it) and judge (that reference's precision)."""
    return _collide.report_hard(n=n, runs=runs)


def report_convergence(*, n=188_800, threads=(1, 2), runs=3, seed=1):
    """The convergence section of ``collide report`` as a list of dicts: a
    resting pile, a stack of columns and debris of about ``n`` contacts each,
    solved with 1 to 32 passes in both orders and both iteration modes, and
    warm-started from the converged J, at the largest of ``threads``. Keys:
    scene, order, iteration, passes, warm, n, threads, isa, runs, seconds,
    collisions_per_second (n x passes / seconds), residual, start_residual
    and next_pass (docs/report.md, "The convergence section")."""
    return _collide.report_convergence(n=n, threads=list(threads), runs=runs, seed=seed)


def isa_supported(isa):
    """True when this CPU (and this build) can run ``isa``: "sse2", "avx2",
    "avx512" or "auto". ValueError for another name."""
    return _collide.isa_supported(isa)


def best_isa():
    """The widest instruction set this CPU and build support. Not always the
    fastest: with COLLIDE_ISA unset a solver measures which is (stats["isa"]
    says what ran)."""
    return _collide.best_isa()


def simd_width(isa="auto", dtype=_np.float32):
    """Lanes of the SIMD path for ``isa`` and dtype ("auto": COLLIDE_ISA, else
    the widest ISA; a measured solve may run fewer, stats["lanes"] says)."""
    return _collide.simd_width(isa, dtype)


# ---------------------------------------------------------------------------
# The packed (record) layout.
# ---------------------------------------------------------------------------


def packed_dtype(model="rigid", dtype=_np.float32):
    """The NumPy structured dtype of one packed body of ``model`` ("rigid",
    "sphere" or "particle") in ``dtype``: the fields of the C++ record
    (collide/packed.hpp) at its offsets, padding included in the itemsize
    (rigid 64/128 bytes, sphere 64/128, particle 16/32 in float32/float64;
    16, 16 and 4 values). Rigid fields: v, w, p (3,), q (4,) as (w, x, y, z),
    inv_inertia (3,), no padding; a rigid body's inverse mass is not in its
    record but in an (N,) array beside the records (``PackedBodies(records,
    inv_mass=...)``), so that a float32 record is one 64-byte cache line.
    Sphere: v, w, p, inv_mass, inv_inertia (one moment); particle: v,
    inv_mass."""
    return _collide.packed_dtype(model, dtype)


def packed_empty(n, model="rigid", dtype=_np.float32, *, columns=False):
    """A zeroed array of ``n`` records, aligned as the records must be (the
    record size for rigid (64 or 128 bytes) and particle, 64 bytes for
    sphere; NumPy alone aligns to 16). A 1-D array of :func:`packed_dtype`,
    or with ``columns=True`` an (n, k) array of ``dtype`` whose rows are the
    records (k values each, padding included). Wrap it with
    :class:`PackedBodies`. Rigid records also need their inverse masses
    beside them, any C-contiguous (n,) array of ``dtype`` (NumPy's own
    alignment suffices)::

        records = collide.packed_empty(n, "rigid", numpy.float32)
        packed = collide.PackedBodies(records, inv_mass=numpy.zeros(n, numpy.float32))
    """
    record = _np.dtype(packed_dtype(model, dtype))
    align = _collide.packed_alignment(model, dtype)
    raw = _np.zeros(n * record.itemsize + align, dtype=_np.uint8)
    start = -raw.ctypes.data % align
    records = raw[start:start + n * record.itemsize].view(record)
    if columns:
        return records.view(_np.dtype(dtype)).reshape(n, record.itemsize // _np.dtype(dtype).itemsize)
    return records


def pack(bodies, model="rigid", *, contacts=None, columns=False):
    """Packs :class:`Bodies` into new aligned records (an exact copy of every
    field the record holds) and returns the :class:`PackedBodies`. Rigid
    records hold everything but the inverse masses, which are copied into a
    new (N,) array beside them (``packed.inv_mass``). Sphere and particle
    records drop what their model does not read, so they need the model to
    fit (ValueError with the reason otherwise, as ``solve(..., model=...)``):
    whether the particle model fits depends on the contacts, so "particle"
    and "auto" (the cheapest model that fits, as :func:`solve` chooses; the
    inputs are validated) need ``contacts``."""
    if not isinstance(bodies, Bodies):
        raise TypeError(f"pack: bodies must be collide.Bodies, got {type(bodies).__name__}")
    if model in ("auto", "particle") and contacts is None:
        raise ValueError(f"pack: model '{model}' needs the contacts (whether the particle model fits depends on them)")
    if contacts is None:
        none = _np.zeros((3, 0), dtype=bodies.dtype)
        contacts = Contacts(_np.zeros(0, _np.uint32), _np.zeros(0, _np.uint32), none, none)
    if model == "auto":
        model = _collide.choose_model(bodies, contacts)
    elif model in ("sphere", "particle"):
        misfit = _collide.model_misfit(bodies, contacts, model)
        if misfit:
            raise ValueError(f"pack: model '{model}' does not fit the scene: {misfit}")
    records = packed_empty(len(bodies), model, bodies.dtype, columns=columns)
    inv_mass = _np.empty(len(bodies), bodies.dtype) if model == "rigid" else None
    packed = PackedBodies(records, model=model, inv_mass=inv_mass)
    _collide.pack_into(bodies, packed)
    return packed
