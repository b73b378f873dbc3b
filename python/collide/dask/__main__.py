"""python -m collide.dask (and the collide-dask command): one scene split
across Dask workers, or many scenes solved and measured.

    python -m collide.dask solve BODIES.npz CONTACTS.npz --out-dir DIR [--iteration accumulate --warm-start J] [options]
    python -m collide.dask scenes SPEC.json | B1.npz C1.npz [B2.npz C2.npz ...] [--out TABLE.csv] [options]

Every subcommand takes ``--scheduler ADDRESS`` (a running Dask scheduler)
or ``--workers N`` (a LocalCluster of N single-threaded processes started
for the run; all cores by default). ``solve`` writes J.npy, v.npy and w.npy
into DIR and prints the stats as one JSON line; ``scenes`` writes the table
as CSV (to stdout without --out). A spec file is a JSON list of scenes, each
the parameters of collide.generate ({"kind": "pairs", "n": 10000, "seed": 3})
or a file pair ({"bodies": "b.npz", "contacts": "c.npz"}, paths relative to
the JSON file), either with an optional warm start ("warm": "j.npz", with
--iteration accumulate). ``solve --warm-start FILE`` starts the accumulated
passes from an impulses file (.npz with jx, jy, jz, as ``collide solve
--out-impulses`` writes it, or a (3, M) .npy such as a J.npy of DIR), as
``collide solve --warm-start`` does. Progress goes to stderr:
dask.distributed.progress on a terminal, a line per finished task
otherwise.

Exit codes: 0 done; 1 bad input or a failed run (the message names the file,
entry or array); 2 a bad command line.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import warnings

import numpy as np


def _parser():
    common = argparse.ArgumentParser(add_help=False)
    where = common.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler (tcp://host:8786)")
    where.add_argument("--workers", metavar="N", type=int,
                       help="start a LocalCluster of N single-threaded worker processes (default: all cores)")
    common.add_argument("--model", default="auto", choices=("auto", "rigid", "sphere", "particle"))
    common.add_argument("--accuracy", default="fast", choices=("fast", "accurate"))
    common.add_argument("--order", default="input", choices=("input", "colour"),
                        help="the solve order, as collide.solve's order= (default input)")
    common.add_argument("--passes", type=int, default=1, help="passes over the contacts in that order (default 1)")
    common.add_argument("--iteration", default="repeat", choices=("repeat", "accumulate"),
                        help="what the passes after the first do, as collide.solve's iteration= (default repeat)")
    common.add_argument("--threads", type=int, default=1, help="solver threads per task (default 1)")
    common.add_argument("--isa", default=None, choices=("sse2", "avx2", "avx512"))
    common.add_argument("--no-progress", action="store_true", help="no progress on stderr")

    parser = argparse.ArgumentParser(prog="python -m collide.dask",
                                     description="collide on Dask workers: one scene by its islands, or many scenes.")
    sub = parser.add_subparsers(dest="command", required=True)
    solve = sub.add_parser("solve", parents=[common], help="solve one binary scene file pair across the workers")
    solve.add_argument("bodies", help="bodies .npz")
    solve.add_argument("contacts", help="contacts .npz")
    solve.add_argument("--out-dir", required=True, help="where J.npy, v.npy and w.npy are written")
    solve.add_argument("--partitions", type=int, default=None, help="default: the cluster's threads")
    solve.add_argument("--precision", choices=("float", "double"), default=None,
                       help="default: the file's own precision")
    solve.add_argument("--warm-start", metavar="FILE", default=None,
                       help="start the accumulated passes from the impulses in FILE (.npz with jx, jy, jz, as "
                            "collide solve --out-impulses writes it, or a (3, M) .npy such as a J.npy of --out-dir: "
                            "the previous frame's J of the same contacts); needs --iteration accumulate")
    scenes = sub.add_parser("scenes", parents=[common], help="solve and measure many scenes, one task each")
    scenes.add_argument("inputs", nargs="+", metavar="SPEC.json | BODIES.npz CONTACTS.npz",
                        help="a JSON spec file, or scene file pairs")
    scenes.add_argument("--out", default=None, help="the table as CSV (default: stdout)")
    scenes.add_argument("--sample", type=int, default=10_000, help="contacts compared with the reference per scene")
    parser.subcommands = {"solve": solve, "scenes": scenes}  # for the usage errors found after parsing
    return parser


def _scene_entries(inputs):
    """The entries of the scenes subcommand, a spec file's or file pairs,
    and their warm starts (None without any): a spec entry's "warm", a path
    relative to the JSON file that lists it, taken out of the entry."""
    if len(inputs) == 1 and inputs[0].endswith(".json"):
        path = inputs[0]
        with open(path, encoding="utf-8") as f:
            try:
                spec = json.load(f)
            except json.JSONDecodeError as e:
                raise ValueError(f"{path}: not valid JSON: {e}") from e
        if not isinstance(spec, list):
            raise ValueError(f"{path}: a spec file is a JSON list of scenes, got {type(spec).__name__}")
        base = os.path.dirname(os.path.abspath(path))
        entries, warm = [], []
        for i, item in enumerate(spec):
            if not isinstance(item, dict):
                raise ValueError(f"{path}: scene {i}: an object, got {json.dumps(item)}")
            item = dict(item)
            start = item.pop("warm", None)
            if start is not None and not isinstance(start, str):
                raise ValueError(f"{path}: scene {i}: \"warm\" is the path of an impulses file, got "
                                 f"{json.dumps(start)}")
            warm.append(None if start is None else os.path.join(base, start))
            if "bodies" in item:
                item.update({k: os.path.join(base, item[k]) for k in ("bodies", "contacts") if k in item})
            entries.append(item)
        return entries, warm if any(w is not None for w in warm) else None
    if len(inputs) % 2 or not all(p.endswith(".npz") for p in inputs):
        raise ValueError("scenes takes one spec file (.json) or pairs of binary scene files (BODIES.npz "
                         f"CONTACTS.npz ...), got {' '.join(inputs)}")
    return [(inputs[i], inputs[i + 1]) for i in range(0, len(inputs), 2)], None


def _write_atomically(path, text):
    directory = os.path.dirname(os.path.abspath(path))
    os.makedirs(directory, exist_ok=True)  # as every writer of collide creates a missing directory
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=".collide-dask-")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def _solve_options(args):
    """The options both subcommands pass on as collide.solve's keywords."""
    return {k: getattr(args, k) for k in ("model", "accuracy", "order", "passes", "iteration", "threads", "isa")}


