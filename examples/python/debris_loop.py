"""A small debris loop in NumPy: contacts found each frame, resolved by collide.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/debris_loop.py

Spheres of radius r fall onto a ground plane (an immovable body) in a box. Each
frame: gravity and positions are integrated in NumPy, contacts are found by
brute force (sphere-sphere pairs closer than 2r and approaching, sphere-ground
below r), collide.solve resolves them in place on the same arrays, and the
kinetic energy is printed; restitution 0.5 (contacts and walls) makes it fall
once the spheres have landed.
The bodies' arrays are allocated once; solve writes v and w into them.
"""

import numpy as np

import collide

RNG = np.random.default_rng(3)
N, R, DT, FRAMES, BOX = 300, 0.05, 1 / 120, 240, 0.6


def main():
    n = N + 1  # the last body is the ground: inverse mass 0
    inv_mass = np.full(n, 1.0)
    inv_mass[-1] = 0.0
    moment = 0.4 * R * R  # solid sphere of unit mass
    inv_inertia = np.full((3, n), 1.0 / moment)
    inv_inertia[:, -1] = 0.0
    q = np.zeros((4, n))
    q[0] = 1.0
    p = np.zeros((3, n))
    p[0, :N] = RNG.uniform(-BOX, BOX, N)
    p[1, :N] = RNG.uniform(-BOX, BOX, N)
    p[2, :N] = RNG.uniform(R, 1.0, N)
    v = np.zeros((3, n))
    v[:, :N] = RNG.normal(0.0, 0.3, (3, N))
    w = np.zeros((3, n))
    bodies = collide.Bodies(inv_mass, inv_inertia, q, p, v, w)
    solver = collide.Solver(threads=1)

    for frame in range(FRAMES):
        v[2, :N] -= 9.81 * DT
        p[:, :N] += v[:, :N] * DT
        # The box walls: a sphere past one comes back in, bouncing with e = 0.5.
        out = np.abs(p[0:2, :N]) > BOX
        v[0:2, :N][out & (p[0:2, :N] * v[0:2, :N] > 0)] *= -0.5
        np.clip(p[0:2, :N], -BOX, BOX, out=p[0:2, :N])

        # Sphere pairs in contact and approaching.
        d = p[:, :N, None] - p[:, None, :N]
        dist = np.sqrt((d * d).sum(axis=0))
        ia, ib = np.nonzero(np.triu(dist < 2 * R, k=1))
        normal = d[:, ia, ib] / np.maximum(dist[ia, ib], 1e-12)
        closing = ((v[:, ia] - v[:, ib]) * normal).sum(axis=0) < 0
        ia, ib, normal = ia[closing], ib[closing], normal[:, closing]
        # Spheres on the ground, moving down.
        g = np.nonzero((p[2, :N] < R) & (v[2, :N] < 0))[0]
        p[2, g] = R

        a = np.concatenate([ia, g]).astype(np.uint32)
        b = np.concatenate([ib, np.full(len(g), N)]).astype(np.uint32)
        n_ = np.ascontiguousarray(np.concatenate([normal, np.tile([[0.0], [0.0], [1.0]], len(g))], axis=1))
        c = np.ascontiguousarray(np.concatenate([0.5 * (p[:, ia] + p[:, ib]), p[:, g] - [[0], [0], [R]]], axis=1))
        if len(a):
            contacts = collide.Contacts(a, b, c, n_, uniform_e=0.5)
            J, stats = solver.solve(bodies, contacts)
        energy = 0.5 * (v[:, :N] ** 2).sum() + 0.5 * moment * (w[:, :N] ** 2).sum()
        if frame % 30 == 0 or frame == FRAMES - 1:
            print(f"frame {frame:3d}: {len(a):4d} contacts, kinetic energy {energy:8.4f} J, "
                  f"lowest sphere at z = {p[2, :N].min():.3f} m")
    assert np.all(np.isfinite(v)) and p[2, :N].min() >= R - 1e-9


if __name__ == "__main__":
    main()
