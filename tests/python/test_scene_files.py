"""collide.load and collide.save: scene files in CSV or binary (.npz), the
binary ones mapped in place, read and written by NumPy's own calls too."""

import os
import subprocess

import numpy as np
import pytest

import collide


def gen(cli, workdir, kind="--debris", n=4000, fmt="npz", precision="float", friction=True):
    args = [cli, "gen", kind, str(n), "--out", workdir, "--format", fmt]
    if fmt == "npz":
        args += ["--precision", precision]
    if friction:
        args.append("--friction")
    subprocess.run(args, check=True)
    return os.path.join(workdir, "bodies." + fmt), os.path.join(workdir, "contacts." + fmt)


def inside(array, mapped):
    address = array.__array_interface__["data"][0]
    return mapped.address <= address and address + array.nbytes <= mapped.address + mapped.size


def test_binary_arrays_are_views_of_the_mapping(cli, workdir):
    bp, cp = gen(cli, workdir)
    bodies, contacts = collide.load(bp, cp)
    assert bodies.dtype == np.float32, "a binary scene loads in its own precision"
    for array in (bodies.q, bodies.p):
        assert isinstance(array.base, collide.MappedFile) and array.base.path == bp
        assert inside(array, array.base) and not array.flags.writeable
    for array in (contacts.a, contacts.b, contacts.c, contacts.n, contacts.e, contacts.mu):
        assert isinstance(array.base, collide.MappedFile) and array.base.path == cp
        assert inside(array, array.base) and not array.flags.writeable
    # What a solve writes is the caller's own memory.
    for array in (bodies.v, bodies.w):
        assert array.flags.writeable and not isinstance(array.base, collide.MappedFile)


def test_load_matches_numpy_and_the_csv_reader(cli, workdir):
    bp, cp = gen(cli, workdir, precision="double")
    bodies, contacts = collide.load(bp, cp)
    with np.load(bp) as z:
        np.testing.assert_array_equal(bodies.q, np.stack([z["qw"], z["qx"], z["qy"], z["qz"]]))
        np.testing.assert_array_equal(bodies.v, np.stack([z["vx"], z["vy"], z["vz"]]))
        finite = np.isfinite(z["m"])
        np.testing.assert_array_equal(bodies.inv_mass[finite], 1 / z["m"][finite])
        assert np.all(bodies.inv_mass[~finite] == 0)
    with np.load(cp) as z:
        np.testing.assert_array_equal(contacts.a, z["a"])
        np.testing.assert_array_equal(contacts.n, np.stack([z["nx"], z["ny"], z["nz"]]))
    # The same scene as CSV, through the CSV reader: the same values.
    csv_dir = os.path.join(workdir, "csv")
    subprocess.run([cli, "convert", "--in", bp, "--out", os.path.join(csv_dir + "_b.csv")], check=True)
    subprocess.run([cli, "convert", "--in", cp, "--out", os.path.join(csv_dir + "_c.csv")], check=True)
    cb, cc = collide.read_scene(csv_dir + "_b.csv", csv_dir + "_c.csv", dtype=np.float64)
    for name in ("inv_mass", "inv_inertia", "q", "p", "v", "w"):
        np.testing.assert_array_equal(getattr(cb, name), getattr(bodies, name), err_msg=name)
    for name in ("a", "b", "c", "n", "e", "mu"):
        np.testing.assert_array_equal(getattr(cc, name), getattr(contacts, name), err_msg=name)


def test_solve_on_a_mapped_scene_matches_a_copied_one(cli, workdir):
    bp, cp = gen(cli, workdir)
    bodies, contacts = collide.load(bp, cp)
    copies = collide.Bodies(*(np.array(getattr(bodies, f), order="C", copy=True) for f in
                              ("inv_mass", "inv_inertia", "q", "p", "v", "w")))
    ccopy = collide.Contacts(*(np.array(getattr(contacts, f), order="C", copy=True) for f in ("a", "b", "c", "n", "e")),
                             mu=np.array(contacts.mu, copy=True))
    J1, _ = collide.solve(bodies, contacts)
    J2, _ = collide.solve(copies, ccopy)
    assert J1.tobytes() == J2.tobytes()
    assert bodies.v.tobytes() == copies.v.tobytes() and bodies.w.tobytes() == copies.w.tobytes()


def test_save_writes_what_numpy_and_load_read(workdir):
    bodies, contacts = collide.generate("debris", 3000, dtype=np.float64, friction=True)
    bp, cp = os.path.join(workdir, "b.npz"), os.path.join(workdir, "c.npz")
    collide.save(bp, cp, bodies, contacts)
    with np.load(bp) as z:
        assert sorted(z.files) == sorted(["m", "Ix", "Iy", "Iz", "qw", "qx", "qy", "qz", "px", "py", "pz",
                                          "vx", "vy", "vz", "wx", "wy", "wz"])
        assert z["m"].dtype == np.float64
    with np.load(cp) as z:
        assert z["a"].dtype == np.uint32 and len(z["a"]) == 3000
    b2, c2 = collide.load(bp, cp)
    for name in ("q", "p", "v", "w"):
        np.testing.assert_array_equal(getattr(b2, name), getattr(bodies, name))
    for name in ("a", "b", "c", "n", "e", "mu"):
        np.testing.assert_array_equal(getattr(c2, name), getattr(contacts, name))


def test_numpy_savez_files_load(workdir):
    # What a NumPy user writes by hand: np.savez, int64 ids, members in any
    # order, data at unaligned offsets (copied, not mapped).
    n = 50
    rng = np.random.default_rng(3)
    cols = {k: np.ones(n) for k in ("m", "Ix", "Iy", "Iz", "qw")}
    cols.update({k: np.zeros(n) for k in ("qx", "qy", "qz", "pz", "vz", "wx", "wy", "wz")})
    cols.update(px=rng.random(n), py=rng.random(n), vx=rng.random(n) - 0.5, vy=rng.random(n) - 0.5)
    bp, cp = os.path.join(workdir, "b.npz"), os.path.join(workdir, "c.npz")
    np.savez(bp, **dict(reversed(list(cols.items()))))
    k = n - 1
    np.savez(cp, a=np.arange(k), b=np.arange(1, n), cx=np.zeros(k), cy=np.zeros(k), cz=np.zeros(k),
             nx=np.ones(k), ny=np.zeros(k), nz=np.zeros(k), e=np.full(k, 0.5), mu=np.zeros(k))
    bodies, contacts = collide.load(bp, cp)
    np.testing.assert_array_equal(bodies.p[0], cols["px"])
    assert contacts.a.dtype == np.uint32 and contacts.a[-1] == k - 1
    assert contacts.mu is None, "no friction in the file: the frictionless solve"
    J, _ = collide.solve(bodies, contacts)
    assert J.shape == (3, k)


def test_bad_binary_files(workdir):
    bodies, contacts = collide.generate("pairs", 10, dtype=np.float64)
    bp, cp = os.path.join(workdir, "b.npz"), os.path.join(workdir, "c.npz")
    collide.save(bp, cp, bodies, contacts)
    with np.load(bp) as z:
        cols = {k: z[k].copy() for k in z.files}
    cols["m"][4] = -1
    np.savez(bp, **cols)
    with pytest.raises(ValueError, match=r"b\.npz: row 4, column 'm': mass must be > 0, got -1"):
        collide.load(bp, cp)
    cols["m"][4] = 1
    np.savez_compressed(bp, **cols)
    with pytest.raises(ValueError, match=r"compressed"):
        collide.load(bp, cp)
    with pytest.raises(FileNotFoundError):
        collide.load(os.path.join(workdir, "missing.npz"), cp)
