"""Build the SG-PRT extension zip with its wheels, and validate it with Blender's own tool.

    .venv/bin/python tools/build_extension.py                  # every platform and Python
    .venv/bin/python tools/build_extension.py --local-only     # this machine's platform only (tests)

Stages the add-on package, the shaders and the manifest under build/extension/,
downloads binary wheels of the runtime dependencies Blender does not ship
(never numpy: Blender has its own), writes their paths into the staged
manifest, then runs `blender_ext.py build` and `validate` from the bpy wheel.
"""
import argparse
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "build"
REQUIREMENTS = ROOT / "requirements.txt"
RUNTIME_PACKAGES = ("embreex", "scipy")
# Blender 4.2-5.0 embed Python 3.11, Blender 5.1+ Python 3.13.
PYTHON_VERSIONS = ("3.11", "3.13")
# pip platform tag that each manifest platform's wheels carry.
PLATFORM_TAGS = {
    "linux-x64": "manylinux_2_28_x86_64",
    "windows-x64": "win_amd64",
    "macos-arm64": "macosx_14_0_arm64",
    "macos-x64": "macosx_13_0_x86_64",
}


def blender_ext_tool():
    # bpy.__file__ is <bpy>/<version>/scripts/modules/bpy/__init__.py
    scripts = Path(bpy.__file__).resolve().parents[2]
    matches = sorted(scripts.glob("addons_core/bl_pkg/cli/blender_ext.py"))
    if not matches:
        sys.exit("build_extension: blender_ext.py not found inside the bpy package")
    return matches[-1]


def pinned_requirements():
    pins = {}
    for line in REQUIREMENTS.read_text().splitlines():
        match = re.match(r"^([A-Za-z0-9_.-]+)==(\S+)", line.strip())
        if match:
            pins[match.group(1).lower()] = match.group(2)
    return [f"{name}=={pins[name]}" for name in RUNTIME_PACKAGES]


def download_wheels(target, platforms, python_versions):
    """One folder per (platform, Python) so exactly the wheels asked for are bundled."""
    wheels = []
    for platform in platforms:
        for python_version in python_versions:
            folder = target / f"{platform}-py{python_version}"
            folder.mkdir(parents=True, exist_ok=True)
            command = [sys.executable, "-m", "pip", "download", "--quiet", "--disable-pip-version-check",
                       "--no-deps", "--only-binary=:all:", "--platform", PLATFORM_TAGS[platform],
                       "--python-version", python_version, "--dest", str(folder), *pinned_requirements()]
            print(f"build_extension: wheels for {platform}, Python {python_version}", flush=True)
            subprocess.run(command, check=True)
            wheels += sorted(folder.glob("*.whl"))
    return wheels


def stage(stage_dir, wheels, platforms):
    if stage_dir.exists():
        shutil.rmtree(stage_dir)
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    shutil.copytree(ROOT / "sg_prt_addon", stage_dir, ignore=ignore)
    shutil.copytree(ROOT / "shaders", stage_dir / "shaders", ignore=ignore)
    (stage_dir / "wheels").mkdir()
    for wheel in wheels:
        shutil.copy2(wheel, stage_dir / "wheels" / wheel.name)
    manifest = (ROOT / "blender_manifest.toml").read_text()
    wheel_list = ", ".join(f'"./wheels/{wheel.name}"' for wheel in wheels)
    manifest = re.sub(r"(?m)^wheels = \[\]$", f"wheels = [{wheel_list}]", manifest)
    platform_list = ", ".join(f'"{p}"' for p in platforms)
    manifest = re.sub(r"(?m)^platforms = \[.*\]$", f"platforms = [{platform_list}]", manifest)
    (stage_dir / "blender_manifest.toml").write_text(manifest)


def local_platform():
    machine = sysconfig.get_platform()
    if machine.startswith("linux") and machine.endswith("x86_64"):
        return "linux-x64"
    if machine.startswith("win"):
        return "windows-x64"
    if machine.startswith("macosx"):
        return "macos-arm64" if machine.endswith("arm64") else "macos-x64"
    sys.exit(f"build_extension: no wheels are known for platform {machine}")


def build(local_only=False, output_dir=None):
    """Build and validate the zip; returns its path."""
    platforms = [local_platform()] if local_only else list(PLATFORM_TAGS)
    python_versions = [f"{sys.version_info.major}.{sys.version_info.minor}"] if local_only else PYTHON_VERSIONS
    wheels = download_wheels(BUILD / "wheels", platforms, python_versions)
    stage_dir = BUILD / "extension" / "sg_prt"
    stage(stage_dir, wheels, platforms)
    output_dir = Path(output_dir or BUILD / "dist")
    output_dir.mkdir(parents=True, exist_ok=True)
    tool = blender_ext_tool()
    subprocess.run([sys.executable, str(tool), "build", "--source-dir", str(stage_dir),
                    "--output-dir", str(output_dir)], check=True)
    zips = sorted(output_dir.glob("sg_prt-*.zip"), key=lambda p: p.stat().st_mtime)
    if not zips:
        sys.exit("build_extension: blender_ext.py build wrote no zip")
    subprocess.run([sys.executable, str(tool), "validate", str(zips[-1])], check=True)
    print(f"build_extension: {zips[-1]} ({zips[-1].stat().st_size / 2**20:.1f} MiB) validated", flush=True)
    return zips[-1]


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--local-only", action="store_true", help="wheels for this platform and Python only")
    parser.add_argument("--output-dir", help="where to write the zip (default build/dist)")
    arguments = parser.parse_args()
    build(arguments.local_only, arguments.output_dir)
