#!/usr/bin/env bash
# Set up and run the whole test suite: every tier on pip bpy 5.0 (the last for Python 3.11) and on the newest,
# 5.3 (Python 3.13, through pyenv), then the Blender and GPU tiers on 5.2 LTS and on the oldest, 4.2 LTS, and
# the real-Blender tier (tests/ui: Debian's Blender 4.3 in a chroot, scripts/real_blender.sh; needs root).  The
# scores against the Monte Carlo reference (marker "reference", about 3 min a tier) and the GPU run's smoke run
# (marker "one_tier", 15-40 s) run on 5.0 alone: the same GLSL, maths and script on every Blender, and the suite
# stays within 30 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_venv.sh .venv requirements.txt
bash scripts/setup_venv.sh .venv-bpy42 requirements-oldest-blender.txt
python313=$(command -v python3.13 || echo "$HOME/.pyenv/versions/3.13.0/bin/python3.13")
PYENV_VERSION=3.13.0 PYTHON=$python313 bash scripts/setup_venv.sh .venv-bpy53 requirements-newest-blender.txt
PYENV_VERSION=3.13.0 PYTHON=$python313 bash scripts/setup_venv.sh .venv-bpy52 requirements-lts-blender.txt

version() { "$1/bin/python" -c 'import bpy; print(bpy.app.version_string)'; }

# One pytest worker a core, at most 4 (pytest-xdist; each is a bpy process with its own GPU context and disk
# cache): on 2 cores the tiers take 0.65-0.7 of their serial time, as Blender, numpy and llvmpipe leave a core
# idle between their parallel parts.  "$@" comes after, so -n 0 runs serially.  The real-Blender tier stays
# serial: its tests share one Xvfb display and one chroot.
workers=$(( $(nproc) < 4 ? $(nproc) : 4 ))

echo "== lint (ruff, pyproject.toml)"
.venv/bin/ruff check .

echo "== all tiers, bpy $(version .venv)"
.venv/bin/python -m pytest tests --ignore=tests/ui -q -p no:cacheprovider -n "$workers" "$@"

echo "== all tiers less the Monte Carlo scores and the one-tier checks, bpy $(version .venv-bpy53)"
.venv-bpy53/bin/python -m pytest tests --ignore=tests/ui -q -p no:cacheprovider -n "$workers" -m "not reference and not one_tier" "$@"

echo "== blender and gpu tiers, bpy $(version .venv-bpy52)"
.venv-bpy52/bin/python -m pytest tests/blender tests/gpu -q -p no:cacheprovider -n "$workers" -m "not reference and not one_tier" "$@"

echo "== blender and gpu tiers, bpy $(version .venv-bpy42)"
.venv-bpy42/bin/python -m pytest tests/blender tests/gpu -q -p no:cacheprovider -n "$workers" -m "not reference and not one_tier" "$@"

echo "== real-Blender tier (Debian's Blender in a chroot, the extension installed from its zip)"
.venv/bin/python -m pytest tests/ui -q -p no:cacheprovider "$@"
