"""Render the example scenes with this checkout and with an earlier commit, and compare the images.

    .venv/bin/python tools/compare_renders.py [--base HEAD] [--size 96]

A refactor must not change what the engine renders.  The earlier commit is checked out in a git worktree
(under the system's temporary directory, reused by later runs); its package builds the scenes, bakes their
visibility, fits a measured material's lobes and saves the .blend files, so the new code also reads files
written by the old one.  Both packages then render every file (Combined, float EXR) and the script prints,
per image, the largest pixel difference relative to the image's peak, and fails above --tolerance.
"""
import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[1]
TOLERANCE = 1e-6


def _use_package(root):
    """Import sg_prt_addon (and examples/) from the checkout at `root`."""
    sys.path.insert(0, str(root))


def _generate_merl(path):
    try:                                            # after the refactor: outside the shipped add-on
        from validation import brdf_generators
    except ImportError:
        from sg_prt_addon.core import brdf_generators
    brdf_generators.generate_merl(str(path))


def _fitted_scene(merl_path):
    """A sphere with a fitted measured material on a floor, lit by a sun and a point light."""
    import bpy

    from examples import build_scenes

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = build_scenes.ENGINE_ID
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=0.8, location=(0, 0, 0.8))
    sphere = bpy.context.active_object
    material = bpy.data.materials.new("Measured")
    sphere.data.materials.append(material)
    bpy.ops.mesh.primitive_plane_add(size=6)
    floor = bpy.context.active_object
    floor.data.materials.append(build_scenes._material("Floor", model="GGX", roughness=0.4,
                                                       diffuse_color=(0.5, 0.5, 0.5), specular_color=(0.04,) * 3))
    for kind, location, energy in (("SUN", (2, -2, 4), 3.0), ("POINT", (-2, -1, 3), 400.0)):
        light = bpy.data.objects.new(kind, bpy.data.lights.new(kind, kind))
        light.data.energy = energy
        light.location = location
        light.rotation_euler = (0.6, 0.2, 0.4)
        scene.collection.objects.link(light)
    build_scenes._world_with_colour(scene, (0.05, 0.06, 0.08))
    build_scenes._add_camera(scene, (3.5, -3.5, 2.5), (0, 0, 0.6))
    bpy.context.view_layer.objects.active = sphere
    result = bpy.ops.sgprt.fit_lobes("EXEC_DEFAULT", filepath=str(merl_path), lobe_count=2)
    if "FINISHED" not in result:
        raise RuntimeError(f"the lobe fit did not finish: {result}")


def prepare(root, directory):
    """Build, bake and save the scenes with the package at `root`; returns the .blend paths."""
    _use_package(root)
    import bpy

    import sg_prt_addon
    from examples import build_scenes

    sg_prt_addon.register()
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, build in build_scenes.SCENES.items():
        build(resolution=96)
        paths.append(build_scenes.save_scene(directory / f"{name}.blend"))
        result = bpy.ops.sgprt.bake_visibility("EXEC_DEFAULT", target="ALL", resolution=16)
        if "FINISHED" not in result:
            raise RuntimeError(f"the visibility bake of {name} did not finish: {result}")
        paths.append(build_scenes.save_scene(directory / f"{name}_baked.blend"))
    _generate_merl(directory / "measured.binary")
    _fitted_scene(directory / "measured.binary")
    paths.append(build_scenes.save_scene(directory / "fitted.blend"))
    result = bpy.ops.sgprt.bake_visibility("EXEC_DEFAULT", target="ALL", resolution=16)
    if "FINISHED" not in result:
        raise RuntimeError(f"the visibility bake of the fitted scene did not finish: {result}")
    paths.append(build_scenes.save_scene(directory / "fitted_baked.blend"))
    return paths


