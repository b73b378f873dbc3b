"""One scene, one answer (docs/collision-law.md, "Scene values"): the same
scene through every Python route to the solver (collide.read_scene,
collide.load of CSV, of `collide convert`'s '<f8' and '<f4' files, of
np.savez's files and of mixed pairs, collide.from_physical from float64
arrays with Contacts cast by NumPy), in float32 and float64, fast and
accurate, gives the same bytes of v, w and J; a value beyond float and a
subnormal the rules refuse are refused by every route with one reason,
collide.dask's included (the bytes its workers give are test_dask.py's)."""

import os
import re
import shutil
import subprocess

import numpy as np
import pytest

import collide
import collide.dask
from conftest import run
from scene_value_text import BODY_COLUMNS, columns, draw_scene, roundings_part, scene_files, value_text, write

DATA = os.path.join(os.path.dirname(__file__), "..", "..", "data", "scene-values", "two-bodies")
DTYPES = (np.float32, np.float64)
ACCURACIES = ("fast", "accurate")


def outputs(bodies, contacts, accuracy):
    """J, v and w of a solve, as bytes."""
    J, _ = collide.solve(bodies, contacts, accuracy=accuracy)
    return J.tobytes(), bodies.v.tobytes(), bodies.w.tobytes()


def from_float64_arrays(bodies_csv, contacts_csv, dtype):
    """The scene as a NumPy user holds it, float64 arrays of the files'
    values: the bodies through from_physical, the contacts cast with
    astype, as Contacts takes them."""
    b, c = columns(bodies_csv), columns(contacts_csv)
    stack = lambda cols, names: np.stack([cols[n] for n in names])
    bodies = collide.from_physical(b["m"], stack(b, ("Ix", "Iy", "Iz")), stack(b, ("qw", "qx", "qy", "qz")),
                                   stack(b, ("px", "py", "pz")), stack(b, ("vx", "vy", "vz")),
                                   stack(b, ("wx", "wy", "wz")), dtype=dtype)
    mu = c["mu"].astype(dtype) if np.any(c["mu"] != 0) else None  # all 0: the frictionless kernel, as the readers
    contacts = collide.Contacts(c["a"].astype(np.uint32), c["b"].astype(np.uint32),
                                np.ascontiguousarray(stack(c, ("cx", "cy", "cz")).astype(dtype)),
                                np.ascontiguousarray(stack(c, ("nx", "ny", "nz")).astype(dtype)), c["e"].astype(dtype),
                                mu=mu)
    return bodies, contacts


def routes(files, dtype):
    """Every Python route of the scene's files in dtype: name -> (bodies,
    contacts) maker."""
    csv, f8, f4, npy = files["csv"], files["f8"], files["f4"], files["np"]
    r = {
        "load csv": lambda: collide.load(*csv, dtype=dtype),
        "load npz f8": lambda: collide.load(*f8, dtype=dtype),
        "load np.savez": lambda: collide.load(*npy, dtype=dtype),
        "load csv bodies, npz f8 contacts": lambda: collide.load(csv[0], f8[1], dtype=dtype),
        "load npz f8 bodies, csv contacts": lambda: collide.load(f8[0], csv[1], dtype=dtype),
        "from_physical": lambda: from_float64_arrays(*csv, dtype),
    }
    if dtype == np.float32:
        # A float file holds the float scene; in float64 it is another scene.
        r["load npz f4"] = lambda: collide.load(*f4, dtype=dtype)
        r["load npz f4 bodies, csv contacts"] = lambda: collide.load(f4[0], csv[1], dtype=dtype)
    return r


def expect_every_route_agrees(files):
    for dtype in DTYPES:
        for accuracy in ACCURACIES:
            want = outputs(*collide.read_scene(*files["csv"], dtype=dtype), accuracy)
            for name, make in routes(files, dtype).items():
                got = outputs(*make(), accuracy)
                for k, what in enumerate(("J", "v", "w")):
                    assert got[k] == want[k], f"{name}, {np.dtype(dtype).name}, {accuracy}: {what} differs"


