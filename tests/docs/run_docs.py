#!/usr/bin/env python3
"""Runs the code blocks of README.md and docs/*.md as a reader would, and
checks the output they show.

The files are read when the test runs, so a block added to any of them is
run without touching this script. Every fenced block is one of:

* ```sh (or console, bash, shell): shell commands, run with bash in a fresh
  directory that holds `build/collide` (this build's tool), `build/python`
  (its Python package) and the source tree's other entries (`data/`,
  `scripts/`, ...), so that the paths of the docs work as written. In a block
  whose lines start with "$ ", each such line (with its "\\"-continued lines)
  is one command and the lines up to the next "$ " are the output it shows,
  stdout and stderr together; without "$ ", every line is a command and no
  output is shown. A command must exit 0.
* ```python: a script, saved as a file and run with this build's module on
  PYTHONPATH (so that code under `if __name__ == "__main__":` runs as it
  does for a reader who saves the snippet). It must exit 0.
* a block without a language: text (a formula, a synopsis, a table header,
  output shown after prose), not run.
* any other language (cpp, cmake, json, ...): must be marked not run.

Markers, HTML comments on the line just before a block (invisible on the
rendered page):

* `<!-- docs-test: not run: REASON -->`: the block is not run, for REASON
  (it builds everything, it needs another machine, it is a fragment that a
  named test compiles, ...). Every such block is listed when the test runs.
* `<!-- docs-test: setup` ... `-->`: Python lines run before the block (the
  names a fragment takes from the text around it: a scene, a count).

Shown output is compared line by line, exactly, with two narrow rules:

* a shown line "..." stands for any number of lines;
* a shown JSON object (a line starting with "{", continued on the
  following lines until its braces close, as --stats prints one object on
  one line) is matched as an object: "..." between members stands for
  members left out, every shown member must be there, in the order shown,
  with the value shown, except the timings, whose values are the machine's
  and only have to be numbers >= 0: members named `*_seconds`,
  `*_per_second` and `io_fraction`.

usage: run_docs.py --root SOURCE --work DIR --kind sh --collide PATH [--python-path DIR]
       run_docs.py --root SOURCE --work DIR --kind python --python PYTHON
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass, field

SHELL_LANGUAGES = {"sh", "console", "bash", "shell"}
MARKER = re.compile(r"^<!--\s*docs-test:\s*(.*?)\s*(-->)?\s*$")
FENCE = re.compile(r"^(\s*)(```+)\s*([\w+-]*)\s*$")
TIMEOUT_SECONDS = 300


@dataclass
class Block:
    path: str  # relative to the root
    line: int  # 1-based line of the opening fence
    language: str
    lines: list[str]
    not_run: str | None = None  # the reason
    setup: list[str] = field(default_factory=list)

    @property
    def where(self) -> str:
        return f"{self.path}:{self.line}"


def doc_files(root: str) -> list[str]:
    docs = sorted(f for f in os.listdir(os.path.join(root, "docs")) if f.endswith(".md"))
    return ["README.md"] + [os.path.join("docs", f) for f in docs]


def blocks_of(root: str, path: str) -> list[Block]:
    """The fenced blocks of one Markdown file, with their markers."""
    with open(os.path.join(root, path), encoding="utf-8") as f:
        text = f.read().split("\n")
    blocks = []
    i = 0
    pending: tuple[str, list[str]] | None = None  # the marker just read: (kind, setup lines)
    while i < len(text):
        line = text[i]
        marker = MARKER.match(line)
        if marker:
            body, closed = marker.group(1), marker.group(2)
            if body.startswith("not run:"):
                if not closed or not body[len("not run:"):].strip():
                    raise SystemExit(f"{path}:{i + 1}: write <!-- docs-test: not run: REASON --> on one line")
                pending = ("not run", [body[len("not run:"):].strip()])
            elif body == "setup" and not closed:
                setup = []
                i += 1
                while i < len(text) and text[i].strip() != "-->":
                    setup.append(text[i])
                    i += 1
                if i == len(text):
                    raise SystemExit(f"{path}: the setup marker before line {i} is not closed with a '-->' line")
                pending = ("setup", setup)
            else:
                raise SystemExit(f"{path}:{i + 1}: unknown docs-test marker '{body}' (the kinds: 'not run: "
                                 f"REASON' on one line, 'setup' followed by Python lines and a '-->' line)")
            i += 1
            j = i  # other one-line comments may stand between (<!-- minimal.cpp: begin -->)
            while j < len(text) and re.match(r"^<!--.*-->\s*$", text[j]) and not MARKER.match(text[j]):
                j += 1
            if j == len(text) or not FENCE.match(text[j]):
                raise SystemExit(f"{path}:{i}: a docs-test marker must stand just before a code block")
            continue
        fence = FENCE.match(line)
        if fence:
            indent, ticks, language = fence.groups()
            start = i
            body_lines = []
            i += 1
            while i < len(text) and not (text[i].strip().startswith(ticks) and text[i].strip().strip("`") == ""):
                body_lines.append(text[i][len(indent):] if text[i].startswith(indent) else text[i].lstrip())
                i += 1
            block = Block(path, start + 1, language.lower(), body_lines)
            if pending:
                if pending[0] == "not run":
                    block.not_run = pending[1][0]
                else:
                    block.setup = pending[1]
                pending = None
            blocks.append(block)
        i += 1
    return blocks


# ---------------------------------------------------------------------------
# Shown output against actual output
# ---------------------------------------------------------------------------

TIMING = re.compile(r"(_seconds|_per_second)$|^io_fraction$")
ELLIPSIS = object()


class Mismatch(Exception):
    pass


def json_pattern(text: str):
    """A shown JSON object as a list of (key, value) members and ELLIPSIS."""
    marked = re.sub(r"(?<=[{,])\s*\.\.\.\s*(?=[,}])", lambda m: ' "\\u0000...": null', text)
    try:
        return json.loads(marked, object_pairs_hook=lambda pairs: [
            ELLIPSIS if k == "\u0000..." else (k, v) for k, v in pairs])
    except json.JSONDecodeError as e:
        raise Mismatch(f"the shown JSON does not parse ({e}): {text}") from e


def match_sequence(pattern, items, match_item) -> bool:
    """Whether items match pattern, where ELLIPSIS matches any run of items."""
    if not pattern:
        return not items
    if pattern[0] is ELLIPSIS:
        return any(match_sequence(pattern[1:], items[k:], match_item) for k in range(len(items) + 1))
    return bool(items) and match_item(pattern[0], items[0]) and match_sequence(pattern[1:], items[1:], match_item)


def json_value_matches(key, shown, actual) -> bool:
    if TIMING.search(key or ""):
        return isinstance(actual, (int, float)) and not isinstance(actual, bool) and actual >= 0
    if isinstance(shown, list) and (not shown or isinstance(shown[0], tuple) or shown[0] is ELLIPSIS):
        return isinstance(actual, list) and json_object_matches(shown, actual)
    return shown == actual


def json_object_matches(pattern, actual_pairs) -> bool:
    return match_sequence(pattern, actual_pairs, lambda p, a: p[0] == a[0] and json_value_matches(p[0], p[1], a[1]))


def shown_items(shown: list[str]):
    """The shown lines, a JSON object spread over several lines joined into one item."""
    items, i = [], 0
    while i < len(shown):
        line = shown[i]
        if line.startswith("{"):
            text = line
            while text.count("{") > text.count("}") and i + 1 < len(shown):
                i += 1
                text += " " + shown[i].strip()
            items.append(("json", text))
        elif line == "...":
            items.append(ELLIPSIS)
        else:
            items.append(("line", line))
        i += 1
    return items


def item_matches(item, actual_line: str) -> bool:
    kind, text = item
    if kind == "line":
        return text == actual_line
    try:
        actual = json.loads(actual_line, object_pairs_hook=lambda pairs: pairs)
    except json.JSONDecodeError:
        return False
    return isinstance(actual, list) and json_object_matches(json_pattern(text), actual)


def check_output(shown: list[str], actual: str) -> None:
    actual_lines = actual.split("\n")
    if actual_lines and actual_lines[-1] == "":
        actual_lines.pop()
    if not match_sequence(shown_items(shown), actual_lines, item_matches):
        raise Mismatch("shown:\n    " + "\n    ".join(shown) + "\nactual:\n    " + "\n    ".join(actual_lines))


# ---------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------


def sandbox(root: str, work: str, block: Block, collide: str | None, python_path: str | None) -> str:
    """A fresh directory laid out like a checkout with a build: the source
    tree's entries linked (read, not written: every block that builds or
    installs is marked not run), build/collide this build's tool, and, for a
    block that names it, build/python a copy of this build's package."""
    name = re.sub(r"[^\w.-]", "_", block.where)
    d = os.path.join(work, name)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "build"))
    for entry in os.listdir(root):
        if entry.startswith(".") or entry.startswith("build"):
            continue
        os.symlink(os.path.join(root, entry), os.path.join(d, entry))
    if collide:
        os.symlink(collide, os.path.join(d, "build", "collide"))
    if python_path and any("build/python" in line for line in block.lines):
        # A copy: a command must not write into this build's own tree.
        shutil.copytree(python_path, os.path.join(d, "build", "python"), symlinks=True,
                        ignore=shutil.ignore_patterns("CMakeFiles", "*.cmake", "Makefile", "docs-*", "tmp"))
    return d


