"""Make the repo root importable however pytest is launched.

`python -m pytest` already puts the current directory on sys.path; the bare
`pytest` entry point does not, so add the repo root once if it is missing.
"""
import os
import shutil
import sys
import tempfile
from pathlib import Path

REPO_ROOT = str(Path(__file__).resolve().parents[1])
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

# The engine's disk cache (engine/disk_cache.py) in a folder of this run's own, not the user's: every run
# builds its environments and tables once, and none reads what another version of the code left.
_own_cache = None
if "SG_PRT_CACHE_DIR" not in os.environ:
    _own_cache = os.environ["SG_PRT_CACHE_DIR"] = tempfile.mkdtemp(prefix="sg-prt-test-cache-")


_exit_status = 0


def pytest_sessionfinish(session, exitstatus):
    global _exit_status
    _exit_status = int(exitstatus)


def pytest_unconfigure(config):
    """Remove this run's disk cache.  Then end the process at once on bpy 4.2: its module crashes at interpreter exit
    (segmentation fault, exit code 139) once a RenderEngine, or a property with an update
    callback, has been registered, even after unregistering; 4.3+ exits cleanly. The
    summary is already printed here, so the exit status is all that is left to give."""
    if _own_cache is not None:
        shutil.rmtree(_own_cache, ignore_errors=True)
    bpy = sys.modules.get("bpy")
    if bpy is not None and bpy.app.version < (4, 3, 0):
        import os
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_exit_status)
