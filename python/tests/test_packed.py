"""The packed (record) layout from Python: PackedBodies over the caller's
records, in place and with no copy; the same bits as the SoA solve; exact
conversion to and from Bodies; every bad record array refused with TypeError
or ValueError naming it (and the first bad element), modifying nothing."""

import numpy as np
import pytest

import collide

MODELS = ("rigid", "sphere", "particle")
DTYPES = (np.float32, np.float64)
# Values per record (padding included): collide/packed.hpp.
COLUMNS = {(np.float32, "rigid"): 32, (np.float32, "sphere"): 16, (np.float32, "particle"): 4,
           (np.float64, "rigid"): 24, (np.float64, "sphere"): 16, (np.float64, "particle"): 4}


def isas():
    return sorted({"sse2", collide.best_isa()})


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("kind,friction", [("pairs", False), ("debris", True)])
@pytest.mark.parametrize("columns", [False, True])
def test_packed_solve_is_bitwise_the_soa_solve(dtype, model, kind, friction, columns):
    bodies, contacts = collide.generate(kind, 3000, model=model, friction=friction, dtype=dtype)
    packed = collide.pack(bodies, model, contacts=contacts, columns=columns)
    assert packed.model == model and len(packed) == len(bodies)
    for isa in isas():
        soa = collide.pack(bodies, model, contacts=contacts).unpack()  # a fresh SoA copy of the same state
        rec = collide.PackedBodies(packed.records, model=model)
        before = packed.records.copy()
        J_soa, s_soa = collide.solve(soa, contacts, model=model, isa=isa)
        J_rec, s_rec = collide.solve(rec, contacts, isa=isa)
        assert s_rec["layout"] == "packed" and s_rec["model"] == model and s_rec["isa"] == isa
        assert np.array_equal(J_rec, J_soa), (isa, np.nanmax(np.abs(J_rec - J_soa)))
        after = rec.unpack()
        assert np.array_equal(after.v, soa.v) and np.array_equal(after.w, soa.w), isa
        packed.records[...] = before  # the next ISA starts from the same state


def test_zero_copy_and_in_place():
    bodies, contacts = collide.generate("pairs", 2000, dtype=np.float32)
    for columns in (False, True):
        packed = collide.pack(bodies, "rigid", columns=columns)
        records = packed.records
        address = records.ctypes.data
        v0 = packed.v.copy()
        assert np.shares_memory(packed.v, records) and np.shares_memory(packed.inv_mass, records)
        out = np.empty((3, len(contacts)), np.float32)
        J, _ = collide.solve(packed, contacts, out=out)
        assert J is out or J.ctypes.data == out.ctypes.data
        assert packed.records is records and records.ctypes.data == address
        assert not np.array_equal(packed.v, v0)  # updated in place
        # A PackedBodies made by the caller over its own array sees the same memory.
        again = collide.PackedBodies(records)
        assert again.records.ctypes.data == address and again.model == "rigid"


@pytest.mark.parametrize("dtype", DTYPES)
def test_conversions_are_exact(dtype):
    bodies, _ = collide.generate("debris", 500, dtype=dtype)
    packed = collide.pack(bodies, "rigid")
    s = packed.structured
    assert np.array_equal(s["v"], bodies.v.T) and np.array_equal(s["q"], bodies.q.T)
    assert np.array_equal(s["inv_mass"], bodies.inv_mass) and np.array_equal(s["inv_inertia"], bodies.inv_inertia.T)
    back = packed.unpack()
    for f in ("inv_mass", "inv_inertia", "q", "p", "v", "w"):
        assert np.array_equal(getattr(back, f), getattr(bodies, f)), f
    # Into existing Bodies, and only the velocities of movable bodies.
    target = collide.pack(bodies, "rigid").unpack()
    target.v[...] = 5
    target.w[...] = 5
    packed.unpack_velocities(target)
    movable = bodies.inv_mass != 0
    assert np.array_equal(target.v[:, movable], bodies.v[:, movable])
    assert np.all(target.v[:, ~movable] == 5)
    assert packed.unpack(into=target) is target
    assert np.array_equal(target.v, bodies.v)


