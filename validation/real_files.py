"""Real files made by others (scripts/fetch_corpus.sh: Debian's assimp-testmodels) through the engine as a
user meets them: a .blend opened, a glTF 2 file through Blender's own importer; rendered unbaked, baked with
Bake Visibility at its defaults, rendered again.  The real-files tier (tests/real_files) runs every file through
`run_file`; `python -m validation.real_files [substring]` does the same, baking every file whatever its size."""
import os
import re
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

REPO_ROOT = Path(__file__).resolve().parents[1]
BLEND_FOLDER = "BLEND"
GLTF_FOLDER = "glTF2"          # glTF 1.0 (models/glTF) is a format Blender's importer does not read
RENDER_SIZE = 64


def corpus_models():
    """The corpus' models folder, fetched and unpacked once (scripts/fetch_corpus.sh)."""
    output = subprocess.run(["bash", str(REPO_ROOT / "scripts" / "fetch_corpus.sh")], check=True,
                            capture_output=True, text=True, cwd=REPO_ROOT).stdout
    path = Path(output.strip().splitlines()[-1])
    return path if path.is_absolute() else REPO_ROOT / path


def corpus_files(models):
    """Paths relative to `models` of every .blend and glTF 2 file, sorted."""
    files = [path for path in (models / BLEND_FOLDER).rglob("*.blend")]
    files += [path for path in (models / GLTF_FOLDER).rglob("*") if path.suffix in (".gltf", ".glb")]
    return sorted(str(path.relative_to(models)) for path in files)


@dataclass
class FileRun:
    """What happened to one file: `refused` (Blender itself could not load it: the reason), else each render's
    error or None, NaN pixels, warnings, and the bake's outcome and reports."""
    path: str
    refused: str = None
    unbaked_error: str = None
    baked_error: str = None
    bake_outcome: str = None
    bake_reports: list = field(default_factory=list)
    unbaked_warnings: list = field(default_factory=list)
    baked_warnings: list = field(default_factory=list)
    nan_pixels: int = 0
    baked_objects: int = 0
    seconds: float = 0.0


def load(models, relative):
    """Open a .blend, or import a glTF into an empty file; returns the scene, or raises RuntimeError when Blender
    itself refuses the file."""
    import bpy

    path = str(models / relative)
    if relative.endswith(".blend"):
        bpy.ops.wm.open_mainfile(filepath=path, load_ui=False)
    else:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.ops.import_scene.gltf(filepath=path)
    return bpy.context.scene


def prepare(scene):
    """The scene set to render with SG-PRT at RENDER_SIZE px, one sample; a camera framing the visible objects
    where the file has none (a glTF without one), as a user would add."""
    import bpy
    from mathutils import Vector

    scene.render.engine = "SG_PRT"
    scene.render.resolution_x = scene.render.resolution_y = RENDER_SIZE
    scene.render.resolution_percentage = 100
    scene.sgprt.render_samples = 1
    if scene.camera is not None:
        return
    corners = [obj.matrix_world @ Vector(corner) for obj in scene.objects if obj.type == "MESH"
               for corner in obj.bound_box]
    low = Vector([min(c[i] for c in corners) for i in range(3)]) if corners else Vector((-1, -1, -1))
    high = Vector([max(c[i] for c in corners) for i in range(3)]) if corners else Vector((1, 1, 1))
    centre, radius = (low + high) / 2, max((high - low).length / 2, 1e-3)
    camera = bpy.data.objects.new("corpus_camera", bpy.data.cameras.new("corpus_camera"))
    scene.collection.objects.link(camera)
    direction = Vector((1.0, -1.5, 1.0)).normalized()
    camera.location = centre + direction * radius * 3.0
    camera.rotation_euler = (-direction).to_track_quat("-Z", "Y").to_euler()
    camera.data.clip_end = max(camera.data.clip_end, radius * 10.0)
    scene.camera = camera


