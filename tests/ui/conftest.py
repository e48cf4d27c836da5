"""The real-Blender tier: Debian's Blender (4.3, Python 3.13) in a chroot (scripts/real_blender.sh), the
extension installed from its zip as a user installs it, driven by its command line and, under Xvfb, in a
window.  Needs root and Debian's package mirror; skipped with the reason elsewhere, never in CI."""
import os
import subprocess
import sys

import pytest
from real_blender_harness import ROOT, SCRIPT, RealBlender


def _unavailable(reason):
    if os.environ.get("CI"):
        pytest.fail(f"the real-Blender tier cannot run in CI: {reason}")
    pytest.skip(f"real Blender not available: {reason}")


@pytest.fixture(scope="session")
def real_blender(tmp_path_factory):
    """A RealBlender with the Linux zip (Python 3.13 wheels) installed and enabled in a fresh user folder."""
    if os.name != "posix" or os.geteuid() != 0:
        _unavailable("scripts/real_blender.sh needs root (a chroot)")
    setup = subprocess.run(["bash", str(SCRIPT), "setup"], capture_output=True, text=True, timeout=1800)
    if setup.returncode != 0:
        _unavailable(f"setup failed:\n{setup.stderr[-3000:]}")
    blender = RealBlender(tmp_path_factory.mktemp("real_blender"))
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import build_extension
    finally:
        sys.path.pop(0)
    [zip_path] = build_extension.build(local_only=True, output_dir=blender.work / "dist", python_version="3.13")
    installed = blender.run("blender", "-b", "--command", "extension", "install-file", "-r", "user_default",
                            "--enable", blender.guest(zip_path))
    blender.install_log = installed.stdout + installed.stderr
    blender.zip_path = zip_path
    return blender