def test_the_two_bodies_give_one_answer(cli, workdir):
    for name in ("bodies.csv", "contacts.csv"):
        shutil.copy(os.path.join(DATA, name), workdir)
    # wz of body 0: the float nearest the text is not the float of its double.
    assert roundings_part("8.856279850006104")
    files = scene_files(cli, workdir, run)
    expect_every_route_agrees(files)
    for accuracy in ACCURACIES:
        bodies, contacts = collide.read_scene(*files["csv"], dtype=np.float32)
        assert bodies.w[2, 0] == np.float32(np.float64("8.856279850006104"))
        collide.solve(bodies, contacts, accuracy=accuracy)
        assert str(bodies.w[2, 0]) == "6.996387"


@pytest.mark.parametrize("seed", [1, 2])
def test_drawn_values_where_the_roundings_part_give_one_answer(cli, workdir, seed):
    bodies, contacts, parted = draw_scene(seed)
    assert parted > 1000, "the scene is made of the cases it is about"
    write(os.path.join(workdir, "bodies.csv"), bodies)
    write(os.path.join(workdir, "contacts.csv"), contacts)
    expect_every_route_agrees(scene_files(cli, workdir, run))


@pytest.mark.parametrize("kind,arg", [("--pairs", 3000), ("--debris", 6000), ("--pile", 8)])
def test_generated_scenes_give_one_answer(cli, workdir, kind, arg):
    run([cli, "gen", kind, str(arg), "--out", workdir, "--seed", "2", "--friction"])
    files = scene_files(cli, workdir, run)
    expect_every_route_agrees(files)
    # And collide.generate's own scene in memory.
    name = kind[2:]
    for dtype in DTYPES:
        for accuracy in ACCURACIES:
            want = outputs(*collide.read_scene(*files["csv"], dtype=dtype), accuracy)
            got = outputs(*collide.generate(name, arg, seed=2, friction=True, dtype=dtype), accuracy)
            assert got == want, f"generate, {np.dtype(dtype).name}, {accuracy}"


# ---------------------------------------------------------------------------
# What every route refuses, with one message.
# ---------------------------------------------------------------------------

GOOD = "2,1,1,1,1,0,0,0,0,0,0,0.5,-3,0,0,0,1"
CONTACTS = "a,b,cx,cy,cz,nx,ny,nz,e,mu\n0,1,0,0,0,0,0,1,0.5,0\n"


def body_rows(changes, rows=3):
    """A bodies file of `rows` good bodies with (row, column) -> text changed."""
    lines = [",".join(BODY_COLUMNS)]
    for i in range(rows):
        fields = GOOD.split(",")
        for (r, column), text in changes.items():
            if r == i:
                fields[BODY_COLUMNS.index(column)] = text
        lines.append(",".join(fields))
    return "\n".join(lines) + "\n"


def refusals(cli, workdir, text):
    """The messages of every float32 route refusing the bodies `text`: the
    CSV reader (read_scene, load), the binary reader (np.savez's file, and
    `collide convert`'s '<f8' file where the text obeys the rules in
    double), from_physical on the float64 columns, and collide.dask's
    client: {route: (location, reason)}."""
    csv = os.path.join(workdir, "bodies.csv")
    contacts = os.path.join(workdir, "contacts.csv")
    write(csv, text)
    write(contacts, CONTACTS)
    # `collide convert` writes a '<f8' file of a text that obeys the rules in
    # double; np.savez writes any.
    f8 = os.path.join(workdir, "bodies.npz")
    convertible = subprocess.run([cli, "convert", "--in", csv, "--out", f8], capture_output=True).returncode == 0
    npy = os.path.join(workdir, "np_bodies.npz")
    cols = columns(csv)
    np.savez(npy, **cols)
    contacts_npz = os.path.join(workdir, "contacts.npz")
    run([cli, "convert", "--in", contacts, "--out", contacts_npz])
    stack = lambda names: np.stack([cols[n] for n in names])
    attempts = {
        "read_scene": lambda: collide.read_scene(csv, contacts, dtype=np.float32),
        "load csv": lambda: collide.load(csv, contacts, dtype=np.float32),
        "load np.savez": lambda: collide.load(npy, contacts, dtype=np.float32),
        "from_physical": lambda: collide.from_physical(cols["m"], stack(("Ix", "Iy", "Iz")),
                                                       stack(("qw", "qx", "qy", "qz")), stack(("px", "py", "pz")),
                                                       stack(("vx", "vy", "vz")), stack(("wx", "wy", "wz")),
                                                       dtype=np.float32),
        "dask": lambda: collide.dask.solve((npy, contacts_npz), dtype=np.float32,
                                           out_dir=os.path.join(workdir, "out")),
    }
    if convertible:
        attempts["load npz f8"] = lambda: collide.load(f8, contacts, dtype=np.float32)
    got = {}
    for name, attempt in attempts.items():
        with pytest.raises(ValueError) as e:
            attempt()
        m = re.fullmatch(r"(.*?: (?:row|body) \d+, column '\w+'): (.*)", str(e.value))
        assert m, f"{name}: {e.value}"
        got[name] = m.groups()
    return got


