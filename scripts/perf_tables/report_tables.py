"""The sections of docs/performance.md drawn from `collide report --json`."""

from __future__ import annotations

from .format import (MODELS, drop_empty_columns, fmt_err, fmt_n, fmt_rate, fmt_ratio, model_order, para, scene_order,
                     table)

SLOW_VARIANTS = ["reference", "textbook", "bullet"]
KERNEL_VARIANTS = ["scalar", "simd", "accurate"]


def report_group_rows(rows: list[dict]) -> list[dict]:
    """The rows of one scene and friction setting worth a table line: every
    single-threaded slow row, and each kernel row at the largest thread count
    its variant ran (the scalar path runs at the first only; its first
    occurrence, the default instruction set)."""
    top: dict[str, int] = {}
    for r in rows:
        v = r.get("variant")
        if v in KERNEL_VARIANTS:
            top[v] = max(top.get(v, 1), r.get("threads") or 1)
    chosen, seen = [], set()
    for r in rows:
        v = r.get("variant")
        if v in KERNEL_VARIANTS:
            if (r.get("threads") or 1) != top[v]:
                continue
            key = (v, r.get("precision"), r.get("model"), r.get("threads"))
            if key in seen:
                continue
            seen.add(key)
        chosen.append(r)

    prec_order = {"long double": 0, "double": 1, "float": 2}

    def order(r):
        v = r.get("variant")
        if v in KERNEL_VARIANTS:
            return (1, model_order(r.get("model")), r.get("precision") != "float", KERNEL_VARIANTS.index(v))
        idx = SLOW_VARIANTS.index(v) if v in SLOW_VARIANTS else len(SLOW_VARIANTS)
        return (0, idx, prec_order.get(r.get("precision"), 3), 0)

    return sorted(chosen, key=order)


def report_line(r: dict, peer: str | None) -> list[str]:
    variant = r.get("variant", "")
    if variant == "bullet":
        variant = "Bullet (peer)"
    bw = r.get("bandwidth_fraction")
    return [variant, r.get("precision", ""), r.get("model", ""), r.get("isa", "") or "", r.get("layout", "") or "",
            str(r.get("threads", "")), fmt_n(r.get("n")),
            fmt_rate(r["collisions_per_second"] / 1e6) if r.get("collisions_per_second") else "",
            f"{bw * 100:.0f}%" if bw else "", fmt_err(r.get("max_err_eps")), fmt_err(r.get("p99_err_eps")),
            f"{r['max_rel_err']:.1e}" if r.get("max_rel_err") else ("0" if r.get("max_rel_err") == 0 else ""),
            (r.get("note") or "").replace("|", "/")]


def section_report(report: dict) -> list[str]:
    rows = report.get("rows", [])
    if not rows:
        return []
    groups: dict[tuple, list] = {}
    for r in rows:
        groups.setdefault((r.get("scene"), bool(r.get("friction"))), []).append(r)
    sample = report.get("error_sample")
    lines = ["## Speed against error (`collide report`)", ""] + para(
        "Every variant of one scene solves the same contacts; *err* is the impulse error against",
        "`reference_solve<long double>` on the error sample",
        f"({sample:,} contacts)" if isinstance(sample, int) else "",
        "in units of eps times the contact's impulse scale (the documented bound is",
        f"{report.get('error_bound_eps', 64)}); *bw* is the share of the triad bandwidth bound at the row's",
        "thread count; *rel* the plain relative error. Kernel rows are shown at the largest thread count they ran",
        "and the instruction set chosen at run time; the report's JSON has every row",
        "([report.md](report.md) explains the columns).")
    header = ["variant", "precision", "model", "isa", "layout", "threads", "n", "Mcoll/s", "bw", "max err",
              "p99 err", "max rel", "note"]
    align = ["l", "l", "l", "l", "l", "r", "r", "r", "r", "r", "r", "r", "l"]
    for (scene, fric) in sorted(groups, key=lambda k: (scene_order(k[0]), k[1])):
        chosen = report_group_rows(groups[(scene, fric)])
        body = [report_line(r, report.get("peer")) for r in chosen]
        h, body, a = drop_empty_columns(header, body, align, keep=3)
        n = max((r.get("n") or 0 for r in groups[(scene, fric)]), default=0)
        lines += [f"### {scene}, {'with' if fric else 'without'} friction ({fmt_n(n)} contacts)", ""]
        lines += table(h, body, a) + [""]
    return lines


