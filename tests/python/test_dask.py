"""collide.dask on a real LocalCluster (2 worker processes of one thread):
the same bytes as collide.solve, scenes given as arrays or as binary scene
files, both orders with one pass and several (the colour order through the
whole scene's solve order), collide.solve's errors for bad options, the
partitions, the giant-island warning, solve_scenes' table, the
command, bad input, a worker killed mid-run, the warm start (arrays, files,
solve_scenes and the command, the same bytes as collide.solve(warm=), bad
ones refused with its messages), and `import collide` without Dask.

The cluster is started once for the module. Dask, distributed and pandas are
required (scripts/install-deps.sh installs them): without them the fixture
fails, it does not skip.
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

import distributed

import collide
import collide.dask as cd
from conftest import run
from scene_value_text import draw_scene, scene_files, write

FIELDS = ("inv_mass", "inv_inertia", "q", "p", "v", "w")
TWO_BODIES = os.path.join(os.path.dirname(__file__), "..", "..", "data", "scene-values", "two-bodies")


@pytest.fixture(scope="module")
def client():
    import cloudpickle

    # The worker plugin below is defined here: the workers get it by value.
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as c:
        yield c


def copy_scene(bodies, contacts):
    """An exact copy over new arrays (a scene to solve twice)."""
    b = collide.Bodies(*(np.array(getattr(bodies, f), copy=True, order="C") for f in FIELDS))
    opt = {k: None if getattr(contacts, k) is None else np.array(getattr(contacts, k), copy=True) for k in ("e", "mu")}
    c = collide.Contacts(np.array(contacts.a), np.array(contacts.b), np.array(contacts.c, order="C"),
                         np.array(contacts.n, order="C"), opt["e"], contacts.uniform_e, opt["mu"])
    return b, c


def island_scene(model="rigid", dtype=np.float64, seed=1, friction=True, piles=6):
    """Many islands over one shared ground: small piles, debris clusters and
    free pairs generated for `model`, every immovable body replaced by the
    first one in the contacts (so the piles stand on one ground), contacts of
    all the parts interleaved by a seeded shuffle."""
    parts = []
    for k in range(piles):
        parts.append(collide.generate("pile", 2 + k % 2, model=model, friction=friction, seed=seed + k, dtype=dtype))
        parts.append(collide.generate("debris", 30, model=model, friction=friction, seed=seed + 50 + k, dtype=dtype))
    parts.append(collide.generate("pairs", 60, model=model, friction=friction, seed=seed + 99, dtype=dtype))
    return interleaved(parts, seed, friction)


def piles_scene(dtype=np.float32, seed=1, friction=True, piles=4, n=20):
    """Piles of n^3 boxes on one ground, their contacts interleaved by a
    seeded shuffle: more contacts than one window of the colour order
    (Schedule's 65,536), so that each pile's contacts fall into every
    window, and into other windows in a partition of the scene than in the
    whole scene."""
    parts = [collide.generate("pile", n, friction=friction, seed=seed + k, dtype=dtype) for k in range(piles)]
    return interleaved(parts, seed, friction)


def interleaved(parts, seed, friction):
    """The scenes ``parts`` as one: bodies concatenated, every immovable
    body replaced by the first one in the contacts, the contacts shuffled by
    a seeded permutation."""
    offsets = np.cumsum([0] + [len(b) for b, _ in parts])
    fields = {f: np.concatenate([getattr(b, f) for b, _ in parts], axis=-1) for f in FIELDS}
    a = np.concatenate([c.a + o for (_, c), o in zip(parts, offsets)]).astype(np.uint32)
    b = np.concatenate([c.b + o for (_, c), o in zip(parts, offsets)]).astype(np.uint32)
    ground = np.flatnonzero(fields["inv_mass"] == 0)[0]
    for x in (a, b):
        x[fields["inv_mass"][x] == 0] = ground
    order = np.random.default_rng(seed).permutation(len(a))
    cat = lambda name: np.concatenate([getattr(c, name) for _, c in parts], axis=-1)  # noqa: E731
    mu = cat("mu")[order] if friction else None
    bodies = collide.Bodies(*(np.ascontiguousarray(fields[f]) for f in FIELDS))
    contacts = collide.Contacts(a[order], b[order], np.ascontiguousarray(cat("c")[:, order]),
                                np.ascontiguousarray(cat("n")[:, order]), cat("e")[order], mu=mu)
    return bodies, contacts


def reference_bytes(bodies, contacts, **kwargs):
    """collide.solve on a copy: the bytes a distributed solve must give."""
    b, c = copy_scene(bodies, contacts)
    J, stats = collide.solve(b, c, **kwargs)
    return J.tobytes(), b.v.tobytes(), b.w.tobytes(), stats


def same_bytes(solution, expected):
    J, v, w, _ = expected
    assert np.ascontiguousarray(solution.J).tobytes() == J
    assert np.ascontiguousarray(solution.v).tobytes() == v
    assert np.ascontiguousarray(solution.w).tobytes() == w


def test_the_scene_has_many_islands_and_a_ground():
    bodies, contacts = island_scene()
    isl = collide.islands(bodies, contacts)
    ground = np.flatnonzero(bodies.inv_mass == 0)[0]
    assert isl.count > 60 and isl.largest < len(contacts) / 4
    assert np.count_nonzero((contacts.a == ground) | (contacts.b == ground)) > 10
    assert isl.body_labels[ground] == collide.Islands.NONE


@pytest.mark.parametrize("model", ["particle", "sphere", "rigid"])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("accuracy", ["fast", "accurate"])
def test_arrays_same_bytes_as_collide_solve(client, model, dtype, accuracy):
    bodies, contacts = island_scene(model, dtype, seed=3)
    expected = reference_bytes(bodies, contacts, accuracy=accuracy)
    assert expected[3]["model"] == model
    solution = cd.solve((bodies, contacts), client, accuracy=accuracy)
    same_bytes(solution, expected)
    assert solution.v is bodies.v and solution.w is bodies.w, "the caller's arrays, updated in place"
    assert solution.stats["model"] == model and solution.stats["accuracy"] == accuracy
    assert len(solution.stats["partitions"]) == 2 and sum(solution.stats["partitions"]) == len(contacts)
    for key in ("kernel_seconds", "allocate_seconds"):  # the partitions' solves, summed
        assert np.isfinite(solution.stats[key]) and solution.stats[key] >= 0, (key, solution.stats)


@pytest.mark.parametrize("order", ["input", "colour"])
@pytest.mark.parametrize("passes", [1, 4])
def test_order_and_passes_same_bytes_as_collide_solve(client, order, passes):
    bodies, contacts = piles_scene(seed=3)
    isl = collide.islands(bodies, contacts)
    assert len(contacts) > 65_536 and isl.count == 4, (len(contacts), isl.count)
    expected = reference_bytes(bodies, contacts, order=order, passes=passes)
    assert (expected[3]["order"], expected[3]["passes"]) == (order, passes)
    with warnings.catch_warnings():
        warnings.simplefilter("error", cd.IslandWarning)
        solution = cd.solve((bodies, contacts), client, order=order, passes=passes)
    same_bytes(solution, expected)
    assert (solution.stats["order"], solution.stats["passes"]) == (order, passes)
    assert len(solution.stats["partitions"]) == 2


def test_a_partitions_own_colour_order_would_not_be_the_scenes(client):
    # What the client's solve order is for: a partition (two of the four
    # piles) solved alone in its own colour order differs from the whole
    # scene's solve, since its contacts fall into other windows.
    from collide.dask import _tasks

    bodies, contacts = piles_scene(seed=3)
    expected = reference_bytes(bodies, contacts, order="colour", passes=2)
    isl = collide.islands(bodies, contacts)
    rows = np.flatnonzero(isl.labels < 2)
    part_bodies, part_contacts, ids = _tasks.sub_scene(bodies, contacts, rows)
    J, _ = collide.solve(part_bodies, part_contacts, order="colour", passes=2)
    whole = np.frombuffer(expected[0], dtype=np.float32).reshape(3, -1)
    assert J.tobytes() != np.ascontiguousarray(whole[:, rows]).tobytes()
    # The same rows in the whole scene's solve order, solved in input order: the whole's bits.
    in_order = collide.Schedule(bodies, contacts, order="colour").solve_order()
    in_order = in_order[np.isin(in_order, rows)].astype(np.int64)
    part_bodies, part_contacts, ids = _tasks.sub_scene(bodies, contacts, in_order)
    J, _ = collide.solve(part_bodies, part_contacts, passes=2)
    assert J.tobytes() == np.ascontiguousarray(whole[:, in_order]).tobytes()


@pytest.mark.parametrize("order, passes", [("colour", 3), ("input", 2)])
def test_scene_files_in_an_order_with_passes(client, tmp_path, order, passes):
    bodies, contacts = piles_scene(np.float64, seed=5, friction=False)
    bp, cp = str(tmp_path / "bodies.npz"), str(tmp_path / "contacts.npz")
    collide.save(bp, cp, bodies, contacts)
    expected = reference_bytes(*collide.load(bp, cp), order=order, passes=passes)
    solution = cd.solve((bp, cp), client, out_dir=tmp_path / "out", order=order, passes=passes, partitions=3)
    same_bytes(solution, expected)
    assert sorted(os.listdir(tmp_path / "out")) == ["J.npy", "v.npy", "w.npy"]
    # The command: the same options, the same bytes.
    r = run_cli("solve", bp, cp, "--out-dir", str(tmp_path / "cmd"), "--scheduler", client.scheduler.address,
                "--order", order, "--passes", str(passes), "--no-progress")
    assert r.returncode == 0, r.stderr
    stats = json.loads(r.stdout)
    assert (stats["order"], stats["passes"]) == (order, passes)
    same_bytes(cd.Solution(*(np.load(tmp_path / "cmd" / f"{k}.npy") for k in "Jvw"), {}), expected)


def collide_solve_error(**options):
    """The exception collide.solve raises for these options (its type and message)."""
    with pytest.raises((TypeError, ValueError)) as e:
        collide.solve(*collide.generate("pairs", 10), **options)
    return type(e.value), str(e.value)


@pytest.mark.parametrize("options", [{"passes": 0}, {"passes": 10**9}, {"passes": 2.5}, {"order": "color"},
                                     {"order": "random"}, {"accuracy": "exact"}, {"threads": -1},
                                     {"isa": "avx9"}])
def test_bad_options_get_collide_solves_errors(client, tmp_path, options):
    kind, message = collide_solve_error(**options)
    scene = collide.generate("pairs", 10)
    v = scene[0].v.copy()
    with pytest.raises(kind) as e:
        cd.solve(scene, client, **options)
    assert str(e.value) == message
    assert scene[0].v.tobytes() == v.tobytes(), "nothing written"
    with pytest.raises(kind) as e:
        cd.solve_scenes([{"kind": "pairs", "n": 10}], client, **options)
    assert str(e.value) == message


def test_the_command_refuses_bad_passes_with_collide_solves_message(client, tmp_path):
    bp, cp = str(tmp_path / "b.npz"), str(tmp_path / "c.npz")
    collide.save(bp, cp, *collide.generate("pairs", 10))
    _, message = collide_solve_error(passes=0)
    for command in (["solve", bp, cp, "--out-dir", str(tmp_path / "out")], ["scenes", bp, cp]):
        r = run_cli(*command, "--passes", "0", "--scheduler", client.scheduler.address)
        assert r.returncode == 1 and r.stderr == f"collide-dask: error: {message}\n", r.stderr
    r = run_cli("solve", bp, cp, "--out-dir", str(tmp_path / "out"), "--order", "color")
    assert r.returncode == 2 and "invalid choice: 'color'" in r.stderr, r.stderr
    assert not (tmp_path / "out").exists()


def test_solve_scenes_in_an_order_with_passes(client):
    scenes = [{"kind": "pile", "n": 8, "seed": 2}, {"kind": "debris", "n": 20_000, "seed": 3, "friction": True},
              {"kind": "pairs", "n": 5000}]
    table = cd.solve_scenes(scenes, client, order="colour", passes=4, sample=1000)
    assert list(table["contacts"]) == [len(collide.generate(**s)[1]) for s in scenes]
    assert list(table["error_sample"]) == [1000, 1000, 1000]
    assert (table["collisions_per_second"] > 0).all()
    assert (table["max_error_eps"] <= collide.error_bound_eps).all(), table["max_error_eps"]
    assert (table["momentum_drift"].abs() < 1e-4).all(), table["momentum_drift"]


def test_grouping_and_forced_model_do_not_change_the_bytes(client):
    bodies, contacts = island_scene("sphere", np.float32, seed=5, friction=False)
    expected = reference_bytes(bodies, contacts, model="rigid")
    for partitions in (1, 3, 7, 1000):
        b, c = copy_scene(bodies, contacts)
        solution = cd.solve((b, c), client, partitions=partitions, model="rigid")
        same_bytes(solution, expected)
        assert len(solution.stats["partitions"]) == min(partitions, collide.islands(b, c).count)


@pytest.mark.parametrize("model,dtype,accuracy,shuffled", [
    ("rigid", np.float32, "fast", True),
    ("sphere", np.float64, "accurate", True),
    ("particle", np.float64, "fast", False),
    ("rigid", np.float64, "accurate", False),
])
def test_scene_files_same_bytes_written_in_place(client, tmp_path, model, dtype, accuracy, shuffled):
    if shuffled:
        bodies, contacts = island_scene(model, dtype, seed=7)
    else:  # independent pairs: every partition a range of contacts
        bodies, contacts = collide.generate("pairs", 5000, model=model, friction=True, seed=7, dtype=dtype)
    bp, cp = str(tmp_path / "bodies.npz"), str(tmp_path / "contacts.npz")
    collide.save(bp, cp, bodies, contacts)
    expected = reference_bytes(*collide.load(bp, cp), accuracy=accuracy)
    out = tmp_path / "out"
    solution = cd.solve((bp, cp), client, out_dir=out, accuracy=accuracy, partitions=3)
    same_bytes(solution, expected)
    assert sorted(os.listdir(out)) == ["J.npy", "v.npy", "w.npy"], "nothing else left behind"
    for name, array in zip("Jvw", solution[:3]):
        assert isinstance(array, np.memmap) and os.path.samefile(array.filename, out / f"{name}.npy")
        assert array.dtype == dtype
    assert solution.stats["outputs"]["J"] == str(out / "J.npy")
    # The file converted on load, as collide.load(dtype=) converts it.
    if dtype == np.float64:
        expected32 = reference_bytes(*collide.load(bp, cp, dtype=np.float32), accuracy=accuracy)
        same_bytes(cd.solve((bp, cp), client, out_dir=tmp_path / "out32", dtype=np.float32, accuracy=accuracy),
                   expected32)


@pytest.mark.parametrize("scene", ["two-bodies", "drawn", "debris"])
def test_scene_files_give_the_csv_readers_bytes(client, cli, tmp_path, scene):
    # One scene, one answer (docs/collision-law.md, "Scene values"): the
    # workers round the rows of a '<f8' file to float32 as the readers round
    # the scene's CSV text, halfway cases, subnormals and floats' largest
    # included; in float64 the values are the file's.
    d = str(tmp_path)
    if scene == "two-bodies":
        for name in ("bodies.csv", "contacts.csv"):
            shutil.copy(os.path.join(TWO_BODIES, name), d)
    elif scene == "drawn":
        bodies_text, contacts_text, parted = draw_scene(3)
        assert parted > 1000
        write(os.path.join(d, "bodies.csv"), bodies_text)
        write(os.path.join(d, "contacts.csv"), contacts_text)
    else:
        run([cli, "gen", "--debris", "20000", "--out", d, "--seed", "2", "--friction"])
    files = scene_files(cli, d, run)
    for dtype in (np.float32, np.float64):
        for accuracy in ("fast", "accurate"):
            expected = reference_bytes(*collide.read_scene(*files["csv"], dtype=dtype), accuracy=accuracy)
            for tag in ("f8", "np"):
                out = tmp_path / f"out-{tag}-{np.dtype(dtype).name}-{accuracy}"
                same_bytes(cd.solve(files[tag], client, out_dir=out, dtype=dtype, accuracy=accuracy, partitions=2),
                           expected)


def chained_scenes(*parts):
    """The scenes ``parts`` one after the other: bodies and contacts
    concatenated in order, each part's indices shifted past the bodies
    before it (each part keeps its own islands)."""
    offsets = np.cumsum([0] + [len(b) for b, _ in parts])
    bodies = collide.Bodies(*(np.ascontiguousarray(np.concatenate([getattr(b, f) for b, _ in parts], axis=-1))
                              for f in FIELDS))
    cat = lambda name: np.ascontiguousarray(np.concatenate([getattr(c, name) for _, c in parts], axis=-1))  # noqa: E731
    a = np.concatenate([c.a + o for (_, c), o in zip(parts, offsets)]).astype(np.uint32)
    b = np.concatenate([c.b + o for (_, c), o in zip(parts, offsets)]).astype(np.uint32)
    return bodies, collide.Contacts(a, b, cat("c"), cat("n"), cat("e"))


def test_scene_files_partitions_of_rows_out_of_order(client, tmp_path):
    # Two chains, the later one longer: the greedy puts the larger island on
    # the first partition, so partition 0 holds the last rows of the file
    # and partition 1 the first ones, each a range of rows, and the workers
    # must read those rows, not the partitions' positions.
    bodies, contacts = chained_scenes(collide.generate("chain", 40, seed=2), collide.generate("chain", 90, seed=3))
    bp, cp = str(tmp_path / "bodies.npz"), str(tmp_path / "contacts.npz")
    collide.save(bp, cp, bodies, contacts)
    expected = reference_bytes(*collide.load(bp, cp))
    solution = cd.solve((bp, cp), client, out_dir=tmp_path / "out", partitions=2)
    assert solution.stats["partitions"] == [90, 40]
    same_bytes(solution, expected)


@pytest.mark.parametrize("elsewhere", [False, True])
def test_a_partition_task_alone_writes_its_rows(tmp_path, elsewhere):
    # The task without Dask, as a worker runs it, on the client's machine
    # (no flush) or on another one (flushed): two partitions, one of a range
    # of rows (read as views, solved in place) and one read through an
    # order file, give the whole solve's bytes.
    from collide.dask import _tasks

    bodies, contacts = chained_scenes(collide.generate("pairs", 50, seed=5), island_scene(seed=9))
    bp, cp = str(tmp_path / "bodies.npz"), str(tmp_path / "contacts.npz")
    collide.save(bp, cp, bodies, contacts)
    expected = reference_bytes(*collide.load(bp, cp))
    outputs = {k: str(tmp_path / f"{k}.npy") for k in "Jvw"}
    np.lib.format.open_memmap(outputs["J"], mode="w+", dtype=np.float64, shape=(3, len(contacts)))
    unnamed = np.flatnonzero(collide.islands(bodies, contacts).body_labels == collide.Islands.NONE)
    for k in "vw":
        out = np.lib.format.open_memmap(outputs[k], mode="w+", dtype=np.float64, shape=(3, len(bodies)))
        out[:, unnamed] = getattr(bodies, k)[:, unnamed]
        out.flush()
        del out
    order = np.arange(50, len(contacts), dtype=np.uint32)
    np.save(tmp_path / "order.npy", order)
    common = {"bodies_path": bp, "contacts_path": cp, "body_count": len(bodies), "dtype": "float64", "friction": False,
              "outputs": outputs, "client_machine": "another kernel" if elsewhere else _tasks.machine()}
    options = cd._options(expected[3]["model"], threads=1)
    assert options["solve"] == {"accuracy": "fast", "order": "input", "passes": 1, "iteration": "repeat", "threads": 1,
                                "isa": None}
    _tasks.solve_part_files(dict(common, order=None, first=0, end=50), options)
    _tasks.solve_part_files(dict(common, order=str(tmp_path / "order.npy"), first=0, end=len(order)), options)
    same_bytes(cd.Solution(*(np.load(outputs[k]) for k in "Jvw"), {}), expected)


def test_workers_map_the_members_of_scene_files(tmp_path):
    from collide.dask._files import MappedNpz

    bodies, contacts = collide.generate("debris", 500, friction=True, dtype=np.float32)
    bp, cp = str(tmp_path / "b.npz"), str(tmp_path / "c.npz")
    collide.save(bp, cp, bodies, contacts)
    np.savez(tmp_path / "numpy.npz", x=np.arange(7, dtype=np.int64), empty=np.zeros(0))
    for path in (bp, cp, tmp_path / "numpy.npz"):
        mapped = MappedNpz(path)
        with np.load(path) as z:
            assert sorted(mapped.columns) == sorted(z.files)
            for name in z.files:
                column = mapped[name]
                assert column.dtype == z[name].dtype and column.tobytes() == z[name].tobytes(), name
                assert not column.flags.writeable, name
    # Rows of members one stride apart: a range is a view of the mapping,
    # anything else (rows picked, another dtype) a new array; the values
    # are the members' either way.
    mapped = MappedNpz(bp)
    with np.load(bp) as z:
        v = np.stack([z["vx"], z["vy"], z["vz"]])
        view = mapped.stacked(("vx", "vy", "vz"), slice(10, 90), np.float32)
        assert view.base is not None and not view.flags.writeable and not view.flags.owndata
        assert view.tobytes() == v[:, 10:90].tobytes()
        picked = np.array([3, 1, 200, 7], dtype=np.int64)
        gathered = mapped.stacked(("vx", "vy", "vz"), picked, np.float32)
        assert gathered.flags.owndata and gathered.tobytes() == v[:, picked].tobytes()
        wide = mapped.stacked(("vx", "vy", "vz"), slice(10, 90), np.float64)
        assert wide.flags.owndata and wide.tobytes() == v[:, 10:90].astype(np.float64).tobytes()
        assert mapped.stacked(("m",), slice(5, 5), np.float32).shape == (1, 0)
    np.savez_compressed(tmp_path / "z.npz", x=np.arange(7))
    with pytest.raises(ValueError, match=r"z\.npz: member 'x\.npy' is compressed"):
        MappedNpz(tmp_path / "z.npz")


def test_a_block_of_columns_written_in_place(tmp_path):
    from collide.dask._files import write_columns

    path = str(tmp_path / "x.npy")
    expected = np.arange(30, dtype=np.float32).reshape(3, 10)
    np.save(path, expected)
    block = -np.arange(12, dtype=np.float32).reshape(3, 4)
    write_columns(path, 5, block)
    expected[:, 5:9] = block
    assert np.load(path).tobytes() == expected.tobytes()
    for first, bad in ((7, block), (0, block.astype(np.float64)), (0, block[:2])):
        with pytest.raises(ValueError, match=r"x\.npy: a \(3, 10\) float32 array cannot take columns"):
            write_columns(path, first, bad)
    assert np.load(path).tobytes() == expected.tobytes()


def test_partition_islands_is_a_balanced_deterministic_greedy():
    # Equal islands: consecutive runs of equal size.
    parts = cd.partition_islands(np.full(100, 5), 4)
    np.testing.assert_array_equal(parts, np.repeat(np.arange(4), 25))
    # Large islands first onto the least loaded partition, then the small ones fill up to the mean.
    sizes = np.array([40, 100, 50, 60] + [1] * 50)
    parts = cd.partition_islands(sizes, 3)
    np.testing.assert_array_equal(parts[:4], [2, 0, 2, 1])
    np.testing.assert_array_equal(np.bincount(parts, weights=sizes), [100, 100, 100])
    # One giant island is one partition; the rest go to the others.
    parts = cd.partition_islands([1000, 1, 1, 1], 2)
    np.testing.assert_array_equal(parts, [0, 1, 1, 1])
    # Random sizes: every partition within one small island of the mean, the same answer every time.
    rng = np.random.default_rng(2)
    for p in (2, 3, 8, 13):
        sizes = np.concatenate([rng.integers(1, 20, 3000), rng.integers(200, 2000, 5)])
        parts = cd.partition_islands(sizes, p)
        np.testing.assert_array_equal(parts, cd.partition_islands(sizes, p))
        loads = np.bincount(parts, weights=sizes, minlength=p)
        assert len(loads) == p and loads.sum() == sizes.sum()
        mean = sizes.sum() / p
        assert loads.max() <= max(mean + 20, sizes.max()), (p, loads, mean)
    # More partitions than islands: one island each.
    np.testing.assert_array_equal(cd.partition_islands([3, 2], 5), [0, 1])
    assert len(cd.partition_islands([], 3)) == 0
    with pytest.raises(ValueError, match="partitions must be >= 1"):
        cd.partition_islands([1, 2], 0)


def test_single_contact_islands_split_into_the_greedys_ranges():
    # Every contact an island of its own (independent pairs): the ranges
    # found in O(partitions) are the ones partition_islands gives.
    from collide.dask._partition import single_contact_ends
    for count in (0, 1, 7, 8, 15, 16, 17, 63, 64, 65, 999, 1000, 1001, 4097, 100_003):
        for p in (1, 2, 3, 5, 8, 13, 64):
            ends = single_contact_ends(count, p)
            parts = cd.partition_islands(np.ones(count, dtype=np.uint32), p)
            if ends is None:
                # Fewer than eight contacts per partition: left to partition_islands.
                assert count < 8 * min(p, count)
                continue
            counts = np.bincount(parts, minlength=len(ends)) if count else np.zeros(1, dtype=np.int64)
            np.testing.assert_array_equal(np.diff(ends, prepend=0), counts, err_msg=f"{count} contacts, {p}")
            np.testing.assert_array_equal(np.repeat(np.arange(len(ends)), counts), parts)


def test_stats_partitions_are_balanced(client):
    bodies, contacts = collide.generate("pairs", 10_000, dtype=np.float32)
    solution = cd.solve((bodies, contacts), client, partitions=4)
    assert solution.stats["partitions"] == [2500] * 4
    assert solution.stats["islands"] == 10_000 and solution.stats["largest_island"] == 1


def test_a_giant_island_warns_and_is_solved_whole(client):
    bodies, contacts = collide.generate("pile", 7, friction=True, dtype=np.float32)
    expected = reference_bytes(bodies, contacts)
    figures = rf"largest island holds {len(contacts):,} of {len(contacts):,} contacts \(100%; 1 islands\)"
    with pytest.warns(cd.IslandWarning, match=figures):
        solution = cd.solve((bodies, contacts), client, partitions=4)
    same_bytes(solution, expected)
    assert solution.stats["partitions"] == [len(contacts)]
    # A scene of many islands does not warn.
    bodies, contacts = island_scene()
    with warnings.catch_warnings():
        warnings.simplefilter("error", cd.IslandWarning)
        cd.solve((bodies, contacts), client)


def test_solve_scenes_table(client, tmp_path):
    bodies, contacts = island_scene("rigid", np.float64, seed=9)
    bp, cp = str(tmp_path / "b.npz"), str(tmp_path / "c.npz")
    collide.save(bp, cp, bodies, contacts)
    scenes = [{"kind": "pairs", "n": 20_000, "seed": 3, "model": "particle", "dtype": "float32"},
              {"kind": "debris", "n": 3000, "seed": 4, "friction": True, "dtype": np.float64, "name": "my debris"},
              (bp, cp),
              {"kind": "pile", "n": 5, "accuracy": "accurate"}]
    table = cd.solve_scenes(scenes, client, sample=2000)
    assert list(table.columns) == list(cd.SCENE_COLUMNS)
    assert list(table["scene"]) == ["kind=pairs n=20000 seed=3 model=particle dtype=float32", "my debris", "b.npz",
                                    "kind=pile n=5"]
    assert list(table["model"]) == ["particle", "rigid", "rigid", "rigid"]
    assert list(table["precision"]) == ["float", "double", "double", "float"]
    assert list(table["accuracy"]) == ["fast", "fast", "fast", "accurate"]
    pile_contacts = len(collide.generate("pile", 5)[1])
    assert list(table["contacts"]) == [20_000, 3000, len(contacts), pile_contacts]
    assert table["islands"][0] == 20_000 and table["largest_island"][0] == 1
    assert table["islands"][2] == collide.islands(bodies, contacts).count
    assert list(table["error_sample"]) == [2000, 2000, min(2000, len(contacts)), min(2000, pile_contacts)]
    assert (table["collisions_per_second"] > 0).all()
    assert (table["max_error_eps"] <= collide.error_target_eps).all(), table["max_error_eps"]
    assert (table["max_error_eps"] > 0).any()
    assert (table["momentum_drift"].abs() < 1e-5).all() and (table["angular_momentum_drift"].abs() < 1e-5).all()


def assert_throughput_keys(stats):
    """collisions_per_second is the kernels' throughput, as collide.solve's;
    the call's wall time is call_seconds."""
    assert "seconds" not in stats
    assert stats["call_seconds"] > 0 and stats["kernel_seconds"] > 0
    assert stats["collisions_per_second"] == stats["collisions"] / stats["kernel_seconds"]


def test_stats_say_what_was_timed(client):
    bodies, contacts = island_scene(seed=21)
    stats = cd.solve((bodies, contacts), client).stats
    assert_throughput_keys(stats)
    assert stats["call_seconds"] >= stats["islands_seconds"]


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "collide.dask", *args], capture_output=True, text=True, timeout=120)


