"""Type stubs of collide.dask (see __init__.py and docs/distributed.md)."""

import os
from typing import Any, Iterable, Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from .. import Bodies, Contacts

FloatArray = npt.NDArray[np.float32] | npt.NDArray[np.float64]
ModelName = Literal["auto", "rigid", "sphere", "particle"]
AccuracyName = Literal["fast", "accurate"]
OrderName = Literal["input", "colour"]
IsaName = Literal["sse2", "avx2", "avx512"]
PathLike = str | os.PathLike[str]
# A distributed.Client, a scheduler address, or None.
ClientLike = Any

GIANT_ISLAND_SHARE: float
SCENE_COLUMNS: tuple[str, ...]

class IslandWarning(UserWarning): ...

class Solution(NamedTuple):
    J: FloatArray
    v: FloatArray
    w: FloatArray
    stats: dict[str, Any]

def partition_islands(sizes: npt.ArrayLike, partitions: int) -> npt.NDArray[np.int64]: ...
def solve(
    scene: tuple[Bodies, Contacts] | tuple[PathLike, PathLike],
    client: ClientLike = None,
    *,
    partitions: int | None = None,
    model: ModelName = "auto",
    accuracy: AccuracyName = "fast",
    order: OrderName = "input",
    passes: int = 1,
    dtype: type[np.float32] | type[np.float64] | np.dtype[Any] | None = None,
    threads: int = 1,
    isa: IsaName | None = None,
    out_dir: PathLike | None = None,
    workers: int | None = None,
    progress: bool = False,
) -> Solution: ...
def solve_scenes(
    scenes: Iterable[tuple[PathLike, PathLike] | dict[str, Any]],
    client: ClientLike = None,
    *,
    model: ModelName = "auto",
    accuracy: AccuracyName = "fast",
    order: OrderName = "input",
    passes: int = 1,
    sample: int = 10000,
    threads: int = 1,
    isa: IsaName | None = None,
    workers: int | None = None,
    progress: bool = False,
) -> Any: ...  # pandas.DataFrame
