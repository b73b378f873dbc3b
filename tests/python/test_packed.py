"""The packed (record) layout from Python: PackedBodies over the caller's
records (and, for rigid records, the inverse masses beside them), in place
and with no copy; the same bits as the SoA solve; exact conversion to and from
Bodies; every bad record or inverse-mass array refused with TypeError or
ValueError naming it (and the first bad element), modifying nothing."""

import numpy as np
import pytest

import collide

MODELS = ("rigid", "sphere", "particle")
DTYPES = (np.float32, np.float64)
# Values per record (padding included): collide/packed.hpp. A rigid record
# holds 16 values and no padding; its inverse mass lives beside it.
COLUMNS = {(np.float32, "rigid"): 16, (np.float32, "sphere"): 16, (np.float32, "particle"): 4,
           (np.float64, "rigid"): 16, (np.float64, "sphere"): 16, (np.float64, "particle"): 4}
# Alignment of a record (alignas in collide/packed.hpp).
ALIGNMENT = {(np.float32, "rigid"): 64, (np.float32, "sphere"): 64, (np.float32, "particle"): 16,
             (np.float64, "rigid"): 128, (np.float64, "sphere"): 64, (np.float64, "particle"): 32}


def side(packed):
    """The inv_mass= a PackedBodies over packed's records takes: rigid records' array beside them, else None."""
    return packed.inv_mass if packed.model == "rigid" else None


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
        rec = collide.PackedBodies(packed.records, model=model, inv_mass=side(packed))
        before = packed.records.copy()
        J_soa, s_soa = collide.solve(soa, contacts, model=model, isa=isa)
        J_rec, s_rec = collide.solve(rec, contacts, isa=isa)
        assert s_rec["layout"] == "packed" and s_rec["model"] == model and s_rec["isa"] == isa
        assert np.array_equal(J_rec, J_soa), (isa, np.nanmax(np.abs(J_rec - J_soa)))
        after = rec.unpack()
        assert np.array_equal(after.v, soa.v) and np.array_equal(after.w, soa.w), isa
        packed.records[...] = before  # the next ISA starts from the same state


@pytest.mark.parametrize("dtype", DTYPES)
def test_zero_copy_and_in_place(dtype):
    bodies, contacts = collide.generate("pairs", 2000, dtype=dtype)
    for columns in (False, True):
        packed = collide.pack(bodies, "rigid", columns=columns)
        records, inv_mass = packed.records, packed.inv_mass
        address, inv_address = records.ctypes.data, inv_mass.ctypes.data
        assert inv_mass.shape == (len(bodies),) and inv_mass.dtype == dtype and inv_mass.flags.c_contiguous
        assert packed.inv_mass is inv_mass  # the array beside the records, not a copy per access
        assert np.shares_memory(packed.v, records) and not np.shares_memory(inv_mass, records)
        assert not np.shares_memory(inv_mass, bodies.inv_mass)  # pack() copies into a new array
        v0, m0 = packed.v.copy(), inv_mass.copy()
        out = np.empty((3, len(contacts)), dtype)
        J, _ = collide.solve(packed, contacts, out=out)
        assert J is out or J.ctypes.data == out.ctypes.data
        assert packed.records is records and records.ctypes.data == address
        assert packed.inv_mass is inv_mass and inv_mass.ctypes.data == inv_address
        assert not np.array_equal(packed.v, v0)  # updated in place
        assert np.array_equal(inv_mass, m0)  # only read
        # A PackedBodies made by the caller over its own arrays sees the same memory.
        again = collide.PackedBodies(records, inv_mass=inv_mass)
        assert again.records.ctypes.data == address and again.model == "rigid"
        assert again.inv_mass is inv_mass
    # Sphere and particle records hold their inverse masses: a view of the records.
    for model in ("sphere", "particle"):
        theirs, tc = collide.generate("pairs", 100, model=model, dtype=dtype)
        packed = collide.pack(theirs, model, contacts=tc)
        assert np.shares_memory(packed.inv_mass, packed.records) and packed._inv_mass is None


