"""Make the repo root importable however pytest is launched.

`python -m pytest` already puts the current directory on sys.path; the bare
`pytest` entry point does not, so add the repo root once if it is missing.
"""
import sys
from pathlib import Path

REPO_ROOT = str(Path(__file__).resolve().parents[1])
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)


_exit_status = 0


def pytest_sessionfinish(session, exitstatus):
    global _exit_status
    _exit_status = int(exitstatus)


def pytest_unconfigure(config):
    """End the process at once on bpy 4.2: its module crashes at interpreter exit
    (segmentation fault, exit code 139) once a RenderEngine, or a property with an update
    callback, has been registered, even after unregistering; 4.3+ exits cleanly. The
    summary is already printed here, so the exit status is all that is left to give."""
    bpy = sys.modules.get("bpy")
    if bpy is not None and bpy.app.version < (4, 3, 0):
        import os
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_exit_status)
