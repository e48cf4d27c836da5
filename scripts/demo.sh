#!/usr/bin/env bash
# Set up and run the main job: build the example scene, bake its visibility, render it with SG-PRT, score it
# against the Monte Carlo reference; writes out/demo.png, out/reference.png, out/report.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_venv.sh .venv requirements.txt
.venv/bin/python examples/demo.py --output out "$@"
cat out/report.md