def commands_of(block: Block):
    """(command, shown output lines) pairs of a shell block."""
    lines = [ln for ln in block.lines]
    prompted = any(ln.startswith("$ ") for ln in lines)
    pairs = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if prompted:
            if not line.startswith("$ "):
                raise Mismatch(f"line {i + 1} of the block is output before any command: {line}")
            command = line[2:]
        else:
            if not line.strip() or line.lstrip().startswith("#"):
                i += 1
                continue
            command = line
        while command.endswith("\\") and i + 1 < len(lines):
            i += 1
            command = command + "\n" + lines[i]
        i += 1
        shown = []
        if prompted:
            while i < len(lines) and not lines[i].startswith("$ "):
                shown.append(lines[i])
                i += 1
        pairs.append((command, shown if prompted else None))
    return pairs


def run_shell(block: Block, cwd: str, env: dict) -> int:
    pairs = commands_of(block)
    for command, shown in pairs:
        r = subprocess.run(["bash", "-o", "pipefail", "-c", command], cwd=cwd, env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True, timeout=TIMEOUT_SECONDS)
        if r.returncode != 0:
            raise Mismatch(f"$ {command}\nexited with {r.returncode}:\n{r.stdout}")
        if shown is not None:
            try:
                check_output(shown, r.stdout)
            except Mismatch as e:
                raise Mismatch(f"$ {command}\n{e}") from None
    return len(pairs)