def test_the_command(client, tmp_path):
    bodies, contacts = island_scene("sphere", np.float32, seed=11)
    bp, cp = str(tmp_path / "b.npz"), str(tmp_path / "c.npz")
    collide.save(bp, cp, bodies, contacts)
    expected = reference_bytes(*collide.load(bp, cp))
    address = client.scheduler.address
    r = run_cli("solve", bp, cp, "--out-dir", str(tmp_path / "out"), "--scheduler", address)
    assert r.returncode == 0, r.stderr
    stats = json.loads(r.stdout)
    assert stats["collisions"] == len(contacts) and stats["model"] == "sphere"
    assert_throughput_keys(stats)
    assert "partitions done" in r.stderr, "a line per task when stderr is not a terminal"
    same_bytes(cd.Solution(*(np.load(tmp_path / "out" / f"{k}.npy") for k in "Jvw"), {}), expected)

    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps([{"kind": "pairs", "n": 3000, "seed": 2}, {"bodies": "b.npz", "contacts": "c.npz"}]))
    # Its own LocalCluster of one worker this time.
    r = run_cli("scenes", str(spec), "--out", str(tmp_path / "t.csv"), "--workers", "1", "--sample", "500",
                "--no-progress")
    assert r.returncode == 0, r.stderr
    assert "Warning" not in r.stderr, "no RuntimeWarning of the cluster's processes: " + r.stderr
    lines = (tmp_path / "t.csv").read_text().splitlines()
    assert lines[0] == ",".join(cd.SCENE_COLUMNS) and len(lines) == 3
    assert lines[1].startswith("kind=pairs n=3000 seed=2,rigid,float,fast,3000,3000,1,")
    assert lines[2].startswith(f"b.npz,sphere,float,fast,{len(contacts)},")


