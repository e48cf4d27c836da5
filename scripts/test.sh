#!/usr/bin/env bash
# Set up and run the whole test suite: every tier on pip bpy 5.0 (the last for Python 3.11) and on the newest,
# 5.3 (Python 3.13, numpy 2, through pyenv), then the Blender and GPU tiers on the oldest, 4.2 LTS, the Blender
# tier and the engine's renders on 5.2 LTS (between 5.0 and 5.3, whose GPU tiers run whole),
# and the real-Blender tier (tests/ui: Debian's Blender 4.3 in a chroot, scripts/real_blender.sh; needs root).
# What does not depend on the Blender version runs on one tier: the scores against the Monte Carlo reference
# (marker "reference") and the GPU run's smoke run ("one_tier") on 5.0; the maths checks over fine grids
# ("slow_maths") on 5.0, the rest of tests/core on both Pythons; the scores against Cycles ("cycles") on 5.0 (the
# truth suite, benchmarks/truth_suite.py, scores against any Blender's).  The files made by others
# (tests/real_files) go through the newest Blender's importers.
# README.md gives each tier's time; the whole stays within 20 minutes on 2 cores.
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
# Each tier's wall time after it, for README.md's table
timed() { local start=$SECONDS; "$@"; echo "   tier time: $((SECONDS - start)) s"; }

echo "== lint (ruff, pyproject.toml)"
.venv/bin/ruff check .

echo "== core, blender and gpu tiers, bpy $(version .venv)"
timed .venv/bin/python -m pytest tests/core tests/blender tests/gpu -q -p no:cacheprovider -n "$workers" "$@"

echo "== all tiers less the one-tier checks and the Cycles scores (real files included), bpy $(version .venv-bpy53)"
timed .venv-bpy53/bin/python -m pytest tests --ignore=tests/ui -q -p no:cacheprovider -n "$workers" \
    -m "not reference and not one_tier and not slow_maths and not cycles" "$@"

echo "== blender tier and the engine's renders, bpy $(version .venv-bpy52)"
timed .venv-bpy52/bin/python -m pytest tests/blender tests/gpu/test_engine_render.py tests/gpu/test_reopen_render.py \
    -q -p no:cacheprovider -n "$workers" -m "not reference and not one_tier and not cycles" "$@"

echo "== blender and gpu tiers less the Cycles scores, bpy $(version .venv-bpy42)"
timed .venv-bpy42/bin/python -m pytest tests/blender tests/gpu -q -p no:cacheprovider -n "$workers" \
    -m "not reference and not one_tier and not cycles" "$@"

echo "== real-Blender tier (Debian's Blender in a chroot, the extension installed from its zip)"
timed .venv/bin/python -m pytest tests/ui -q -p no:cacheprovider "$@"
