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
