"""The sections of docs/performance.md drawn from the benchmark's rows."""

from __future__ import annotations

from .bench_rows import find, label_isa, select
from .format import (ISAS, LAYOUTS, ORDERS, drop_empty_columns, fmt_n, fmt_rate, fmt_ratio, model_order, para,
                     scene_order, table)


def triad(rows) -> dict[int, float]:
    return {r.threads: r.gbs for r in select(rows, family="triad") if r.threads and r.gbs}


def isa_summary(rows) -> tuple[list[str], dict[str, set]]:
    """ISAs this CPU ran in the isa/ rows, and the ISA the solve/ simd rows ran per scene."""
    have = sorted({r.kind for r in select(rows, family="isa") if r.kind in ISAS and r.kind != "auto"},
                  key=ISAS.index)
    ran: dict[str, set] = {}
    for r in rows:
        if r.family in ("solve", "model") and (r.kind == "simd"):
            isa = label_isa(r.label)
            if isa:
                ran.setdefault(r.scene, set()).add(isa)
    return have, ran


def section_throughput(rows) -> list[str]:
    solve = select(rows, family="solve")
    textbook = select(rows, family="textbook")
    if not solve and not textbook:
        return []
    threads = sorted({r.threads for r in solve if r.threads})
    paths = [p for p in ("scalar", "simd") if any(r.kind == p for r in solve)]
    cols = [(p, t) for p in paths for t in threads]
    top = ("simd", max(threads)) if "simd" in paths and threads else None
    header = ["scene", "precision", "N"] + [f"{p}, {t} thr" for p, t in cols] + ["textbook, 1 thr"]
    if top:
        header += [f"simd {top[1]} thr / bound", "simd / scalar"]
    align = ["l", "l", "r"] + ["r"] * (len(header) - 3)
    keys = sorted({(r.scene, r.friction, r.precision, r.n) for r in solve + textbook},
                  key=lambda k: (scene_order(k[0]), k[1], k[2] != "float", k[3] or 0))
    out_rows = []
    for scene, fric, prec, n in keys:
        name = scene + (" + friction" if fric else "")
        row = [name, prec, fmt_n(n)]
        for p, t in cols:
            r = find(solve, scene=scene, friction=fric, precision=prec, n=n, kind=p, threads=t)
            row.append(fmt_rate(r.rate) if r else "")
        tb = find(textbook, scene=scene, friction=fric, precision=prec, n=n)
        row.append(fmt_rate(tb.rate) if tb else "")
        if top:
            r = find(solve, scene=scene, friction=fric, precision=prec, n=n, kind="simd", threads=top[1])
            row.append(fmt_ratio(r.bw_frac) if r and r.bw_frac else "")
            sc = find(solve, scene=scene, friction=fric, precision=prec, n=n, kind="scalar", threads=top[1])
            row.append(f"{r.rate / sc.rate:.1f}x" if r and sc and r.rate and sc.rate else "")
        out_rows.append(row)
    header, out_rows, align = drop_empty_columns(header, out_rows, align, keep=3)
    lines = ["## Throughput by scene", ""] + para(
        "Millions of contacts resolved per second (`solve/` and `textbook/` rows; the SIMD rows run the",
        "instruction set chosen at run time). *bound*: the row's bytes per contact (the law's inputs and",
        "outputs, `collide/eval/traffic.hpp`) moved at its rate, over the triad bandwidth at the same",
        "thread count; above 1 the data came from cache. *textbook*: the law as written, one contact at",
        "a time (`textbook_solve`).")
    return lines + table(header, out_rows, align) + [""]


