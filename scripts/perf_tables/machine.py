"""Where and how the figures were taken: the machine, the commit, the load."""

from __future__ import annotations

import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent.parent


def cpu_model() -> str | None:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.lower().startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=False).stdout
        for line in out.splitlines():
            if line.startswith("Model name:"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def git_commit() -> str | None:
    try:
        out = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True, check=False)
        return out.stdout.strip() or None
    except OSError:
        return None


def machine_line(context: dict, report: dict | None, cpu: str | None) -> str:
    parts = []
    cpu = cpu or (report or {}).get("machine", {}).get("cpu") or "unknown CPU"
    parts.append(cpu)
    threads = context.get("num_cpus") or (report or {}).get("machine", {}).get("hardware_threads")
    if threads:
        parts.append(f"{threads} hardware threads")
    if context.get("mhz_per_cpu"):
        parts.append(f"{context['mhz_per_cpu']} MHz")
    caches = []
    for c in context.get("caches", []):
        if c.get("type") in ("Data", "Unified"):
            size = c.get("size", 0)
            text = f"{size >> 20} MiB" if size >= 1 << 20 else f"{size >> 10} KiB"
            caches.append(f"L{c.get('level')} {text}")
    if not caches and report:
        m = report.get("machine", {})
        for key, name in (("l1d_bytes", "L1"), ("l2_bytes", "L2"), ("l3_bytes", "L3")):
            if m.get(key):
                size = m[key]
                caches.append(f"{name} {size >> 20} MiB" if size >= 1 << 20 else f"{name} {size >> 10} KiB")
    if caches:
        parts.append(", ".join(caches))
    return "; ".join(parts)


def load_text(context: dict, report: dict | None) -> str | None:
    loads = []
    if context.get("load_avg"):
        loads.append(f"{context['load_avg'][0]:.2f} at the start of the benchmark")
    if report and report.get("machine", {}).get("load_average") is not None:
        loads.append(f"{report['machine']['load_average']:.2f} at the start of the report")
    return "; ".join(loads) if loads else None