def test_bad_input(client, tmp_path):
    # Arrays: the library's message, nothing written.
    bodies, contacts = island_scene(seed=13)
    contacts.b[3] = len(bodies)
    v0 = bodies.v.copy()
    with pytest.raises(ValueError, match=rf"contacts\.b\[3\] = {len(bodies)}: out of range"):
        cd.solve((bodies, contacts), client)
    assert bodies.v.tobytes() == v0.tobytes()
    with pytest.raises(TypeError, match="collide.Bodies"):
        cd.solve((contacts, bodies), client)
    with pytest.raises(ValueError, match="model 'particle' does not fit"):
        cd.solve(collide.generate("pairs", 10), client, model="particle")
    with pytest.raises(ValueError, match=r"^unknown accuracy 'exact' \(expected fast or accurate\)$"):
        cd.solve(collide.generate("pairs", 10), client, accuracy="exact")
    with pytest.raises(ValueError, match=r"^collide.dask.solve_scenes: scene 0: unknown accuracy 'exact'"):
        cd.solve_scenes([{"kind": "pairs", "n": 10, "accuracy": "exact"}], client)

    # Files: the reader's message (file, row, column), no output.
    bodies, contacts = collide.generate("pairs", 100, dtype=np.float64)
    bp, cp = str(tmp_path / "b.npz"), str(tmp_path / "c.npz")
    collide.save(bp, cp, bodies, contacts)
    with np.load(bp) as z:
        cols = {k: z[k].copy() for k in z.files}
    cols["m"][4] = -1
    np.savez(bp, **cols)
    out = tmp_path / "out"
    with pytest.raises(ValueError, match=r"b\.npz: row 4, column 'm': mass must be > 0, got -1"):
        cd.solve((bp, cp), client, out_dir=out)
    assert not out.exists() or os.listdir(out) == []
    with pytest.raises(ValueError, match="out_dir"):
        cd.solve((bp, cp), client)
    csv_b, csv_c = str(tmp_path / "b.csv"), str(tmp_path / "c.csv")
    collide.save(csv_b, csv_c, *collide.generate("pairs", 10))
    with pytest.raises(ValueError, match=r"b\.csv: workers map their rows of a binary scene file"):
        cd.solve((csv_b, csv_c), client, out_dir=out)
    with pytest.raises(ValueError, match="scene 1: a generated scene has 'kind' and 'n'"):
        cd.solve_scenes([{"kind": "pairs", "n": 10}, {"kind": "pairs", "size": 10}], client)
    with pytest.raises(FileNotFoundError, match="scene 0: no such scene file"):
        cd.solve_scenes([(str(tmp_path / "missing.npz"), cp)], client)
    with pytest.raises(ValueError, match=r"b\.npz: row 4, column 'm'"):
        cd.solve_scenes([(bp, cp)], client)

    # The command: exit 1, the file named.
    address = client.scheduler.address
    r = run_cli("solve", bp, cp, "--out-dir", str(out), "--scheduler", address)
    assert r.returncode == 1 and "collide-dask: error:" in r.stderr and "b.npz: row 4, column 'm'" in r.stderr
    r = run_cli("solve", str(tmp_path / "nope.npz"), cp, "--out-dir", str(out), "--scheduler", address)
    assert r.returncode == 1 and "nope.npz" in r.stderr, r.stderr
    bad_spec = tmp_path / "bad.json"
    bad_spec.write_text("[{\"kind\": \"pairs\"")
    r = run_cli("scenes", str(bad_spec), "--scheduler", address)
    assert r.returncode == 1 and "bad.json: not valid JSON" in r.stderr, r.stderr
    r = run_cli("scenes", bp, "--scheduler", address)
    assert r.returncode == 1 and "pairs of binary scene files" in r.stderr, r.stderr
    r = run_cli("solve", bp, cp)
    assert r.returncode == 2 and "--out-dir" in r.stderr


