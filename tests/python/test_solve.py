"""collide.solve against `collide solve`, in place and without copies."""

import json
import os

import numpy as np
import pytest

import collide
from conftest import run


def read_impulses(path, dtype):
    # The CLI writes the shortest decimal that reads back to the same value.
    rows = np.loadtxt(path, delimiter=",", skiprows=1, dtype=np.float64, ndmin=2)
    return np.ascontiguousarray(rows.T.astype(dtype))


@pytest.mark.parametrize("dtype,precision", [(np.float32, "float"), (np.float64, "double")])
@pytest.mark.parametrize("scene", [["--pairs", "3000"], ["--debris", "3000", "--friction"],
                                   ["--pile", "9", "--shuffle", "--friction"], ["--chain", "2000"]])
def test_bitwise_equal_to_cli(cli, workdir, dtype, precision, scene):
    run([cli, "gen", *scene, "--out", workdir, "--seed", "7"])
    b_csv, c_csv = os.path.join(workdir, "bodies.csv"), os.path.join(workdir, "contacts.csv")
    ob, oj = os.path.join(workdir, "out_bodies.csv"), os.path.join(workdir, "out_j.csv")
    r = run([cli, "solve", "--bodies", b_csv, "--contacts", c_csv, "--out-bodies", ob, "--out-impulses", oj,
             "--precision", precision, "--stats"])
    cli_stats = json.loads(r.stderr.strip().splitlines()[-1])

    bodies, contacts = collide.read_scene(b_csv, c_csv, dtype=dtype)
    J, stats = collide.solve(bodies, contacts)
    assert J.dtype == dtype and J.shape == (3, len(contacts))
    np.testing.assert_array_equal(J.view(np.uint32 if dtype == np.float32 else np.uint64),
                                  read_impulses(oj, dtype).view(np.uint32 if dtype == np.float32 else np.uint64))
    after, _ = collide.read_scene(ob, c_csv, dtype=dtype)
    assert np.array_equal(bodies.v, after.v) and np.array_equal(bodies.w, after.w)
    # The stats dict has every key of --stats that is not about files.
    for key in set(cli_stats) - {"read_seconds", "write_seconds", "io_seconds", "io_fraction"}:
        assert key in stats, key
    for key in ("collisions", "impacts", "bodies", "precision", "model", "path", "batches", "largest_batch",
                "isa_choice", "accuracy"):
        assert stats[key] == cli_stats[key], key
    # Each process measures its own pick: an ISA this CPU has, the same bits.
    assert collide.isa_supported(stats["isa"]) and collide.isa_supported(cli_stats["isa"])


def test_zero_copy_and_in_place():
    bodies, contacts = collide.generate("pairs", 1000, dtype=np.float64)
    v, w = bodies.v, bodies.w
    addr_v, addr_w = v.ctypes.data, w.ctypes.data
    v0, w0 = v.copy(), w.copy()
    J, _ = collide.solve(bodies, contacts)
    assert bodies.v is v and bodies.w is w
    assert v.ctypes.data == addr_v and w.ctypes.data == addr_w
    assert not np.array_equal(v, v0) and not np.array_equal(w, w0)

    # Bodies built over the caller's own arrays keep them, not copies.
    arrays = [np.array(a) for a in (bodies.inv_mass, bodies.inv_inertia, bodies.q, bodies.p, v0, w0)]
    mine = collide.Bodies(*arrays)
    for name, a in zip(("inv_mass", "inv_inertia", "q", "p", "v", "w"), arrays):
        assert getattr(mine, name).ctypes.data == a.ctypes.data, name
    collide.solve(mine, contacts)
    assert np.array_equal(arrays[4], bodies.v)  # the caller's v was updated in place, same result

    # out=: J written into the caller's buffer.
    out = np.empty((3, len(contacts)), dtype=np.float64)
    arrays2 = [np.array(a) for a in (bodies.inv_mass, bodies.inv_inertia, bodies.q, bodies.p, v0, w0)]
    J2, _ = collide.solve(collide.Bodies(*arrays2), contacts, out=out)
    assert J2.ctypes.data == out.ctypes.data and np.array_equal(out, J)

    # out= and v, w as columns of wider arrays (rows one stride apart, as a
    # mapped file gives them): each row written where it lies, nothing
    # around it touched; J's error read from the same rows.
    m, n = len(contacts), len(bodies)
    wide_j = np.full((3, m + 7), -1.0)
    wide_v, wide_w = np.full((3, n + 5), -2.0), np.full((3, n + 5), -3.0)
    wide_v[:, 2:n + 2], wide_w[:, 2:n + 2] = v0, w0
    arrays3 = [np.array(a) for a in (bodies.inv_mass, bodies.inv_inertia, bodies.q, bodies.p)]
    J3, _ = collide.solve(collide.Bodies(*arrays3, wide_v[:, 2:n + 2], wide_w[:, 2:n + 2]), contacts,
                          out=wide_j[:, 3:m + 3])
    assert J3.tobytes() == J.tobytes() and wide_j[:, 3:m + 3].tobytes() == J.tobytes()
    assert (wide_j[:, :3] == -1).all() and (wide_j[:, m + 3:] == -1).all()
    assert wide_v[:, 2:n + 2].tobytes() == bodies.v.tobytes() and wide_w[:, 2:n + 2].tobytes() == bodies.w.tobytes()
    assert (wide_v[:, :2] == -2).all() and (wide_v[:, n + 2:] == -2).all() and (wide_w[:, n + 2:] == -3).all()
    ref = collide.reference_solve(collide.Bodies(*arrays3, v0.copy(), w0.copy()), contacts)
    assert collide.impulse_error(wide_j[:, 3:m + 3], ref).tobytes() == collide.impulse_error(J, ref).tobytes()