def render(scene):
    """(error or None, Combined pixels or None, warnings) of a final render."""
    import bpy

    from sg_prt_addon.engine import render_engine

    try:
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(scene=scene.name, write_still=False)
    except RuntimeError as error:
        return str(error), None, []
    result = render_engine.last_render
    if "error" in result:
        return result["error"], None, []
    state = result["state"]
    return None, result["passes"]["Combined"].copy(), list(dict.fromkeys(state.warnings + state.unshadowed_warnings()))


def bake(scene):
    """(outcome, reports) of Bake Visibility (all visible meshes, the operator's defaults)."""
    import bpy

    with bpy.context.temp_override(scene=scene, view_layer=scene.view_layers[0]):
        try:
            outcome = bpy.ops.sgprt.bake_visibility(target="ALL")
        except RuntimeError as error:           # an operator's ERROR report raises in background mode
            return "ERROR", [str(error)]
    return ",".join(sorted(outcome)), []


def rendered_vertices(scene):
    """Vertices of the visible meshes as a final render evaluates them (what Bake Visibility bakes)."""
    import bpy

    from sg_prt_addon.blender import modifier_stack

    with modifier_stack.as_rendered(scene):
        depsgraph = bpy.context.evaluated_depsgraph_get()
        return sum(len(obj.evaluated_get(depsgraph).data.vertices) for obj in scene.objects
                   if obj.type == "MESH" and obj.visible_get())


def run_file(models, relative, bake_vertex_limit=None):
    """FileRun of one corpus file; a file of more than bake_vertex_limit rendered vertices is not baked (its bake
    takes minutes: `python -m validation.real_files` bakes every file)."""
    start = time.perf_counter()
    run = FileRun(relative)
    try:
        scene = load(models, relative)
    except Exception as error:          # the importer's own refusals (broken files), of any type
        lines = [line for line in str(error).strip().splitlines() if line.strip()] or [""]
        run.refused = next((line for line in lines if line.startswith("Error")), lines[-1])
        run.seconds = time.perf_counter() - start
        return run
    prepare(scene)
    run.unbaked_error, image, run.unbaked_warnings = render(scene)
    run.nan_pixels += 0 if image is None else int(np.count_nonzero(~np.isfinite(image)))
    vertices = rendered_vertices(scene)
    if bake_vertex_limit is not None and vertices > bake_vertex_limit:
        run.bake_outcome = f"SKIPPED: {vertices} vertices"
    else:
        run.bake_outcome, run.bake_reports = bake(scene)
    run.baked_error, image, run.baked_warnings = render(scene)
    run.nan_pixels += 0 if image is None else int(np.count_nonzero(~np.isfinite(image)))
    from sg_prt_addon.engine import render_engine
    state = render_engine.last_render.get("state")
    run.baked_objects = len(state.visibility) if state is not None else 0
    run.seconds = time.perf_counter() - start
    return run


def quoted_names(text):
    """The names a message quotes ('name')."""
    return re.findall(r"'([^']+)'", text)


def datablock_names():
    """Every name a warning may quote: objects, meshes, materials, images, lights, worlds, node names, modifiers."""
    import bpy

    names = set()
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.materials, bpy.data.images, bpy.data.lights,
                       bpy.data.worlds, bpy.data.node_groups, bpy.data.cameras, bpy.data.collections):
        names.update(item.name for item in collection)
    for material in bpy.data.materials:
        if material.node_tree is not None:
            names.update(node.name for node in material.node_tree.nodes)
            names.update(node.bl_idname for node in material.node_tree.nodes)
    for obj in bpy.data.objects:
        names.update(modifier.name for modifier in obj.modifiers)
    return names


if __name__ == "__main__":
    import sys

    import bpy  # noqa: F401

    import sg_prt_addon
    sg_prt_addon.register()
    root = corpus_models()
    wanted = sys.argv[1] if len(sys.argv) > 1 else ""
    for name in corpus_files(root):
        if wanted in name:
            outcome = run_file(root, name)
            print(outcome, flush=True)
    os._exit(0)
