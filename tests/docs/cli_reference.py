#!/usr/bin/env python3
"""Checks docs/cli.md against the tool it describes, as the tool says it
is today:

* every option that `collide <command> --help` lists, for every command
  the main help names, appears in docs/cli.md (as `--option`, a whole
  word);
* every key that `collide solve --stats` prints, and every key `--check`
  adds, appears in docs/cli.md between backquotes (`key`), where the page
  says what it means.

The tool is this build's; a scene is solved from data/example in a scratch
directory. Nothing is written into the source tree.

usage: cli_reference.py --root SOURCE --collide PATH --work DIR
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys

OPTION = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")


def commands(collide: str) -> list[str]:
    """The commands the main help lists (its 'commands:' section)."""
    text = subprocess.run([collide, "--help"], capture_output=True, text=True, check=True).stdout
    section = text.split("commands:", 1)[1].split("\n\n", 1)[0]
    return [m.group(1) for m in re.finditer(r"^  (\w+)\s", section, re.M)]


def options(collide: str, command: str) -> list[str]:
    """The options `collide <command> --help` lists, in order of appearance."""
    text = subprocess.run([collide, command, "--help"], capture_output=True, text=True, check=True).stdout
    seen = []
    for name in OPTION.findall(text):
        if name not in seen and name != "--help":
            seen.append(name)
    return seen


def stats_keys(collide: str, root: str, work: str) -> list[str]:
    """The keys of `collide solve --stats --check` on the example scene."""
    example = os.path.join(root, "data", "example")
    r = subprocess.run([collide, "solve", "--bodies", os.path.join(example, "bodies.csv"), "--contacts",
                        os.path.join(example, "contacts.csv"), "--out-bodies", os.path.join(work, "ob.csv"),
                        "--out-impulses", os.path.join(work, "oj.csv"), "--stats", "--check"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"collide solve --stats --check exited with {r.returncode}:\n{r.stderr}")
    lines = [line for line in r.stderr.splitlines() if line.startswith("{")]
    if len(lines) != 1:
        raise SystemExit(f"collide solve --stats printed no single JSON line on stderr:\n{r.stderr}")
    return list(json.loads(lines[0]))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", required=True, help="the source tree")
    ap.add_argument("--collide", required=True, help="the collide executable")
    ap.add_argument("--work", required=True, help="a scratch directory (emptied)")
    args = ap.parse_args()
    collide = os.path.abspath(args.collide)
    work = os.path.abspath(args.work)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    with open(os.path.join(args.root, "docs", "cli.md"), encoding="utf-8") as f:
        page = f.read()
    documented_options = set(OPTION.findall(page))
    missing = []
    listed = commands(collide)
    if not {"solve", "gen", "convert", "report"} <= set(listed):
        missing.append(f"the main help's commands are {listed}: expected solve, gen, convert and report among them")
    for command in listed:
        for option in options(collide, command):
            if option not in documented_options:
                missing.append(f"`collide {command}` option {option} (in its --help) is not in docs/cli.md")
    keys = stats_keys(collide, args.root, work)
    for key in keys:
        if f"`{key}`" not in page:
            missing.append(f"`collide solve --stats` key {key!r} is not in docs/cli.md as `{key}`")
    for line in missing:
        print(line, file=sys.stderr)
    print(f"{len(listed)} commands, {len(keys)} --stats keys checked against docs/cli.md; {len(missing)} missing")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
