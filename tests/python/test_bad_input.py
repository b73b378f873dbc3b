"""Every bad input: TypeError for dtype, shape and layout, ValueError for
lengths, indices, a == b, NaN/inf, negative inverse mass, a quaternion that
cannot be normalised, a normal off unit length; the message names the array
and the first bad element, and nothing is modified."""

import numpy as np
import pytest

import collide

FIELDS = ("inv_mass", "inv_inertia", "q", "p", "v", "w")


def scene(dtype=np.float64, n=40):
    bodies, contacts = collide.generate("pairs", n, friction=True, dtype=dtype)
    arrays = {f: np.array(getattr(bodies, f)) for f in FIELDS}
    carrays = {f: np.array(getattr(contacts, f)) for f in ("a", "b", "c", "n", "mu")}
    carrays["e"] = np.array(contacts.e)
    return arrays, carrays


def make(arrays, carrays):
    b = collide.Bodies(*(arrays[f] for f in FIELDS))
    c = collide.Contacts(carrays["a"], carrays["b"], carrays["c"], carrays["n"], e=carrays["e"], mu=carrays["mu"])
    return b, c


@pytest.mark.parametrize("field", FIELDS)
def test_wrong_dtype(field):
    arrays, _ = scene()
    arrays[field] = arrays[field].astype(np.float32)
    # The array that differs from the others is named, whichever it is.
    with pytest.raises(TypeError, match=rf"^bodies\.{field} has dtype float32, expected float64 like every other "
                                        rf"array of bodies: one dtype per scene \(bodies\.{field}\.astype"
                                        r"\(numpy\.float64\) converts a copy\)$"):
        collide.Bodies(*(arrays[f] for f in FIELDS))


@pytest.mark.parametrize("field", ["c", "n", "e", "mu"])
def test_wrong_contact_dtype(field):
    _, carrays = scene(np.float32)
    carrays[field] = carrays[field].astype(np.float64)
    with pytest.raises(TypeError, match=rf"^contacts\.{field} has dtype float64, expected float32 like every other "
                                        r"array of contacts"):
        collide.Contacts(carrays["a"], carrays["b"], carrays["c"], carrays["n"], e=carrays["e"], mu=carrays["mu"])
    # Two arrays, one of each: the first one's dtype is the scene's.
    with pytest.raises(TypeError, match=r"^contacts\.n has dtype float64, expected float32 like contacts\.c"):
        collide.Contacts(carrays["a"], carrays["b"], carrays["c"].astype(np.float32), carrays["n"].astype(np.float64))


def test_arrays_the_solve_writes_say_where_the_results_would_go():
    arrays, carrays = scene()
    bad = dict(arrays, v=np.asfortranarray(arrays["v"]))
    with pytest.raises(TypeError, match=r"bodies\.v must be C-contiguous \(the solve writes into it in place: a "
                                        r"contiguous copy, numpy\.ascontiguousarray, would receive the results "
                                        r"instead"):
        collide.Bodies(*(bad[f] for f in FIELDS))
    b, c = make(arrays, carrays)
    with pytest.raises(TypeError, match=r"solve\.out must be C-contiguous \(the solve writes into it in place"):
        collide.solve(b, c, out=np.asfortranarray(np.zeros((3, len(c)))))
    # An array the solve only reads: a copy is all it takes.
    bad = dict(arrays, p=np.asfortranarray(arrays["p"]))
    with pytest.raises(TypeError, match=r"bodies\.p must be C-contiguous \(numpy\.ascontiguousarray makes a "
                                        r"contiguous copy\)$"):
        collide.Bodies(*(bad[f] for f in FIELDS))


def test_uniform_e_is_one_value_not_an_element():
    arrays, carrays = scene()
    b = collide.Bodies(*(arrays[f] for f in FIELDS))
    c = collide.Contacts(carrays["a"], carrays["b"], carrays["c"], carrays["n"], uniform_e=-0.1)
    with pytest.raises(ValueError, match=r"^contacts\.uniform_e = -0\.1: must be in \[0, 1\]$"):
        collide.solve(b, c)


