"""Figures of the scene files (docs/decisions/0002-binary-scene-files.md,
docs/cli.md): what reading
and writing a scene costs in the binary format, against CSV, against `cat`
of the same bytes, and collide.load from Python.

In a temporary directory, a pairs scene of --n contacts (4M by default,
float) is generated as binary files (`collide gen --format npz`) and
converted to CSV (`collide convert`). Then, --runs times, alternated:

  * `collide solve --stats` of the binary scene into binary outputs, and of
    the CSV scene into CSV outputs (the CSV side --csv-runs times only: it
    takes seconds), each after removing the previous outputs and `sync`, so
    that every run writes new files and pays for nothing earlier;
  * `cat` of the binary run's four files (inputs and outputs) to /dev/null,
    page cache warm, and of its two inputs alone; and `cat` of its two
    outputs into a new file: what writing those bytes into new page-cache
    pages costs on the machine that runs it, whoever writes them. collide's read and
    write are compared with both: cat of all four files to /dev/null, and
    cat moving the same bytes the way the solve does (the inputs read, the
    outputs written into new files);
and then --loads calls of `collide.load` of the binary scene in a row in this
process, checking that the arrays it returns are views of the files'
mappings, not copies.

Prints the best and median of each, the ratios of
docs/decisions/0027-writing-the-binary-scene-files.md (binary I/O against
CSV I/O and against cat, io_fraction, collide.load), and checks that
binary -> CSV -> binary gives the same bytes. Exit 1 if the round trip or
the views check fails. Runs vary: a virtual machine that hands memory back
to its host makes a run that writes into new pages cost two to five times a
quiet one; compare the best runs.

    PYTHONPATH=build/python /usr/bin/python3 scripts/io_bench.py [--collide build/collide]
    PYTHONPATH=build/python /usr/bin/python3 scripts/io_bench.py --n 100000 --runs 2   # a smoke run
"""

import argparse
import filecmp
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import collide


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({r.returncode}):\n{r.stderr}")
    return r


def solve(collide_bin, d, fmt, threads):
    """`collide solve --stats` of d's scene in format fmt into new outputs."""
    outs = [os.path.join(d, f"out_{k}.{fmt}") for k in ("bodies", "impulses")]
    for path in outs:
        if os.path.exists(path):
            os.remove(path)
    os.sync()
    r = run([collide_bin, "solve", "--bodies", os.path.join(d, f"bodies.{fmt}"), "--contacts",
             os.path.join(d, f"contacts.{fmt}"), "--out-bodies", outs[0], "--out-impulses", outs[1], "--stats",
             "--threads", str(threads), "--precision", "float"])
    line = [x for x in r.stderr.splitlines() if x.startswith("{")][-1]
    return json.loads(line), outs


def timed_cat(paths):
    t = time.perf_counter()
    subprocess.run(["cat", *paths], stdout=subprocess.DEVNULL, check=True)
    return time.perf_counter() - t