def run_python(block: Block, cwd: str, env: dict, python: str) -> None:
    script = os.path.join(cwd, "snippet.py")
    with open(script, "w", encoding="utf-8") as f:
        f.write("\n".join(block.setup + block.lines) + "\n")
    r = subprocess.run([python, script], cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       text=True, timeout=TIMEOUT_SECONDS)
    if r.returncode != 0:
        raise Mismatch(f"exited with {r.returncode}:\n{r.stdout}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", required=True, help="the source tree")
    ap.add_argument("--work", required=True, help="a scratch directory (emptied)")
    ap.add_argument("--kind", required=True, choices=["sh", "python"], help="which blocks to run")
    ap.add_argument("--collide", help="the collide executable (build/collide)")
    ap.add_argument("--python-path", help="the directory holding this build's collide package (build/python)")
    ap.add_argument("--python", default=sys.executable, help="the interpreter of the Python blocks")
    args = ap.parse_args()
    if args.kind == "sh" and not args.collide:
        ap.error("--kind sh needs --collide")
    root = os.path.abspath(args.root)
    work = os.path.abspath(args.work)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    collide = os.path.abspath(args.collide) if args.collide else None
    python_path = os.path.abspath(args.python_path) if args.python_path else None
    env = dict(os.environ)
    if python_path:
        env["PYTHONPATH"] = python_path + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")

    blocks = [b for path in doc_files(root) for b in blocks_of(root, path)]
    failures, ran, not_run = [], [], []
    for block in blocks:
        language = block.language
        if block.not_run is not None:
            not_run.append(block)
            continue
        if not language:
            continue  # text: a formula, a synopsis, output shown after prose
        if language in SHELL_LANGUAGES:
            kind = "sh"
        elif language == "python":
            kind = "python"
        else:
            if args.kind == "sh":  # reported once, by the shell run
                failures.append((block, f"a ```{language} block is not run: run it as sh or python, or mark it "
                                        f"<!-- docs-test: not run: REASON -->"))
            continue
        if block.setup and kind != "python":
            failures.append((block, "a setup marker belongs before a python block"))
            continue
        if kind != args.kind:
            continue
        cwd = sandbox(root, work, block, collide, python_path)
        try:
            if kind == "sh":
                n = run_shell(block, cwd, env)
                print(f"ran   {block.where} (sh, {n} command{'s' if n != 1 else ''})", flush=True)
            else:
                run_python(block, cwd, env, args.python)
                print(f"ran   {block.where} (python)", flush=True)
            ran.append(block)
            shutil.rmtree(cwd, ignore_errors=True)  # a failed block's directory stays, to look into
        except (Mismatch, subprocess.TimeoutExpired) as e:
            failures.append((block, f"{e}\n(its directory: {cwd})"))
    for block in not_run:
        if args.kind == "sh":
            print(f"not run {block.where} ({block.language or 'text'}): {block.not_run}")
    for block, why in failures:
        print(f"\nFAILED {block.where}:\n{why}", file=sys.stderr)
    print(f"\n{len(ran)} {args.kind} block(s) run, {len(failures)} failed"
          + (f"; {len(not_run)} block(s) marked not run" if args.kind == "sh" else ""))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