def test_paths_models_threads_and_isas_agree():
    bodies, contacts = collide.generate("debris", 5000, friction=True, dtype=np.float32)
    v0, w0 = bodies.v.copy(), bodies.w.copy()
    results = []
    isas = [isa for isa in ("sse2", "avx2", "avx512") if collide.isa_supported(isa)]
    for kwargs in ({"path": "scalar"}, {"path": "simd", "threads": 1}, {"threads": 2},
                   *({"isa": isa} for isa in isas)):
        bodies.v[...] = v0
        bodies.w[...] = w0
        J, stats = collide.solve(bodies, contacts, **kwargs)
        results.append((J, bodies.v.copy(), bodies.w.copy()))
    for J, v, w in results[1:]:
        assert np.array_equal(J, results[0][0]) and np.array_equal(v, results[0][1]) and np.array_equal(w, results[0][2])


def test_solver_and_schedule_reuse():
    bodies, contacts = collide.generate("debris", 2000, dtype=np.float64)
    v0, w0 = bodies.v.copy(), bodies.w.copy()
    J1, _ = collide.solve(bodies, contacts)
    bodies.v[...] = v0
    bodies.w[...] = w0
    solver = collide.Solver(threads=1)
    schedule = collide.Schedule(bodies, contacts)
    assert schedule.batches >= 1
    J2, stats = solver.solve(bodies, contacts, schedule=schedule)
    assert np.array_equal(J1, J2)
    other, other_contacts = collide.generate("pairs", 10, dtype=np.float64)
    with pytest.raises(ValueError, match="schedule was built for"):
        solver.solve(other, other_contacts, schedule=schedule)


def test_isa_and_accuracy_pass_through():
    bodies, contacts = collide.generate("pairs", 100, dtype=np.float32)
    solver = collide.Solver(isa="sse2", accuracy="fast")
    assert solver.isa == "sse2" and solver.accuracy == "fast"  # the options reach the library's Solver
    _, stats = solver.solve(bodies, contacts)
    assert stats["accuracy"] == "fast"
    assert stats["isa"] == "sse2"  # what ran (SolveStats::isa)
    _, stats = collide.solve(bodies, contacts)
    assert collide.Solver().isa == "auto" and stats["isa_choice"] == "measured"  # chosen per solve
    assert stats["isa"] != "auto" and collide.isa_supported(stats["isa"])
    with pytest.raises(ValueError, match="accuracy"):
        collide.solve(bodies, contacts, accuracy="sloppy")
    with pytest.raises(ValueError, match="instruction set"):
        collide.solve(bodies, contacts, isa="mmx")
    with pytest.raises(ValueError, match="path"):
        collide.solve(bodies, contacts, path="gpu")
    with pytest.raises(ValueError, match="model"):
        collide.solve(bodies, contacts, model="cube")


def test_models_fit_or_refuse():
    bodies, contacts = collide.generate("pairs", 100, model="particle", dtype=np.float64)
    _, stats = collide.solve(bodies, contacts)
    assert stats["model"] == "particle"
    rigid, rc = collide.generate("pairs", 100, model="rigid", dtype=np.float64)
    with pytest.raises(ValueError, match="does not fit"):
        collide.solve(rigid, rc, model="particle")