@pytest.mark.parametrize("dtype", DTYPES)
def test_rigid_inverse_masses_are_read_beside_the_records(dtype):
    """The solve, the schedule and unpack_velocities read a rigid body's
    inverse mass from the array beside the records: making bodies immovable
    there changes what they do exactly as in the SoA arrays."""
    bodies, contacts = collide.generate("debris", 3000, friction=True, dtype=dtype)
    packed = collide.pack(bodies, "rigid")
    records0 = packed.records.copy()
    J_before, _ = collide.solve(collide.pack(bodies, "rigid"), contacts)
    batches_before = collide.Schedule(packed, contacts).batches
    frozen = np.unique(np.asarray(contacts.a)[::3])  # a third of the contacts get an immovable body a
    packed.inv_mass[frozen] = 0
    soa = packed.unpack()
    assert np.all(soa.inv_mass[frozen] == 0)
    assert collide.Schedule(packed, contacts).batches == collide.Schedule(soa, contacts).batches != batches_before
    J_rec, _ = collide.solve(packed, contacts)
    J_soa, _ = collide.solve(soa, contacts, model="rigid")
    assert np.array_equal(J_rec, J_soa) and not np.array_equal(J_rec, J_before)
    assert np.array_equal(packed.v[frozen], records0["v"][frozen])  # immovable: untouched
    assert np.array_equal(packed.unpack().v, soa.v)
    # unpack_velocities skips the bodies the array beside the records says are immovable.
    target = collide.pack(bodies, "rigid").unpack()
    target.v[...] = 5
    packed.unpack_velocities(target)
    assert np.all(target.v[:, frozen] == 5)
    movable = packed.inv_mass != 0
    assert np.array_equal(target.v[:, movable], packed.v.T[:, movable])


def test_records_can_share_the_soa_inverse_masses():
    """A PackedBodies may keep the Bodies' own inv_mass array beside its
    records (what the C++ solver does for SoA input): packing then leaves it
    as it is, even read-only; another read-only array cannot be packed into."""
    bodies, contacts = collide.generate("debris", 500, dtype=np.float32)
    bodies.inv_mass.setflags(write=False)
    shared = collide.PackedBodies(collide.packed_empty(len(bodies), "rigid"), inv_mass=bodies.inv_mass)
    collide._collide.pack_into(bodies, shared)
    assert shared.inv_mass is bodies.inv_mass
    assert np.array_equal(shared.unpack().q, bodies.q)
    J_shared, _ = collide.solve(shared, contacts)
    J_own, _ = collide.solve(collide.pack(bodies, "rigid"), contacts)
    assert np.array_equal(J_shared, J_own)
    read_only = np.zeros(len(bodies), np.float32)
    read_only.setflags(write=False)
    other = collide.PackedBodies(collide.packed_empty(len(bodies), "rigid"), inv_mass=read_only)
    with pytest.raises(TypeError, match=r"packed\.inv_mass must be writeable to pack into it"):
        collide._collide.pack_into(bodies, other)
    assert not read_only.any()


