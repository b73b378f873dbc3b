"""--run: the benchmark and the report run with a preset's arguments, their
JSON kept, the page and the README's table written."""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

from .machine import REPO
from .page import readme_block, render, update_readme

# and README.md show, at the two sizes the benchmark treats as "in cache" and
# "streaming", float and double for the plain solve rows, float for the rest.
# A couple of minutes on an idle 2-core machine.
SHORT_BENCH_FILTER = (
    r"^(solve|isa)/(pairs|debris|pile|pile\+shuffle|chain)/f32/"
    r"|^solve/(pairs|debris|pile)/f64/"
    r"|^schedule/(pairs|debris|pile|pile\+shuffle|chain)/f32/"
    r"|^textbook/pairs/"
    r"|^model/(pairs|debris)/[a-z+]+/f32/simd/t:2/n:4194304"
    r"|^accurate/pairs/[a-z+]+/f32/simd/t:2/n:4194304"
    r"|^layout/debris/[a-z]+/f32/(soa|records)/t:2/n:4194304"
    r"|^order/(pairs|debris|pile|pile\+shuffle|chain)/f32/(input|colour)/passes:[14]/t:2/"
)
PRESETS = {
    "short": {
        "bench": ["--sizes=65536,4194304", "--benchmark_min_time=0.05", "--benchmark_filter=" + SHORT_BENCH_FILTER],
        "report": ["--n", "200000", "--runs", "3", "--hard"],
    },
    # Every row of the benchmark and the report at their default settings, and
    # the report's hard section: tens of minutes, the page for an idle machine.
    "full": {
        "bench": [],
        "report": ["--hard"],
    },
}


def shell_join(argv: list[str]) -> str:
    return " ".join(shlex.quote(a) for a in argv)


def run_all(args) -> int:
    bench = Path(args.bench)
    collide = Path(args.collide)
    for exe in ([bench] if not args.no_bench else []) + ([collide] if not args.no_report else []):
        if not os.access(exe, os.X_OK):
            print(f"perf_tables.py: {exe} is not an executable (build first, or pass --bench/--collide)",
                  file=sys.stderr)
            return 1
    preset = PRESETS[args.preset]
    bench_args = shlex.split(args.bench_args) if args.bench_args is not None else preset["bench"]
    report_args = shlex.split(args.report_args) if args.report_args is not None else preset["report"]
    workdir = Path(args.json_dir) if args.json_dir else Path(tempfile.mkdtemp(prefix="collide-perf-"))
    workdir.mkdir(parents=True, exist_ok=True)
    bench_json = workdir / "bench.json"
    report_json = workdir / "report.json"
    bench_cmd = report_cmd = None
    if not args.no_bench:
        argv = [str(bench), "--benchmark_format=json"] + bench_args
        bench_cmd = shell_join(argv) + " > bench.json"
        print(f"perf_tables.py: running {bench_cmd}", file=sys.stderr, flush=True)
        with open(bench_json, "w") as out:
            rc = subprocess.run(argv, stdout=out).returncode
        if rc != 0:
            print(f"perf_tables.py: collide_bench exited with {rc}", file=sys.stderr)
            return 1
    if not args.no_report:
        argv = [str(collide), "report"] + report_args + ["--json", "report.json"]
        report_cmd = shell_join(argv)
        print(f"perf_tables.py: running {report_cmd}", file=sys.stderr, flush=True)
        with open(workdir / "report.txt", "w") as out:
            rc = subprocess.run(argv[:-1] + [str(report_json)], stdout=out).returncode
        if rc == 3:
            print("perf_tables.py: collide report exited with 3 (an error above its bound); its rows are "
                  f"tabulated as measured; see {workdir / 'report.txt'}", file=sys.stderr)
        elif rc != 0:
            print(f"perf_tables.py: collide report exited with {rc}", file=sys.stderr)
            return 1
    bp = None if args.no_bench else bench_json
    rp = None if args.no_report else report_json
    page = render(bp, rp, cpu=args.machine, commit=args.commit, bench_cmd=bench_cmd, report_cmd=report_cmd)
    out = Path(args.out or REPO / "docs" / "performance.md")
    out.write_text(page)
    print(f"perf_tables.py: wrote {out} (JSON in {workdir})", file=sys.stderr)
    readme = Path(args.readme) if args.readme else REPO / "README.md"
    if not args.no_readme and readme.exists():
        block = readme_block(bp, rp, cpu=args.machine, commit=args.commit)
        if block and update_readme(readme, block):
            print(f"perf_tables.py: refreshed the table in {readme}", file=sys.stderr)
    return 0