def test_wrong_shape_and_layout():
    arrays, carrays = scene()
    bad = dict(arrays, v=arrays["v"][:2].copy())
    with pytest.raises(TypeError, match=r"bodies\.v has shape \(2, 80\)"):
        collide.Bodies(*(bad[f] for f in FIELDS))
    bad = dict(arrays, q=np.asfortranarray(arrays["q"]))
    with pytest.raises(TypeError, match=r"bodies\.q must be C-contiguous"):
        collide.Bodies(*(bad[f] for f in FIELDS))
    bad = dict(arrays, p=arrays["p"].tolist())
    with pytest.raises(TypeError, match=r"bodies\.p must be a numpy\.ndarray"):
        collide.Bodies(*(bad[f] for f in FIELDS))
    ro = arrays["w"].copy()
    ro.setflags(write=False)
    with pytest.raises(TypeError, match=r"bodies\.w must be writeable"):
        collide.Bodies(*(dict(arrays, w=ro)[f] for f in FIELDS))
    with pytest.raises(TypeError, match=r"contacts\.a has dtype int64"):
        collide.Contacts(carrays["a"].astype(np.int64), carrays["b"], carrays["c"], carrays["n"])
    with pytest.raises(TypeError, match=r"contacts\.n has shape"):
        collide.Contacts(carrays["a"], carrays["b"], carrays["c"], carrays["n"].T.copy())
    with pytest.raises(TypeError, match=r"contacts\.c must be C-contiguous"):
        collide.Contacts(carrays["a"], carrays["b"], np.asfortranarray(carrays["c"]), carrays["n"])


def test_lengths():
    arrays, carrays = scene()
    bad = dict(arrays, w=np.zeros((3, 79)))
    with pytest.raises(ValueError, match=r"bodies\.w has 79 elements, inv_mass has 80"):
        collide.Bodies(*(bad[f] for f in FIELDS))
    with pytest.raises(ValueError, match=r"contacts\.mu has 3 elements"):
        collide.Contacts(carrays["a"], carrays["b"], carrays["c"], carrays["n"], mu=np.zeros(3))
    b, c = make(arrays, carrays)
    with pytest.raises(ValueError, match=r"solve\.out has"):
        collide.solve(b, c, out=np.zeros((3, 5)))


def test_mixed_dtypes():
    arrays, _ = scene(np.float64)
    _, carrays = scene(np.float32)
    b, c = make(arrays, carrays)
    with pytest.raises(TypeError, match="bodies are float64 but contacts are float32"):
        collide.solve(b, c)


def corrupt(kind):
    """A scene with one bad value, and the message naming it."""
    arrays, carrays = scene()
    if kind == "index":
        carrays["b"][7] = 80
        return arrays, carrays, r"contacts\.b\[7\] = 80: out of range"
    if kind == "self":
        carrays["b"][5] = carrays["a"][5]
        return arrays, carrays, r"contacts\.b\[5\].*itself"
    if kind == "nan_v":
        arrays["v"][1, 9] = np.nan
        return arrays, carrays, r"bodies\.v\.y\[9\] = nan: must be finite"
    if kind == "inf_c":
        carrays["c"][2, 3] = np.inf
        return arrays, carrays, r"contacts\.c\.z\[3\] = inf: must be finite"
    if kind == "negative_mass":
        arrays["inv_mass"][4] = -1.0
        return arrays, carrays, r"bodies\.inv_mass\[4\] = -1"
    if kind == "quaternion":
        arrays["q"][:, 6] = [0.0, 0.0, 0.0, 0.0]  # any other length is the caller's: the law normalises q
        return arrays, carrays, r"bodies\.\|q\|\^2\[6\] = 0: must be a normal, finite number"
    if kind == "normal":
        carrays["n"][:, 11] *= 1.5
        return arrays, carrays, r"^contact 11: normal length 1\.5\d* is not 1 within 1e-3$"
    if kind == "restitution":
        carrays["e"][2] = 1.5
        return arrays, carrays, r"contacts\.e\[2\] = 1\.5"
    raise AssertionError(kind)


@pytest.mark.parametrize("kind", ["index", "self", "nan_v", "inf_c", "negative_mass", "quaternion", "normal",
                                  "restitution"])
def test_bad_values_name_the_element_and_modify_nothing(kind):
    arrays, carrays, message = corrupt(kind)
    b, c = make(arrays, carrays)
    before = {f: arrays[f].copy() for f in FIELDS}
    out = np.full((3, len(c)), 7.0)
    with pytest.raises(ValueError, match=message):
        collide.solve(b, c, out=out)
    for f in FIELDS:
        assert np.array_equal(arrays[f], before[f], equal_nan=True), f
    assert np.all(out == 7.0)
    with pytest.raises(ValueError, match=message):
        collide.reference_solve(b, c)
    with pytest.raises(ValueError, match=message):
        collide.Schedule(b, c)