@pytest.mark.parametrize("dtype", DTYPES)
def test_sphere_and_particle_records(dtype):
    bodies, contacts = collide.generate("pairs", 1000, model="sphere", dtype=dtype)
    sphere = collide.pack(bodies, "sphere")
    back = sphere.unpack()
    assert np.array_equal(back.inv_inertia[0], bodies.inv_inertia[0])
    assert np.array_equal(back.inv_inertia[1], back.inv_inertia[0]) and np.all(back.q[0] == 1)
    assert collide.pack(bodies, "auto", contacts=contacts).model == "sphere"  # the cheapest model that fits
    with pytest.raises(ValueError, match="model 'particle' does not fit the scene"):
        collide.pack(bodies, "particle", contacts=contacts)
    with pytest.raises(ValueError, match="model 'particle' needs the contacts"):
        collide.pack(bodies, "particle")
    rigid, _ = collide.generate("pairs", 100, model="rigid", dtype=dtype)
    with pytest.raises(ValueError, match="model 'sphere' does not fit the scene: body 0"):
        collide.pack(rigid, "sphere")
    particles, pc = collide.generate("pairs", 100, model="particle", dtype=dtype)
    p = collide.pack(particles, "particle", contacts=pc)
    assert p.records.dtype.itemsize == (16 if dtype == np.float32 else 32)
    assert np.array_equal(p.unpack().v, particles.v)


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("model", MODELS)
def test_record_dtype_and_alignment(dtype, model):
    d = collide.packed_dtype(model, dtype)
    assert d.itemsize == COLUMNS[(dtype, model)] * np.dtype(dtype).itemsize
    r = collide.packed_empty(7, model, dtype)
    assert r.dtype == d and r.shape == (7,) and not r.view(np.uint8).any()
    assert r.ctypes.data % collide._collide.packed_alignment(model, dtype) == 0
    c = collide.packed_empty(7, model, dtype, columns=True)
    assert c.shape == (7, COLUMNS[(dtype, model)]) and c.dtype == np.dtype(dtype)
    assert collide.PackedBodies(c).model == model and collide.PackedBodies(r).model == model


def test_bad_record_arrays():
    good = collide.packed_empty(10, "rigid", np.float32, columns=True)
    with pytest.raises(TypeError, match=r"packed\.records must be a numpy\.ndarray, got <class 'list'>"):
        collide.PackedBodies(good.tolist())
    with pytest.raises(TypeError, match=r"packed\.records has shape \(10, 12\), expected \(N, 32\) for rigid or "
                                        r"\(N, 16\) for sphere or \(N, 4\) for particle records of float32"):
        collide.PackedBodies(np.zeros((10, 12), np.float32))
    with pytest.raises(TypeError, match=r"packed\.records has dtype int32"):
        collide.PackedBodies(np.zeros((10, 32), np.int32))
    wrong = np.dtype({"names": ["w", "v"], "formats": [("<f4", (3,)), ("<f4", (3,))], "itemsize": 128})
    with pytest.raises(TypeError, match=r"packed\.records has dtype .* which is not a record dtype"):
        collide.PackedBodies(np.zeros(10, wrong))
    with pytest.raises(TypeError, match=r"packed\.records has dtype .* which is not collide\.packed_dtype\('sphere'"):
        collide.PackedBodies(collide.packed_empty(10, "rigid"), model="sphere")
    raw = collide.packed_empty(11, "rigid", np.float32, columns=True)
    shifted = raw.reshape(-1)[4:4 + 320].reshape(10, 32)  # 16 bytes past the 64-byte boundary
    with pytest.raises(TypeError, match=r"starts 16 bytes past a multiple of 64, the alignment of rigid float32 "
                                        r"records: allocate them with collide\.packed_empty\(\) or collide\.pack\(\)"):
        collide.PackedBodies(shifted)
    with pytest.raises(TypeError, match=r"packed\.records must be C-contiguous"):
        collide.PackedBodies(collide.packed_empty(20, "rigid")[::2])
    ro = collide.packed_empty(10, "rigid")
    ro.setflags(write=False)
    with pytest.raises(TypeError, match=r"packed\.records must be writeable"):
        collide.PackedBodies(ro)
    with pytest.raises(TypeError, match=r"packed\.records has shape \(2, 5\), expected \(N,\) records"):
        collide.PackedBodies(collide.packed_empty(10, "rigid").reshape(2, 5))


def corrupted(kind):
    bodies, contacts = collide.generate("pairs", 40, friction=True, dtype=np.float64)
    packed = collide.pack(bodies, "rigid")
    s = packed.structured
    if kind == "nan_v":
        s["v"][9, 1] = np.nan
        return packed, contacts, r"bodies\.v\.y\[9\] = nan: must be finite"
    if kind == "negative_mass":
        s["inv_mass"][4] = -1.0
        return packed, contacts, r"bodies\.inv_mass\[4\] = -1"
    if kind == "inertia":
        s["inv_inertia"][3, 2] = np.inf
        return packed, contacts, r"bodies\.inv_inertia\.z\[3\] = inf"
    if kind == "quaternion":
        s["q"][6] = [2.0, 0.0, 0.0, 0.0]
        return packed, contacts, r"bodies\.\|q\|\[6\] = 2"
    if kind == "index":
        contacts.b[7] = 80
        return packed, contacts, r"contacts\.b\[7\] = 80: out of range"
    raise AssertionError(kind)


