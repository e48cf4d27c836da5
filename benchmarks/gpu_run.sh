#!/usr/bin/env bash
# Frame times of SG-PRT and EEVEE on this machine's GPU, from nothing: any Linux machine with an NVIDIA GPU and
# its driver, no display (the pip bpy module renders through EGL without one).
#   bash benchmarks/gpu_run.sh [--venv DIR] [--resolution 1920x1080] [--output out/gpu_run] [--smoke] [...]
# Makes its own venv (.venv-gpu-run) with the pinned requirements.txt (scripts/setup_venv.sh; needs Python
# 3.11 and PyPI), unless --venv DIR or SGPRT_GPU_RUN_VENV=DIR names an existing one (the test suite's smoke
# run uses .venv).  Then benchmarks/gpu_run.py builds, bakes and renders the example scenes and the scaling
# scenes with SG-PRT and EEVEE and writes OUTPUT/gpu_run.json and OUTPUT/gpu_run.md (--help: its options).
set -euo pipefail
cd "$(dirname "$0")/.."

venv=${SGPRT_GPU_RUN_VENV:-}
arguments=()
while [ $# -gt 0 ]; do
    case $1 in
        --venv) venv=$2; shift 2 ;;
        --venv=*) venv=${1#--venv=}; shift ;;
        *) arguments+=("$1"); shift ;;
    esac
done

if [ -z "$venv" ]; then
    venv=.venv-gpu-run
    # bpy 5.0.1 is built for Python 3.11 alone
    PYTHON=${PYTHON:-$(command -v python3.11 || command -v python3)} bash scripts/setup_venv.sh "$venv" requirements.txt
fi
if [ ! -x "$venv/bin/python" ]; then
    echo "gpu_run.sh: no Python in $venv" >&2
    exit 1
fi

# pip bpy links the X11 and GL client libraries even when it renders through EGL: name the missing ones
module=$("$venv/bin/python" -c 'import importlib.util; print(importlib.util.find_spec("bpy").origin)')
missing=$(ldd "$module" | awk '/not found/ {print $1}' | tr '\n' ' ')
if [ -n "$missing" ]; then
    echo "gpu_run.sh: bpy needs system libraries missing here: $missing" >&2
    echo "  (Debian/Ubuntu: apt-get install libx11-6 libxrender1 libxfixes3 libxi6 libxkbcommon0 libsm6 libgl1 libegl1 libvulkan1)" >&2
    exit 1
fi

# (the expansion guards bash before 4.4, where an empty array is unbound under set -u)
exec "$venv/bin/python" -m benchmarks.gpu_run ${arguments[@]+"${arguments[@]}"}