def test_arrays_a_solve_writes_share_no_memory():
    arrays, carrays = scene()
    # The same array for v and w: the solve would write each into the other.
    with pytest.raises(ValueError, match=r"^bodies\.v and bodies\.w share memory: the solve writes both$"):
        collide.Bodies(*(dict(arrays, w=arrays["v"])[f] for f in FIELDS))
    # An array it reads, overlapping one it writes (p shifted by one element into v).
    pv = np.zeros((3, 2 * 80 + 1))
    p, v = pv[:, 1:81], pv[:, :80]
    with pytest.raises(ValueError, match=r"^bodies\.p and bodies\.v share memory: the solve writes bodies\.v while "
                                         r"it reads bodies\.p$"):
        collide.Bodies(*(dict(arrays, p=p, v=v)[f] for f in FIELDS))
    # out= into bodies.v, or into a contact array; and contacts over v.
    b, c = make(arrays, carrays)
    before = {f: arrays[f].copy() for f in FIELDS}
    with pytest.raises(ValueError, match=r"^bodies\.v and solve\.out share memory: the solve writes both$"):
        collide.solve(b, c, out=arrays["v"][:, :len(c)])
    with pytest.raises(ValueError, match=r"^contacts\.n and solve\.out share memory: the solve writes solve\.out "
                                         r"while it reads contacts\.n$"):
        collide.Solver().solve(b, c, out=carrays["n"], check=False)
    mu_in_w = arrays["w"][0, :len(c)]
    with pytest.raises(ValueError, match=r"^bodies\.w and contacts\.mu share memory: the solve writes bodies\.w "
                                         r"while it reads contacts\.mu$"):
        collide.solve(b, collide.Contacts(carrays["a"], carrays["b"], carrays["c"], carrays["n"], mu=mu_in_w))
    for f in FIELDS:
        assert np.array_equal(arrays[f], before[f]), f
    # Packed records: out= into them.
    packed = collide.pack(b, "rigid")
    with pytest.raises(ValueError, match=r"^packed\.records and solve\.out share memory: the solve writes both$"):
        collide.solve(packed, c, out=packed.records.view(np.float64).reshape(-1)[:3 * len(c)].reshape(3, -1))


def test_views_of_one_array_that_touch_other_bytes_are_accepted():
    arrays, carrays = scene()
    expected_b, c = make({f: arrays[f].copy() for f in FIELDS}, carrays)
    J0, _ = collide.solve(expected_b, c)
    # v and w as the rows of one (6, N) array, then as its even and odd rows;
    # c and n the same array (both only read).
    for pick in (lambda vw: (vw[:3], vw[3:]), lambda vw: (vw[0::2], vw[1::2])):
        vw = np.zeros((6, 80))
        v, w = pick(vw)
        v[...] = arrays["v"]
        w[...] = arrays["w"]
        b = collide.Bodies(*(dict(arrays, v=v, w=w)[f] for f in FIELDS))
        J, _ = collide.solve(b, c)
        assert J.tobytes() == J0.tobytes()
        assert np.array_equal(v, expected_b.v) and np.array_equal(w, expected_b.w)
    same = collide.Contacts(carrays["a"], carrays["b"], carrays["n"], carrays["n"])
    collide.solve(make(arrays, carrays)[0], same)


def test_bad_file(tmp_path):
    (tmp_path / "b.csv").write_text("m,Ix\n1,2\n")
    (tmp_path / "c.csv").write_text("a,b\n")
    with pytest.raises(ValueError, match="b.csv"):
        collide.read_scene(tmp_path / "b.csv", tmp_path / "c.csv")


def test_bad_options():
    with pytest.raises(ValueError, match="threads"):
        collide.Solver(threads=-1)
    with pytest.raises(TypeError, match="dtype"):
        collide.generate("pairs", 10, dtype=np.int32)
    with pytest.raises(ValueError, match="kind"):
        collide.generate("cubes", 10)


@pytest.mark.parametrize("kind", ["index", "self"])
def test_unchecked_solve_still_checks_indices(kind):
    arrays, carrays, message = corrupt(kind)
    b, c = make(arrays, carrays)
    before = {f: arrays[f].copy() for f in FIELDS}
    with pytest.raises(ValueError, match=message):
        collide.solve(b, c, model="rigid", check=False)
    for f in FIELDS:
        assert np.array_equal(arrays[f], before[f]), f


