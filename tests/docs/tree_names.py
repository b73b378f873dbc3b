#!/usr/bin/env python3
"""Every repository path and header the tree names exists.

    tree_names.py [--root DIR]

Reads the comments of the code (C++ `//` and `/* */`; `#` of Python, shell,
CMake and the CI script; Python's triple-quoted strings) and the whole text
of every Markdown file, and checks each name it finds there:

  * a path under a top-level folder of the repository (core/src/lanes.hpp,
    tests/core/, docs/decisions/0005-...md, fuzz/corpus/<target>/): the file or
    folder exists; a glob (io/src/csv_*.cpp) matches something; a placeholder
    (<target>, ...) is checked up to the folder before it;
  * a public header in its include form (collide/solve.hpp,
    collide/io/scene.hpp, or io/scene.hpp from collide/): it is in
    core/include, io/include or eval/include;
  * a file name of the code's own kinds (.hpp, .cpp) without a folder: some
    file of the tree has that name;
  * a Markdown link to a local file ([x](decisions/0002-binary-scene-files.md)):
    the file exists, relative to the Markdown file.

docs/decisions/ is exempt: a decision record tells what the tree was when it
was written. The check prints every name that does not exist, with the file
and line that names it, and exits 1 if there is one. No build is needed.
"""

import argparse
import fnmatch
import io
import os
import re
import sys
import tokenize

# The folders at the top of the repository; a path is a name that starts
# with one of them.
TOP = ("core", "io", "eval", "cli", "bench", "python", "tests", "docs", "scripts", "cmake", "examples", "fuzz",
       "data", ".ci")
# Folders that hold no text of the project's own: build trees, caches, data.
SKIP_DIRS = {".git", "__pycache__", ".pytest_cache", "corpus"}
SKIP_PREFIXES = ("build",)
# Exempt: history.
EXEMPT = (os.path.join("docs", "decisions") + os.sep,)

# Names that look like source files of the tree but are the reader's own, in
# examples of how to use collide, or files a build writes.
NOT_TREE_FILES = {
    "my_sim.cpp", "my_tool.cpp",  # docs/embedding.md: the reader's program
    "all_headers.cpp",  # tests/package: generated at configure time
}

PATH_RE = re.compile(r"(?<![\w./$@{}-])((?:%s)/[\w./*<>+-]*[\w*>+-](?:/\.\.\.)?)" %
                     "|".join(re.escape(t) for t in TOP))
INCLUDE_RE = re.compile(r"(?<![\w./-])(collide/(?:[\w-]+/)*[\w-]+\.hpp)\b")
BARE_RE = re.compile(r"(?<![\w./<>*-])([\w-]+\.(?:hpp|cpp))\b(?![\w/-])")
LINK_RE = re.compile(r"\]\(([^)\s]+)\)")


def comments_cpp(text):
    """(line, text) of every comment of a C++ file; string and character
    literals are skipped."""
    out = []
    i, n, line = 0, len(text), 1
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append((line, text[i + 2:j]))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j
            body = text[i + 2:j]
            for k, part in enumerate(body.split("\n")):
                out.append((line + k, part))
            line += body.count("\n")
            i = j + 2
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i)
            end = n if end < 0 else end
            line += text.count("\n", i, end)
            i = end + len(m.group(1)) + 2
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            i = j + 1
        else:
            i += 1
    return out


def comments_hash(text):
    """(line, text) of every `#` comment of a shell, CMake or similar file:
    a `#` outside quotes that starts a word."""
    out = []
    for number, raw in enumerate(text.split("\n"), 1):
        quote = None
        for k, c in enumerate(raw):
            if quote:
                if c == "\\" and quote == '"':
                    continue
                if c == quote:
                    quote = None
            elif c in "\"'":
                quote = c
            elif c == "#" and (k == 0 or raw[k - 1] in " \t(;"):
                # ${#array[@]} and $# are not comments.
                out.append((number, raw[k + 1:]))
                break
    return out


def comments_python(text):
    """(line, text) of every comment and triple-quoted string of a Python file."""
    out = []
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
    except (tokenize.TokenError, SyntaxError):
        return comments_hash(text)
    for tok in tokens:
        if tok.type == tokenize.COMMENT:
            out.append((tok.start[0], tok.string[1:]))
        elif tok.type == tokenize.STRING and re.match(r"^[rRbBuUfF]*('''|\"\"\")", tok.string):
            for k, part in enumerate(tok.string.split("\n")):
                out.append((tok.start[0] + k, part))
    return out


def whole_text(text):
    return list(enumerate(text.split("\n"), 1))


def reader(rel):
    name = os.path.basename(rel)
    if name.endswith((".cpp", ".hpp", ".h", ".cc")):
        return comments_cpp
    if name.endswith(".py"):
        return comments_python
    if name.endswith((".sh", ".cmake", ".in", ".toml", ".supp")) or name in ("CMakeLists.txt", "run", ".clang-tidy",
                                                                             ".clang-format", ".gitignore"):
        return comments_hash
    if name.endswith(".md"):
        return whole_text
    return None