@pytest.mark.parametrize("kind", ["nan_v", "negative_mass", "inertia", "quaternion", "index"])
def test_bad_values_in_records_name_the_element_and_modify_nothing(kind):
    packed, contacts, message = corrupted(kind)
    before = packed.records.view(np.uint8).copy()  # every byte, padding included
    out = np.full((3, len(contacts)), 7.0)
    with pytest.raises(ValueError, match=message):
        collide.solve(packed, contacts, out=out)
    assert np.array_equal(packed.records.view(np.uint8), before)
    assert np.all(out == 7.0)
    with pytest.raises(ValueError, match=message):
        collide.Schedule(packed, contacts)
    with pytest.raises(ValueError, match=message):
        collide.reference_solve(packed, contacts)


def test_padding_is_not_read():
    bodies, contacts = collide.generate("pairs", 100, dtype=np.float32)
    cols = collide.pack(bodies, "rigid", columns=True).records
    cols[:, 17:] = np.nan  # the padding of PackedRigid<float>: values 17 to 31
    J, _ = collide.solve(collide.PackedBodies(cols), contacts)
    assert np.all(np.isfinite(J))


def test_packed_model_and_precision_mismatches():
    bodies, contacts = collide.generate("pairs", 50, dtype=np.float32)
    packed = collide.pack(bodies, "rigid")
    with pytest.raises(ValueError, match="model 'sphere' does not match the records: they are rigid records"):
        collide.solve(packed, contacts, model="sphere")
    _, contacts64 = collide.generate("pairs", 50, dtype=np.float64)
    with pytest.raises(TypeError, match="bodies are float32 but contacts are float64"):
        collide.solve(packed, contacts64)
    other, _ = collide.generate("pairs", 60, dtype=np.float32)
    with pytest.raises(ValueError, match="bodies has 120 bodies but the records 100"):
        packed.unpack(into=other)
    with pytest.raises(ValueError, match="schedule was built for"):
        collide.solve(packed, contacts, schedule=collide.Schedule(collide.pack(other), collide.generate(
            "pairs", 60, dtype=np.float32)[1]))


def test_frame_loop_on_records():
    bodies, contacts = collide.generate("debris", 4000, friction=True, dtype=np.float32)
    soa = collide.pack(bodies, "rigid").unpack()
    packed = collide.pack(bodies, "rigid")
    solver, schedule = collide.Solver(), collide.Schedule(packed, contacts)
    out = np.empty((3, len(contacts)), np.float32)
    for _ in range(3):
        J, stats = solver.solve(packed, contacts, schedule=schedule, out=out, check=False, impacts=False)
        J_soa, _ = collide.solve(soa, contacts, model="rigid")
        assert np.array_equal(J, J_soa) and stats["impacts"] is None
    assert np.array_equal(packed.unpack().v, soa.v)


def test_missing_scene_file_is_an_os_error(tmp_path):
    (tmp_path / "c.csv").write_text("a,b,cx,cy,cz,nx,ny,nz,e,mu\n")
    missing = tmp_path / "nope" / "b.csv"
    with pytest.raises(FileNotFoundError, match=r"cannot open: No such file or directory") as info:
        collide.read_scene(missing, tmp_path / "c.csv")
    assert info.value.filename == str(missing)
    with pytest.raises(IsADirectoryError) as info:
        collide.read_scene(tmp_path, tmp_path / "c.csv")
    assert info.value.filename == str(tmp_path)
    # A bad content is still ValueError naming file, line, row and column.
    (tmp_path / "b.csv").write_text("m,Ix\n")
    with pytest.raises(ValueError, match="b.csv"):
        collide.read_scene(tmp_path / "b.csv", tmp_path / "c.csv")


def test_impacts_can_be_skipped():
    bodies, contacts = collide.generate("pairs", 1000, dtype=np.float64)
    v0, w0 = bodies.v.copy(), bodies.w.copy()
    J1, s1 = collide.solve(bodies, contacts)
    np.copyto(bodies.v, v0)
    np.copyto(bodies.w, w0)
    J2, s2 = collide.solve(bodies, contacts, impacts=False)
    assert np.array_equal(J1, J2)
    assert s1["impacts"] == np.count_nonzero(np.any(J1 != 0, axis=0)) and s2["impacts"] is None
    assert list(s1) == list(s2)
