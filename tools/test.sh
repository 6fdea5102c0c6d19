#!/usr/bin/env bash
# The project's test command (what CI runs through .ci/run).
#
#   tools/test.sh [extra pytest args for the main run]
#   tools/test.sh -m "not slow"    # the fast tier (no renders or exact-model sweeps)
#
# 1. Blender 5.0 venv: `ruff check .`, the type check (`mypy`, configured in pyproject.toml),
#    the import contract (tools/check_imports.py), then the whole suite, `pytest -q`.
# 2. If MAKEUP_SKIN_BLENDER_LINES (default "5.0 4.5") names 4.5: the Blender-side tests,
#    `pytest -q -m bpy`, on the 4.5 LTS venv.
# pytest runs on every core (pytest-xdist, `-n auto`, a test file per worker at a time);
# MAKEUP_SKIN_PYTEST_WORKERS=0 runs it in one process.
# Venvs come from tools/venv.sh (built once, then cached). Exits non-zero on any failure,
# including a pytest run that collects no test (exit 5). Each pytest run prints its wall time
# and is limited to MAKEUP_SKIN_PYTEST_TIMEOUT seconds (default 2700) so that a hung Blender
# cannot stall CI: the whole of this script takes about 6 minutes on a quiet 2-core machine
# (docs/architecture.md, "Tests"), so the limit leaves room for a machine four times slower
# and busy, and the whole CI run (90 minutes) for both Blender lines.
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo"
lines="${MAKEUP_SKIN_BLENDER_LINES:-5.0 4.5}"
limit="${MAKEUP_SKIN_PYTEST_TIMEOUT:-2700}"
workers="${MAKEUP_SKIN_PYTEST_WORKERS:-auto}"

run_pytest() { # run_pytest <venv> <label> <pytest args...>
    local venv="$1" label="$2" rc=0
    shift 2
    echo "== [$label] pytest $*"
    local began=$SECONDS
    timeout --kill-after=30 "$limit" "$venv/bin/python" -m pytest -n "$workers" --dist loadfile "$@" || rc=$?
    echo "== [$label] pytest took $((SECONDS - began)) s (limit $limit s)"
    case $rc in
        0) ;;
        5) echo "== [$label] FAILED: pytest collected no test" >&2 ;;
        124 | 137) echo "== [$label] FAILED: pytest timed out after ${limit} s" >&2 ;;
        *) echo "== [$label] FAILED: pytest exited $rc" >&2 ;;
    esac
    return "$rc"
}

for line in $lines; do
    [[ $line == 5.0 || $line == 4.5 ]] || { echo "unknown Blender line '$line'" >&2; exit 2; }
done
[[ " $lines " == *" 5.0 "* ]] || echo "== warning: 5.0 not in MAKEUP_SKIN_BLENDER_LINES: no ruff, no full suite" >&2

start=$SECONDS
if [[ " $lines " == *" 5.0 "* ]]; then
    venv50="$(tools/venv.sh 5.0 | tail -n 1)"
    echo "== [5.0] ruff check ."
    "$venv50/bin/ruff" check .
    echo "== [5.0] type check (mypy)"
    "$venv50/bin/mypy"
    echo "== [5.0] import contract (tools/check_imports.py)"
    "$venv50/bin/python" tools/check_imports.py
    run_pytest "$venv50" 5.0 -q "$@"
fi

if [[ " $lines " == *" 4.5 "* ]]; then
    venv45="$(tools/venv.sh 4.5 | tail -n 1)"
    run_pytest "$venv45" 4.5 -q -m bpy
fi
echo "== tools/test.sh: all passed in $((SECONDS - start)) s (Blender lines: $lines)"