class Tree:
    def __init__(self, root):
        self.root = root
        self.files = []
        self.names = set()
        self.dirs = set()
        for dirpath, dirnames, filenames in os.walk(root):
            rel_dir = os.path.relpath(dirpath, root)
            dirnames[:] = [d for d in dirnames
                           if d not in SKIP_DIRS and not d.startswith(SKIP_PREFIXES) and
                           not (d.startswith(".") and d != ".ci")]
            if rel_dir != ".":
                self.dirs.add(rel_dir.replace(os.sep, "/"))
            for f in filenames:
                rel = os.path.normpath(os.path.join(rel_dir, f)).replace(os.sep, "/")
                self.files.append(rel)
                self.names.add(f)
        self.all_paths = set(self.files) | self.dirs

    def exists(self, rel):
        rel = rel.rstrip("/")
        return rel in self.all_paths or os.path.exists(os.path.join(self.root, rel))

    def glob(self, pattern):
        pattern = pattern.rstrip("/")
        return any(fnmatch.fnmatchcase(p, pattern) for p in self.all_paths)


def check_path(tree, token):
    """True when the path `token` names something in the tree. A header of
    io or eval may be named from collide/, as its #include does
    (io/scene_io.hpp for collide/io/scene_io.hpp)."""
    token = token.rstrip(".")
    if token.endswith(".hpp") and token.startswith(("io/", "eval/")) and check_include(tree, "collide/" + token):
        return True
    # A placeholder: the folder before it must exist.
    cut = min([token.find(m) for m in ("<", "...", "{") if m in token] or [-1])
    if cut >= 0:
        head = token[:cut]
        head = head[:head.rfind("/") + 1] if "/" in head else head
        return tree.exists(head) if head else True
    if "*" in token:
        return tree.glob(token)
    return tree.exists(token)


def check_include(tree, token):
    for base in ("core/include", "io/include", "eval/include"):
        if tree.exists(base + "/" + token):
            return True
    return False


def check_link(tree, md_rel, target):
    if re.match(r"^[a-z]+:", target) or target.startswith("#"):
        return True
    target = target.split("#", 1)[0]
    if not target:
        return True
    path = os.path.normpath(os.path.join(os.path.dirname(md_rel), target)).replace(os.sep, "/")
    return tree.exists(path)


def problems(tree):
    found = []
    for rel in sorted(tree.files):
        if rel.startswith(tuple(e.replace(os.sep, "/") for e in EXEMPT)):
            continue
        read = reader(rel)
        if read is None:
            continue
        try:
            with open(os.path.join(tree.root, rel), encoding="utf-8") as f:
                text = f.read()
        except (UnicodeDecodeError, OSError):
            continue
        for line, part in read(text):
            for m in PATH_RE.finditer(part):
                if not check_path(tree, m.group(1)):
                    found.append((rel, line, m.group(1), "no such path in the repository"))
            for m in INCLUDE_RE.finditer(part):
                if not check_include(tree, m.group(1)):
                    found.append((rel, line, m.group(1), "no such public header (core/, io/, eval/include)"))
            for m in BARE_RE.finditer(part):
                name = m.group(1)
                if name not in tree.names and name not in NOT_TREE_FILES:
                    found.append((rel, line, name, "no file of that name in the repository"))
            if rel.endswith(".md"):
                for m in LINK_RE.finditer(part):
                    if not check_link(tree, rel, m.group(1)):
                        found.append((rel, line, m.group(1), "link to a file that does not exist"))
    return found


def self_test():
    """The readers and the checks on made-up text: a check that cannot fail
    would pass any tree."""
    cpp = 'int x = 1;  // see core/src/lanes.hpp\nconst char* s = "// tests/nothing.cpp";\n/* a\n   b docs/x.md */'
    assert comments_cpp(cpp) == [(1, " see core/src/lanes.hpp"), (3, " a"), (4, "   b docs/x.md ")], comments_cpp(cpp)
    sh = 'echo "# not/a comment" # tests/a.sh\nn=${#arr[@]}\n# core/x'
    assert comments_hash(sh) == [(1, " tests/a.sh"), (3, " core/x")], comments_hash(sh)
    py = '"""Doc core/a.py."""\nx = "core/b.py"  # core/c.py\n'
    assert [t for _, t in comments_python(py)] == ['"""Doc core/a.py."""', " core/c.py"], comments_python(py)
    paths = [m.group(1) for m in PATH_RE.finditer(
        "core/src/lanes.hpp, tests/kernel/..., build/tests/x, ${DIR}/core/y, io/src/csv_*.cpp and docs/decisions/.")]
    assert paths == ["core/src/lanes.hpp", "tests/kernel/...", "io/src/csv_*.cpp", "docs/decisions"], paths
    assert [m.group(1) for m in INCLUDE_RE.finditer("<collide/io/scene.hpp> and collide/solve.hpp")] == [
        "collide/io/scene.hpp", "collide/solve.hpp"]
    assert [m.group(1) for m in BARE_RE.finditer("lanes.hpp, core/src/x.hpp, <a.hpp>, test_*.cpp")] == ["lanes.hpp"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    args = ap.parse_args()
    self_test()
    tree = Tree(os.path.abspath(args.root))
    if not any(f.startswith("core/src/") for f in tree.files):
        print(f"tree_names: {args.root} is not a collide checkout (no core/src/)", file=sys.stderr)
        return 2
    found = problems(tree)
    for rel, line, name, why in found:
        print(f"{rel}:{line}: {name}: {why}")
    if found:
        print(f"tree_names: {len(found)} name(s) of things that do not exist; name what exists, or say what is meant",
              file=sys.stderr)
        return 1
    print(f"tree_names: every path and header named in {len(tree.files)} files exists")
    return 0


if __name__ == "__main__":
    sys.exit(main())
