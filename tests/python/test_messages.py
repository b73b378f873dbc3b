"""What Python callers are told, in Python's terms: counts with their range
(the tool's range), the order's name, a schedule of another order, counts
that start at 1 as `collide gen`'s do, outputs whose folder is missing,
binary files of two precisions, the reprs of every public type, dir(collide),
and `import collide` where NumPy is missing."""

import os
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import collide


def small_scene(dtype=np.float64):
    return collide.generate("pairs", 10, dtype=dtype)


@pytest.mark.parametrize("value, error", [(2.5, TypeError), ("2", TypeError), (None, TypeError), (0, ValueError),
                                          (-1, ValueError), (2**31, ValueError), (1_000_001, ValueError),
                                          (2**70, ValueError)])
def test_passes_says_its_range(value, error):
    message = rf"^passes must be an integer from 1 to 1000000, got {re.escape(repr(value))}$"
    bodies, contacts = small_scene()
    with pytest.raises(error, match=message):
        collide.Solver(passes=value)
    with pytest.raises(error, match=message):
        collide.solve(bodies, contacts, passes=value)
    with pytest.raises(error, match=message):
        collide.reference_solve(bodies, contacts, passes=value)


def test_passes_above_the_tools_limit_get_the_tools_message(cli, tmp_path):
    # One limit (collide::kMaxPasses), one message: the tool's, in Python's
    # terms (the keyword's name, the value as Python shows it).
    bodies, contacts = small_scene()
    collide.save(str(tmp_path / "b.npz"), str(tmp_path / "c.npz"), bodies, contacts)
    for value in (0, 1_000_001, 10**9):
        r = subprocess.run([cli, "solve", "--bodies", str(tmp_path / "b.npz"), "--contacts", str(tmp_path / "c.npz"),
                            "--out-bodies", str(tmp_path / "out-b.npz"), "--out-impulses", str(tmp_path / "out-j.npz"),
                            "--passes", str(value)], capture_output=True, text=True)
        assert r.returncode == 2
        tool = r.stderr.splitlines()[0]
        assert tool == f"collide solve: --passes must be an integer from 1 to 1000000, got '{value}'", tool
        with pytest.raises(ValueError) as python:
            collide.solve(bodies, contacts, passes=value)
        assert str(python.value) == tool.replace("collide solve: --", "").replace(f"'{value}'", str(value))
    assert collide.solve(bodies, contacts, passes=1_000_000, threads=1)[1]["passes"] == 1_000_000


def test_counts_accept_python_and_numpy_integers():
    assert collide.Solver(passes=np.int64(3), threads=np.int32(1)).passes == 3
    assert collide.Solver(passes=1_000_000).passes == 1_000_000
    with pytest.raises(ValueError, match=r"^threads must be an integer from 0 to 4096, got -1$"):
        collide.Solver(threads=-1)
    with pytest.raises(TypeError, match=r"^threads must be an integer from 0 to 4096, got 1\.5$"):
        collide.Solver(threads=1.5)


@pytest.mark.parametrize("kind, most", [("pairs", 2**31 - 1), ("debris", 2**32 - 1), ("chain", 2**32 - 2)])
@pytest.mark.parametrize("n", [0, -5, 2**40])
def test_generate_counts_start_at_one(kind, most, n):
    # The range of `collide gen --<kind> N`; 0 is refused there too.
    with pytest.raises(ValueError, match=rf"^n must be an integer from 1 to {most}, got {n}$"):
        collide.generate(kind, n)


def test_generate_pile_and_non_integers():
    with pytest.raises(ValueError, match=r"^n \(boxes per side of a pile\) must be an integer from 1 to 1625, got 0$"):
        collide.generate("pile", 0)
    with pytest.raises(TypeError, match=r"^n must be an integer from 1 to 2147483647, got 2\.5$"):
        collide.generate("pairs", 2.5)
    bodies, contacts = collide.generate("pairs", np.uint8(1))
    assert len(contacts) == 1 and len(bodies) == 2


def test_the_cli_refuses_an_empty_scene_too(cli, tmp_path):
    for kind, most in (("pairs", 2**31 - 1), ("pile", 1625), ("chain", 2**32 - 2)):
        r = subprocess.run([cli, "gen", f"--{kind}", "0", "--out", str(tmp_path / kind)], capture_output=True,
                           text=True)
        assert r.returncode == 2
        assert r.stderr == (f"collide gen: --{kind} must be an integer from 1 to {most}, got '0'\n"
                            "see 'collide gen --help'\n")
        assert not (tmp_path / kind).exists()