def section_models(rows) -> list[str]:
    fast = select(rows, family="model")
    acc = select(rows, family="accurate")
    twin = select(rows, family="twin")
    if not fast and not acc:
        return []
    keys = sorted({(r.scene, r.model, r.friction, r.precision, r.n, r.threads) for r in fast + acc},
                  key=lambda k: (scene_order(k[0]), k[2], model_order(k[1]), k[3] != "float", k[4] or 0, k[5] or 0))
    header = ["scene", "model", "friction", "precision", "N", "threads", "B/contact", "fast", "fast / bound",
              "accurate", "accurate / fast", "memory-only twin", "fast / twin"]
    align = ["l", "l", "l", "l", "r", "r", "r", "r", "r", "r", "r", "r", "r"]
    out_rows = []
    for scene, model, fric, prec, n, t in keys:
        f = find(fast, scene=scene, model=model, friction=fric, precision=prec, n=n, threads=t)
        a = find(acc, scene=scene, model=model, friction=fric, precision=prec, n=n, threads=t)
        w = find(twin, scene=scene, model=model, friction=fric, precision=prec, n=n, threads=t)
        b = (f or a).bytes
        out_rows.append([
            scene, model, "yes" if fric else "no", prec, fmt_n(n), str(t), f"{b:.0f}" if b else "",
            fmt_rate(f.rate) if f else "", fmt_ratio(f.bw_frac) if f and f.bw_frac else "",
            fmt_rate(a.rate) if a else "", fmt_ratio(a.rate / f.rate) if a and f and f.rate else "",
            fmt_rate(w.rate) if w else "", fmt_ratio(f.rate / w.rate) if f and w and w.rate else "",
        ])
    header, out_rows, align = drop_empty_columns(header, out_rows, align, keep=6)
    lines = ["## Body models and accuracy modes", ""] + para(
        "SIMD path, millions of contacts per second (`model/` rows: the fast mode; `accurate/` rows: the",
        "accurate mode; `twin/` rows: the model's memory-only twin, the same loads and stores without the",
        "law). Each model runs on the scene reshaped to fit it ([report.md](report.md), \"The scenes\").")
    return lines + table(header, out_rows, align) + [""]


def section_isa(rows) -> list[str]:
    isa_rows = select(rows, family="isa")
    if not isa_rows:
        return []
    solve = select(rows, family="solve")
    isas = [i for i in ISAS if any(r.kind == i for r in isa_rows)]
    keys = sorted({(r.scene, r.friction, r.precision, r.n, r.threads) for r in isa_rows},
                  key=lambda k: (scene_order(k[0]), k[1], k[2] != "float", k[3] or 0, k[4] or 0))
    header = ["scene", "precision", "N", "threads", "scalar"] + isas
    widest = [i for i in isas if i != "auto"]
    widest = widest[-1] if widest else None
    if widest and len([i for i in isas if i != "auto"]) > 1:
        header += [f"{widest} / scalar"]
    align = ["l", "l", "r", "r"] + ["r"] * (len(header) - 4)
    out_rows = []
    for scene, fric, prec, n, t in keys:
        sc = find(solve, scene=scene, friction=fric, precision=prec, n=n, kind="scalar", threads=t)
        row = [scene + (" + friction" if fric else ""), prec, fmt_n(n), str(t), fmt_rate(sc.rate) if sc else ""]
        for i in isas:
            r = find(isa_rows, scene=scene, friction=fric, precision=prec, n=n, threads=t, kind=i)
            cell = fmt_rate(r.rate) if r else ""
            if i == "auto" and r and label_isa(r.label):
                cell += f" ({label_isa(r.label)})"
            row.append(cell)
        if len(header) > len(row):
            w = find(isa_rows, scene=scene, friction=fric, precision=prec, n=n, threads=t, kind=widest)
            row.append(f"{w.rate / sc.rate:.1f}x" if w and sc and sc.rate else "")
        out_rows.append(row)
    lines = ["## Instruction sets", ""] + para(
        "The SIMD path forced to each instruction set the CPU has (`isa/` rows), beside the scalar path",
        "(one lane) and `auto`, the run-time choice (in parentheses, the set it ran), in millions of",
        "contacts per second. Results are the same bits on every set.")
    return lines + table(header, out_rows, align) + [""]


def section_layout(rows) -> list[str]:
    lay = select(rows, family="layout")
    if not lay:
        return []
    twin = select(rows, family="twin/packed")
    models = select(rows, family="model")
    keys = sorted({(r.scene, r.model, r.friction, r.precision, r.n, r.threads) for r in lay},
                  key=lambda k: (scene_order(k[0]), k[2], model_order(k[1]), k[3] != "float", k[4] or 0, k[5] or 0))
    layouts = [l for l in LAYOUTS if any(r.kind == l for r in lay)]
    header = ["scene", "model", "friction", "precision", "N", "threads"] + layouts + \
        ["memory-only twin (packed)", "pairs, same model", "records / pairs"]
    align = ["l"] * 4 + ["r"] * (len(header) - 4)
    out_rows = []
    for scene, model, fric, prec, n, t in keys:
        row = [scene, model, "yes" if fric else "no", prec, fmt_n(n), str(t)]
        for l in layouts:
            r = find(lay, scene=scene, model=model, friction=fric, precision=prec, n=n, threads=t, kind=l)
            row.append(fmt_rate(r.rate) if r else "")
        w = find(twin, scene=scene, model=model, friction=fric, precision=prec, n=n, threads=t)
        row.append(fmt_rate(w.rate) if w else "")
        p = None
        if scene != "pairs":
            p = find(models, scene="pairs", model=model, friction=fric, precision=prec, n=n, threads=t)
        rec = find(lay, scene=scene, model=model, friction=fric, precision=prec, n=n, threads=t, kind="records")
        row.append(fmt_rate(p.rate) if p else "")
        row.append(fmt_ratio(rec.rate / p.rate) if p and rec and p.rate else "")
        out_rows.append(row)
    header, out_rows, align = drop_empty_columns(header, out_rows, align, keep=6)
    lines = ["## Body layouts", ""] + para(
        "Millions of contacts per second by body layout (`layout/` rows): *soa* solves the caller's",
        "arrays in place, *packed* is SoA input that the solver packs into records and unpacks around",
        "the solve (included in the time), *records* is the caller's packed records",
        "(`collide/packed.hpp`). *pairs, same model* is the `model/` row of the streaming scene at the",
        "same size and thread count, the scattered scene's ceiling.")
    return lines + table(header, out_rows, align) + [""]


