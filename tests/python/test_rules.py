"""The input rules (collide/rules.hpp) from Python: ``collide.from_physical``
refuses every body the scene reader refuses, with the reader's reason, and
``collide.write_scene`` writes the library's file format (the shortest text
that reads back to the same value)."""

import math
import os
import re
from decimal import Decimal

import numpy as np
import pytest

import collide

COLUMNS = ("m", "Ix", "Iy", "Iz", "qw", "qx", "qy", "qz", "px", "py", "pz", "vx", "vy", "vz", "wx", "wy", "wz")
GOOD = {"m": 2.0, "Ix": 1.0, "Iy": 0.5, "Iz": 0.25, "qw": 0.5, "qx": 0.5, "qy": 0.5, "qz": 0.5, "px": 1.0,
        "py": -2.0, "pz": 3.0, "vx": 0.5, "vy": -3.0, "vz": 0.0, "wx": 0.0, "wy": 1.0, "wz": -1.0}
NAN, INF = float("nan"), float("inf")

# (name, dtype, changed columns, expected reason or None (then only the
# reader's reason is the expectation), expected column)
CASES = [
    # The three that from_physical let through before: a float mass whose
    # inverse overflows, a quaternion whose |q|^2 is subnormal, NaN/inf in p, v, w.
    ("tiny_mass_float", np.float32, {"m": 1e-45}, "mass 1e-45 is too small: its inverse overflows float", "m"),
    ("subnormal_q2_float", np.float32, {"qw": 1e-20, "qx": 0.0, "qy": 0.0, "qz": 0.0},
     "quaternion cannot be normalised in float: it is too close to zero (qw, qx, qy, qz = 1e-20, 0, 0, 0)", "qw"),
    ("subnormal_q2_double", np.float64, {"qw": 1e-160, "qx": 0.0, "qy": 0.0, "qz": 0.0},
     "quaternion cannot be normalised in double: it is too close to zero (qw, qx, qy, qz = 1e-160, 0, 0, 0)", "qw"),
    ("nan_p", np.float64, {"py": NAN}, "NaN is not allowed", "py"),
    ("nan_v", np.float32, {"vx": NAN}, "NaN is not allowed", "vx"),
    ("nan_w", np.float64, {"wz": NAN}, "NaN is not allowed", "wz"),
    ("inf_p", np.float32, {"pz": INF}, "inf is not allowed here (only m, Ix, Iy and Iz may be inf), got inf", "pz"),
    ("inf_v", np.float64, {"vy": -INF}, "inf is not allowed here (only m, Ix, Iy and Iz may be inf), got -inf", "vy"),
    ("inf_w", np.float32, {"wx": INF}, "inf is not allowed here (only m, Ix, Iy and Iz may be inf), got inf", "wx"),
    # Every other body rule, both precisions.
    ("nan_m", np.float64, {"m": NAN}, "NaN is not allowed", "m"),
    ("negative_m", np.float32, {"m": -1.0}, "mass must be > 0, got -1", "m"),
    ("zero_m", np.float64, {"m": 0.0}, "mass must be > 0, got 0 (an immovable body has m = inf)", "m"),
    ("minus_inf_m", np.float64, {"m": -INF}, "mass must be > 0, got -inf", "m"),
    ("tiny_mass_double", np.float64, {"m": 5e-324}, "mass 5e-324 is too small: its inverse overflows double", "m"),
    ("zero_moment", np.float32, {"Iy": 0.0}, "moment of inertia must be > 0, got 0 (a locked axis has moment inf)", "Iy"),
    ("negative_moment", np.float64, {"Iz": -0.5}, "moment of inertia must be > 0, got -0.5", "Iz"),
    ("tiny_moment_float", np.float32, {"Ix": 1e-40},
     "moment of inertia 1e-40 is too small: its inverse overflows float", "Ix"),
    ("nan_q", np.float32, {"qz": NAN}, "NaN is not allowed", "qz"),
    ("inf_q", np.float64, {"qw": INF}, "inf is not allowed here (only m, Ix, Iy and Iz may be inf), got inf", "qw"),
    ("zero_q", np.float64, {"qw": 0.0, "qx": 0.0, "qy": 0.0, "qz": 0.0},
     "zero quaternion (qw, qx, qy, qz are all 0)", "qw"),
    ("underflowing_q2_float", np.float32, {"qw": 1e-25, "qx": 1e-25, "qy": 0.0, "qz": 0.0},
     "quaternion cannot be normalised in float: it is too close to zero (qw, qx, qy, qz = 1e-25, 1e-25, 0, 0)", "qw"),
    ("overflowing_q2_float", np.float32, {"qw": 1e20},
     "quaternion cannot be normalised in float: it is too large (qw, qx, qy, qz = 1e+20, 0.5, 0.5, 0.5)", "qw"),
    ("overflowing_q2_double", np.float64, {"qx": -1e200},
     "quaternion cannot be normalised in double: it is too large (qw, qx, qy, qz = 0.5, -1e+200, 0.5, 0.5)", "qw"),
]