def test_order_color_is_named():
    bodies, contacts = small_scene()
    message = r"^unknown order 'color' \(expected input or colour\): did you mean 'colour'\?$"
    with pytest.raises(ValueError, match=message):
        collide.solve(bodies, contacts, order="color")
    with pytest.raises(ValueError, match=message):
        collide.Schedule(bodies, contacts, order="color")


def test_an_order_beside_a_schedule_is_explained_in_python():
    # The schedule owns the order: a call takes one or the other.
    bodies, contacts = collide.generate("pile", 4, dtype=np.float64)
    schedule = collide.Schedule(bodies, contacts)
    for call, name in ((lambda **k: collide.Solver().solve(bodies, contacts, **k), "solve"),
                       (lambda **k: collide.solve(bodies, contacts, **k), "solve"),
                       (lambda **k: collide.reference_solve(bodies, contacts, **k), "reference_solve")):
        for order in ("input", "colour"):
            with pytest.raises(ValueError) as e:
                call(order=order, schedule=schedule)
            assert str(e.value) == (f"{name}: give order= or schedule=, not both: a schedule runs in the order it "
                                    "was built in (this one: 'input')")
    with pytest.raises(TypeError, match="order must be 'input', 'colour' or None"):
        collide.solve(bodies, contacts, order=1)


def test_save_creates_the_folder(tmp_path):
    bodies, contacts = small_scene()
    for name in ("b.npz", "b.csv"):
        path = tmp_path / "nodir" / "deeper" / name
        collide.save(path, str(path).replace("b.", "c."), bodies, contacts)
        back, _ = collide.load(path, str(path).replace("b.", "c."))
        assert np.array_equal(back.v, bodies.v)


def test_binary_files_of_two_precisions_need_a_dtype(tmp_path):
    b64, c64 = small_scene(np.float64)
    b32, c32 = small_scene(np.float32)
    collide.save(tmp_path / "b64.npz", tmp_path / "c64.npz", b64, c64)
    collide.save(tmp_path / "b32.npz", tmp_path / "c32.npz", b32, c32)
    with pytest.raises(ValueError, match=r"b64\.npz holds float64 values but .*c32\.npz float32: say which precision "
                                         r"to load the scene in with dtype=numpy\.float32 or dtype=numpy\.float64$"):
        collide.load(tmp_path / "b64.npz", tmp_path / "c32.npz")
    for dtype in (np.float32, np.float64):
        bodies, contacts = collide.load(tmp_path / "b64.npz", tmp_path / "c32.npz", dtype=dtype)
        assert bodies.dtype == dtype and contacts.dtype == dtype
    assert collide.load(tmp_path / "b32.npz", tmp_path / "c32.npz")[0].dtype == np.float32


def test_every_public_type_says_what_it_holds():
    bodies, contacts = collide.generate("pile", 3, dtype=np.float32)
    packed = collide.pack(bodies, "rigid")
    reprs = {
        "PackedBodies": repr(packed),
        "Islands": repr(collide.islands(bodies, contacts)),
        "Reference": repr(collide.reference_solve(bodies, contacts)),
        "Solver": repr(collide.Solver(passes=2, isa="sse2")),
        "Schedule": repr(collide.Schedule(bodies, contacts, order="colour")),
        "ThreadLimit": repr(collide._collide.ThreadLimit(2)),
    }
    for name, text in reprs.items():
        assert " object at 0x" not in text, text
        assert text.startswith(f"collide.{name}("), text
    n, m = len(bodies), len(contacts)
    assert reprs["PackedBodies"] == f"collide.PackedBodies({n} rigid records, float32, 64 bytes each, " \
                                    "inv_mass (N,) beside them)"
    s = collide.islands(bodies, contacts)  # a pile: one island
    assert (s.count, s.largest) == (1, m)
    assert reprs["Islands"] == (f"collide.Islands(1 island of {m} contacts over {n} bodies; the largest, island 0, "
                                f"has {m} contacts)")
    pairs, pair_contacts = collide.generate("pairs", 2)
    assert repr(collide.islands(pairs, pair_contacts)) == ("collide.Islands(2 islands of 2 contacts over 4 bodies; "
                                                           "the largest, island 0, has 1 contact)")
    assert reprs["Reference"] == (f"collide.Reference({m} contacts, {n} bodies, of a float32 scene: J, v, w and "
                                  "impulse_scale in float64)")
    assert reprs["Solver"] == ("collide.Solver(path='simd', threads=0, isa='sse2', accuracy='fast', passes=2, "
                               "iteration='repeat')")
    assert re.fullmatch(rf"collide\.Schedule\({m} contacts, {n} bodies, order 'colour': \d+ batch(es)?, the largest "
                        r"\d+ contacts?, \d+ colours?, \d+ overflow contacts?\)", reprs["Schedule"]), reprs["Schedule"]
    by_input = repr(collide.Schedule(bodies, contacts))
    assert re.fullmatch(rf"collide\.Schedule\({m} contacts, {n} bodies, order 'input': \d+ batch(es)?, the largest "
                        r"\d+ contacts?\)", by_input), by_input
    spheres, _ = collide.generate("pairs", 5, model="sphere", dtype=np.float64)
    assert repr(collide.pack(spheres, "sphere")) == "collide.PackedBodies(10 sphere records, float64, 128 bytes each)"