def section_schedule(rows) -> list[str]:
    # The input order's schedules; the colour order's are section_order's.
    sched = [r for r in select(rows, family="schedule") if r.kind != "colour"]
    if not sched:
        return []
    sched.sort(key=lambda r: (scene_order(r.scene), r.precision != "float", r.n or 0))
    out_rows = [[r.scene, r.precision, fmt_n(r.n), fmt_rate(r.rate), f"{r.batches:.0f}" if r.batches else "",
                 f"{r.sched_bytes:.1f}" if r.sched_bytes else ""] for r in sched]
    lines = ["## Schedule", ""] + para(
        "`Schedule::build` alone: millions of contacts scheduled per second, the batches (dependency",
        "levels) of the scene, and the schedule's memory in bytes per contact.")
    return lines + table(["scene", "precision", "N", "M contacts/s", "batches", "bytes/contact"], out_rows,
                         ["l", "l", "r", "r", "r", "r"]) + [""]


def section_order(rows) -> list[str]:
    """Each scene in input and in colour order, one pass and four, at the
    largest size and thread count the order/ rows ran: the rate, each pass
    counted, and its ratio to pairs in the same order and passes."""
    order = [r for r in select(rows, family="order") if r.kind in ORDERS and r.passes]
    if not order:
        return []
    t = max(r.threads for r in order if r.threads)
    at_t = [r for r in order if r.threads == t]
    cols = [(o, p) for o in ORDERS for p in sorted({r.passes for r in at_t}) if any(
        r.kind == o and r.passes == p for r in at_t)]
    colour_schedules = select(rows, family="schedule", kind="colour")

    def largest(scene, candidates):
        ns = [r.n for r in candidates if r.scene == scene and r.n]
        return max(ns) if ns else None

    pairs_n = largest("pairs", at_t)
    out_rows = []
    for scene in sorted({r.scene for r in at_t}, key=scene_order):
        n = largest(scene, at_t)
        row = [scene, fmt_n(n)]
        for o, p in cols:
            r = find(at_t, scene=scene, n=n, kind=o, passes=p)
            base = find(at_t, scene="pairs", n=pairs_n, kind=o, passes=p)
            if not r or not r.rate:
                row.append("")
            elif base and base.rate:
                row.append(f"{fmt_rate(r.rate)} ({fmt_ratio(r.rate / base.rate)})")
            else:
                row.append(fmt_rate(r.rate))
        s = find(colour_schedules, scene=scene, n=largest(scene, colour_schedules))
        row.append(fmt_rate(s.rate) if s else "")
        out_rows.append(row)
    header = ["scene", "N"] + [f"{o}, {p} pass{'es' if p > 1 else ''}" for o, p in cols] + ["colour schedule"]
    header, out_rows, align = drop_empty_columns(header, out_rows, ["l", "r"] + ["r"] * (len(header) - 2), keep=2)
    lines = ["## Solve order", ""] + para(
        "`order/` rows: each scene solved in input order and in colour order (`SolverOptions::order`;",
        "[collision-law.md](collision-law.md), \"The solve order\"), with one pass and with four per",
        "schedule (`SolverOptions::passes`), float, rigid bodies,",
        f"{t} thread{'s' if t > 1 else ''}, at the largest size run: millions of contacts per second,",
        "each pass counted, and in parentheses the ratio to pairs in the same order and passes of the",
        "same run. *colour schedule*: `Schedule::build` in colour order alone, millions of contacts per",
        "second (`schedule/<scene>/f32/colour/` rows).")
    return lines + table(header, out_rows, align) + [""]