@pytest.mark.parametrize("dtype", DTYPES)
def test_conversions_are_exact(dtype):
    bodies, _ = collide.generate("debris", 500, dtype=dtype)
    packed = collide.pack(bodies, "rigid")
    s = packed.structured
    assert s.dtype.names == ("v", "w", "p", "q", "inv_inertia")  # the inverse mass is beside the records
    assert np.array_equal(s["v"], bodies.v.T) and np.array_equal(s["q"], bodies.q.T)
    assert np.array_equal(s["w"], bodies.w.T) and np.array_equal(s["p"], bodies.p.T)
    assert np.array_equal(packed.inv_mass, bodies.inv_mass) and np.array_equal(s["inv_inertia"], bodies.inv_inertia.T)
    assert np.any(bodies.inv_mass == 0) and np.any(bodies.inv_mass != 0)  # the debris ground is immovable
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
    assert collide._collide.packed_alignment(model, dtype) == ALIGNMENT[(dtype, model)]
    if model == "rigid":
        assert d.names == ("v", "w", "p", "q", "inv_inertia")
        assert [d.fields[f][1] // np.dtype(dtype).itemsize for f in d.names] == [0, 3, 6, 9, 13]
    else:
        assert "inv_mass" in d.names
    r = collide.packed_empty(7, model, dtype)
    assert r.dtype == d and r.shape == (7,) and not r.view(np.uint8).any()
    assert r.ctypes.data % ALIGNMENT[(dtype, model)] == 0
    c = collide.packed_empty(7, model, dtype, columns=True)
    assert c.shape == (7, COLUMNS[(dtype, model)]) and c.dtype == np.dtype(dtype)
    assert c.ctypes.data % ALIGNMENT[(dtype, model)] == 0
    m = np.zeros(7, dtype) if model == "rigid" else None
    assert collide.PackedBodies(r, inv_mass=m).model == model
    assert collide.PackedBodies(c, model=model, inv_mass=m).model == model
    if model == "rigid":  # 16 columns: rigid or sphere; inv_mass= says rigid
        assert collide.PackedBodies(c, inv_mass=m).model == "rigid"
    if model == "particle":
        assert collide.PackedBodies(c).model == "particle"


def test_bad_record_arrays():
    good = collide.packed_empty(10, "rigid", np.float32, columns=True)
    m = np.zeros(10, np.float32)
    with pytest.raises(TypeError, match=r"packed\.records must be a numpy\.ndarray, got <class 'list'>"):
        collide.PackedBodies(good.tolist(), inv_mass=m)
    with pytest.raises(TypeError, match=r"packed\.records has shape \(10, 12\), expected \(N, 16\) for rigid or "
                                        r"sphere or \(N, 4\) for particle records of float32"):
        collide.PackedBodies(np.zeros((10, 12), np.float32), inv_mass=m)
    with pytest.raises(TypeError, match=r"packed\.records has shape \(10, 16\), expected \(N, 4\) for particle "
                                        r"records of float32"):
        collide.PackedBodies(good, model="particle")
    with pytest.raises(TypeError, match=r"packed\.records has dtype int32"):
        collide.PackedBodies(np.zeros((10, 16), np.int32), inv_mass=m)
    wrong = np.dtype({"names": ["w", "v"], "formats": [("<f4", (3,)), ("<f4", (3,))], "itemsize": 64})
    with pytest.raises(TypeError, match=r"packed\.records has dtype .* which is not a record dtype"):
        collide.PackedBodies(np.zeros(10, wrong), inv_mass=m)
    with pytest.raises(TypeError, match=r"packed\.records has dtype .* which is not collide\.packed_dtype\('sphere'"):
        collide.PackedBodies(collide.packed_empty(10, "rigid"), model="sphere")
    raw = collide.packed_empty(11, "rigid", np.float32, columns=True)
    shifted = raw.reshape(-1)[4:4 + 160].reshape(10, 16)  # 16 bytes past the 64-byte boundary
    with pytest.raises(TypeError, match=r"starts 16 bytes past a multiple of 64, the alignment of rigid float32 "
                                        r"records: allocate them with collide\.packed_empty\(\) or collide\.pack\(\)"):
        collide.PackedBodies(shifted, inv_mass=m)
    raw64 = collide.packed_empty(11, "rigid", np.float64, columns=True)
    shifted64 = raw64.reshape(-1)[8:8 + 160].reshape(10, 16)  # 64 bytes past the 128-byte boundary
    with pytest.raises(TypeError, match=r"starts 64 bytes past a multiple of 128, the alignment of rigid float64"):
        collide.PackedBodies(shifted64, inv_mass=np.zeros(10))
    with pytest.raises(TypeError, match=r"packed\.records must be C-contiguous"):
        collide.PackedBodies(collide.packed_empty(20, "rigid")[::2], inv_mass=m)
    ro = collide.packed_empty(10, "rigid")
    ro.setflags(write=False)
    with pytest.raises(TypeError, match=r"packed\.records must be writeable"):
        collide.PackedBodies(ro, inv_mass=m)
    with pytest.raises(TypeError, match=r"packed\.records has shape \(2, 5\), expected \(N,\) records"):
        collide.PackedBodies(collide.packed_empty(10, "rigid").reshape(2, 5), inv_mass=m)


@pytest.mark.parametrize("columns", [False, True])
def test_bad_inverse_mass_arrays(columns):
    """Rigid records need their inverse masses beside them: an (N,) array of
    their dtype, C-contiguous and aligned, apart from the records; sphere and
    particle records refuse one (they hold theirs)."""
    records = collide.packed_empty(10, "rigid", np.float32, columns=columns)
    good = np.zeros(10, np.float32)
    assert collide.PackedBodies(records, model="rigid", inv_mass=good).inv_mass is good
    with pytest.raises(TypeError, match=r"packed\.inv_mass is missing: rigid records hold no inverse mass, it lives "
                                        r"beside them; give PackedBodies\(records, inv_mass=\.\.\.\) a C-contiguous "
                                        r"\(N,\) float32 array"):
        collide.PackedBodies(records, model="rigid")
    if columns:  # 16 float values: rigid or sphere records, and nothing says which
        with pytest.raises(TypeError, match=r"packed\.records of shape \(10, 16\) and dtype float32 may be rigid or "
                                            r"sphere records: say which with model=, or give rigid records their "
                                            r"inv_mass="):
            collide.PackedBodies(records)
    else:
        with pytest.raises(TypeError, match=r"packed\.inv_mass is missing"):
            collide.PackedBodies(records)
    with pytest.raises(ValueError, match=r"packed\.inv_mass has 9 elements, packed\.records has 10"):
        collide.PackedBodies(records, inv_mass=np.zeros(9, np.float32))
    with pytest.raises(ValueError, match=r"packed\.inv_mass has 11 elements, packed\.records has 10"):
        collide.PackedBodies(records, inv_mass=np.zeros(11, np.float32))
    with pytest.raises(TypeError, match=r"packed\.inv_mass has dtype float64, expected float32"):
        collide.PackedBodies(records, inv_mass=np.zeros(10, np.float64))
    with pytest.raises(TypeError, match=r"packed\.inv_mass must be C-contiguous"):
        collide.PackedBodies(records, inv_mass=np.zeros(20, np.float32)[::2])
    with pytest.raises(TypeError, match=r"packed\.inv_mass has shape \(10, 1\), expected \(N,\)"):
        collide.PackedBodies(records, inv_mass=np.zeros((10, 1), np.float32))
    with pytest.raises(TypeError, match=r"packed\.inv_mass must be a numpy\.ndarray, got <class 'list'>"):
        collide.PackedBodies(records, inv_mass=[0.0] * 10)
    misaligned = np.zeros(48, np.uint8)[1:41].view(np.float32)
    with pytest.raises(TypeError, match=r"packed\.inv_mass must be aligned"):
        collide.PackedBodies(records, inv_mass=misaligned)
    inside = records.reshape(-1)[:10] if columns else records.view(np.float32)[:10]
    with pytest.raises(ValueError, match=r"packed\.records and packed\.inv_mass share memory: the solve writes "
                                         r"packed\.records while it reads packed\.inv_mass"):
        collide.PackedBodies(records, inv_mass=inside)
    read_only = np.zeros(10, np.float32)
    read_only.setflags(write=False)
    assert collide.PackedBodies(records, inv_mass=read_only).inv_mass is read_only  # the solve only reads it
    for model in ("sphere", "particle"):
        theirs = collide.packed_empty(10, model, np.float32, columns=columns)
        if columns and model == "sphere":  # 16 columns and inv_mass=: rigid records, as documented
            assert collide.PackedBodies(theirs, inv_mass=good).model == "rigid"
        else:
            with pytest.raises(TypeError, match=f"packed\\.inv_mass is given, but {model} records hold their "
                                                r"inverse masses: inv_mass= is for rigid records only"):
                collide.PackedBodies(theirs, inv_mass=good)
        with pytest.raises(TypeError, match=r"packed\.inv_mass is given"):
            collide.PackedBodies(theirs, model=model, inv_mass=good)


def corrupted(kind):
    bodies, contacts = collide.generate("pairs", 40, friction=True, dtype=np.float64)
    packed = collide.pack(bodies, "rigid")
    s = packed.structured
    if kind == "nan_v":
        s["v"][9, 1] = np.nan
        return packed, contacts, r"bodies\.v\.y\[9\] = nan: must be finite"
    if kind == "negative_mass":  # in the array beside the records
        packed.inv_mass[4] = -1.0
        return packed, contacts, r"bodies\.inv_mass\[4\] = -1"
    if kind == "nan_mass":
        packed.inv_mass[2] = np.nan
        return packed, contacts, r"bodies\.inv_mass\[2\] = nan"
    if kind == "inertia":
        s["inv_inertia"][3, 2] = np.inf
        return packed, contacts, r"bodies\.inv_inertia\.z\[3\] = inf"
    if kind == "quaternion":
        s["q"][6] = [0.0, 0.0, 0.0, 0.0]
        return packed, contacts, r"bodies\.\|q\|\^2\[6\] = 0: must be a normal, finite number"
    if kind == "index":
        contacts.b[7] = 80
        return packed, contacts, r"contacts\.b\[7\] = 80: out of range"
    raise AssertionError(kind)


@pytest.mark.parametrize("kind", ["nan_v", "negative_mass", "nan_mass", "inertia", "quaternion", "index"])
def test_bad_values_in_records_name_the_element_and_modify_nothing(kind):
    packed, contacts, message = corrupted(kind)
    before = packed.records.view(np.uint8).copy()  # every byte, padding included
    inv_mass_before = packed.inv_mass.view(np.uint8).copy()
    out = np.full((3, len(contacts)), 7.0)
    with pytest.raises(ValueError, match=message):
        collide.solve(packed, contacts, out=out)
    assert np.array_equal(packed.records.view(np.uint8), before)
    assert np.array_equal(packed.inv_mass.view(np.uint8), inv_mass_before)
    assert np.all(out == 7.0)
    with pytest.raises(ValueError, match=message):
        collide.Schedule(packed, contacts)
    with pytest.raises(ValueError, match=message):
        collide.reference_solve(packed, contacts)


@pytest.mark.parametrize("dtype", DTYPES)
def test_padding_is_not_read(dtype):
    # Rigid records have no padding (16 values); sphere records 5 values of it.
    bodies, contacts = collide.generate("pairs", 100, model="sphere", dtype=dtype)
    cols = collide.pack(bodies, "sphere", columns=True).records
    J_clean, _ = collide.solve(collide.pack(bodies, "sphere"), contacts)
    cols[:, 11:] = np.nan  # the padding of PackedSphere<T>: values 11 to 15
    J, _ = collide.solve(collide.PackedBodies(cols, model="sphere"), contacts)
    assert np.all(np.isfinite(J)) and np.array_equal(J, J_clean)


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