def expect_one_reason(got, row, column, reason):
    for name, (location, r) in got.items():
        assert r == reason, f"{name}: {location}: {r}"
        assert location.endswith(f"{'body' if name == 'from_physical' else 'row'} {row}, column '{column}'"), \
            f"{name}: {location}"


@pytest.mark.parametrize("text", ["3.4028235677973366e+38", "3.4028235677973365e38", "1e39"])
def test_a_double_beyond_float_is_refused_by_every_route_with_one_reason(cli, workdir, text):
    # 2^128 - 2^103 (float's largest plus half its spacing) and beyond round
    # to inf; text a little below it reads as that double too.
    value = np.float64(text)
    with np.errstate(over="ignore"):
        assert np.isinf(np.float32(value))
    for column in ("m", "vx"):
        got = refusals(cli, workdir, body_rows({(1, column): text}))
        expect_one_reason(got, 1, column, f"value {value!r} is out of the range of float")


def test_rows_are_judged_in_the_readers_order_by_every_route(cli, workdir):
    # A rule broken in an earlier row comes first; in one row, a value beyond
    # float comes before the rules, the first column first.
    expect_one_reason(refusals(cli, workdir, body_rows({(0, "m"): "-1", (1, "vx"): "1e39"})), 0, "m",
                      "mass must be > 0, got -1")
    expect_one_reason(refusals(cli, workdir, body_rows({(1, "m"): "-1", (1, "vx"): "1e39"})), 1, "vx",
                      "value 1e+39 is out of the range of float")
    expect_one_reason(refusals(cli, workdir, body_rows({(1, "vx"): "1e39", (1, "py"): "4e38"})), 1, "py",
                      "value 4e+38 is out of the range of float")


def test_subnormals_the_rules_refuse_are_refused_by_every_route_with_one_reason(cli, workdir):
    expect_one_reason(refusals(cli, workdir, body_rows({(1, "m"): "1e-40"})), 1, "m",
                      "mass 1e-40 is too small: its inverse overflows float")
    # Text above the halfway point of two subnormal floats: the float is the
    # even one, below, on every route.
    even = np.uint32(0x00012344).view(np.float32)
    above = value_text(even, 3)
    assert roundings_part(above)
    got = refusals(cli, workdir, body_rows({(1, "Iy"): above}))
    number = re.fullmatch(r"moment of inertia (\S+) is too small: its inverse overflows float", got["read_scene"][1])
    assert number and np.float32(number.group(1)) == even, got["read_scene"]
    expect_one_reason(got, 1, "Iy", got["read_scene"][1])
    expect_one_reason(refusals(cli, workdir, body_rows({(1, "m"): "1e-46"})), 1, "m",
                      "mass must be > 0, got 0 (an immovable body has m = inf)")
    expect_one_reason(refusals(cli, workdir, body_rows({(1, "qw"): "1e-20", (1, "qx"): "3e-21"})), 1, "qw",
                      "quaternion cannot be normalised in float: it is too close to zero "
                      "(qw, qx, qy, qz = 1e-20, 3e-21, 0, 0)")
