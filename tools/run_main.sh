#!/usr/bin/env bash
# The main job: set up the Blender 5.0 venv, bake the default preset's lookup tables into out/
# and render a reference sphere with them to out/sphere.png.
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo"
venv="$(tools/venv.sh 5.0 | tail -n 1)"
mkdir -p out
"$venv/bin/python" -m lut_baker bake --preset paper --out out/
"$venv/bin/python" tools/render_sphere.py --tables out/paper.exr --out out/sphere.png
echo "wrote $repo/out/sphere.png"