def test_reference_and_impulse_error_match_check(cli, workdir):
    run([cli, "gen", "--debris", "2000", "--friction", "--out", workdir])
    b_csv, c_csv = os.path.join(workdir, "bodies.csv"), os.path.join(workdir, "contacts.csv")
    ob, oj = os.path.join(workdir, "ob.csv"), os.path.join(workdir, "oj.csv")
    r = run([cli, "solve", "--bodies", b_csv, "--contacts", c_csv, "--out-bodies", ob, "--out-impulses", oj,
             "--precision", "float", "--stats", "--check"])
    cli_stats = json.loads(r.stderr.strip().splitlines()[-1])
    bodies, contacts = collide.read_scene(b_csv, c_csv, dtype=np.float32)
    v0 = bodies.v.copy()
    ref = collide.reference_solve(bodies, contacts)
    assert np.array_equal(bodies.v, v0)  # the reference works on a copy
    J, _ = collide.solve(bodies, contacts)
    err = collide.impulse_error(J, ref)
    assert err.shape == (len(contacts),) and err.dtype == np.float64
    assert float(np.max(err)) == pytest.approx(cli_stats["max_impulse_error_eps"], rel=1e-8)
    assert int(np.argmax(err)) == cli_stats["worst_contact"]
    assert np.max(err) <= collide.error_bound_eps
    # The measure is not blind: a perturbed impulse shows its error.
    bad = J.copy()
    k = int(np.argmax(ref.impulse_scale))
    bad[0, k] += np.float32(1e3) * np.finfo(np.float32).eps * np.float32(ref.impulse_scale[k])
    assert collide.impulse_error(bad, ref)[k] > 500


@pytest.mark.parametrize("iteration", ["repeat", "accumulate"])
@pytest.mark.parametrize("order", ["input", "colour"])
@pytest.mark.parametrize("passes", [1, 4, 16])
@pytest.mark.parametrize("kind,n,friction", [("pile", 12, False), ("pile", 12, True), ("debris", 20000, True)])
def test_error_bound_can_fail_at_every_pass_count(kind, n, friction, order, passes, iteration):
    # docs/python.md's assert, on the solve and on a J that is 1% too large
    # or all zero (docs/collision-law.md, "The error bound over passes").
    bodies, contacts = collide.generate(kind, n, friction=friction, seed=7)
    ref = collide.reference_solve(bodies, contacts, order=order, passes=passes, iteration=iteration)
    J, stats = collide.solve(bodies, contacts, order=order, passes=passes, iteration=iteration)
    assert stats["iteration"] == iteration
    assert collide.impulse_error(J, ref).max() <= collide.error_bound_eps
    assert collide.impulse_error(J * np.float32(1.01), ref).max() > collide.error_bound_eps
    assert collide.impulse_error(np.zeros_like(J), ref).max() > collide.error_bound_eps


def test_scene_round_trip(workdir):
    bodies, contacts = collide.generate("debris", 500, friction=True, dtype=np.float64)
    b_csv, c_csv = os.path.join(workdir, "b.csv"), os.path.join(workdir, "c.csv")
    collide.write_scene(b_csv, c_csv, bodies, contacts)
    b2, c2 = collide.read_scene(b_csv, c_csv, dtype=np.float64)
    for name in ("v", "w", "p"):
        assert np.array_equal(getattr(b2, name), getattr(bodies, name)), name
    np.testing.assert_allclose(b2.inv_mass, bodies.inv_mass, rtol=1e-15)
    assert np.array_equal(c2.a, contacts.a) and np.array_equal(c2.b, contacts.b)
    np.testing.assert_allclose(c2.n, contacts.n, rtol=0, atol=1e-15)


def test_from_physical():
    m = np.array([2.0, np.inf])
    inertia = np.array([[1.0, 1.0], [2.0, 1.0], [np.inf, 1.0]])
    q = np.array([[2.0, 1.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]])
    p = np.zeros((3, 2))
    bodies = collide.from_physical(m, inertia, q, p, dtype=np.float64)
    assert list(bodies.inv_mass) == [0.5, 0.0]
    assert list(bodies.inv_inertia[:, 0]) == [1.0, 0.5, 0.0]
    assert list(bodies.inv_inertia[:, 1]) == [0.0, 0.0, 0.0]  # immovable: no rotation either
    assert list(bodies.q[:, 0]) == [2.0, 0.0, 0.0, 0.0]  # as given: the law normalises q
    with pytest.raises(ValueError, match=r"^from_physical: body 0, column 'm': mass must be > 0, got -1$"):
        collide.from_physical(np.array([-1.0]), np.ones((3, 1)), q[:, :1].copy(), np.zeros((3, 1)))


