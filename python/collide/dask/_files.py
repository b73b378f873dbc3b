"""The columns of a binary scene file (.npz) as read-only views of one
mapping of the file.

``numpy.load`` reads a member of an .npz archive whole (``mmap_mode`` applies
to .npy files only), and ``collide.load`` checks and converts every row. A
worker that solves a part of a scene needs only its rows, so it maps the
archive once (it is uncompressed: NumPy's ``np.savez`` or collide's writer)
and reads the rows it needs where they lie. Rows of consecutive members of
equal length, such as a file's ``vx``, ``vy``, ``vz``, are one stride apart
in the file, so a range of them is a (3, k) view with no copy at all, as
``collide.load`` makes its arrays. The client has checked the whole scene
with ``collide.load`` before any worker reads it.

A warm start's impulses (:class:`MappedImpulses`: an impulses file's members
``jx``, ``jy``, ``jz``, or a (3, M) ``.npy``) are mapped the same way, so
that each worker reads the columns of its own contacts only.
"""

from __future__ import annotations

import mmap
import os
import struct
import zipfile

import numpy as np

from .. import _collide

_LOCAL_HEADER = struct.Struct("<4s5H3I2H")  # the ZIP local file header, 30 bytes


class MappedNpz:
    """Every member of the uncompressed .npz archive ``path``, by member name
    without ``.npy``, as a read-only array over one mapping of the file
    (``columns``). ValueError naming the file and the member for a
    compressed member or one that is not a plain .npy array."""

    def __init__(self, path):
        path = str(path)
        self.path = path
        with zipfile.ZipFile(path) as archive:
            members = [m for m in archive.infolist() if m.filename.endswith(".npy")]
        self.columns, self._offsets = {}, {}
        with open(path, "rb") as f:
            # An empty file cannot be mapped; a zip archive is never empty.
            self._map = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
            for member in members:
                name = member.filename[:-4]
                if member.compress_type != zipfile.ZIP_STORED:
                    raise ValueError(f"{path}: member '{member.filename}' is compressed; a scene file must be "
                                     "uncompressed (np.savez, or collide's writer) to be mapped")
                f.seek(member.header_offset)
                fields = _LOCAL_HEADER.unpack(f.read(_LOCAL_HEADER.size))
                if fields[0] != b"PK\x03\x04":
                    raise ValueError(f"{path}: member '{member.filename}': bad local header")
                f.seek(member.header_offset + _LOCAL_HEADER.size + fields[9] + fields[10])
                version = np.lib.format.read_magic(f)
                if version == (1, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
                elif version == (2, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
                else:
                    raise ValueError(f"{path}: member '{member.filename}': .npy version {version} is not read")
                if fortran and len(shape) > 1:
                    raise ValueError(f"{path}: member '{member.filename}' is in Fortran order")
                if dtype.hasobject:
                    raise ValueError(f"{path}: member '{member.filename}' holds Python objects")
                offset = f.tell()
                if offset + int(np.prod(shape)) * dtype.itemsize > len(self._map):
                    raise ValueError(f"{path}: member '{member.filename}' runs past the end of the file")
                self.columns[name] = np.ndarray(shape, dtype, buffer=self._map, offset=offset)
                self._offsets[name] = offset

    def __getitem__(self, name):
        return self.columns[name]

    def stacked(self, names, rows, dtype):
        """Rows ``rows`` (a slice, or an array of row numbers) of the 1-D
        members ``names`` as a (len(names), k) array of ``dtype``: a view of
        the mapping when the rows are a range, the members lie one stride
        apart and hold ``dtype``; otherwise a new array (a gather, converted:
        float64 to float32 by the library's rounding of scene values)."""
        dtype = np.dtype(dtype)
        cols = [self.columns[k] for k in names]
        count = len(range(*rows.indices(len(cols[0])))) if isinstance(rows, slice) else len(rows)
        if isinstance(rows, slice):
            first = rows.indices(len(cols[0]))[0]
            offsets = [self._offsets[k] for k in names]
            stride = offsets[1] - offsets[0] if len(names) > 1 else 0
            item = dtype.itemsize
            # A view only where the solver can use it: aligned (np.savez's
            # members lie at any offset), the rows one stride apart.
            one_stride = all(c.dtype == dtype and c.shape == cols[0].shape for c in cols) and all(
                b - a == stride for a, b in zip(offsets, offsets[1:])) and stride % item == 0 and (
                    offsets[0] % item == 0) and (len(names) == 1 or stride >= len(cols[0]) * item)
            if one_stride and count:
                return np.ndarray((len(names), count), dtype, buffer=self._map, offset=offsets[0] + first * item,
                                  strides=(stride, item))
        out = np.empty((len(names), count), dtype)
        for r, c in enumerate(cols):
            if c.dtype == np.float64 and dtype == np.float32:
                # Scene values rounded to float as the library's readers
                # round them (docs/collision-law.md, "Scene values").
                _collide.scene_values(np.require(c[rows], requirements=("C", "A")), out[r])
            elif isinstance(rows, slice) or c.dtype != dtype:
                out[r] = c[rows]
            else:
                np.take(c, rows, out=out[r])
        return out


#: The members of an impulses file (``collide solve --out-impulses x.npz``).
IMPULSE_MEMBERS = ("jx", "jy", "jz")


class MappedImpulses:
    """The impulses J (3, M) of a warm start file, over a read-only mapping:
    an impulses file (``.npz``, members ``jx``, ``jy``, ``jz``: what
    ``collide solve --out-impulses x.npz`` writes) or a (3, M) ``.npy`` (the
    ``J.npy`` collide.dask.solve writes). Members of float32 or float64, as
    a scene file's. ValueError naming the file for anything else; OSError
    for a file that cannot be read. ``count`` is M, ``dtype`` the stored
    precision; :meth:`columns` reads the columns of some contacts only."""

    def __init__(self, path):
        path = os.fspath(path)
        self.path = path
        if path.endswith(".npz"):
            try:
                self._npz = MappedNpz(path)
            except zipfile.BadZipFile as e:
                raise ValueError(f"{path}: not an .npz archive: {e}") from None
            have = sorted(self._npz.columns)
            if any(k not in self._npz.columns for k in IMPULSE_MEMBERS):
                raise ValueError(f"{path}: an impulses file has the members jx, jy and jz (what `collide solve "
                                 f"--out-impulses x.npz` writes), this one has {', '.join(have) or 'none'}")
            rows = [self._npz[k] for k in IMPULSE_MEMBERS]
            where = [lambda i, k=k: f"row {i}, column '{k}'" for k in IMPULSE_MEMBERS]
        elif path.endswith(".npy"):
            self._npz = None
            # A .npy of Python objects is refused: np.load does not unpickle.
            try:
                array = self._array = np.load(path, mmap_mode="r")
            except ValueError as e:
                raise ValueError(f"{path}: not a .npy array NumPy maps: {e}") from None
            if array.ndim != 2 or array.shape[0] != 3:
                raise ValueError(f"{path}: a warm start .npy holds J, shape (3, M), got shape {array.shape}")
            rows = [array[k] for k in range(3)]
            where = [lambda i, k=k: f"J[{k}, {i}]" for k in range(3)]
        else:
            raise ValueError(f"{path}: a warm start file is an impulses file (.npz with jx, jy, jz, as `collide "
                             "solve --out-impulses x.npz` writes; `collide convert` writes one from CSV) or a (3, M) "
                             ".npy such as the J.npy collide.dask.solve writes")
        if any(r.ndim != 1 for r in rows) or len({r.shape for r in rows}) != 1:
            raise ValueError(f"{path}: jx, jy and jz must be 1-D and of one length, got shapes "
                             f"{', '.join(str(r.shape) for r in rows)}")
        dtypes = {r.dtype for r in rows}
        if len(dtypes) != 1 or rows[0].dtype not in (np.float32, np.float64):
            raise ValueError(f"{path}: impulses are float32 or float64, one precision per file, got "
                             f"{', '.join(str(r.dtype) for r in rows)}")
        self._rows, self._where = rows, where
        self.count, self.dtype = len(rows[0]), rows[0].dtype

    def columns(self, rows, dtype):
        """The J of contacts ``rows`` (a slice, or an array of row numbers),
        in that order, as a (3, k) array of ``dtype``: a view of the mapping
        where the rows are a range of values stored in ``dtype`` one stride
        apart (a J.npy, the members of collide's writer), else a new array.
        float64 values for float32 are rounded as the readers round a
        scene's (the library's rounding, as ``collide solve --warm-start``
        reads an impulses file), and a value beyond float is refused with
        the readers' reason, naming the file, the row and the column."""
        dtype = np.dtype(dtype)
        if dtype == self.dtype:
            if self._npz is not None:
                return self._npz.stacked(IMPULSE_MEMBERS, rows, dtype)
            if isinstance(rows, slice) and self._array.flags.c_contiguous:
                return self._array[:, rows]
            return np.ascontiguousarray(self._array[:, rows])
        count = len(range(*rows.indices(self.count))) if isinstance(rows, slice) else len(rows)
        out = np.empty((3, count), dtype)
        for k, (row, where) in enumerate(zip(self._rows, self._where)):
            values = np.require(row[rows], requirements=("C", "A"))
            if self.dtype == np.float32:
                out[k] = values  # float to double: exact
                continue
            try:
                _collide.scene_values(values, out[k])
            except ValueError as e:
                # "scene_values: element i: reason", i counted in the rows read.
                element, _, reason = str(e).partition(": ")[2].partition(": ")
                at = int(element.split()[-1]) if element.startswith("element ") else 0
                row_number = range(*rows.indices(self.count))[at] if isinstance(rows, slice) else int(rows[at])
                raise ValueError(f"{self.path}: {where(row_number)}: {reason or e}") from None
        return out


def write_columns(path, first, block):
    """Writes ``block`` (k, c) into columns ``first`` .. ``first + c`` of the
    (k, n) C-ordered array of the .npy file ``path``, one positioned write
    per row (a row of the block is a contiguous run of the file). Writing
    through ``os.pwrite`` copies into the page cache once; filling a mapping
    of a new file would first fault in and zero every page it touches."""
    block = np.ascontiguousarray(block)
    with open(path, "r+b") as f:
        version = np.lib.format.read_magic(f)
        shape, fortran, dtype = (np.lib.format.read_array_header_1_0(f) if version == (1, 0) else
                                 np.lib.format.read_array_header_2_0(f))
        if fortran or len(shape) != 2 or dtype != block.dtype or block.shape[0] != shape[0] or (
                first < 0 or first + block.shape[1] > shape[1]):
            raise ValueError(f"{path}: a ({shape[0]}, {shape[1]}) {dtype} array cannot take columns {first} to "
                             f"{first + block.shape[1]} of a {block.shape} {block.dtype} block")
        data = f.tell()
        for k in range(block.shape[0]):
            row = memoryview(block[k]).cast("B")
            at = data + (k * shape[1] + first) * dtype.itemsize
            written = 0
            while written < len(row):  # pwrite may write less than asked
                written += os.pwrite(f.fileno(), row[written:], at + written)