def text_of(x, dtype):
    """The shortest text of x in dtype (what the library's writer writes)."""
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return str(dtype(x)) if dtype == np.float32 else repr(float(x))


def physical_arrays(values, dtype):
    """from_physical's arguments for one body."""
    col = lambda names: np.array([[values[n]] for n in names], dtype=dtype)
    return (np.array([values["m"]], dtype=dtype), col(("Ix", "Iy", "Iz")), col(("qw", "qx", "qy", "qz")),
            col(("px", "py", "pz")), col(("vx", "vy", "vz")), col(("wx", "wy", "wz")))


def reader_message(workdir, values, dtype):
    """The scene reader's message for a one-body file holding `values`."""
    b_csv, c_csv = os.path.join(workdir, "bodies.csv"), os.path.join(workdir, "contacts.csv")
    with open(b_csv, "w") as f:
        f.write(",".join(COLUMNS) + "\n" + ",".join(text_of(values[c], dtype) for c in COLUMNS) + "\n")
    with open(c_csv, "w") as f:
        f.write("a,b,cx,cy,cz,nx,ny,nz,e,mu\n")
    with pytest.raises(ValueError) as e:
        collide.read_scene(b_csv, c_csv, dtype=dtype)
    return str(e.value), b_csv


# from_physical refuses with the reader's very reason (a zero mass or moment
# names inf, what the caller most likely meant, on every route).
@pytest.mark.parametrize("name,dtype,change,reason,column", CASES, ids=[c[0] for c in CASES])
def test_from_physical_gives_the_readers_reason(workdir, name, dtype, change, reason, column):
    values = dict(GOOD, **change)
    message, path = reader_message(workdir, values, dtype)
    m = re.fullmatch(re.escape(path) + r":2: row 0, column '(\w+)': (.*)", message)
    assert m, message
    assert m.group(1) == column
    assert m.group(2) == reason
    with pytest.raises(ValueError) as e:
        m_, inertia, q, p, v, w = physical_arrays(values, dtype)
        collide.from_physical(m_, inertia, q, p, v, w, dtype=dtype)
    assert str(e.value) == f"from_physical: body 0, column '{column}': {reason}"


def test_from_physical_names_the_body():
    m = np.array([1.0, 2.0, 3.0, -4.0])
    inertia = np.ones((3, 4))
    q = np.zeros((4, 4))
    q[0] = 1
    p = np.zeros((3, 4))
    p[2, 1] = np.nan  # body 1 comes first
    with pytest.raises(ValueError, match=r"^from_physical: body 1, column 'pz': NaN is not allowed$"):
        collide.from_physical(m, inertia, q, p)
    p[2, 1] = 0
    with pytest.raises(ValueError, match=r"^from_physical: body 3, column 'm': mass must be > 0, got -4$"):
        collide.from_physical(m, inertia, q, p)
    m[2] = 0.0  # the immovable body written as in kernel units: m = inf is the one
    with pytest.raises(ValueError, match=r"^from_physical: body 2, column 'm': mass must be > 0, got 0 "
                                         r"\(an immovable body has m = inf\)$"):
        collide.from_physical(m, inertia, q, p)