def test_readable_reprs():
    bodies, contacts = collide.generate("pairs", 10, friction=True, dtype=np.float32)
    assert repr(bodies) == "collide.Bodies(20 bodies, float32: inv_mass (N,), inv_inertia, p, v, w (3, N), q (4, N))"
    assert repr(contacts) == "collide.Contacts(10 contacts, float32, e per contact, mu per contact)"
    plain = collide.Contacts(contacts.a, contacts.b, contacts.c, contacts.n, uniform_e=0.5)
    assert repr(plain) == "collide.Contacts(10 contacts, float32, uniform_e 0.5, frictionless)"
    # The stats: a dict, shown one key per line, that reads back as itself.
    J, stats = collide.solve(bodies, contacts)
    assert isinstance(stats, dict) and type(stats) is collide.Stats
    text = repr(stats)
    assert text.startswith("Stats({'collisions': 10,\n       'impacts': ")
    assert len(text.splitlines()) == len(stats)
    assert eval(text, {"Stats": collide.Stats}) == stats


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_allocate_seconds_apart_from_the_kernel(dtype):
    # A one-shot solve of a pile in the colour order allocates the solver's
    # copy of the contacts first: its allocate phase, reported on its own.
    bodies, contacts = collide.generate("pile", 20, dtype=dtype)
    _, stats = collide.solve(bodies, contacts, order="colour")
    for key in ("allocate_seconds", "kernel_seconds", "isa_calibration_seconds"):
        assert isinstance(stats[key], float) and np.isfinite(stats[key]) and stats[key] >= 0, (key, stats)
    assert stats["allocate_seconds"] > 0, stats
    assert "'allocate_seconds': " in repr(stats)
    # A reused solver finds its buffers sized: nothing to allocate.
    solver = collide.Solver()
    schedule = collide.Schedule(bodies, contacts, order="colour")
    _, first = solver.solve(bodies, contacts, schedule=schedule)
    _, second = solver.solve(bodies, contacts, schedule=schedule)
    assert first["allocate_seconds"] > 0, first
    assert second["allocate_seconds"] == 0.0, second


def test_report_quick_rows():
    rows = collide.report(n=2000, sample=500, runs=1, threads=[1], quick=True)
    assert rows and {"scene", "variant", "model", "precision", "max_err_eps", "collisions_per_second"} <= set(rows[0])
    kernel = [r for r in rows if r["variant"] in ("scalar", "simd")]
    assert kernel and all(r["max_err_eps"] <= collide.error_bound_eps for r in kernel)
    assert {r["scene"] for r in rows} == {"pairs", "debris", "pile"}
    with pytest.raises(ValueError, match="runs"):
        collide.report(n=10, runs=0)


def test_report_hard_rows():
    # The hard section from Python: every catalogue scene in both precisions
    # and both modes, each fast row within the fast mode's target and each
    # judged accurate row within its ulps (the C++ report test checks the
    # same rows through the CLI).
    rows = collide.report_hard(n=200, runs=1)
    assert rows
    assert {r["mode"] for r in rows} == {"fast", "accurate"}
    assert {r["precision"] for r in rows} == {"float", "double"}
    assert {"mass-ratio", "grazing"} <= {r["family"] for r in rows}
    keys = {(r["family"], r["model"], r["precision"]) for r in rows}
    assert len(rows) == 2 * len(keys)  # one fast and one accurate row per scene, model and precision
    for r in rows:
        assert r["collisions_per_second"] > 0 and r["runs"] >= 1 and 0 <= r["acting"] <= r["n"]
        assert r["max_err_eps"] <= collide.error_target_eps, r
        if r["mode"] == "accurate" and r["max_err_ulps"] is not None:
            assert r["max_err_ulps"] <= collide.accurate_error_ulps, r
    assert any(r["max_err_ulps"] is not None for r in rows if r["mode"] == "accurate")
    with pytest.raises(ValueError, match="hard_n"):
        collide.report_hard(n=0)
    with pytest.raises(ValueError, match="runs"):
        collide.report_hard(runs=0)