def test_mapped_file_repr(tmp_path):
    bodies, contacts = small_scene()
    collide.save(tmp_path / "b.npz", tmp_path / "c.npz", bodies, contacts)
    loaded, _ = collide.load(tmp_path / "b.npz", tmp_path / "c.npz")
    mapped = loaded.p.base  # q and p stay in the mapping: views whose base is the file
    assert isinstance(mapped, collide.MappedFile)
    assert repr(mapped) == f"collide.MappedFile({str(tmp_path / 'b.npz')!r}, {mapped.size} bytes)"


def test_dir_lists_the_api():
    names = dir(collide)
    assert names == sorted(set(collide.__all__) | {"__version__"})
    for name in ("annotations", "_np", "_collide", "_os", "_sys"):
        assert name not in names
    for name in names:
        assert hasattr(collide, name), name


def run_without_numpy(python, path):
    """`import collide` in a fresh `python`, NumPy hidden (sys.modules['numpy']
    = None makes `import numpy` raise ImportError), the collide of this build
    on sys.path."""
    program = textwrap.dedent("""
        import sys
        sys.modules["numpy"] = None
        try:
            import collide
        except ImportError as e:
            print(e)
        else:
            print("imported")
    """)
    env = dict(os.environ, PYTHONPATH=path)
    return subprocess.run([python, "-c", program], capture_output=True, text=True, env=env, timeout=60)


def test_import_without_numpy_names_the_interpreter():
    from collide import _build

    package_dir = os.path.dirname(os.path.dirname(os.path.abspath(collide.__file__)))
    r = run_without_numpy(sys.executable, package_dir)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(f"collide needs NumPy: this module was built for {_build.PYTHON}"), r.stdout
    assert os.path.realpath(_build.PYTHON) == os.path.realpath(sys.executable), "this suite runs the build's Python"
    assert "install it (Debian: python3-numpy; pip: numpy)" in r.stdout, r.stdout


def other_python_without_numpy():
    """Another python3 of this machine that has no NumPy (a pyenv one first on
    PATH, say), or None."""
    seen = {os.path.realpath(sys.executable)}
    for d in os.environ.get("PATH", "").split(os.pathsep):
        candidate = os.path.join(d, "python3")
        if not os.path.isfile(candidate) or os.path.realpath(candidate) in seen:
            continue
        seen.add(os.path.realpath(candidate))
        probe = subprocess.run([candidate, "-c", "import numpy"], capture_output=True, timeout=60)
        if probe.returncode != 0:
            return candidate
    return None


def test_import_under_another_interpreter_names_the_build_s():
    from collide import _build

    python = other_python_without_numpy()
    if python is None:
        pytest.skip("no other python3 without NumPy on PATH")
    package_dir = os.path.dirname(os.path.dirname(os.path.abspath(collide.__file__)))
    r = subprocess.run([python, "-c", "import collide"], capture_output=True, text=True, timeout=60,
                       env=dict(os.environ, PYTHONPATH=package_dir))
    assert r.returncode != 0
    last = r.stderr.strip().splitlines()[-1]
    assert last.startswith(f"ImportError: collide needs NumPy: this module was built for {_build.PYTHON} "
                           f"(Python {_build.PYTHON_VERSION}), and this is "), last
    assert f"run it with {_build.PYTHON}" in last, last
