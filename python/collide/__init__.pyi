"""Type stubs of the collide package (see __init__.py and docs/python.md)."""

from typing import Any, Literal, Sequence, SupportsIndex

import os

import numpy as np
import numpy.typing as npt

Float = np.float32 | np.float64
FloatArray = npt.NDArray[np.float32] | npt.NDArray[np.float64]
ModelName = Literal["auto", "rigid", "sphere", "particle"]
PathName = Literal["simd", "scalar"]
IsaName = Literal["auto", "sse2", "avx2", "avx512"]
AccuracyName = Literal["fast", "accurate"]
OrderName = Literal["input", "colour"]
IterationName = Literal["repeat", "accumulate"]

__version__: str
error_bound_eps: float
error_target_eps: float
accurate_error_ulps: float

def __dir__() -> list[str]: ...

class Stats(dict[str, Any]):
    """The statistics of a solve: a dict with the keys of `collide solve --stats`.
    Times: kernel_seconds (the solve less the two next), isa_calibration_seconds,
    allocate_seconds (the solver's buffers grown and first touched, 0 when they
    were sized), schedule_seconds."""

class Bodies:
    """N bodies over the caller's arrays (no copy): inv_mass (N,), inv_inertia,
    p, v, w (3, N), q (4, N) as (w, x, y, z); one dtype, C-contiguous."""

    inv_mass: FloatArray
    inv_inertia: FloatArray
    q: FloatArray
    p: FloatArray
    v: FloatArray
    w: FloatArray
    dtype: np.dtype[Any]
    def __init__(
        self,
        inv_mass: FloatArray,
        inv_inertia: FloatArray,
        q: FloatArray,
        p: FloatArray,
        v: FloatArray,
        w: FloatArray,
    ) -> None: ...
    def __len__(self) -> int: ...
    def __repr__(self) -> str: ...

class MappedFile:
    """A scene file mapped into memory: the base of the arrays load() leaves in it."""
    path: str
    address: int
    size: int
    def __repr__(self) -> str: ...

class Contacts:
    """M contacts: a, b uint32 (M,), c, n (3, M), e and mu (M,) or None."""

    a: npt.NDArray[np.uint32]
    b: npt.NDArray[np.uint32]
    c: FloatArray
    n: FloatArray
    e: FloatArray | None
    mu: FloatArray | None
    uniform_e: float
    dtype: np.dtype[Any]
    def __init__(
        self,
        a: npt.NDArray[np.uint32],
        b: npt.NDArray[np.uint32],
        c: FloatArray,
        n: FloatArray,
        e: FloatArray | None = None,
        uniform_e: float = 1.0,
        mu: FloatArray | None = None,
    ) -> None: ...
    def __len__(self) -> int: ...
    def __repr__(self) -> str: ...

class PackedBodies:
    """N packed bodies over the caller's records (no copy): a 1-D array of
    packed_dtype(model, dtype), or a C-contiguous (N, k) float array whose
    rows are the records; aligned as the record type says (packed_empty and
    pack allocate so). The record type is the model; v and w are updated in
    place. The field properties are views of the records. Rigid records hold
    no inverse mass: ``inv_mass`` (required for rigid records, refused for
    sphere and particle records) is a C-contiguous (N,) array of their dtype
    beside them, kept (no copy) and only read by a solve. Float records of
    16 values are rigid or sphere records: ``inv_mass`` given says rigid,
    else ``model`` must."""

    records: npt.NDArray[Any]
    model: Literal["rigid", "sphere", "particle"]
    dtype: np.dtype[Any]
    record_dtype: np.dtype[Any]
    structured: npt.NDArray[Any]
    v: FloatArray
    w: FloatArray
    p: FloatArray
    q: FloatArray
    inv_mass: FloatArray
    inv_inertia: FloatArray
    def __init__(
        self,
        records: npt.NDArray[Any],
        *,
        model: ModelName = "auto",
        inv_mass: FloatArray | None = None,
    ) -> None: ...
    def __len__(self) -> int: ...
    def __repr__(self) -> str: ...
    def unpack(self, into: Bodies | None = None) -> Bodies: ...
    def unpack_velocities(self, into: Bodies) -> Bodies: ...

AnyBodies = Bodies | PackedBodies

class Schedule:
    """The batches of a contact set; reusable while indices and inverse masses stay."""

    order: OrderName
    batches: int
    largest_batch: int
    colours: int
    overflow_contacts: int
    build_seconds: float
    def __init__(self, bodies: AnyBodies, contacts: Contacts, *, order: OrderName = "input") -> None: ...
    def solve_order(self) -> npt.NDArray[np.uint32]: ...
    def __repr__(self) -> str: ...

class Solver:
    """A reusable solver (its thread arena and options) for frame loops."""

    path: PathName
    threads: int
    isa: IsaName
    accuracy: AccuracyName
    passes: int
    iteration: IterationName
    warm_start: bool
    def __init__(
        self,
        *,
        path: PathName = "simd",
        threads: SupportsIndex = 0,
        isa: IsaName | None = None,
        accuracy: AccuracyName = "fast",
        passes: SupportsIndex = 1,
        iteration: IterationName = "repeat",
        warm_start: bool = False,
    ) -> None:
        """``threads`` from 0 (all) to 4096 and ``passes`` from 1 to 1000000,
        as the command's options: TypeError for a value that is not an
        integer, ValueError outside the range. Ctrl-C stops a solve of
        several passes on the main thread after the pass in progress
        (KeyboardInterrupt; the arrays as the passes done left them). The
        order is the schedule's: a Solver runs schedules of either order."""
    def __repr__(self) -> str: ...
    def solve(
        self,
        bodies: AnyBodies,
        contacts: Contacts,
        *,
        model: ModelName = "auto",
        order: OrderName | None = None,
        schedule: Schedule | None = None,
        out: FloatArray | None = None,
        warm: FloatArray | None = None,
        check: bool = True,
        impacts: bool = True,
    ) -> tuple[FloatArray, Stats]: ...

