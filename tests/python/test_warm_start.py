"""The warm start (warm=) of collide.solve, collide.Solver and
collide.reference_solve, against `collide solve --warm-start`."""

import json
import os
import subprocess

import numpy as np
import pytest

import collide
from conftest import run
from test_solve import read_impulses


def next_pass_share(bodies, contacts, J, order):
    """The next-pass measure: one more one-pass solve on a copy of the solved
    bodies, its largest |J| over the solve's largest |J|."""
    again = collide.Bodies(bodies.inv_mass.copy(), bodies.inv_inertia.copy(), bodies.q.copy(), bodies.p.copy(),
                           bodies.v.copy(), bodies.w.copy())
    more, _ = collide.solve(again, contacts, order=order)
    return float(np.linalg.norm(more, axis=0).max() / np.linalg.norm(J, axis=0).max())


def test_warm_start_as_the_tool_runs_it(cli, workdir):
    # `collide solve --warm-start` and collide.solve(warm=) give the same
    # bytes and residual from the same J, CSV or binary, and --check holds.
    run([cli, "gen", "--pile", "9", "--friction", "--out", workdir, "--seed", "3"])
    b_csv, c_csv = os.path.join(workdir, "bodies.csv"), os.path.join(workdir, "contacts.csv")
    ob, j0 = os.path.join(workdir, "ob.csv"), os.path.join(workdir, "j0.csv")
    common = ["--bodies", b_csv, "--contacts", c_csv, "--out-bodies", ob, "--precision", "double", "--order",
              "colour", "--iteration", "accumulate"]
    run([cli, "solve", *common, "--out-impulses", j0, "--passes", "8"])
    j0_npz = os.path.join(workdir, "j0.npz")
    run([cli, "convert", "--in", j0, "--out", j0_npz])
    bodies, contacts = collide.read_scene(b_csv, c_csv, dtype=np.float64)
    warm = read_impulses(j0, np.float64)
    J, stats = collide.solve(bodies, contacts, order="colour", passes=2, iteration="accumulate", warm=warm)
    for start in (j0, j0_npz):
        oj = os.path.join(workdir, "j.csv")
        r = run([cli, "solve", *common, "--out-impulses", oj, "--passes", "2", "--warm-start", start, "--stats",
                 "--check"])
        cli_stats = json.loads(r.stderr.strip().splitlines()[-1])
        np.testing.assert_array_equal(J.view(np.uint64), read_impulses(oj, np.float64).view(np.uint64))
        assert cli_stats["check_passed"]
        assert cli_stats["residual"] == pytest.approx(stats["residual"], rel=1e-9)
    # The warm start is what the passes start from: far closer than cold.
    cold, _ = collide.read_scene(b_csv, c_csv, dtype=np.float64)
    _, cold_stats = collide.solve(cold, contacts, order="colour", passes=2, iteration="accumulate")
    assert stats["residual"] < cold_stats["residual"]


def test_the_tool_refuses_a_bad_warm_start(cli, workdir):
    run([cli, "gen", "--debris", "300", "--friction", "--out", workdir, "--seed", "3"])
    b_csv, c_csv = os.path.join(workdir, "bodies.csv"), os.path.join(workdir, "contacts.csv")
    ob, oj = os.path.join(workdir, "ob.csv"), os.path.join(workdir, "oj.csv")
    _, contacts = collide.read_scene(b_csv, c_csv, dtype=np.float64)
    m = len(contacts)

    def solve(warm, *extra):
        path = os.path.join(workdir, "warm.csv")
        with open(path, "w") as f:
            f.write("jx,jy,jz\n" + "".join(f"{x!r},{y!r},{z!r}\n" for x, y, z in warm.T))
        return subprocess.run([cli, "solve", "--bodies", b_csv, "--contacts", c_csv, "--out-bodies", ob,
                               "--out-impulses", oj, "--warm-start", path, *extra], capture_output=True, text=True)

    good = contacts.n.astype(np.float64)
    short = solve(good[:, :-1], "--iteration", "accumulate")
    assert short.returncode == 1
    assert f"--warm-start holds {m - 1} impulses but {c_csv} holds {m} contacts" in short.stderr
    pulls = good.copy()
    pulls[:, 17] *= -1
    r = solve(pulls, "--iteration", "accumulate")
    assert r.returncode == 1
    assert "warm.csv: the J of contact 17 (" in r.stderr
    assert "points against the normal (J . n = " in r.stderr and "): a normal impulse never pulls" in r.stderr
    nan = good.copy()
    nan[1, 40] = np.nan
    r = solve(nan, "--iteration", "accumulate")
    assert r.returncode == 1 and "the J of contact 40 (" in r.stderr and "is not finite" in r.stderr
    r = solve(good)
    assert r.returncode == 2 and "--warm-start needs --iteration accumulate" in r.stderr
    assert not os.path.exists(ob) and not os.path.exists(oj)
    assert solve(good, "--iteration", "accumulate").returncode == 0


