#!/usr/bin/env python3
"""Markdown tables of collide's current performance: docs/performance.md and
the README's table. The code is the package scripts/perf_tables/ (its
__init__.py says which module does what); this file is its command line.

  python3 scripts/perf_tables.py BENCH.json [--report REPORT.json] [--out FILE]
  python3 scripts/perf_tables.py --run [--bench build/collide_bench] [--collide build/collide]
  python3 scripts/perf_tables.py --self-test
"""

import os
import sys

# The package directory scripts/perf_tables/ sits beside this file and is
# found before it: a directory package wins over a module of the same name.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from perf_tables.cli import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
