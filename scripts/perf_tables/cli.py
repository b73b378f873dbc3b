"""The command line of scripts/perf_tables.py."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .machine import REPO
from .page import readme_block, render, update_readme
from .runner import PRESETS, run_all
from .self_test import self_test


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=sys.modules[__package__].__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("bench_json", nargs="?", help="collide_bench --benchmark_format=json output")
    p.add_argument("--report", help="collide report --json output")
    p.add_argument("--out", help="output file (default: stdout; with --run: docs/performance.md)")
    p.add_argument("--machine", help="the machine line's CPU (default: /proc/cpuinfo's model name, now)")
    p.add_argument("--commit", help="the commit to name (default: git rev-parse --short HEAD)")
    p.add_argument("--bench-command", help="the command that produced BENCH_JSON, to print in the header")
    p.add_argument("--report-command", help="the command that produced --report, to print in the header")
    p.add_argument("--readme", help="README to refresh between the perf-table markers (default with --run: "
                                    "README.md; in file mode only when given)")
    p.add_argument("--run", action="store_true", help="run the benchmark and the report, then write the page")
    p.add_argument("--bench", default=str(REPO / "build" / "collide_bench"), help="collide_bench (with --run)")
    p.add_argument("--collide", default=str(REPO / "build" / "collide"), help="collide (with --run)")
    p.add_argument("--preset", choices=sorted(PRESETS), default="short",
                   help="what --run measures: short (default, a couple of minutes on 2 cores) or full (every "
                        "row at the default settings, tens of minutes)")
    p.add_argument("--bench-args", help="collide_bench arguments instead of the preset's (one string)")
    p.add_argument("--report-args", help="collide report arguments instead of the preset's (one string)")
    p.add_argument("--json-dir", help="keep the run's JSON here (default: a new temporary directory)")
    p.add_argument("--no-bench", action="store_true", help="with --run: skip the benchmark")
    p.add_argument("--no-report", action="store_true", help="with --run: skip the report")
    p.add_argument("--no-readme", action="store_true", help="with --run: leave README.md alone")
    p.add_argument("--self-test", action="store_true", help="check the script on synthetic input")
    args = p.parse_args(argv)

    if args.self_test:
        return self_test()
    if args.run:
        return run_all(args)
    if not args.bench_json and not args.report:
        p.error("give a benchmark JSON file (and/or --report FILE), or --run")
    bench = Path(args.bench_json) if args.bench_json else None
    report = Path(args.report) if args.report else None
    page = render(bench, report, cpu=args.machine, commit=args.commit, bench_cmd=args.bench_command,
                  report_cmd=args.report_command)
    if args.out:
        Path(args.out).write_text(page)
    else:
        sys.stdout.write(page)
    if args.readme:
        block = readme_block(bench, report, cpu=args.machine, commit=args.commit)
        if not block or not update_readme(Path(args.readme), block):
            print(f"perf_tables.py: no table or no perf-table markers for {args.readme}", file=sys.stderr)
            return 1
    return 0