def test_from_physical_accepts_the_edges():
    m = np.array([np.inf, 1e-30, 2.0], dtype=np.float32)
    inertia = np.array([[1.0, 1.0, np.inf], [1.0, 1.0, 1.0], [1.0, 1.0, np.inf]], dtype=np.float32)
    q = np.array([[2.0, 1e-15, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]], dtype=np.float32)
    p = np.zeros((3, 3), dtype=np.float32)
    v = np.full((3, 3), np.float32(1e-40))  # subnormal: finite, allowed
    bodies = collide.from_physical(m, inertia, q, p, v, dtype=np.float32)
    assert list(bodies.inv_mass) == [0.0, np.float32(1) / np.float32(1e-30), 0.5]
    assert list(bodies.q[:, 0]) == [2.0, 0.0, 0.0, 0.0]  # as given: the law normalises q


# ---------------------------------------------------------------------------
# write_scene: the library's writer.
# ---------------------------------------------------------------------------

def rows(path):
    with open(path) as f:
        lines = f.read().split("\n")
    assert lines[-1] == ""
    return lines[0], [line.split(",") for line in lines[1:-1]]


def same_number(text, expected, dtype):
    """`text` is the shortest text of `expected` in dtype: the same decimal
    value as Python's / NumPy's shortest repr."""
    return Decimal(text) == Decimal(text_of(float(expected), dtype))


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_write_scene_writes_the_shortest_text_of_every_value(workdir, dtype):
    # More rows than one block of the parallel writer (16384).
    bodies, contacts = collide.generate("debris", 40000, friction=True, dtype=dtype)
    b_csv, c_csv = os.path.join(workdir, "b.csv"), os.path.join(workdir, "c.csv")
    collide.write_scene(b_csv, c_csv, bodies, contacts)

    header, body_rows = rows(b_csv)
    assert header == ",".join(COLUMNS)
    assert len(body_rows) == len(bodies)
    one = dtype(1)
    with np.errstate(divide="ignore"):
        physical = [np.where(bodies.inv_mass == 0, dtype(np.inf), one / bodies.inv_mass)]
        physical += [np.where(x == 0, dtype(np.inf), one / x) for x in bodies.inv_inertia]
    physical += list(bodies.q) + list(bodies.p) + list(bodies.v) + list(bodies.w)
    for i in list(range(0, len(bodies), 97)) + [len(bodies) - 1]:
        for k, col in enumerate(COLUMNS):
            assert same_number(body_rows[i][k], physical[k][i], dtype), (i, col, body_rows[i][k], physical[k][i])

    header, contact_rows = rows(c_csv)
    assert header == "a,b,cx,cy,cz,nx,ny,nz,e,mu"
    assert len(contact_rows) == len(contacts)
    values = list(contacts.c) + list(contacts.n) + [contacts.e, contacts.mu]
    for k in list(range(0, len(contacts), 89)) + [len(contacts) - 1]:
        r = contact_rows[k]
        assert (int(r[0]), int(r[1])) == (contacts.a[k], contacts.b[k])
        for j in range(8):
            assert same_number(r[2 + j], values[j][k], dtype), (k, j, r[2 + j], values[j][k])

    # And the files read back to the same scene.
    b2, c2 = collide.read_scene(b_csv, c_csv, dtype=dtype)
    for name in ("p", "v", "w"):
        assert np.array_equal(getattr(b2, name), getattr(bodies, name)), name
    assert np.array_equal(c2.a, contacts.a) and np.array_equal(c2.b, contacts.b)
    assert np.array_equal(c2.c, contacts.c) and np.array_equal(c2.e, contacts.e) and np.array_equal(c2.mu, contacts.mu)


def test_write_scene_uniform_e_and_frictionless(workdir):
    bodies, contacts = collide.generate("pairs", 3, dtype=np.float64)
    plain = collide.Contacts(contacts.a, contacts.b, contacts.c, contacts.n, uniform_e=0.25)
    b_csv, c_csv = os.path.join(workdir, "b.csv"), os.path.join(workdir, "c.csv")
    collide.write_scene(b_csv, c_csv, bodies, plain)
    _, contact_rows = rows(c_csv)
    assert [r[8:] for r in contact_rows] == [["0.25", "0"]] * 3
