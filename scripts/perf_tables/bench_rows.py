"""The rows of the benchmark's JSON (Google Benchmark's format, as
`collide_bench --benchmark_format=json` writes it): each row's name split into
its parts, one figure per row (the median), and the selection of rows by
their parts."""

from __future__ import annotations

import json
import re
import statistics
from pathlib import Path


PRECISION_NAMES = {"f32": "float", "f64": "double"}


class BenchRow:
    __slots__ = ("family", "scene", "friction", "model", "precision", "kind", "threads", "n", "passes", "rate",
                 "bw_frac", "bytes", "batches", "sched_bytes", "gbs", "label")

    def __init__(self, **kw):
        for k in self.__slots__:
            setattr(self, k, kw.get(k))


def parse_bench_name(name: str) -> dict | None:
    """Split a collide_bench row name into its parts; None for unknown rows.
    `kind` is the last positional part: the path, ISA or layout, the order
    of an order/ row, "colour" for a colour schedule/ row (None for the
    input order's)."""
    parts = [p for p in name.split("/") if p and p != "manual_time" and p != "real_time"]
    if not parts:
        return None
    family = parts[0]
    rest = parts[1:]
    if family == "twin" and rest and rest[0] == "packed":
        family, rest = "twin/packed", rest[1:]
    out = {"family": family, "threads": None, "n": None, "precision": None, "passes": None}
    positional = []
    for p in rest:
        if m := re.fullmatch(r"t:(\d+)", p):
            out["threads"] = int(m.group(1))
        elif m := re.fullmatch(r"n:(\d+)", p):
            out["n"] = int(m.group(1))
        elif m := re.fullmatch(r"passes:(\d+)", p):
            out["passes"] = int(m.group(1))
        elif p in PRECISION_NAMES:
            out["precision"] = PRECISION_NAMES[p]
        else:
            positional.append(p)
    if family == "triad":
        return out
    if not positional:
        return None
    scene = positional.pop(0)
    out["friction"] = scene.endswith("+mu")
    out["scene"] = scene[: -len("+mu")] if out["friction"] else scene
    if family in ("model", "accurate", "layout", "twin", "twin/packed"):
        if not positional:
            return None
        model = positional.pop(0)
        if model.endswith("+mu"):
            out["friction"] = True
            model = model[: -len("+mu")]
        out["model"] = model
    out["kind"] = positional[-1] if positional else None  # path, ISA or layout
    return out


def load_bench(path: Path) -> tuple[dict, list[BenchRow]]:
    with open(path) as f:
        data = json.load(f)
    context = data.get("context", {})
    # Group the runs of one row: prefer the median aggregate when repetitions
    # were asked for, else the median of the iteration runs.
    groups: dict[str, dict] = {}
    for b in data.get("benchmarks", []):
        if b.get("error_occurred"):
            continue
        key = b.get("run_name") or b.get("name", "")
        g = groups.setdefault(key, {"iterations": [], "median": None})
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "median":
                g["median"] = b
        else:
            g["iterations"].append(b)
    rows = []
    for key, g in groups.items():
        parsed = parse_bench_name(key)
        if parsed is None:
            continue
        if g["median"] is not None:
            src = [g["median"]]
        elif g["iterations"]:
            src = g["iterations"]
        else:
            continue

        def med(counter):
            vals = [b[counter] for b in src if isinstance(b.get(counter), (int, float))]
            return statistics.median(vals) if vals else None

        rate = med("coll/s")
        bw = med("bw_frac")
        rows.append(BenchRow(
            family=parsed["family"], scene=parsed.get("scene"), friction=parsed.get("friction", False),
            model=parsed.get("model"), precision=parsed.get("precision"), kind=parsed.get("kind"),
            threads=parsed.get("threads"), n=parsed.get("n"), passes=parsed.get("passes"),
            rate=rate / 1e6 if rate else None,
            bw_frac=bw if bw else None,  # 0 where the bench has no bound for the row
            bytes=med("B/coll") or None, batches=med("batches"), sched_bytes=med("sched_B/c") or None,
            gbs=med("GB/s"), label=src[0].get("label", "")))
    return context, rows


def find(rows, **kw):
    for r in rows:
        if all(getattr(r, k) == v for k, v in kw.items()):
            return r
    return None


def select(rows, **kw):
    return [r for r in rows if all(getattr(r, k) == v for k, v in kw.items())]


def label_isa(label: str) -> str | None:
    for isa in ["avx512", "avx2", "sse2"]:
        if re.search(rf"\b{isa}\b", label or ""):
            return isa
    return None
