"""Build the SG-PRT extension zip with its wheels, and validate it with Blender's own tool.

    .venv/bin/python tools/build_extension.py                  # a zip per platform, each for both Pythons
    .venv/bin/python tools/build_extension.py --local-only     # this machine's platform and Python (tests)
    .venv/bin/python tools/build_extension.py --local-only --python 3.13    # ... for another Python

Stages the add-on package, the shaders and the manifest under build/extension/,
downloads binary wheels of the runtime dependencies Blender does not ship
(never numpy: Blender has its own), writes their paths into the staged
manifest, then runs `blender_ext.py build --split-platforms` and `validate` from
the bpy wheel.  A platform's zip carries the wheels of both Pythons Blender
embeds (3.11 in 4.2-5.0, 3.13 from 5.1, and in Linux distributions' builds such
as Debian's 4.3): about 50 MB each, of which scipy is 35 MB.
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
RUNTIME_PACKAGES = ("embreex", "scipy", "threadpoolctl")
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
    wheels = {}
    for platform in platforms:
        for python_version in python_versions:
            folder = target / f"{platform}-py{python_version}"
            folder.mkdir(parents=True, exist_ok=True)
            command = [sys.executable, "-m", "pip", "download", "--quiet", "--disable-pip-version-check",
                       "--no-deps", "--only-binary=:all:", "--platform", PLATFORM_TAGS[platform],
                       "--python-version", python_version, "--dest", str(folder), *pinned_requirements()]
            print(f"build_extension: wheels for {platform}, Python {python_version}", flush=True)
            subprocess.run(command, check=True)
            for wheel in sorted(folder.glob("*.whl")):
                wheels.setdefault(wheel.name, wheel)    # a pure-Python wheel is in every folder: bundle it once
    return list(wheels.values())


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


def build(local_only=False, output_dir=None, python_version=None):
    """Build and validate the zips, one a platform (this machine's alone with local_only, for the running
    Python's version or `python_version`); returns their paths."""
    platforms = [local_platform()] if local_only else list(PLATFORM_TAGS)
    if local_only:
        python_versions = [python_version or f"{sys.version_info.major}.{sys.version_info.minor}"]
    else:
        python_versions = PYTHON_VERSIONS
    wheels = download_wheels(BUILD / "wheels", platforms, python_versions)
    stage_dir = BUILD / "extension" / "sg_prt"
    stage(stage_dir, wheels, platforms)
    output_dir = Path(output_dir or BUILD / "dist")
    output_dir.mkdir(parents=True, exist_ok=True)
    for old in output_dir.glob("sg_prt-*.zip"):
        old.unlink()
    tool = blender_ext_tool()
    subprocess.run([sys.executable, str(tool), "build", "--source-dir", str(stage_dir),
                    "--output-dir", str(output_dir), "--split-platforms"], check=True)
    zips = sorted(output_dir.glob("sg_prt-*.zip"))
    if len(zips) != len(platforms):
        sys.exit(f"build_extension: blender_ext.py build wrote {len(zips)} zips for {len(platforms)} platforms")
    for path in zips:
        subprocess.run([sys.executable, str(tool), "validate", str(path)], check=True)
        print(f"build_extension: {path} ({path.stat().st_size / 2**20:.1f} MiB) validated", flush=True)
    return zips


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--local-only", action="store_true", help="wheels for this platform and Python only")
    parser.add_argument("--python", help="with --local-only: the Python version of the wheels (default this one's)")
    parser.add_argument("--output-dir", help="where to write the zips (default build/dist)")
    arguments = parser.parse_args()
    build(arguments.local_only, arguments.output_dir, arguments.python)
