#!/usr/bin/env bash
# Create (or reuse) a virtual environment with pinned requirements.
#   scripts/setup_venv.sh VENV_DIR REQUIREMENTS_FILE
# Reinstalls only when the requirements file changed (hash stamp in the venv).
set -euo pipefail
venv=$1
requirements=$2
python=${PYTHON:-python3}
stamp="$venv/.requirements.sha256"
wanted=$(sha256sum "$requirements" | cut -d' ' -f1)
if [ -x "$venv/bin/python" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$wanted" ]; then
    exit 0
fi
echo "setting up $venv from $requirements" >&2
[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$requirements"
echo "$wanted" > "$stamp"
