#!/usr/bin/env bash
# clang-tidy (Debian's clang-tidy 14, the checks of .clang-tidy) on C++ files
# of the project, with the compile commands of a configured build.
#
#   scripts/clang-tidy.sh [-p BUILD] FILE...          the files named
#   scripts/clang-tidy.sh [-p BUILD] --changed [BASE] the C++ files a change
#                                                     touches against BASE
#
# BUILD is a configured build directory (default build/: scripts/build.sh,
# or `cmake --preset release`); its compile_commands.json, which every preset
# of CMakePresets.json writes (CMAKE_EXPORT_COMPILE_COMMANDS), gives each
# file's flags.
# With --changed, BASE defaults to $COLLIDE_TIDY_BASE, else to where HEAD left
# the branch main (git merge-base main HEAD), else, on main itself, to HEAD~1;
# the change is BASE against the working tree, added and modified files only.
#
# A source file is checked as its own translation unit (the first of its
# compile commands: the kernel, compiled once per ISA, is checked once). A
# header is checked through a translation unit that includes it: a changed
# source file that does, else the first source file of the build that does.
# Only diagnostics in the files asked about are reported (clang-tidy's
# -line-filter), so a change answers for its own files; every diagnostic is
# an error (the exit status is 1 if there is one). The files are checked in
# parallel on every core.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

build="$root/build"
changed=""
base=""
files=()
while [ $# -gt 0 ]; do
  case "$1" in
    -p) build="$(cd "$2" && pwd)"; shift 2 ;;
    --changed)
      changed=1; shift
      if [ $# -gt 0 ] && [ "${1#-}" = "$1" ] && git rev-parse --verify -q "$1^{commit}" >/dev/null; then
        base="$1"; shift
      fi ;;
    -h|--help) sed -n '2,24p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "clang-tidy.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) files+=("$1"); shift ;;
  esac
done

tidy="$(command -v clang-tidy-14 || command -v clang-tidy || true)"
if [ -z "$tidy" ]; then
  echo "clang-tidy.sh: clang-tidy not found (Debian: apt-get install clang-tidy-14; scripts/install-deps.sh)" >&2
  exit 2
fi
if [ ! -f "$build/compile_commands.json" ]; then
  echo "clang-tidy.sh: $build/compile_commands.json not found: configure first (cmake --preset release, or -DCMAKE_EXPORT_COMPILE_COMMANDS=ON)" >&2
  exit 2
fi