@pytest.mark.parametrize("kind", ["index", "self"])
def test_unchecked_model_choice_still_checks_indices(kind):
    # collide.dask's client chooses the model of a loaded scene without a
    # second pass of the rules, never without the index check.
    arrays, carrays, message = corrupt(kind)
    b, c = make(arrays, carrays)
    with pytest.raises(ValueError, match=message):
        collide._collide.choose_model(b, c, check=False)
    with pytest.raises(ValueError, match=message):
        collide._collide.choose_model(b, c)
    arrays, carrays = scene()
    arrays["v"][0, 3] = np.nan
    b, c = make(arrays, carrays)
    with pytest.raises(ValueError, match=r"v.*3"):
        collide._collide.choose_model(b, c)
    assert collide._collide.choose_model(b, c, check=False) == "rigid"


def test_unchecked_solve_is_the_same_solve():
    bodies, contacts = collide.generate("debris", 3000, friction=True, dtype=np.float32)
    v0, w0 = bodies.v.copy(), bodies.w.copy()
    J1, _ = collide.solve(bodies, contacts)
    np.copyto(bodies.v, v0)
    np.copyto(bodies.w, w0)
    J2, _ = collide.solve(bodies, contacts, model="rigid", check=False)
    assert np.array_equal(J1, J2)


def _arrays_unchanged(arrays, before):
    for f, a in arrays.items():
        assert np.array_equal(a, before[f], equal_nan=True), f


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("kind", ["index", "self"])
def test_unchecked_solve_builds_a_schedule_that_refuses_bad_indices(dtype, kind):
    # check=False without a schedule: the library's Schedule::build checks
    # the indices in its level pass and its std::invalid_argument arrives as
    # ValueError, before anything is written.
    arrays, carrays, message = corrupt(kind)
    arrays = {f: a.astype(dtype) for f, a in arrays.items()}
    carrays = {f: (a.astype(dtype) if a.dtype.kind == "f" else a) for f, a in carrays.items()}
    b, c = make(arrays, carrays)
    before, cbefore = ({f: a.copy() for f, a in d.items()} for d in (arrays, carrays))
    out = np.full((3, len(c)), 7.0, dtype=dtype)
    for model in ("auto", "rigid", "particle"):
        with pytest.raises(ValueError, match="Schedule::build: " + message):
            collide.solve(b, c, model=model, check=False, out=out)
        with pytest.raises(ValueError, match="Schedule::build: " + message):
            collide.Solver(path="scalar").solve(b, c, model=model, check=False, out=out)
    packed = collide.pack(b, "rigid")
    records = packed.records.tobytes()
    with pytest.raises(ValueError, match="Schedule::build: " + message):
        collide.solve(packed, c, check=False, out=out)
    assert packed.records.tobytes() == records
    _arrays_unchanged(arrays, before)
    _arrays_unchanged(carrays, cbefore)
    assert np.all(out == 7.0)


@pytest.mark.parametrize("kind", ["index", "self"])
def test_unchecked_solve_with_an_earlier_schedule_refuses_indices_changed_since(kind):
    # A schedule built while the indices were good, then one index broken in
    # the caller's array: the solve checks the indices again beside it.
    arrays, carrays = scene()
    b, c = make(arrays, carrays)
    schedule = collide.Schedule(b, c)
    good = {f: carrays[f].copy() for f in ("a", "b")}
    _, broken, message = corrupt(kind)
    for f in ("a", "b"):
        np.copyto(carrays[f], broken[f])
    before, cbefore = ({f: a.copy() for f, a in d.items()} for d in (arrays, carrays))
    out = np.full((3, len(c)), 7.0)
    for model in ("auto", "rigid"):
        with pytest.raises(ValueError, match=message):
            collide.solve(b, c, model=model, schedule=schedule, check=False, out=out)
        with pytest.raises(ValueError, match=message):
            collide.Solver().solve(b, c, model=model, schedule=schedule, check=False, out=out)
    _arrays_unchanged(arrays, before)
    _arrays_unchanged(carrays, cbefore)
    assert np.all(out == 7.0)
    # The same schedule with the indices restored solves as before.
    for f in ("a", "b"):
        np.copyto(carrays[f], good[f])
    J, _ = collide.solve(b, c, schedule=schedule, check=False)
    assert np.all(np.isfinite(J))