def _show_warning(message, category, filename, lineno, file=None, line=None):
    print(f"collide-dask: warning: {message}", file=sys.stderr)


def main(argv=None):
    parser = _parser()
    args = parser.parse_args(argv)
    if args.command == "solve" and args.warm_start is not None and args.iteration != "accumulate":
        # `collide solve`'s usage error, as argparse reports one (exit 2).
        parser.subcommands["solve"].error("--warm-start needs --iteration accumulate (the repeat mode's passes add "
                                          "impulses and cannot start from a J)")
    warnings.showwarning = _show_warning
    try:
        import collide.dask as cd

        client = args.scheduler
        workers = args.workers
        if workers is not None and workers < 1:
            raise ValueError(f"--workers must be >= 1, got {workers}")
        progress = not args.no_progress
        if args.command == "solve":
            dtype = {"float": np.float32, "double": np.float64, None: None}[args.precision]
            solution = cd.solve((args.bodies, args.contacts), client, partitions=args.partitions, dtype=dtype,
                                warm=args.warm_start, out_dir=args.out_dir, workers=workers, progress=progress,
                                **_solve_options(args))
            print(json.dumps(solution.stats))
        else:
            entries, warm = _scene_entries(args.inputs)
            if warm is not None and args.iteration != "accumulate":
                first = next(i for i, w in enumerate(warm) if w is not None)
                raise ValueError(f"{args.inputs[0]}: scene {first} has a warm start, which needs --iteration "
                                 "accumulate (the repeat mode's passes add impulses and cannot start from a J)")
            table = cd.solve_scenes(entries, client, warm=warm, sample=args.sample, workers=workers,
                                    progress=progress, **_solve_options(args))
            csv = table.to_csv(index=False)
            if args.out:
                _write_atomically(args.out, csv)
            else:
                sys.stdout.write(csv)
    except (ValueError, TypeError, OSError, ImportError, RuntimeError) as e:
        print(f"collide-dask: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