def test_report_convergence_rows():
    # The convergence section from Python: every scene, order and mode, one
    # cold pass leaving all of J to do, a warm start less.
    rows = collide.report_convergence(n=1408, threads=[1], runs=1)
    assert len(rows) == 3 * 2 * (2 * 6 + 2)
    assert {r["scene"] for r in rows} == {"pile", "stack", "debris"}
    for r in rows:
        assert 0 < r["residual"] <= 1 and r["seconds"] > 0, r
        if r["passes"] == 1:
            assert (r["residual"] < 1) if r["warm"] else (r["residual"] == 1), r
    with pytest.raises(ValueError, match="convergence_n"):
        collide.report_convergence(n=0)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_generate_chain(dtype):
    bodies, contacts = collide.generate("chain", 500, dtype=dtype)
    assert len(bodies) == 501 and len(contacts) == 500
    # Each contact joins box k and box k + 1: one batch per contact.
    assert np.array_equal(contacts.a, np.arange(500)) and np.array_equal(contacts.b, np.arange(1, 501))
    J, stats = collide.solve(bodies, contacts)
    assert stats["batches"] == 500 and stats["impacts"] > 0
    ref_bodies, ref_contacts = collide.generate("chain", 500, dtype=dtype)
    J_scalar, _ = collide.solve(ref_bodies, ref_contacts, path="scalar")
    assert np.array_equal(J.view(np.uint8), J_scalar.view(np.uint8))
    with pytest.raises(ValueError, match="shuffle"):
        collide.generate("chain", 10, shuffle=True)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_generate_pile(dtype):
    side = 6
    bodies, contacts = collide.generate("pile", side, friction=True, dtype=dtype)
    shuffled, shuffled_contacts = collide.generate("pile", side, friction=True, shuffle=True, dtype=dtype)
    assert len(bodies) == side**3 + 1 and len(contacts) == 3 * side**2 * (side - 1) + side**2
    # The ground is the last body and immovable; every box is movable.
    assert bodies.inv_mass[-1] == 0 and np.all(bodies.inv_mass[:-1] > 0)
    # Shuffling moves contacts, never changes one: the same bodies, and the
    # same contacts as a set of rows in another order.
    assert np.array_equal(bodies.v, shuffled.v) and np.array_equal(bodies.q, shuffled.q)
    rows = lambda c: sorted(zip(c.a.tolist(), c.b.tolist(), *c.c.tolist(), *c.n.tolist(), c.e.tolist()))
    assert rows(contacts) == rows(shuffled_contacts)
    assert not np.array_equal(contacts.a, shuffled_contacts.a)
    # Contacts off the lines of centres: the rigid model, chosen by solve().
    J, stats = collide.solve(bodies, contacts)
    assert stats["model"] == "rigid" and stats["collisions"] == len(contacts)
    with pytest.raises(ValueError, match="boxes per side"):
        collide.generate("pile", 0)
    with pytest.raises(ValueError, match="shuffle"):
        collide.generate("pairs", 10, shuffle=True)


def test_accumulated_passes_as_the_tool_runs_them(cli, workdir):
    # collide.solve(iteration="accumulate") and `collide solve --iteration
    # accumulate` give the same bytes, and the same residual.
    run([cli, "gen", "--pile", "9", "--friction", "--out", workdir, "--seed", "3"])
    b_csv, c_csv = os.path.join(workdir, "bodies.csv"), os.path.join(workdir, "contacts.csv")
    ob, oj = os.path.join(workdir, "out_bodies.csv"), os.path.join(workdir, "out_j.csv")
    r = run([cli, "solve", "--bodies", b_csv, "--contacts", c_csv, "--out-bodies", ob, "--out-impulses", oj,
             "--precision", "double", "--order", "colour", "--passes", "6", "--iteration", "accumulate", "--stats",
             "--check"])
    cli_stats = json.loads(r.stderr.strip().splitlines()[-1])
    bodies, contacts = collide.read_scene(b_csv, c_csv, dtype=np.float64)
    J, stats = collide.solve(bodies, contacts, order="colour", passes=6, iteration="accumulate")
    np.testing.assert_array_equal(J.view(np.uint64), read_impulses(oj, np.float64).view(np.uint64))
    assert (cli_stats["iteration"], stats["iteration"]) == ("accumulate", "accumulate")
    # The tool's JSON prints ten significant digits.
    assert cli_stats["residual"] == pytest.approx(stats["residual"], rel=1e-9) and 0 < stats["residual"] < 1
    assert cli_stats["check_passed"]


def test_the_accurate_mode_takes_repeated_passes():
    bodies, contacts = collide.generate("pile", 3)
    with pytest.raises(ValueError, match="iteration='accumulate' runs in the fast mode"):
        collide.solve(bodies, contacts, accuracy="accurate", iteration="accumulate")
    with pytest.raises(ValueError, match="unknown iteration 'sum' \\(expected repeat or accumulate\\)"):
        collide.solve(bodies, contacts, iteration="sum")
    assert repr(collide.Solver(iteration="accumulate")).endswith("iteration='accumulate')")
