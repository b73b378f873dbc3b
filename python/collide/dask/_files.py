"""The columns of a binary scene file (.npz) as read-only memory maps.

``numpy.load`` reads a member of an .npz archive whole (``mmap_mode`` applies
to .npy files only), and ``collide.load`` checks and converts every row. A
worker that solves a part of a scene needs only its rows, so it maps each
member where it lies in the archive (the archive is uncompressed: NumPy's
``np.savez`` or collide's writer) and reads the rows it gathers, no more.
The client has checked the whole scene with ``collide.load`` before any
worker reads it.
"""

from __future__ import annotations

import struct
import zipfile

import numpy as np

_LOCAL_HEADER = struct.Struct("<4s5H3I2H")  # the ZIP local file header, 30 bytes


def npz_columns(path):
    """Every member of the uncompressed .npz archive ``path`` as a read-only
    array mapped from the file (``numpy.memmap``), by member name without
    ``.npy``. ValueError naming the file and the member for a compressed
    member or one that is not a .npy array."""
    path = str(path)
    with zipfile.ZipFile(path) as archive:
        members = [m for m in archive.infolist() if m.filename.endswith(".npy")]
    columns = {}
    with open(path, "rb") as f:
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
            if int(np.prod(shape)) == 0:
                columns[name] = np.empty(shape, dtype)
            else:
                columns[name] = np.memmap(path, dtype=dtype, mode="r", offset=f.tell(), shape=shape)
    return columns
