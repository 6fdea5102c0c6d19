#!/usr/bin/env bash
# Create (or reuse) the Python venv for one Blender line and print its path.
#
#   tools/venv.sh [5.0|4.5]        (default 5.0)
#
# The venv lives in ${MAKEUP_SKIN_CACHE:-$HOME/.cache/makeup_skin}/venv-<line>-<hash>, where
# <hash> is taken from requirements/bpy<line>.txt, so a second run only checks a marker file and a
# changed requirements file gets a fresh venv. A venv without the marker (an install that was
# interrupted or failed) is deleted and rebuilt. Everything is logged to stderr; the last line on
# stdout is the venv path, so `VENV=$(tools/venv.sh 4.5)` works.
#
# Environment: MAKEUP_SKIN_CACHE (cache folder), MAKEUP_SKIN_PYTHON (a CPython 3.11 to build from;
# bpy wheels exist for 3.11 only).
set -euo pipefail

# Bump to force every cached venv to be rebuilt when this recipe changes.
RECIPE=1
APT_PACKAGES=(libx11-6 libxrender1 libxfixes3 libxi6 libxkbcommon0 libsm6 libgl1 libegl1)

log() { printf 'venv.sh: %s\n' "$*" >&2; }
die() { log "error: $*"; exit 1; }

line="${1:-5.0}"
case "$line" in
    5.0 | 4.5) ;;
    *) die "unknown Blender line '$line' (expected 5.0 or 4.5)" ;;
esac

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
req="$repo/requirements/bpy${line/./}.txt"
[[ -f "$req" ]] || die "missing $req"

cache="${MAKEUP_SKIN_CACHE:-$HOME/.cache/makeup_skin}"
mkdir -p "$cache"
hash="$( { echo "recipe=$RECIPE"; cat "$req"; } | sha256sum | cut -c1-12)"
venv="$cache/venv-$line-$hash"
marker="$venv/.makeup_skin_ok"

# --- system libraries that `import bpy` loads (Debian/Ubuntu only) ---------------------------
ensure_apt_packages() {
    command -v dpkg-query > /dev/null || return 0
    local missing=() pkg
    for pkg in "${APT_PACKAGES[@]}"; do
        if ! dpkg-query -W -f='${Status}' "$pkg" 2> /dev/null | grep -q 'install ok installed'; then
            missing+=("$pkg")
        fi
    done
    ((${#missing[@]})) || return 0
    local sudo=()
    if [[ $(id -u) -ne 0 ]]; then
        if command -v sudo > /dev/null && sudo -n true 2> /dev/null; then
            sudo=(sudo -n)
        else
            log "warning: missing ${missing[*]} and not root: install them or 'import bpy' fails"
            return 0
        fi
    fi
    log "installing system libraries for bpy: ${missing[*]}"
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq >&2
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive \
        apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
}

# --- the interpreter --------------------------------------------------------------------------
find_python() {
    local cand
    for cand in "${MAKEUP_SKIN_PYTHON:-}" python3.11 python3; do
        [[ -n "$cand" ]] || continue
        command -v "$cand" > /dev/null 2>&1 || continue
        if "$cand" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' 2> /dev/null; then
            echo "$cand"
            return 0
        fi
    done
    return 1
}

venv_ok() {
    [[ -f "$marker" ]] && "$venv/bin/python" -c 'import sys' 2> /dev/null
}

ensure_apt_packages

# Fast path: no lock needed to read a finished venv.
if venv_ok; then
    echo "$venv"
    exit 0
fi

# Serialise builders (two test runs starting at once must not pip into the same folder).
exec 9> "$cache/venv-$line.lock"
flock 9
if venv_ok; then # someone else finished it while we waited
    echo "$venv"
    exit 0
fi

if [[ -e "$venv" ]]; then
    log "removing incomplete venv $venv"
    rm -rf "$venv"
fi

python="$(find_python)" || die "no CPython 3.11 found (bpy needs 3.11); set MAKEUP_SKIN_PYTHON"
log "building $venv from $req with $python (takes a few minutes once)"
start=$SECONDS
"$python" -m venv "$venv" >&2
"$venv/bin/python" -m pip install --quiet --progress-bar off --upgrade pip >&2 ||
    log "warning: could not upgrade pip, continuing with the bundled one"
"$venv/bin/python" -m pip install --quiet --progress-bar off -r "$req" >&2
# Smoke test before declaring the venv good: bpy needs the system libraries above.
"$venv/bin/python" -c 'import bpy, numpy, scipy, OpenImageIO, pytest
print("venv.sh: bpy", bpy.app.version_string, "numpy", numpy.__version__,
      "scipy", scipy.__version__)' >&2
{
    echo "requirements=$req"
    echo "hash=$hash"
    echo "built=$(date -u +%Y-%m-%dT%H:%M:%SZ) in $((SECONDS - start)) s"
} > "$marker"
log "venv ready in $((SECONDS - start)) s"
echo "$venv"