class KillOnce(distributed.WorkerPlugin):
    """A worker plugin that kills its worker process (os._exit) when a
    partition task starts there, the first time only: the marker file says
    it happened, for every worker and for the restarted one."""

    name = "collide-test-kill-once"

    def __init__(self, marker):
        self.marker = marker

    def transition(self, key, start, finish, **kwargs):
        if finish == "executing" and "collide-dask-part-" in str(key):
            try:
                fd = os.open(self.marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
            except FileExistsError:
                return
            os.close(fd)
            os._exit(1)


@pytest.mark.parametrize("files", [True, False])
def test_a_worker_killed_mid_run_gives_the_same_bytes(client, tmp_path, files):
    bodies, contacts = island_scene("rigid", np.float32, seed=17)
    marker = str(tmp_path / "killed")
    client.register_worker_plugin(KillOnce(marker))
    try:
        if files:
            bp, cp = str(tmp_path / "b.npz"), str(tmp_path / "c.npz")
            collide.save(bp, cp, bodies, contacts)
            expected = reference_bytes(*collide.load(bp, cp))
            solution = cd.solve((bp, cp), client, out_dir=tmp_path / "out", partitions=4)
        else:
            expected = reference_bytes(bodies, contacts)
            solution = cd.solve((bodies, contacts), client, partitions=4)
    finally:
        client.unregister_worker_plugin(KillOnce.name)
    assert os.path.exists(marker), "a worker was killed during the run"
    same_bytes(solution, expected)
    client.wait_for_workers(2, timeout=60)


# ---------------------------------------------------------------------------
# The warm start: warm= of collide.solve, across the workers.
# ---------------------------------------------------------------------------


def warm_frame(kind="piles", dtype=np.float32, order="input"):
    """A scene and a warm start for it: four piles of 6^3 boxes on one
    ground (four islands, 2304 contacts) or 2000 independent pairs, and the
    J of six accumulated passes of a solve of it before (on a copy)."""
    if kind == "piles":
        bodies, contacts = piles_scene(dtype, seed=3, piles=4, n=6)
    else:
        bodies, contacts = collide.generate("pairs", 2000, friction=True, seed=4, dtype=dtype)
    J0, _ = collide.solve(*copy_scene(bodies, contacts), order=order, passes=6, iteration="accumulate")
    return bodies, contacts, J0


def solved_copy(bodies, contacts, **kwargs):
    """collide.solve on a copy of the scene: (J, the copy's bodies, stats)."""
    b, c = copy_scene(bodies, contacts)
    J, stats = collide.solve(b, c, **kwargs)
    return J, b, stats


def same_bits(solution, J, bodies):
    """J, v and w of a distributed solve are, bit for bit, collide.solve's."""
    bits = np.uint32 if J.dtype == np.float32 else np.uint64
    for got, want in ((solution.J, J), (solution.v, bodies.v), (solution.w, bodies.w)):
        assert np.asarray(got).dtype == want.dtype
        assert np.array_equal(np.asarray(got).view(bits), want.view(bits))


def save_impulses(path, J):
    """J as an impulses file (members jx, jy, jz), written by NumPy."""
    np.savez(path, jx=J[0], jy=J[1], jz=J[2])


def read_impulses_npz(path):
    with np.load(path) as z:
        return np.stack([z["jx"], z["jy"], z["jz"]])


@pytest.mark.parametrize("order", ["input", "colour"])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_warm_arrays_same_bits_as_collide_solve(client, order, dtype):
    bodies, contacts, J0 = warm_frame("piles", dtype, order)
    J, after, stats = solved_copy(bodies, contacts, order=order, passes=2, iteration="accumulate", warm=J0)
    assert stats["warm_start"]
    cold, _, _ = solved_copy(bodies, contacts, order=order, passes=2, iteration="accumulate")
    assert not np.array_equal(cold, J), "the warm start changes the solve"
    warm = J0.copy()
    solution = cd.solve((bodies, contacts), client, order=order, passes=2, iteration="accumulate", warm=warm)
    same_bits(solution, J, after)
    assert warm.tobytes() == J0.tobytes(), "the warm start is only read"
    assert solution.stats["warm_start"] is True and solution.stats["iteration"] == "accumulate"
    assert len(solution.stats["partitions"]) == 2
    assert cd.solve(copy_scene(bodies, contacts), client).stats["warm_start"] is False


@pytest.mark.parametrize("kind, order, start", [
    ("pairs", "input", "tool"),     # partitions of consecutive rows: the impulses file's columns mapped in place
    ("piles", "colour", "tool"),    # rows through the order file: the columns gathered
    ("pairs", "input", "out_dir"),  # out_dir's own J.npy, of the solve before, replaced by this one's
    ("piles", "colour", "out_dir"),
])
def test_warm_files_same_bits_as_collide_solve(client, cli, tmp_path, kind, order, start):
    bodies, contacts, _ = warm_frame(kind, np.float32, order)
    bp, cp = str(tmp_path / "bodies.npz"), str(tmp_path / "contacts.npz")
    collide.save(bp, cp, bodies, contacts)
    out = tmp_path / "out"
    if start == "tool":
        warm = str(tmp_path / "j0.npz")
        run([cli, "solve", "--bodies", bp, "--contacts", cp, "--out-bodies", str(tmp_path / "ob.npz"),
             "--out-impulses", warm, "--order", order, "--passes", "6", "--iteration", "accumulate"])
        J0 = read_impulses_npz(warm)
    else:
        before = cd.solve((bp, cp), client, out_dir=out, order=order, passes=6, iteration="accumulate", partitions=3)
        J0 = np.array(before.J)
        warm = out / "J.npy"
    J, after, _ = solved_copy(*collide.load(bp, cp), order=order, passes=2, iteration="accumulate", warm=J0)
    solution = cd.solve((bp, cp), client, out_dir=out, order=order, passes=2, iteration="accumulate", warm=warm,
                        partitions=3)
    same_bits(solution, J, after)
    assert solution.stats["warm_start"] is True
    assert sorted(os.listdir(out)) == ["J.npy", "v.npy", "w.npy"], "nothing else left behind"


def test_a_double_warm_start_file_for_a_float_solve_is_rounded_as_the_tool_rounds_it(client, cli, tmp_path):
    # `collide solve --precision float --warm-start` of a float64 impulses
    # file: the same bits, the impulses rounded as scene values are.
    bodies, contacts, J0 = warm_frame("piles", np.float64, "input")
    bp, cp = str(tmp_path / "bodies.npz"), str(tmp_path / "contacts.npz")
    collide.save(bp, cp, bodies, contacts)
    warm = str(tmp_path / "j0.npz")
    save_impulses(warm, J0)
    ob, oj = str(tmp_path / "ob.npz"), str(tmp_path / "oj.npz")
    run([cli, "solve", "--bodies", bp, "--contacts", cp, "--out-bodies", ob, "--out-impulses", oj, "--precision",
         "float", "--passes", "2", "--iteration", "accumulate", "--warm-start", warm])
    with np.load(ob) as z:
        tool = {k: np.stack([z[k + axis] for axis in "xyz"]) for k in "vw"}
    solution = cd.solve((bp, cp), client, out_dir=tmp_path / "out", dtype=np.float32, passes=2,
                        iteration="accumulate", warm=warm, partitions=2)
    assert np.array_equal(np.asarray(solution.J).view(np.uint32), read_impulses_npz(oj).view(np.uint32))
    for k in "vw":
        assert np.array_equal(np.asarray(getattr(solution, k)).view(np.uint32), tool[k].view(np.uint32))


def collide_solve_warm_error(bodies, contacts, warm, **options):
    """collide.solve's exception (type, message) for this warm start (raised
    before it writes anything: on the scene itself, so that a warm start
    sharing its memory is seen as such)."""
    with pytest.raises((TypeError, ValueError)) as e:
        collide.solve(bodies, contacts, warm=warm, **options)
    return type(e.value), str(e.value)


def pulling(J0, contacts, k):
    """J0 with contact k's J turned against its normal."""
    bad = J0.copy()
    bad[:, k] = -contacts.n[:, k]
    return bad


def test_a_bad_warm_start_gets_collide_solves_errors(client):
    bodies, contacts, J0 = warm_frame("pairs")
    m = len(contacts)
    nan = pulling(J0, contacts, 1500)
    nan[1, 40] = np.nan
    cases = [(J0.astype(np.float64), {}), (np.ascontiguousarray(J0.T), {}), (J0.tolist(), {}),
             (J0[:, :-1], {}), (pulling(J0, contacts, 17), {}), (nan, {}),
             (bodies.v[:, :m], {}),  # shares memory with what the solve writes
             (J0, {"iteration": "repeat"}), (J0, {"accuracy": "accurate"})]
    v0 = bodies.v.copy()
    for warm, extra in cases:
        options = dict({"iteration": "accumulate", "passes": 2}, **extra)
        kind, message = collide_solve_warm_error(bodies, contacts, warm, **options)
        with pytest.raises(kind) as e:
            cd.solve((bodies, contacts), client, warm=warm, **options)
        assert str(e.value) == message
        assert bodies.v.tobytes() == v0.tobytes(), "nothing written"
    # The first refused J by row, named by its row in the scene.
    assert collide_solve_warm_error(bodies, contacts, nan, iteration="accumulate")[1].startswith(
        "solve: warm[:, 40] = (")
    assert collide_solve_warm_error(bodies, contacts, pulling(J0, contacts, 17), iteration="accumulate")[1].startswith(
        "solve: warm[:, 17] = (")


def test_a_bad_warm_start_file_is_refused_naming_it(client, tmp_path):
    bodies, contacts, J0 = warm_frame("pairs")
    m = len(contacts)
    bp, cp = str(tmp_path / "bodies.npz"), str(tmp_path / "contacts.npz")
    collide.save(bp, cp, bodies, contacts)
    out = tmp_path / "out"

    def refused(kind, warm, match, **options):
        with pytest.raises(kind, match=match):
            cd.solve((bp, cp), client, out_dir=out, warm=warm, **dict({"iteration": "accumulate"}, **options))
        assert not out.exists(), "nothing written"

    path = lambda name: str(tmp_path / name)  # noqa: E731
    refused(TypeError, J0, "for scene files, warm is the path of an impulses file")
    refused(ValueError, J0, r"^a warm start needs iteration='accumulate'", iteration="repeat")
    refused(FileNotFoundError, path("missing.npz"), "missing.npz")
    np.savetxt(path("j.csv"), J0.T, delimiter=",", header="jx,jy,jz", comments="")
    refused(ValueError, path("j.csv"), r"j\.csv: a warm start file is an impulses file \(.npz with jx, jy, jz")
    np.savez(path("two.npz"), jx=J0[0], jy=J0[1])
    refused(ValueError, path("two.npz"), r"two\.npz: an impulses file has the members jx, jy and jz .* has jx, jy$")
    save_impulses(path("short.npz"), J0[:, :-1])
    refused(ValueError, path("short.npz"), rf"short\.npz: warm holds {m - 1} impulses but {cp} holds {m} contacts")
    np.save(path("short.npy"), np.ascontiguousarray(J0[:, :-1]))
    refused(ValueError, path("short.npy"), rf"short\.npy: warm holds {m - 1} impulses")
    np.save(path("rows.npy"), np.ascontiguousarray(J0.T))
    refused(ValueError, path("rows.npy"), rf"rows\.npy: a warm start \.npy holds J, shape \(3, M\), got shape "
                                          rf"\({m}, 3\)")
    save_impulses(path("int.npz"), J0.astype(np.int32))
    refused(ValueError, path("int.npz"), r"int\.npz: impulses are float32 or float64")
    bad = pulling(J0, contacts, 17)
    save_impulses(path("pull.npz"), bad)
    _, message = collide_solve_warm_error(*collide.load(bp, cp), bad, iteration="accumulate")
    assert message.startswith("solve: warm[:, 17] = (")
    with pytest.raises(ValueError) as e:
        cd.solve((bp, cp), client, out_dir=out, warm=path("pull.npz"), iteration="accumulate")
    assert str(e.value) == path("pull.npz") + ": " + message.removeprefix("solve: ")
    huge = J0.astype(np.float64)
    huge[1, 33] = 1e300
    save_impulses(path("huge.npz"), huge)
    refused(ValueError, path("huge.npz"), r"huge\.npz: row 33, column 'jy': ", dtype=np.float32)


def test_solve_scenes_from_warm_starts(client, tmp_path):
    pile = {"kind": "pile", "n": 6, "seed": 2, "friction": True}
    pile_bodies, pile_contacts = collide.generate("pile", 6, seed=2, friction=True)
    pile_J0, _ = collide.solve(*copy_scene(pile_bodies, pile_contacts), passes=6, iteration="accumulate")
    bodies, contacts, J0 = warm_frame("piles", np.float64)
    bp, cp, jp = str(tmp_path / "b.npz"), str(tmp_path / "c.npz"), str(tmp_path / "j0.npz")
    collide.save(bp, cp, bodies, contacts)
    save_impulses(jp, J0)
    scenes = [pile, (bp, cp), {"kind": "pairs", "n": 2000}]
    table = cd.solve_scenes(scenes, client, passes=2, iteration="accumulate", warm=[pile_J0, jp, None], sample=500)
    assert list(table["contacts"]) == [len(pile_contacts), len(contacts), 2000]
    assert (table["max_error_eps"] <= collide.error_bound_eps).all(), table["max_error_eps"]
    # The sample's error is that of its solve from the first columns of the warm start.
    sample_bodies, sample_contacts, _ = cd._tasks.sub_scene(pile_bodies, pile_contacts, np.arange(500))
    start = np.ascontiguousarray(pile_J0[:, :500])
    ref = collide.reference_solve(sample_bodies, sample_contacts, passes=2, iteration="accumulate", warm=start)
    J, _ = collide.solve(sample_bodies, sample_contacts, model=table["model"][0], passes=2, iteration="accumulate",
                         warm=start)
    assert table["max_error_eps"][0] == collide.impulse_error(J, ref).max()

    # Refused before anything runs, or by the scene's worker naming the scene.
    with pytest.raises(TypeError, match="warm is a list, one warm start"):
        cd.solve_scenes([pile], client, iteration="accumulate", warm=pile_J0)
    with pytest.raises(ValueError, match=r"warm has 1 entries for 2 scenes"):
        cd.solve_scenes([pile, pile], client, iteration="accumulate", warm=[pile_J0])
    with pytest.raises(ValueError, match=r"^a warm start needs iteration='accumulate'"):
        cd.solve_scenes([pile], client, warm=[pile_J0])
    with pytest.raises(FileNotFoundError, match="scene 1: no such warm start file"):
        cd.solve_scenes([pile, pile], client, iteration="accumulate", warm=[None, str(tmp_path / "missing.npz")])
    m = len(pile_contacts)
    with pytest.raises(ValueError, match=rf"^collide.dask.solve_scenes: scene 1: solve.warm has {m - 1} elements, "
                                         rf"contacts.a has {m}$"):
        cd.solve_scenes([pile, pile], client, iteration="accumulate", warm=[None, pile_J0[:, :-1]])
    with pytest.raises(ValueError, match=r"^collide.dask.solve_scenes: scene 0: solve: warm\[:, 17\] = "):
        cd.solve_scenes([pile], client, iteration="accumulate", warm=[pulling(pile_J0, pile_contacts, 17)])


def test_the_command_takes_a_warm_start(client, tmp_path):
    bodies, contacts, J0 = warm_frame("piles", np.float32, "colour")
    bp, cp, jp = str(tmp_path / "b.npz"), str(tmp_path / "c.npz"), str(tmp_path / "j0.npz")
    collide.save(bp, cp, bodies, contacts)
    save_impulses(jp, J0)
    J, after, _ = solved_copy(*collide.load(bp, cp), order="colour", passes=2, iteration="accumulate", warm=J0)
    address = client.scheduler.address
    common = ["--scheduler", address, "--no-progress", "--order", "colour", "--passes", "2"]
    r = run_cli("solve", bp, cp, "--out-dir", str(tmp_path / "out"), *common, "--iteration", "accumulate",
                "--warm-start", jp)
    assert r.returncode == 0, r.stderr
    stats = json.loads(r.stdout)
    assert stats["warm_start"] is True and stats["iteration"] == "accumulate"
    same_bits(cd.Solution(*(np.load(tmp_path / "out" / f"{k}.npy") for k in "Jvw"), {}), J, after)
    # Without --iteration accumulate: a usage error, as `collide solve` gives it.
    r = run_cli("solve", bp, cp, "--out-dir", str(tmp_path / "out2"), *common, "--warm-start", jp)
    assert r.returncode == 2 and r.stderr.startswith("usage: python -m collide.dask solve "), r.stderr
    assert r.stderr.endswith("error: --warm-start needs --iteration accumulate (the repeat mode's passes add "
                             "impulses and cannot start from a J)\n"), r.stderr
    assert not (tmp_path / "out2").exists()
    save_impulses(str(tmp_path / "short.npz"), J0[:, :-1])
    r = run_cli("solve", bp, cp, "--out-dir", str(tmp_path / "out2"), *common, "--iteration", "accumulate",
                "--warm-start", str(tmp_path / "short.npz"))
    assert r.returncode == 1 and r.stderr.startswith(f"collide-dask: error: {tmp_path / 'short.npz'}: warm holds"), \
        r.stderr
    # scenes: an entry's "warm", relative to the JSON file that lists it.
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps([{"bodies": "b.npz", "contacts": "c.npz", "warm": "j0.npz"},
                                {"kind": "pairs", "n": 100}]))
    r = run_cli("scenes", str(spec), *common, "--iteration", "accumulate", "--sample", "200")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert len(lines) == 3 and lines[1].startswith("b.npz,") and f",float,fast,{len(contacts)}," in lines[1], lines
    r = run_cli("scenes", str(spec), *common)
    assert r.returncode == 1 and r.stderr == (f"collide-dask: error: {spec}: scene 0 has a warm start, which needs "
                                              "--iteration accumulate (the repeat mode's passes add impulses and "
                                              "cannot start from a J)\n"), r.stderr


