"""Decimal text for scene values where the two roundings part: the float
nearest the text against the float nearest the double nearest the text
(docs/collision-law.md, "Scene values"), and scene files made of it. The
Python counterpart of tests/support/scene_value_text.hpp, for the route
tests of test_scene_routes.py and test_dask.py."""

import ctypes
import decimal
import os

import numpy as np

_libc = ctypes.CDLL(None)
_libc.strtof.restype = ctypes.c_float
_libc.strtof.argtypes = (ctypes.c_char_p, ctypes.c_void_p)

_EXACT = decimal.Context(prec=120)
F32_MAX = np.finfo(np.float32).max

BODY_COLUMNS = ("m", "Ix", "Iy", "Iz", "qw", "qx", "qy", "qz", "px", "py", "pz", "vx", "vy", "vz", "wx", "wy", "wz")
CONTACT_COLUMNS = ("a", "b", "cx", "cy", "cz", "nx", "ny", "nz", "e", "mu")


def float_nearest_text(text):
    """The float nearest the text itself (glibc's strtof rounds correctly)."""
    return np.float32(_libc.strtof(text.encode(), None))


def roundings_part(text):
    """Whether the float nearest the text differs from the float of its
    double."""
    return float_nearest_text(text).tobytes() != np.float32(float(text)).tobytes()


def value_text(f, kind):
    """Text near the finite float32 f: 0 its shortest text, 1 17 digits (not
    its shortest form), 2 the shortest text of the double halfway to the
    next float up, 3 and 4 40 digits a quarter of a double's spacing above
    and below that halfway point (f below float's largest for 2 to 4): its
    double is the halfway point, and its float the even neighbour, while the
    float nearest the text is the one on its side."""
    f = np.float32(f)
    if kind == 0:
        return np.format_float_scientific(f, unique=True)
    if kind == 1:
        return format(float(f), ".16e")
    m = (float(f) + float(np.nextafter(f, np.float32(np.inf)))) / 2  # exact
    if kind == 2:
        return repr(m)
    quarter = _EXACT.divide(decimal.Decimal(abs(np.spacing(m))), 4)
    nudged = (_EXACT.add if kind == 3 else _EXACT.subtract)(decimal.Decimal(m), quarter)
    return format(nudged, ".39e")


def draw_scene(seed, bodies=240, contacts=700, loners=10):
    """The CSV text of a scene (bodies, contacts) made of value_text's kinds:
    halfway cases, long text, subnormals, values near float's largest (only
    in the last `loners` contacts and their own pairs of bodies, whose float
    solves overflow) and inf masses; every value obeys the rules in both
    precisions. Returns (bodies_text, contacts_text, fields whose roundings
    part)."""
    rng = np.random.default_rng(seed)
    parted = 0
    shared = bodies - 2 * loners

    def text(f):
        nonlocal parted
        f = np.float32(f)
        kind = int(rng.integers(5)) if abs(f) < F32_MAX else 1
        t = value_text(f, kind)
        parted += roundings_part(t)
        return t

    def value(lo, hi, extremes, signed):
        f = np.float32(rng.uniform(lo, hi))
        pick = rng.integers(100)
        if extremes and pick < 8:
            f = np.uint32(rng.integers(1, 0x7FFFFF)).view(np.float32)  # subnormal
        elif extremes == "largest" and pick < 40:
            f = np.uint32(0x7F7FFFFF - rng.integers(4)).view(np.float32)
        return -f if signed and rng.integers(2) else f

    rows = [",".join(BODY_COLUMNS)]
    for i in range(bodies):
        extremes = "subnormal" if i < shared else "largest"
        fields = []
        for _ in range(4):  # m, Ix, Iy, Iz
            pick = rng.integers(50)
            fields.append("inf" if pick == 0 else text(F32_MAX / 2 if pick == 1 else value(0.25, 40, None, False)))
        for _ in range(4):  # q
            x = rng.normal()
            if rng.integers(20) == 0:
                x = np.uint32(rng.integers(1, 0x7FFFFF)).view(np.float32)
            fields.append(text(x))
        for k in range(9):  # p, v, w
            scale = 100.0 if k < 3 else 10.0
            fields.append(text(value(-scale, scale, extremes, True)))
        rows.append(",".join(fields))
    body_text = "\n".join(rows) + "\n"

    rows = [",".join(CONTACT_COLUMNS)]
    for k in range(contacts):
        loner = k + loners >= contacts
        if loner:
            a = shared + 2 * (k + loners - contacts)
            b = a + 1
        else:
            a = int(rng.integers(shared))
            b = (a + 1 + int(rng.integers(shared - 1))) % shared
        fields = [str(a), str(b)]
        fields += [text(value(-100, 100, "largest" if loner else "subnormal", True)) for _ in range(3)]
        n = rng.normal(size=3)
        fields += [text(x) for x in n / np.linalg.norm(n)]
        fields.append(text(value(0, 0.999, None, False)))  # e
        fields.append(text(value(0, 1, None, False)))  # mu
        rows.append(",".join(fields))
    return body_text, "\n".join(rows) + "\n", parted


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


def columns(path):
    """The columns of a CSV scene file as the double nearest each field
    (Python's float() rounds correctly): {name: float64 array}."""
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [[float(x) for x in line.split(",")] for line in f if line.strip()]
    data = np.array(rows, dtype=np.float64).reshape(len(rows), len(header))
    return {name: data[:, k].copy() for k, name in enumerate(header)}


def savez(csv_path, npz_path):
    """The CSV file as NumPy writes it: np.savez of its float64 columns (ids
    as NumPy's default int64)."""
    cols = columns(csv_path)
    for k in ("a", "b"):
        if k in cols:
            cols[k] = cols[k].astype(np.int64)
    np.savez(npz_path, **cols)


def scene_files(cli, d, run):
    """The scene d/bodies.csv, d/contacts.csv in every format: `collide
    convert` to '<f8' (d/f8) and to '<f4' (d/f4), and np.savez of the float64
    columns (d/np). Returns {name: (bodies, contacts)}."""
    files = {"csv": (os.path.join(d, "bodies.csv"), os.path.join(d, "contacts.csv"))}
    for tag, precision in (("f8", "double"), ("f4", "float")):
        os.makedirs(os.path.join(d, tag), exist_ok=True)
        files[tag] = tuple(os.path.join(d, tag, f"{t}.npz") for t in ("bodies", "contacts"))
        for src, dst in zip(files["csv"], files[tag]):
            run([cli, "convert", "--in", src, "--out", dst, "--precision", precision])
    os.makedirs(os.path.join(d, "np"), exist_ok=True)
    files["np"] = tuple(os.path.join(d, "np", f"{t}.npz") for t in ("bodies", "contacts"))
    for src, dst in zip(files["csv"], files["np"]):
        savez(src, dst)
    return files
