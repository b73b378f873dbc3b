"""collide.islands and collide.conservation_drift: the library's islands and
conservation figures on NumPy arrays."""

import numpy as np
import pytest

import collide


def topology(n, edges, immovable=(), dtype=np.float64):
    """A scene of n unit bodies (immovable where listed) and contacts `edges`;
    only the topology matters to islands."""
    inv_mass = np.ones(n, dtype)
    inv_mass[list(immovable)] = 0
    q = np.zeros((4, n), dtype)
    q[0] = 1
    bodies = collide.Bodies(inv_mass, np.ones((3, n), dtype), q, np.zeros((3, n), dtype), np.zeros((3, n), dtype),
                            np.zeros((3, n), dtype))
    m = len(edges)
    a = np.array([e[0] for e in edges], np.uint32)
    b = np.array([e[1] for e in edges], np.uint32)
    normal = np.zeros((3, m), dtype)
    normal[2] = 1
    return bodies, collide.Contacts(a, b, np.zeros((3, m), dtype), normal)


def test_hand_made_islands():
    bodies, contacts = topology(7, [(3, 4), (0, 1), (1, 2), (4, 3), (0, 5), (5, 6)], immovable=[5, 6])
    s = collide.islands(bodies, contacts)
    assert isinstance(s, collide.Islands)
    # Contact 4 reaches body 0 (its other body is immovable); contact 5 joins two immovable bodies.
    np.testing.assert_array_equal(s.labels, [0, 1, 1, 0, 1, 2])
    np.testing.assert_array_equal(s.sizes, [2, 3, 1])
    none = collide.Islands.NONE
    np.testing.assert_array_equal(s.body_labels, [1, 1, 1, 0, 0, none, none])
    assert (s.count, len(s), s.largest, s.largest_label) == (3, 3, 3, 1)
    for array in (s.labels, s.body_labels, s.sizes):
        assert array.dtype == np.uint32 and not array.flags.writeable


def test_labels_and_sizes_agree_and_threads_do_not_matter():
    bodies, contacts = collide.generate("pairs", 100_000, dtype=np.float32)
    s = collide.islands(bodies, contacts, threads=1)
    assert s.count == 100_000 and s.largest == 1
    np.testing.assert_array_equal(s.labels, np.arange(100_000))
    bodies, contacts = collide.generate("pile", 12, dtype=np.float64)
    one = collide.islands(bodies, contacts, threads=1)
    two = collide.islands(bodies, contacts, threads=2)
    for name in ("labels", "body_labels", "sizes"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name))
    np.testing.assert_array_equal(np.bincount(one.labels, minlength=one.count), one.sizes)
    assert one.sizes.sum() == len(contacts) and one.largest == one.sizes.max()
    # The pile stands on an immovable ground, which belongs to no island.
    assert np.all(one.body_labels[bodies.inv_mass == 0] == collide.Islands.NONE)


def test_packed_records_give_the_same_islands():
    bodies, contacts = collide.generate("debris", 5000, dtype=np.float32)
    soa = collide.islands(bodies, contacts)
    for model in ("rigid", "sphere"):
        b = collide.generate("debris", 5000, model=model, dtype=np.float32)[0]
        packed = collide.pack(b, model)
        np.testing.assert_array_equal(collide.islands(packed, contacts).labels, soa.labels)


def test_bad_indices_are_refused():
    bodies, contacts = topology(3, [(0, 1), (1, 2)])
    contacts.b[1] = 3
    with pytest.raises(ValueError, match=r"collide::islands: contacts\.b\[1\] = 3: out of range \(3 bodies\)"):
        collide.islands(bodies, contacts)
    with pytest.raises(ValueError, match="threads must be >= 0"):
        collide.islands(*topology(3, [(0, 1)]), threads=-1)
    b32, _ = topology(3, [(0, 1)], dtype=np.float32)
    with pytest.raises(TypeError, match="one precision"):
        collide.islands(b32, topology(3, [(0, 1)])[1])


def test_conservation_drift():
    bodies, contacts = collide.generate("debris", 20_000, friction=True, dtype=np.float64)
    ref = collide.reference_solve(bodies, contacts)
    collide.solve(bodies, contacts)
    drift = collide.conservation_drift(bodies, ref)
    assert set(drift) == {"momentum_drift", "angular_momentum_drift", "energy_drift"}
    assert 0 <= drift["momentum_drift"] < 1e-12 and 0 <= drift["angular_momentum_drift"] < 1e-12
    # A body pushed off the law's result is seen.
    bodies.v[0, np.flatnonzero(bodies.inv_mass)[0]] += 1.0
    assert collide.conservation_drift(bodies, ref)["momentum_drift"] > 1e-6
    with pytest.raises(ValueError, match="conservation_drift"):
        collide.conservation_drift(collide.generate("pairs", 10)[0], ref)
