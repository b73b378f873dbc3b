"""The solve order and passes from Python: order="colour", passes=k, the reference in the solve's order."""

import json
import os

import numpy as np
import pytest

import collide
from conftest import run


def bits(a):
    return a.view(np.uint32 if a.dtype == np.float32 else np.uint64)


@pytest.mark.parametrize("scene", [["--pile", "12", "--friction"], ["--debris", "5000"], ["--chain", "3000"]])
def test_colour_order_with_passes_matches_the_cli(cli, workdir, scene):
    run([cli, "gen", *scene, "--out", workdir, "--seed", "3", "--format", "npz", "--precision", "float"])
    b, c = os.path.join(workdir, "bodies.npz"), os.path.join(workdir, "contacts.npz")
    ob, oj = os.path.join(workdir, "ob.npz"), os.path.join(workdir, "oj.npz")
    r = run([cli, "solve", "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses", oj,
             "--order", "colour", "--passes", "3", "--stats", "--check"])
    cli_stats = json.loads(r.stderr.strip().splitlines()[-1])
    assert cli_stats["order"] == "colour" and cli_stats["passes"] == 3 and cli_stats["check_passed"]
    assert cli_stats["colours"] >= 1 and cli_stats["overflow_contacts"] == 0

    bodies, contacts = collide.load(b, c)
    J, stats = collide.solve(bodies, contacts, order="colour", passes=3)
    for key in ("order", "passes", "colours", "overflow_contacts", "batches", "largest_batch"):
        assert stats[key] == cli_stats[key], key
    with np.load(oj) as cli_j:
        np.testing.assert_array_equal(bits(J), bits(np.stack([cli_j["jx"], cli_j["jy"], cli_j["jz"]])))


def test_passes_are_that_many_solves_added():
    for order in ("input", "colour"):
        bodies, contacts = collide.generate("pile", 10, dtype=np.float32)
        again = collide.Bodies(*(np.array(a) for a in (bodies.inv_mass, bodies.inv_inertia, bodies.q, bodies.p,
                                                       bodies.v, bodies.w)))
        J4, _ = collide.solve(bodies, contacts, order=order, passes=4)
        solver = collide.Solver()
        schedule = collide.Schedule(again, contacts, order=order)
        total = None
        for _ in range(4):
            J, _ = solver.solve(again, contacts, schedule=schedule)
            total = J if total is None else total + J
        np.testing.assert_array_equal(bits(J4), bits(total))
        np.testing.assert_array_equal(bits(bodies.v), bits(again.v))
        np.testing.assert_array_equal(bits(bodies.w), bits(again.w))


def test_reference_replays_the_solve_order():
    bodies, contacts = collide.generate("pile", 12, dtype=np.float32)
    for passes in (1, 4):
        ref = collide.reference_solve(bodies, contacts, order="colour", passes=passes)
        ref_input = collide.reference_solve(bodies, contacts, passes=passes)
        copy = collide.Bodies(*(np.array(a) for a in (bodies.inv_mass, bodies.inv_inertia, bodies.q, bodies.p,
                                                      bodies.v, bodies.w)))
        J, _ = collide.solve(copy, contacts, order="colour", passes=passes)
        assert collide.impulse_error(J, ref).max() <= collide.error_bound_eps
        if passes == 1:
            # Input order is another sequence of the law: far outside the bound.
            assert collide.impulse_error(J, ref_input).max() > collide.error_bound_eps
    # The schedule's own order, given.
    schedule = collide.Schedule(bodies, contacts, order="colour")
    by_schedule = collide.reference_solve(bodies, contacts, schedule=schedule)
    by_name = collide.reference_solve(bodies, contacts, order="colour")
    np.testing.assert_array_equal(by_schedule.J, by_name.J)


def test_one_solver_runs_each_schedule_in_its_order():
    # The schedule owns the order: one Solver gives each order's bits.
    bodies, contacts = collide.generate("pile", 8, dtype=np.float32)
    solver = collide.Solver()
    seen = {}
    for order in ("colour", "input", "colour"):
        copy = collide.Bodies(*(np.array(a) for a in (bodies.inv_mass, bodies.inv_inertia, bodies.q, bodies.p,
                                                      bodies.v, bodies.w)))
        J, stats = solver.solve(copy, contacts, schedule=collide.Schedule(copy, contacts, order=order))
        want, _ = collide.solve(collide.Bodies(*(np.array(a) for a in (bodies.inv_mass, bodies.inv_inertia, bodies.q,
                                                                       bodies.p, bodies.v, bodies.w))),
                                contacts, order=order)
        assert stats["order"] == order
        np.testing.assert_array_equal(bits(J), bits(want))
        seen[order] = J
    assert not np.array_equal(bits(seen["input"]), bits(seen["colour"]))


def test_schedule_describes_its_order():
    bodies, contacts = collide.generate("pile", 10, dtype=np.float64)
    s = collide.Schedule(bodies, contacts, order="colour")
    assert s.order == "colour" and 1 <= s.colours <= 24 and s.overflow_contacts == 0
    order = s.solve_order()
    assert order.dtype == np.uint32 and sorted(order.tolist()) == list(range(len(contacts)))
    assert collide.Schedule(bodies, contacts).order == "input"


def test_mismatched_orders_and_bad_values_are_refused():
    bodies, contacts = collide.generate("pile", 6, dtype=np.float64)
    schedule = collide.Schedule(bodies, contacts)
    with pytest.raises(ValueError, match=r"give order= or schedule=, not both"):
        collide.Solver().solve(bodies, contacts, order="colour", schedule=schedule)
    with pytest.raises(ValueError, match="expected input or colour"):
        collide.solve(bodies, contacts, order="color")
    with pytest.raises(ValueError, match="passes must be an integer from 1 to 1000000, got 0"):
        collide.solve(bodies, contacts, passes=0)
    with pytest.raises(ValueError, match="expected input or colour"):
        collide.Schedule(bodies, contacts, order="random")