def section_hard(report: dict) -> list[str]:
    hard = report.get("hard") or []
    if not hard:
        return []
    families = []
    for h in hard:
        if h.get("family") not in families:
            families.append(h.get("family"))
    cols = [(p, m) for p in ("float", "double") for m in ("fast", "accurate")
            if any(h.get("precision") == p and h.get("mode") == m for h in hard)]
    out_rows = []
    for fam in families:
        row = [fam]
        for p, m in cols:
            sel = [h for h in hard if h.get("family") == fam and h.get("precision") == p and h.get("mode") == m]
            if not sel:
                row.append("")
                continue
            err = max((h["max_err_eps"] for h in sel if h.get("max_err_eps") is not None), default=None)
            ulps_vals = [h["max_err_ulps"] for h in sel if h.get("max_err_ulps") is not None]
            ulps = max(ulps_vals) if ulps_vals else None
            row.append(f"{fmt_err(err)} / {fmt_err(ulps)}")
        out_rows.append(row)
    header = ["scene"] + [f"{p} {m}: err / ulps" for p, m in cols]
    # Speed of the accurate mode against the fast mode, per precision and model, on the first family.
    speed_rows = []
    first = families[0] if families else None
    for p in ("float", "double"):
        for model in MODELS:
            f = next((h for h in hard if h.get("family") == first and h.get("precision") == p
                      and h.get("model") == model and h.get("mode") == "fast"), None)
            a = next((h for h in hard if h.get("family") == first and h.get("precision") == p
                      and h.get("model") == model and h.get("mode") == "accurate"), None)
            if f and a and f.get("collisions_per_second") and a.get("collisions_per_second"):
                speed_rows.append([p, model, fmt_rate(f["collisions_per_second"] / 1e6),
                                   fmt_rate(a["collisions_per_second"] / 1e6),
                                   fmt_ratio(a["collisions_per_second"] / f["collisions_per_second"])])
    lines = ["## Hard scenes (`collide report --hard`)", ""] + para(
        f"Worst figure over the body models each scene fits ({report.get('hard_n', 'n/a')} pairs per pair",
        "family; SIMD path, one thread). *err*: eps-units of the impulse scale, the fast mode's target is",
        f"{report.get('impulse_error_target_eps', 2)}; *ulps*: plain relative error of J, the accurate mode's",
        f"bound is {report.get('accurate_error_ulps', 8)}.")
    lines += table(header, out_rows, ["l"] + ["r"] * len(cols)) + [""]
    if speed_rows:
        lines += [f"Speed of the two modes on the `{first}` scene, in cache (millions of contacts per second):",
                  ""]
        lines += table(["precision", "model", "fast", "accurate", "accurate / fast"], speed_rows,
                       ["l", "l", "r", "r", "r"]) + [""]
    return lines


def section_sweep(report: dict) -> list[str]:
    sweep = report.get("sweep") or []
    if not sweep:
        return []
    models = [m for m in MODELS if any(s.get("model") == m for s in sweep)]
    ns = sorted({s.get("n") for s in sweep if s.get("n")})
    out_rows = []
    for n in ns:
        row = [fmt_n(n)]
        for m in models:
            s = next((x for x in sweep if x.get("n") == n and x.get("model") == m), None)
            row.append(f"{fmt_rate(s['collisions_per_second'] / 1e6)} ({s['bandwidth_fraction']:.2f})"
                       if s and s.get("collisions_per_second") and s.get("bandwidth_fraction") is not None else
                       (fmt_rate(s["collisions_per_second"] / 1e6) if s and s.get("collisions_per_second") else ""))
        out_rows.append(row)
    t = sweep[0].get("threads")
    lines = ["## Throughput against N", ""] + para(
        f"SIMD float kernel on the first N pairs of one scene, {t} threads: millions of contacts per second",
        "(fraction of the bandwidth bound).")
    return lines + table(["N"] + models, out_rows, ["r"] * (1 + len(models))) + [""]


def section_isa_auto(report: dict) -> list[str]:
    picks = report.get("machine", {}).get("isa_auto") or []
    if not picks:
        return []
    keys = []
    for p in picks:
        k = (p.get("precision"), p.get("accuracy"))
        if k not in keys:
            keys.append(k)
    models = [m for m in MODELS if any(p.get("model") == m for p in picks)]
    out_rows = []
    for prec, acc in keys:
        row = [prec, acc]
        for m in models:
            s = next((p.get("isa") for p in picks if (p.get("precision"), p.get("accuracy"), p.get("model"),
                                                      p.get("scene")) == (prec, acc, m, "streaming")), "")
            c = next((p.get("isa") for p in picks if (p.get("precision"), p.get("accuracy"), p.get("model"),
                                                      p.get("scene")) == (prec, acc, m, "scattered")), "")
            row.append(f"{s} / {c}")
        out_rows.append(row)
    lines = ["## Run-time instruction set choice", ""] + para(
        "What `--isa auto` picked on the machine of the run for each kind of solve (streaming / scattered scene),",
        "measured once per process at the first solve of each kind (the report's machine block).")
    return lines + table(["precision", "accuracy"] + models, out_rows, ["l", "l"] + ["l"] * len(models)) + [""]
