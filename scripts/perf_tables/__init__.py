"""perf_tables - Markdown tables of collide's current performance.

Reads the JSON that `collide_bench --benchmark_format=json` writes (Google
Benchmark's format) and, optionally, the JSON of `collide report --json FILE`,
and writes Markdown: a header that says where and how the figures were taken
(machine, instruction sets, triad bandwidth, date, commit, the exact
commands), then one table per kind of row the files contain. Only rows that
exist are shown; nothing is computed that the files do not hold, except
ratios of two figures of the same run.

  # tables from files you already have
  python3 scripts/perf_tables.py BENCH.json [--report REPORT.json] [--out FILE]

  # run the benchmark and the report, write docs/performance.md (and refresh
  # the table between the perf-table markers of README.md)
  python3 scripts/perf_tables.py --run [--bench build/collide_bench] [--collide build/collide]

  # check the script itself on synthetic input (no binaries needed)
  python3 scripts/perf_tables.py --self-test

One module per job:
  bench_rows.py     the benchmark's rows: names parsed, medians, selection
  machine.py        the machine, the commit, the load
  format.py         numbers, paragraphs, Markdown tables, the order of scenes
  bench_tables.py   the sections drawn from the benchmark
  report_tables.py  the sections drawn from the report
  page.py           the page and the README's short table
  runner.py         --run: the presets, the runs, the files written
  self_test.py      --self-test: sample JSON and the checks on its tables
  cli.py            the command line

Standard library only.
"""