@pytest.mark.parametrize("order", ["input", "colour"])
@pytest.mark.parametrize("passes", [1, 4])
@pytest.mark.parametrize("friction", [False, True])
def test_error_bound_holds_from_a_warm_start_and_can_fail(order, passes, friction):
    # The warm start: J of 8 passes of an earlier solve of the same input.
    earlier, contacts = collide.generate("pile", 12, friction=friction, seed=7)
    start, _ = collide.solve(earlier, contacts, order=order, passes=8, iteration="accumulate")
    bodies, _ = collide.generate("pile", 12, friction=friction, seed=7)
    ref = collide.reference_solve(bodies, contacts, order=order, passes=passes, iteration="accumulate", warm=start)
    J, stats = collide.solve(bodies, contacts, order=order, passes=passes, iteration="accumulate", warm=start)
    assert 0 < stats["residual"] < 1
    assert collide.impulse_error(J, ref).max() <= collide.error_bound_eps
    assert collide.impulse_error(J * np.float32(1.01), ref).max() > collide.error_bound_eps
    assert collide.impulse_error(np.zeros_like(J), ref).max() > collide.error_bound_eps


def test_a_warm_pile_converges_in_two_passes():
    # The pile at rest after the frame before, then one step of gravity
    # (every box falling at g dt): cold, its next pass still moves J by a
    # lot; warm-started from the frame before's converged J, two passes
    # leave it within 1%.
    bodies, contacts = collide.generate("pile", 8, seed=7)
    fall = np.float32(9.81 / 60)
    movable = bodies.inv_mass > 0

    def rested():
        b = collide.generate("pile", 8, seed=7)[0]
        b.v[:, :] = 0
        b.w[:, :] = 0
        b.v[2, movable] = -fall
        return b

    converged, _ = collide.solve(rested(), contacts, order="colour", passes=400, iteration="accumulate")
    frame = rested()
    J, stats = collide.solve(frame, contacts, order="colour", passes=2, iteration="accumulate", warm=converged)
    assert stats["residual"] <= 0.01
    assert next_pass_share(frame, contacts, J, "colour") <= 0.01
    cold = rested()
    _, cold_stats = collide.solve(cold, contacts, order="colour", passes=2, iteration="accumulate")
    assert cold_stats["residual"] > 0.05


def test_warm_is_checked_and_speaks_its_own_terms():
    bodies, contacts = collide.generate("debris", 500, friction=True, seed=3)
    m = len(contacts)
    good = contacts.n.copy()
    with pytest.raises(ValueError, match="a warm start needs iteration='accumulate'"):
        collide.solve(bodies, contacts, warm=good)
    with pytest.raises(ValueError, match="a warm start needs iteration='accumulate'"):
        collide.reference_solve(bodies, contacts, warm=good)
    solver = collide.Solver(iteration="accumulate", warm_start=True)
    assert solver.warm_start and repr(solver).endswith("iteration='accumulate', warm_start=True)")
    with pytest.raises(ValueError, match="built with warm_start=True and takes warm="):
        solver.solve(bodies, contacts)
    with pytest.raises(ValueError, match="warm= needs a Solver built with warm_start=True"):
        collide.Solver(iteration="accumulate").solve(bodies, contacts, warm=good)
    v0 = bodies.v.copy()
    bad = good.copy()
    bad[:, 17] *= -1
    bad[:, 300] *= -1
    with pytest.raises(ValueError, match=r"solve: warm\[:, 17\] = \(.*\) points against the normal \(J \. n = "):
        collide.solve(bodies, contacts, iteration="accumulate", warm=bad)
    bad[2, 5] = np.inf
    with pytest.raises(ValueError, match=r"solve: warm\[:, 5\] = \(.*\) is not finite"):
        collide.solve(bodies, contacts, iteration="accumulate", warm=bad)
    # Without the value checks, the Solver refuses it in its own terms.
    with pytest.raises(ValueError, match=r"warm start impulses\.j\[5\] = \(.*\) is not finite"):
        collide.solve(bodies, contacts, iteration="accumulate", warm=bad, check=False)
    with pytest.raises(ValueError, match=f"solve.warm has {m - 1} elements, contacts.a has {m}"):
        collide.solve(bodies, contacts, iteration="accumulate", warm=good[:, 1:])
    with pytest.raises((TypeError, ValueError), match="warm"):
        collide.solve(bodies, contacts, iteration="accumulate", warm=good.astype(np.float64))
    assert np.array_equal(bodies.v, v0)
    # warm may be out itself (the frame loop's J, in place), not a part of
    # an array the solve writes.
    J = good.copy()
    out, _ = collide.solve(bodies, contacts, iteration="accumulate", warm=J, out=J)
    assert out is J
    view = J[:, :]
    with pytest.raises(ValueError, match="share memory"):
        collide.solve(bodies, contacts, iteration="accumulate", warm=view, out=J)