class Reference:
    """The long double reference of one scene (values rounded to float64)."""

    J: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    w: npt.NDArray[np.float64]
    impulse_scale: npt.NDArray[np.float64]
    dtype: np.dtype[Any]
    def __len__(self) -> int: ...
    def __repr__(self) -> str: ...

def solve(
    bodies: AnyBodies,
    contacts: Contacts,
    *,
    model: ModelName = "auto",
    path: PathName = "simd",
    threads: SupportsIndex = 0,
    isa: IsaName | None = None,
    accuracy: AccuracyName = "fast",
    order: OrderName | None = None,
    passes: SupportsIndex = 1,
    iteration: IterationName = "repeat",
    warm: FloatArray | None = None,
    schedule: Schedule | None = None,
    out: FloatArray | None = None,
    check: bool = True,
    impacts: bool = True,
) -> tuple[FloatArray, Stats]: ...
class Islands:
    """The islands of a scene: read-only uint32 views of the library's result."""

    NONE: int
    labels: npt.NDArray[np.uint32]
    body_labels: npt.NDArray[np.uint32]
    sizes: npt.NDArray[np.uint32]
    count: int
    largest: int
    largest_label: int
    def __len__(self) -> int: ...
    def __repr__(self) -> str: ...

def islands(bodies: AnyBodies, contacts: Contacts, *, threads: int = 0) -> Islands: ...
def reference_solve(
    bodies: AnyBodies,
    contacts: Contacts,
    *,
    order: OrderName | None = None,
    passes: SupportsIndex = 1,
    iteration: IterationName = "repeat",
    warm: FloatArray | None = None,
    schedule: Schedule | None = None,
) -> Reference: ...
def conservation_drift(bodies: AnyBodies, reference: Reference) -> dict[str, float]: ...
def impulse_error(J: FloatArray, reference: Reference) -> npt.NDArray[np.float64]: ...
def generate(
    kind: Literal["pairs", "debris", "pile", "chain"],
    n: SupportsIndex,
    *,
    seed: int = 1,
    model: Literal["rigid", "sphere", "particle"] = "rigid",
    friction: bool = False,
    shuffle: bool = False,
    dtype: type[Float] | np.dtype[Any] = ...,
) -> tuple[Bodies, Contacts]: ...
def read_scene(bodies_csv: str, contacts_csv: str, dtype: type[Float] | np.dtype[Any] = ...) -> tuple[Bodies, Contacts]: ...
def write_scene(bodies_csv: str, contacts_csv: str, bodies: AnyBodies, contacts: Contacts) -> None: ...
def load(
    bodies: str | os.PathLike[str], contacts: str | os.PathLike[str], *, dtype: type[Float] | np.dtype[Any] | None = ...
) -> tuple[Bodies, Contacts]: ...
def save(bodies_path: str | os.PathLike[str], contacts_path: str | os.PathLike[str], bodies: AnyBodies, contacts: Contacts) -> None: ...
def packed_dtype(model: Literal["rigid", "sphere", "particle"] = "rigid", dtype: type[Float] | np.dtype[Any] = ...) -> np.dtype[Any]: ...
def packed_empty(
    n: int,
    model: Literal["rigid", "sphere", "particle"] = "rigid",
    dtype: type[Float] | np.dtype[Any] = ...,
    *,
    columns: bool = False,
) -> npt.NDArray[Any]: ...
def pack(
    bodies: Bodies,
    model: ModelName = "rigid",
    *,
    contacts: Contacts | None = None,
    columns: bool = False,
) -> PackedBodies: ...
def from_physical(
    m: npt.ArrayLike,
    inertia: npt.ArrayLike,
    q: npt.ArrayLike,
    p: npt.ArrayLike,
    v: npt.ArrayLike | None = None,
    w: npt.ArrayLike | None = None,
    *,
    dtype: type[Float] | np.dtype[Any] = ...,
) -> Bodies: ...
def report(
    *,
    n: int = 1000000,
    debris_n: int | None = None,
    pile_n: int | None = None,
    threads: Sequence[int] = (1, 2),
    sample: int = 100000,
    runs: int = 3,
    seed: int = 1,
    quick: bool = False,
) -> list[dict[str, Any]]: ...
def report_hard(*, n: int = 1000, runs: int = 5) -> list[dict[str, Any]]: ...
def report_convergence(
    *, n: int = 188800, threads: Sequence[int] = (1, 2), runs: int = 3, seed: int = 1
) -> list[dict[str, Any]]: ...
def isa_supported(isa: IsaName) -> bool: ...
def best_isa() -> str: ...
def simd_width(isa: IsaName = "auto", dtype: type[Float] | np.dtype[Any] = ...) -> int: ...
