"""Runs commands in the real-Blender chroot (scripts/real_blender.sh) for the tests of tests/ui."""
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "real_blender.sh"
GUEST_REPO = "/sgprt"           # where the repository appears inside the chroot
GUEST_WORK = "/work"            # the session's folder: the zip, the user resources, scenes, renders


class RealBlender:
    """Runs commands in the chroot with the repository and a work folder bound, and the extension's user
    resources (BLENDER_USER_RESOURCES) in the work folder."""

    def __init__(self, work):
        self.work = Path(work)
        self.user = self.work / "user"
        self.user.mkdir(parents=True, exist_ok=True)

    def guest(self, path):
        """The chroot's path of a file in the work folder."""
        return f"{GUEST_WORK}/{Path(path).relative_to(self.work)}"

    def run(self, *command, timeout=600, check=True):
        completed = subprocess.run(
            ["bash", str(SCRIPT), "run", "--bind", f"{ROOT}:{GUEST_REPO}", "--bind", f"{self.work}:{GUEST_WORK}",
             "--", "env", f"BLENDER_USER_RESOURCES={GUEST_WORK}/user", *command],
            capture_output=True, text=True, timeout=timeout)
        if check and completed.returncode != 0:
            raise AssertionError(f"{' '.join(command)} exited {completed.returncode}:\n"
                                 f"{completed.stdout[-4000:]}\n{completed.stderr[-4000:]}")
        return completed