# The project's own C++ files: the libraries, the tools and the tests.
is_ours() {
  case "$1" in
    core/*|io/*|eval/*|cli/*|bench/*|python/src/*|tests/*|fuzz/*|examples/*) ;;
    *) return 1 ;;
  esac
  case "$1" in
    *.cpp|*.hpp) return 0 ;;
    *) return 1 ;;
  esac
}

if [ -n "$changed" ]; then
  if [ -z "$base" ]; then
    base="${COLLIDE_TIDY_BASE:-}"
  fi
  if [ -z "$base" ]; then
    base="$(git merge-base main HEAD 2>/dev/null || true)"
    if [ -z "$base" ] || [ "$base" = "$(git rev-parse HEAD)" ]; then
      base="$(git rev-parse -q --verify HEAD~1 || true)"
    fi
  fi
  if [ -z "$base" ]; then
    echo "clang-tidy.sh: no base commit to compare with (give one: --changed BASE)" >&2
    exit 2
  fi
  while IFS= read -r f; do files+=("$f"); done < <(git diff --name-only --diff-filter=AMR "$base" --)
  echo "clang-tidy.sh: the change against $(git rev-parse --short "$base")"
fi

wanted=()
for f in "${files[@]}"; do
  f="${f#./}"
  f="${f#"$root"/}"
  if [ ! -f "$f" ]; then
    echo "clang-tidy.sh: no such file: $f" >&2
    exit 2
  fi
  if is_ours "$f"; then
    wanted+=("$f")
  elif [ -z "$changed" ]; then
    echo "clang-tidy.sh: $f is not a C++ file of the project (core, io, eval, cli, bench, python/src, tests, fuzz, examples)" >&2
    exit 2
  fi
done
if [ ${#wanted[@]} -eq 0 ]; then
  echo "clang-tidy.sh: no C++ file to check"
  exit 0
fi

# Translation units, the files whose diagnostics count, as a JSON line
# filter; a header without a translation unit in this build is an error.
plan="$(python3 - "$build/compile_commands.json" "$root" "${wanted[@]}" <<'PY'
import collections, json, os, re, subprocess, sys
db_path, root, wanted = sys.argv[1], sys.argv[2], sys.argv[3:]
sources = []
for entry in json.load(open(db_path)):
    path = os.path.normpath(os.path.join(entry["directory"], entry["file"]))
    rel = os.path.relpath(path, root)
    if rel not in sources and not rel.startswith(".."):
        sources.append(rel)
known = set(sources)
# Who includes whom, among the project's files: the path an #include gives,
# in quotes or angle brackets, names the tracked file whose path ends with it.
tracked = subprocess.run(["git", "-C", root, "ls-files", "*.cpp", "*.hpp"], capture_output=True, text=True,
                         check=True).stdout.split()
by_name = collections.defaultdict(list)
for f in tracked:
    by_name[os.path.basename(f)].append(f)
included_by = collections.defaultdict(set)
for f in tracked:
    try:
        text = open(os.path.join(root, f), encoding="utf-8").read()
    except OSError:
        continue
    for inc in re.findall(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]', text, re.M):
        for target in by_name.get(os.path.basename(inc), []):
            if target.endswith(inc):
                included_by[target].add(f)
def unit_for(header, preferred):
    """A source of the build that includes `header`, directly or through
    other headers: one of `preferred` if it can, the nearest otherwise."""
    seen, queue, found = {header}, collections.deque([header]), []
    while queue:
        f = queue.popleft()
        for g in sorted(included_by[f]):
            if g in seen:
                continue
            seen.add(g)
            if g in known:
                found.append(g)
            queue.append(g)
    return next((g for g in found if g in preferred), found[0] if found else None)
units, missing = [], []
for f in wanted:
    if f.endswith(".cpp"):
        if f in known:
            units.append(f)
        else:
            missing.append(f + " (not compiled in this build)")
for f in wanted:
    if f.endswith(".hpp"):
        unit = unit_for(f, set(units))
        if unit is None:
            missing.append(f + " (no source of this build includes it)")
        elif unit not in units:
            units.append(unit)
print(json.dumps({"units": units, "missing": missing, "filter": [{"name": os.path.join(root, f)} for f in wanted]}))
PY
)"
missing="$(python3 -c 'import json,sys; print("\n".join(json.loads(sys.argv[1])["missing"]))' "$plan")"
if [ -n "$missing" ]; then
  echo "clang-tidy.sh: cannot check:" >&2
  echo "$missing" | sed 's/^/  /' >&2
  exit 2
fi
mapfile -t units < <(python3 -c 'import json,sys; print("\n".join(json.loads(sys.argv[1])["units"]))' "$plan")
filter="$(python3 -c 'import json,sys; print(json.dumps(json.loads(sys.argv[1])["filter"]))' "$plan")"
echo "clang-tidy.sh: ${#wanted[@]} file(s) through ${#units[@]} translation unit(s), $("$tidy" --version | grep -o 'version [0-9.]*')"

# Flags of GCC that clang does not know are not findings.
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
jobs="$(nproc)"
status=0
printf '%s\n' "${units[@]}" | xargs -P "$jobs" -I{} sh -c '
  log="$1/$(echo "$2" | tr / _).log"
  if "$3" -p "$4" --quiet --warnings-as-errors="*" --line-filter="$5" \
       --extra-arg=-Wno-unknown-warning-option --extra-arg=-Wno-ignored-optimization-argument "$2" >"$log" 2>&1; then
    rm -f "$log"
  else
    exit 1
  fi' _ "$out" {} "$tidy" "$build" "$filter" || status=1
for log in "$out"/*.log; do
  [ -e "$log" ] || continue
  # clang-tidy's own summary lines ("N warnings generated") say nothing here.
  grep -v -E '^[0-9]+ warnings? (and [0-9]+ errors? )?generated\.$|^Suppressed [0-9]+ warnings|^Use -header-filter' "$log" || true
done
if [ "$status" -ne 0 ]; then
  echo "clang-tidy.sh: findings above (fix them, or say in a NOLINT comment why the code is right)" >&2
  exit 1
fi
echo "clang-tidy.sh: no findings"