def render(root, blends, output, size):
    """Render each .blend with the package at `root` into output/<name>.npy (float32, row 0 at the top)."""
    _use_package(root)
    import numpy as np

    from sg_prt_addon import render as batch

    batch.ensure_registered()
    output.mkdir(parents=True, exist_ok=True)
    for blend in blends:
        scene = batch.open_blend(blend)
        scene.render.use_persistent_data = False
        exr = batch.render_to_file(scene, output / f"{Path(blend).stem}.exr", size, size)
        np.save(output / f"{Path(blend).stem}.npy", batch.read_float_image(exr))


def _worktree(base):
    sha = subprocess.run(["git", "rev-parse", base], cwd=REPOSITORY, check=True, capture_output=True,
                         text=True).stdout.strip()
    path = Path(tempfile.gettempdir()) / f"sgprt-compare-{sha[:12]}"
    if not (path / "sg_prt_addon").is_dir():
        subprocess.run(["git", "worktree", "add", "--detach", str(path), sha], cwd=REPOSITORY, check=True)
    return sha, path


def _child(*arguments):
    subprocess.run([sys.executable, str(Path(__file__).resolve()), *map(str, arguments)], check=True,
                   env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})


def compare(before_dir, after_dir, tolerance):
    """(name, largest |after - before| / peak of before, relative RMSE) per image; the worst first."""
    import numpy as np

    rows = []
    for before_path in sorted(before_dir.glob("*.npy")):
        before = np.load(before_path).astype(np.float64)
        after_path = after_dir / before_path.name
        if not after_path.is_file():
            rows.append((before_path.stem, float("inf"), float("inf")))
            continue
        after = np.load(after_path).astype(np.float64)
        if after.shape != before.shape or not np.all(np.isfinite(after)):
            rows.append((before_path.stem, float("inf"), float("inf")))
            continue
        peak = max(float(np.max(np.abs(before))), 1e-30)
        rmse = float(np.sqrt(np.mean((after - before) ** 2)) / max(np.sqrt(np.mean(before ** 2)), 1e-30))
        rows.append((before_path.stem, float(np.max(np.abs(after - before))) / peak, rmse))
    return sorted(rows, key=lambda row: -row[1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", default="HEAD", help="the commit to compare against (default HEAD)")
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--tolerance", type=float, default=TOLERANCE, help="largest difference / peak allowed")
    parser.add_argument("--work", type=Path, default=None, help="directory for scenes and images")
    parser.add_argument("--prepare", nargs=2, metavar=("ROOT", "DIR"), help=argparse.SUPPRESS)
    parser.add_argument("--render", nargs=3, metavar=("ROOT", "SCENES", "OUT"), help=argparse.SUPPRESS)
    arguments = parser.parse_args(argv)
    if arguments.prepare:
        prepare(Path(arguments.prepare[0]), Path(arguments.prepare[1]))
        return 0
    if arguments.render:
        root, scenes, out = map(Path, arguments.render)
        render(root, sorted(scenes.glob("*.blend")), out, arguments.size)
        return 0

    sha, base_root = _worktree(arguments.base)
    work = arguments.work or Path(tempfile.mkdtemp(prefix="sgprt-compare-"))
    scenes = work / "scenes"
    _child("--prepare", base_root, scenes)
    _child("--size", arguments.size, "--render", base_root, scenes, work / "before")
    _child("--size", arguments.size, "--render", REPOSITORY, scenes, work / "after")
    rows = compare(work / "before", work / "after", arguments.tolerance)
    print(f"\nrenders of {REPOSITORY} against {sha[:12]} ({work}):")
    print(f"{'image':24s} {'max diff / peak':>16s} {'rel. RMSE':>12s}")
    for name, worst, rmse in rows:
        print(f"{name:24s} {worst:16.3g} {rmse:12.3g}")
    failed = [name for name, worst, _ in rows if not worst <= arguments.tolerance]
    if failed or not rows:
        print(f"FAILED: {', '.join(failed) or 'no images'} beyond {arguments.tolerance:g}")
        return 1
    print(f"all {len(rows)} images within {arguments.tolerance:g} of the peak")
    return 0


if __name__ == "__main__":
    sys.exit(main())
