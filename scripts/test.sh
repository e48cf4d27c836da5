#!/usr/bin/env bash
# Set up and run the whole test suite: every tier on the newest supported
# Blender (pip bpy 5.0), then the Blender and GPU tiers on the oldest (4.2 LTS).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_venv.sh .venv requirements.txt
bash scripts/setup_venv.sh .venv-bpy42 requirements-oldest-blender.txt

echo "== all tiers, bpy $(.venv/bin/python -c 'import bpy; print(bpy.app.version_string)')"
.venv/bin/python -m pytest tests -q -p no:cacheprovider "$@"

echo "== blender and gpu tiers, bpy $(.venv-bpy42/bin/python -c 'import bpy; print(bpy.app.version_string)')"
.venv-bpy42/bin/python -m pytest tests/blender tests/gpu -q -p no:cacheprovider "$@"
