"""--self-test: the tables rendered from sample JSON (no binaries, no
timing), and what must and must not appear in them."""

from __future__ import annotations

import json
import re
import sys
import tempfile
from pathlib import Path

from .page import GENERATED_NOTE, README_BEGIN, README_END, readme_block, render, update_readme
from .runner import SHORT_BENCH_FILTER


def self_test() -> int:
    """Render synthetic files and check what must and must not appear."""

    def row(name, rate, bw=0.5, label="avx2, 8 lanes", extra=None):
        r = {"name": name + "/manual_time", "run_name": name + "/manual_time", "run_type": "iteration",
             "iterations": 3, "real_time": 1.0, "time_unit": "ms", "coll/s": rate * 1e6, "bw_frac": bw,
             "B/coll": 232.0, "GB/s": rate * 0.232, "batches": 1.0, "sched_B/c": 7.0, "label": label}
        r.update(extra or {})
        return r

    bench = {"context": {"date": "2000-01-01T00:00:00+00:00", "num_cpus": 2, "load_avg": [0.5, 0.5, 0.5],
                         "caches": [{"type": "Unified", "level": 3, "size": 32 << 20}]},
             "benchmarks": [
                 row("triad/t:1", 1000, 1.0, None, {"GB/s": 20.0}), row("triad/t:2", 2000, 1.0, None, {"GB/s": 30.0}),
                 row("schedule/pairs/f32/n:4194304", 300, 0),
                 row("solve/pairs/f32/scalar/t:2/n:4194304", 30, 0.2, "scalar, 1 lanes"),
                 row("solve/pairs/f32/simd/t:2/n:4194304", 120, 0.8),
                 row("solve/chain/f64/simd/t:2/n:65536", 12.5, 0.1),
                 row("isa/pairs/f32/sse2/t:2/n:4194304", 60), row("isa/pairs/f32/auto/t:2/n:4194304", 121),
                 row("model/pairs/rigid/f32/simd/t:2/n:4194304", 110, 0.7, "rigid, soa, avx2, 8 lanes"),
                 row("accurate/pairs/rigid/f32/simd/t:2/n:4194304", 55, 0.35, "rigid, soa, avx2, 8 lanes"),
                 row("layout/debris/rigid/f32/records/t:2/n:4194304", 33, 0.1, "rigid, packed, avx2, 8 lanes"),
                 row("textbook/pairs/f32/t:1/n:4194304", 8, 0.05, None),
                 # The solve orders: pairs, debris, the pile and the chain at
                 # 4Mi on 2 threads; a 1-thread row the table must leave out.
                 row("schedule/debris/f32/colour/n:4194304", 150, 0),
                 row("order/pairs/f32/input/passes:1/t:2/n:4194304", 100, 0.6),
                 row("order/pairs/f32/colour/passes:1/t:2/n:4194304", 100, 0.6),
                 row("order/pairs/f32/input/passes:4/t:2/n:4194304", 110, 0.65),
                 row("order/pairs/f32/colour/passes:4/t:2/n:4194304", 105, 0.62),
                 row("order/debris/f32/input/passes:1/t:2/n:4194304", 40, 0.2),
                 row("order/debris/f32/colour/passes:1/t:2/n:4194304", 60, 0.3),
                 row("order/debris/f32/input/passes:4/t:2/n:4194304", 44, 0.22),
                 row("order/debris/f32/colour/passes:4/t:2/n:4194304", 70, 0.35),
                 row("order/debris/f32/colour/passes:1/t:1/n:4194304", 999, 0.9),
                 row("order/pile/f32/colour/passes:1/t:2/n:4189696", 80, 0.4),
                 row("order/pile/f32/colour/passes:1/t:2/n:64288", 90, 0.4),
                 row("order/chain/f32/colour/passes:1/t:2/n:4194304", 30, 0.15),
             ]}
    # Two repetitions with a median aggregate: the aggregate wins.
    agg = row("solve/debris/f32/simd/t:2/n:4194304", 25, 0.2)
    agg_med = dict(agg, run_type="aggregate", aggregate_name="median", name=agg["name"] + "_median")
    agg_med["coll/s"] = 26e6
    bench["benchmarks"] += [agg, dict(agg, **{"coll/s": 27e6}), agg_med]
    report = {"n": 1000, "error_sample": 1000, "error_bound_eps": 64, "peer": "bullet 3.24",
              "machine": {"cpu": "Test CPU", "simd": "simd rows: avx2", "load_average": 0.1,
                          "isa_auto": [{"precision": "float", "model": "rigid", "accuracy": "fast",
                                        "scene": "streaming", "isa": "avx2"}]},
              "rows": [
                  {"scene": "pairs", "variant": "bullet", "model": "rigid", "precision": "float", "friction": False,
                   "threads": 1, "n": 1000, "isa": "sse2", "layout": "soa", "collisions_per_second": 1.5e6,
                   "bandwidth_fraction": 0.02, "max_err_eps": 2.3, "p99_err_eps": 0.5, "max_rel_err": 1e-4,
                   "note": "bullet 3.24"},
                  {"scene": "pairs", "variant": "simd", "model": "rigid", "precision": "float", "friction": False,
                   "threads": 2, "n": 1000, "isa": "avx2", "layout": "soa", "collisions_per_second": 9.7e7,
                   "bandwidth_fraction": 0.74, "max_err_eps": 0.68, "p99_err_eps": 0.31, "max_rel_err": 1e-4,
                   "note": ""},
                  {"scene": "pairs", "variant": "simd", "model": "rigid", "precision": "float", "friction": False,
                   "threads": 1, "n": 1000, "isa": "sse2", "layout": "soa", "collisions_per_second": 2e7,
                   "bandwidth_fraction": 0.3, "max_err_eps": 0.68, "p99_err_eps": 0.31, "max_rel_err": 1e-4,
                   "note": ""}],
              "hard": [{"family": "grazing", "model": "rigid", "precision": "float", "mode": m,
                        "collisions_per_second": c, "max_err_eps": e, "max_err_ulps": u}
                       for m, c, e, u in (("fast", 4e7, 0.3, 1.9e8), ("accurate", 3e7, 0.1, 0.48))],
              "sweep": []}
    with tempfile.TemporaryDirectory() as d:
        bp, rp = Path(d) / "b.json", Path(d) / "r.json"
        bp.write_text(json.dumps(bench))
        rp.write_text(json.dumps(report))
        page = render(bp, rp, cpu="Test CPU", commit="abc1234", bench_cmd="collide_bench x", report_cmd="collide y")
        only_bench = render(bp, None, cpu="Test CPU", commit="abc1234")
        readme = Path(d) / "README.md"
        readme.write_text(f"intro\n{README_BEGIN}\nold\n{README_END}\nrest\n")
        block = readme_block(bp, rp, cpu="Test CPU", commit="abc1234")
        ok_readme = update_readme(readme, block)
        readme_text = readme.read_text()
    checks = [
        ("generated note", page.startswith(GENERATED_NOTE)),
        ("machine", "Test CPU" in page),
        ("commit", "`abc1234`" in page),
        ("commands", "`collide_bench x`" in page and "`collide y`" in page),
        ("triad", "20.0 GB/s on 1 thread" in page and "30.0 GB/s on 2 threads" in page),
        ("pairs rate", "| pairs | float | 4Mi |" in page and "| 120 |" in page),
        ("chain scene", "| chain | double | 64Ki |" in page),
        ("no shuffled pile scene", "pile+shuffle" not in page),
        ("short run has the chain", all(re.search(SHORT_BENCH_FILTER, name) for name in (
            "solve/chain/f32/simd/t:2/n:4194304", "isa/chain/f32/auto/t:1/n:65536", "schedule/chain/f32/n:4194304"))),
        ("median aggregate", "| 26.0 |" in page and "| 27.0 |" not in page),
        ("simd / scalar", "4.0x" in page),
        ("accurate / fast", "| 0.50 |" in page),
        ("auto isa", "121 (avx2)" in page),
        ("layout", "## Body layouts" in page and "| 0.30 |" in page),
        ("peer row", "Bullet (peer)" in page),
        ("kernel rows at the top thread count", "| 20.0 |" not in page),
        ("hard", "| grazing | 0.30 / 1.9e+08 | 0.10 / 0.48 |" in page),
        ("no report sections without a report", "collide report" not in only_bench),
        ("readme block", ok_readme and "old" not in readme_text and "rest" in readme_text
         and "Bullet (peer)" in readme_text),
        ("no invented sweep", "Throughput against N" not in page),
        ("solve order", "## Solve order" in page and "| debris | 4Mi | 40.0 (0.40) | 44.0 (0.40) | 60.0 (0.60) | "
         "70.0 (0.67) | 150 |" in page),
        ("solve order: each scene at its largest size", "| pile | 4,189,696 |  |  | 80.0 (0.80) |  |  |" in page
         and "| 90.0 |" not in page and "64,288" not in page),
        ("solve order: one thread count", "999" not in page),
        ("colour schedules only in the solve order", "| debris | float | 4Mi | 150 |" not in page),
        ("short run has the orders", all(re.search(SHORT_BENCH_FILTER, name) for name in (
            "order/pile+shuffle/f32/colour/passes:4/t:2/n:4189696", "schedule/chain/f32/colour/n:4194304"))
         and not re.search(SHORT_BENCH_FILTER, "order/debris/f32/colour/passes:4/t:1/n:4194304")),
        ("readme colour rows", all(f"| {s}, colour order | float |" in readme_text for s in ("debris", "pile", "chain"))
         and "| pairs, colour order |" not in readme_text and "| pile, colour order | float | 4,189,696 | 80.0 | 0.40 |"
         in readme_text),
    ]
    failed = [name for name, ok in checks if not ok]
    for name in failed:
        print(f"perf_tables.py --self-test: FAILED {name}", file=sys.stderr)
    if failed:
        print(page, file=sys.stderr)
        return 1
    print(f"perf_tables.py --self-test: {len(checks)} checks passed")
    return 0
