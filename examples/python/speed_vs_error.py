"""Speed against error on 1M pairs, every variant of the solver, as a PNG.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/speed_vs_error.py [--n N] [--out FILE.png]

For float32 and float64, the SIMD and the scalar path, every body model and 1
and 2 threads: the median of three timed solves (stats["kernel_seconds"]) and
the worst and 99th-percentile impulse error against the long double reference
on the same scene (collide.impulse_error, in eps * impulse_scale). One point
per variant: throughput against the worst error relative to the impulse scale
(max_err x eps, so float and double share the axis), and the bound the tests
hold every variant to (error_bound_eps).
"""

import argparse
import statistics

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import collide  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000, help="pairs (default 1M)")
    ap.add_argument("--sample", type=int, default=100_000, help="pairs compared with the reference")
    ap.add_argument("--out", default="speed_vs_error.png")
    args = ap.parse_args()

    fig, ax = plt.subplots(figsize=(8, 5.5))
    markers = {"rigid": "o", "sphere": "s", "particle": "^"}
    colors = {("float32", "simd"): "tab:blue", ("float32", "scalar"): "tab:cyan",
              ("float64", "simd"): "tab:red", ("float64", "scalar"): "tab:orange"}
    simd_isas = set()  # what the SIMD rows ran (the scalar path always runs the baseline, sse2)
    for dtype in (np.float32, np.float64):
        eps = float(np.finfo(dtype).eps)
        for model in ("rigid", "sphere", "particle"):
            bodies, contacts = collide.generate("pairs", args.n, model=model, dtype=dtype)
            # The error on a sample: the first pairs of a pairs scene are the
            # scene of fewer pairs (pair k depends only on seed and k).
            sb, sc = collide.generate("pairs", min(args.sample, args.n), model=model, dtype=dtype)
            ref = collide.reference_solve(sb, sc)
            v0, w0 = bodies.v.copy(), bodies.w.copy()
            schedule = collide.Schedule(bodies, contacts)
            out = np.empty((3, args.n), dtype=dtype)
            for path in ("simd", "scalar"):
                sv, sw = sb.v.copy(), sb.w.copy()
                Js, _ = collide.solve(sb, sc, model=model, path=path)
                np.copyto(sb.v, sv)
                np.copyto(sb.w, sw)
                err = collide.impulse_error(Js, ref)
                for threads in (1, 2):
                    solver = collide.Solver(path=path, threads=threads)
                    seconds = []
                    for _ in range(3):
                        np.copyto(bodies.v, v0)
                        np.copyto(bodies.w, w0)
                        _, stats = solver.solve(bodies, contacts, model=model, schedule=schedule, out=out,
                                                check=False)
                        seconds.append(stats["kernel_seconds"])
                    if path == "simd":
                        simd_isas.add(stats["isa"])
                    speed = args.n / statistics.median(seconds)
                    worst = max(float(err.max()) * eps, eps * 1e-3)  # an exact variant sits at the left edge
                    name = np.dtype(dtype).name
                    print(f"{name} {path:6} {model:8} {threads} thread(s): {speed / 1e6:7.1f} M collisions/s, "
                          f"max error {err.max():6.2f} eps, p99 {np.percentile(err, 99):6.2f} eps")
                    ax.scatter(worst, speed, marker=markers[model], color=colors[(name, path)],
                               s=30 if threads == 1 else 80, edgecolors="black", linewidths=0.5)
    for (name, path), color in colors.items():
        ax.scatter([], [], color=color, label=f"{name} {path}")
    for model, marker in markers.items():
        ax.scatter([], [], marker=marker, color="gray", label=model)
    ax.scatter([], [], color="white", edgecolors="black", s=30, label="1 thread")
    ax.scatter([], [], color="white", edgecolors="black", s=80, label="2 threads")
    for dtype, style in ((np.float32, "--"), (np.float64, ":")):
        ax.axvline(collide.error_bound_eps * float(np.finfo(dtype).eps), color="gray", linestyle=style, linewidth=1)
    ax.set_xscale("log")
    ax.set_xlabel("worst impulse error / impulse scale (max_err_eps x eps); dashed: float bound, dotted: double")
    ax.set_ylabel("collisions per second")
    ax.set_title(f"collide: speed against error, {args.n:,} pairs (SIMD on {', '.join(sorted(simd_isas))})")
    ax.legend(fontsize=8, loc="center")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print("wrote", args.out)


if __name__ == "__main__":
    main()