def test_import_collide_without_dask():
    code = textwrap.dedent("""
        import importlib.abc, sys

        class Blocked(importlib.abc.MetaPathFinder):
            def find_spec(self, name, path, target=None):
                if name.split(".")[0] in ("dask", "distributed", "pandas"):
                    raise ImportError(f"No module named '{name}' (blocked)")
                return None

        sys.meta_path.insert(0, Blocked())
        import numpy as np
        import collide, collide.dask
        assert not [m for m in sys.modules if m.split(".")[0] in ("dask", "distributed", "pandas")]
        bodies, contacts = collide.generate("pairs", 100)
        J, stats = collide.solve(bodies, contacts)
        print(collide.islands(bodies, contacts).count, collide.dask.partition_islands([3, 1, 2], 2).tolist())
        try:
            collide.dask.solve((bodies, contacts))
        except ImportError as e:
            print("ImportError:", e)
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0] == "100 [0, 1, 1]"
    assert lines[1].startswith("ImportError: collide.dask needs distributed (Debian: python3-dask python3-distributed")


def test_a_script_without_the_main_guard_runs_once(tmp_path):
    # docs/distributed.md's call saved as a script, at its top level, without
    # `if __name__ == "__main__":`. The cluster collide.dask starts for it
    # runs in a process of its own, so its spawned workers never import the
    # script: it runs once, finishes well within a minute, and gives
    # collide.solve's bytes. (Started from the script's own process, every
    # worker would run the script again and start a cluster, for ever.)
    runs = tmp_path / "runs.txt"
    script = tmp_path / "plain_script.py"
    script.write_text(textwrap.dedent("""
        import os
        import numpy as np
        import collide, collide.dask

        with open(RUNS, "a") as f:
            f.write(f"{os.getpid()}\\n")
        bodies, contacts = collide.generate("pairs", 2000, friction=True, dtype=np.float32)
        alone, _ = collide.generate("pairs", 2000, friction=True, dtype=np.float32)
        expected, _ = collide.solve(alone, contacts)
        J, v, w, stats = collide.dask.solve((bodies, contacts), workers=2)
        assert J.tobytes() == expected.tobytes()
        assert v.tobytes() == alone.v.tobytes() and w.tobytes() == alone.w.tobytes()
        print("solved in", len(stats["partitions"]), "partitions")
    """).replace("RUNS", repr(str(runs))))
    r = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout == "solved in 2 partitions\n", r.stdout
    # Nothing on stderr: in particular no RuntimeWarning from runpy in the
    # cluster's process or its workers.
    assert "Warning" not in r.stderr, r.stderr
    assert len(runs.read_text().split()) == 1, "the script ran again in a worker: " + runs.read_text()
