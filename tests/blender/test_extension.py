"""The extension zip: built with its wheels, accepted by Blender's validator,
installed into a clean user directory of the pip bpy, enabled, and rendering."""
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

INSTALL_AND_RENDER = r"""
import json, sys
import bpy
zip_path, image_path = sys.argv[1], sys.argv[2]
bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
enabled = [name for name in bpy.context.preferences.addons.keys() if name.endswith("sg_prt")]
# (read_factory_settings would disable the freshly installed extension: empty the scene instead)
scene = bpy.context.scene
for obj in list(scene.objects):
    bpy.data.objects.remove(obj)
scene.render.engine = "SG_PRT"
scene.render.resolution_x = scene.render.resolution_y = 64
bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0)
material = bpy.data.materials.new("Probe")
material.sgprt.diffuse_color = (0.8, 0.4, 0.2)
bpy.context.active_object.data.materials.append(material)
light = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
light.rotation_euler = (0.5, 0.3, 0.0)
scene.collection.objects.link(light)
camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
camera.location = (0.0, -5.0, 0.0)
camera.rotation_euler = (1.5707963, 0.0, 0.0)
scene.collection.objects.link(camera)
scene.camera = camera
scene.render.filepath = image_path
scene.render.image_settings.file_format = "PNG"
bpy.ops.render.render(write_still=True)
image = bpy.data.images.load(image_path)
pixels = list(image.pixels)
print("RESULT " + json.dumps({"enabled": enabled, "max": max(pixels[0::4]), "size": list(image.size)}))
"""


def _build_extension_module():
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import build_extension
    finally:
        sys.path.pop(0)
    return build_extension


def test_a_pure_python_wheel_is_bundled_once_for_every_platform_and_python(tmp_path, monkeypatch):
    """download_wheels asks pip once a (platform, Python): a py3-none-any wheel lands in every folder."""
    build_extension = _build_extension_module()

    def pip_download(command, check):
        folder = Path(command[command.index("--dest") + 1])
        python = command[command.index("--python-version") + 1].replace(".", "")
        (folder / f"scipy-1.0-cp{python}-{command[command.index('--platform') + 1]}.whl").touch()
        (folder / "threadpoolctl-3.8.0-py3-none-any.whl").touch()

    monkeypatch.setattr(build_extension.subprocess, "run", pip_download)
    names = [wheel.name for wheel in build_extension.download_wheels(tmp_path, ["linux-x64", "windows-x64"],
                                                                     ["3.11", "3.13"])]
    assert len(names) == 5 and names.count("threadpoolctl-3.8.0-py3-none-any.whl") == 1, names


def test_extension_builds_validates_installs_and_renders(tmp_path):
    build_extension = _build_extension_module()
    [zip_path] = build_extension.build(local_only=True, output_dir=tmp_path / "dist")  # raises unless validated
    assert zip_path.name.endswith("-linux_x64.zip")             # one zip a platform
    _check_contents(zip_path)
    with zipfile.ZipFile(zip_path) as archive:
        wheels = [name.rsplit("/", 1)[-1] for name in archive.namelist() if name.endswith(".whl")]
    for package in build_extension.RUNTIME_PACKAGES:        # one wheel each (a pure-Python one too, once)
        assert len([wheel for wheel in wheels if wheel.startswith(package + "-")]) == 1, (package, wheels)

    environment = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_path / "user"))
    environment.pop("PYTHONPATH", None)
    completed = subprocess.run([sys.executable, "-c", INSTALL_AND_RENDER, str(zip_path), str(tmp_path / "probe.png")],
                               cwd=tmp_path, env=environment, capture_output=True, text=True, timeout=600)
    lines = [line for line in completed.stdout.splitlines() if line.startswith("RESULT ")]
    assert completed.returncode == 0 and lines, completed.stdout[-3000:] + completed.stderr[-3000:]
    result = json.loads(lines[-1][len("RESULT "):])
    assert result["enabled"] == ["bl_ext.user_default.sg_prt"]
    assert result["size"] == [64, 64]
    assert result["max"] > 0.05, "the installed engine rendered a black image"


# What checks the engine and never runs in it (the top-level validation/ package, tests, benchmarks)
VALIDATION_MODULES = {path.name for path in (ROOT / "validation").glob("*.py") if path.name != "__init__.py"}


def _check_contents(zip_path):
    """The zip ships the add-on, its shaders and its wheels, and none of the validation code."""
    with zipfile.ZipFile(zip_path) as archive:
        names = archive.namelist()
    python = [name for name in names if name.endswith(".py")]
    print(f"{len(names)} files in {zip_path.name}, {len(python)} Python modules:", *sorted(python), sep="\n  ")
    assert not [name for name in names if name.split("/")[0] in ("validation", "tests", "benchmarks", "tools")]
    shipped = {name.rsplit("/", 1)[-1] for name in python}
    assert VALIDATION_MODULES and not shipped & VALIDATION_MODULES, sorted(shipped & VALIDATION_MODULES)
    for required in ("techniques/sg/sg_parametric.py", "techniques/sg/sg_fitted.py", "engine/renderer.py",
                     "shaders/techniques/sg/sg_shading.glsl", "shaders/engine/mesh.vert.glsl", "blender_manifest.toml"):
        assert any(name.endswith(required) for name in names), f"{required} missing from the zip"