def is_view_of_file(a):
    """True when a's memory is a file's mapping: its base a
    collide.MappedFile (collide.load of a binary file)."""
    base = a
    while getattr(base, "base", None) is not None:
        base = base.base
        if isinstance(base, collide.MappedFile):
            return True
    return False


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--collide", default="build/collide", help="the collide binary (default build/collide)")
    p.add_argument("--n", type=int, default=4 * 1024 * 1024, help="pairs of the scene (default 4Mi)")
    p.add_argument("--runs", type=int, default=5, help="runs of the binary side (default 5)")
    p.add_argument("--csv-runs", type=int, default=2, help="runs of the CSV side (default 2)")
    p.add_argument("--loads", type=int, default=7, help="collide.load calls in a row (default 7)")
    p.add_argument("--threads", type=int, default=0, help="collide solve --threads (default 0: all)")
    p.add_argument("--tmp", default=None, help="directory for the scene files (default: a new one in $TMPDIR)")
    args = p.parse_args()
    collide_bin = os.path.abspath(args.collide)
    tmp = tempfile.mkdtemp(prefix="collide-io-bench-", dir=args.tmp)
    ok = True
    try:
        t = time.perf_counter()
        run([collide_bin, "gen", "--pairs", str(args.n), "--out", tmp, "--format", "npz", "--precision", "float"])
        for table in ("bodies", "contacts"):
            run([collide_bin, "convert", "--in", os.path.join(tmp, f"{table}.npz"), "--out",
                 os.path.join(tmp, f"{table}.csv")])
        print(f"{args.n:,} pairs, float, written as .npz and .csv in {time.perf_counter() - t:.1f} s", flush=True)

        npz, csv, cat, cat_read, cat_write, load = [], [], [], [], [], []
        for r in range(args.runs):
            stats, outs = solve(collide_bin, tmp, "npz", args.threads)
            npz.append(stats)
            inputs = [os.path.join(tmp, "bodies.npz"), os.path.join(tmp, "contacts.npz")]
            cat.append(timed_cat([*inputs, *outs]))
            cat_read.append(timed_cat(inputs))
            copy = os.path.join(tmp, "copy")
            os.sync()
            t = time.perf_counter()
            with open(copy, "wb") as f:
                subprocess.run(["cat", *outs], stdout=f, check=True)
            cat_write.append(time.perf_counter() - t)
            os.remove(copy)
            if r < args.csv_runs:
                csv.append(solve(collide_bin, tmp, "csv", args.threads)[0])
        # collide.load warm: the files in the page cache, and loads in a row,
        # so that each reuses the memory the one before freed.
        for _ in range(args.loads):
            t = time.perf_counter()
            bodies, contacts = collide.load(os.path.join(tmp, "bodies.npz"), os.path.join(tmp, "contacts.npz"))
            load.append(time.perf_counter() - t)
            views = all(is_view_of_file(x) for x in (bodies.q, bodies.p, contacts.c, contacts.n))
            if not views:
                print("collide.load: q, p, c, n are not views of the file mappings", file=sys.stderr)
                ok = False
            del bodies, contacts

        def io(s):
            return s["read_seconds"] + s["write_seconds"]

        def row(name, xs, unit="s", scale=1.0):
            print(f"  {name:44s} best {min(xs) * scale:8.3f} {unit}   median {statistics.median(xs) * scale:8.3f} {unit}"
                  f"   ({', '.join(f'{x * scale:.3f}' for x in xs)})")

        print(f"\n{platform.processor() or platform.machine()}, {os.cpu_count()} hardware threads; "
              f"`collide solve --stats` (read_seconds + write_seconds):")
        row("binary read", [s["read_seconds"] for s in npz])
        row("binary write", [s["write_seconds"] for s in npz])
        row("binary read + write", [io(s) for s in npz])
        row("binary io_fraction", [s["io_fraction"] for s in npz], unit="")
        row("CSV read + write", [io(s) for s in csv])
        row("cat of the four binary files to /dev/null", cat)
        row("cat of the two inputs to /dev/null", cat_read)
        row("cat of the two outputs into a new file", cat_write)
        row("collide.load (Python, views of the mapping)", load, unit="ms", scale=1000)
        best_npz = min(io(s) for s in npz)
        # In brackets: the values decisions 0024 and 0027 measure against.
        print("\nratios of the best runs (in brackets: the values of docs/decisions/0024 and 0027):")
        print(f"  CSV I/O / binary I/O      {min(io(s) for s in csv) / best_npz:6.1f}x   [>= 30x]")
        print(f"  binary I/O / cat          {best_npz / min(cat):6.2f}x   [<= 3x]  (writing the outputs' bytes into a new "
              f"file alone, by cat: {min(cat_write) / min(cat):.2f}x)")
        print(f"  binary I/O / cat moving the same bytes (inputs read to /dev/null, outputs written into a new file) "
              f"{best_npz / (min(cat_read) + min(cat_write)):.2f}x")
        print(f"  binary io_fraction        {min(s['io_fraction'] for s in npz):6.3f}    [< 0.9]")
        print(f"  collide.load              {min(load) * 1000:6.1f} ms  [< 50 ms at 4M contacts]")

        # Binary -> CSV -> binary: the same bytes.
        for table in ("bodies", "contacts"):
            back = os.path.join(tmp, f"{table}.back.npz")
            run([collide_bin, "convert", "--in", os.path.join(tmp, f"{table}.csv"), "--out", back, "--precision",
                 "float"])
            same = filecmp.cmp(os.path.join(tmp, f"{table}.npz"), back, shallow=False)
            print(f"  {table}: binary -> CSV -> binary, same bytes: {'yes' if same else 'NO'}")
            ok &= same
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
