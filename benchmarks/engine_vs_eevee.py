"""Frame time of the SG-PRT engine beside EEVEE on the same scene, same process, same machine.

Scene: Suzanne subdivided twice (15.7k triangles, smooth), a floor, GGX roughness 0.3
(EEVEE: Diffuse + Glossy GGX BSDF), one point light, Blender's courtyard.exr world.

SG-PRT figures: the first render (export, environment prefilter + SG fit, shader compile
and JIT, upload, draw, read back) and the steady-state frame (draw + read back of the
three passes, median of repeated redraws inside one render()).  EEVEE: wall time of
bpy.ops.render.render at 1 and 16 samples, after a first render that compiles its shaders
(reported apart).

    .venv/bin/python -m benchmarks.engine_vs_eevee [--size 512] [--eevee-samples 1 16]
"""
import argparse
import math
import os
import statistics
import sys
import tempfile
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)


def build_scene(size):
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    bpy.ops.mesh.primitive_monkey_add(size=2.0, location=(0.0, 0.0, 1.0))
    monkey = bpy.context.object
    subdivision = monkey.modifiers.new("subdivision", "SUBSURF")
    subdivision.levels = subdivision.render_levels = 2
    bpy.ops.object.shade_smooth()
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, -0.2))
    floor = bpy.context.object

    material = bpy.data.materials.new("glossy")
    material.sgprt.model = "GGX"
    material.sgprt.roughness = 0.3
    material.sgprt.diffuse_color = (0.5, 0.35, 0.25)
    material.sgprt.specular_color = (0.25, 0.25, 0.25)
    _eevee_nodes(material, (0.5, 0.35, 0.25), (0.25, 0.25, 0.25), 0.3)
    monkey.data.materials.append(material)
    floor_material = bpy.data.materials.new("floor")
    floor_material.sgprt.roughness = 0.6
    _eevee_nodes(floor_material, (0.5, 0.5, 0.5), (0.25, 0.25, 0.25), 0.6)
    floor.data.materials.append(floor_material)

    light = bpy.data.lights.new("key", "POINT")
    light.energy = 1000.0
    light.shadow_soft_size = 0.25
    light_object = bpy.data.objects.new("key", light)
    light_object.location = (3.0, -3.0, 4.0)
    scene.collection.objects.link(light_object)

    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    camera.location = (0.0, -6.5, 2.0)
    camera.rotation_euler = (math.radians(80.0), 0.0, 0.0)
    scene.camera = camera

    world = bpy.data.worlds.new("courtyard")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    nodes = world.node_tree.nodes
    environment = nodes.new("ShaderNodeTexEnvironment")
    environment.image = bpy.data.images.load(
        os.path.join(bpy.utils.system_resource("DATAFILES"), "studiolights", "world", "courtyard.exr"))
    background = next(node for node in nodes if node.type == "BACKGROUND")
    world.node_tree.links.new(environment.outputs["Color"], background.inputs["Color"])
    scene.world = world
    triangles = sum(len(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.loop_triangles)
                    for obj in (monkey, floor))
    return scene, triangles


def _eevee_nodes(material, diffuse, specular, roughness):
    """Diffuse + GGX Glossy, the same reflectance the SG-PRT material describes."""
    import bpy

    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    diffuse_node = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse_node.inputs["Color"].default_value = tuple(diffuse) + (1.0,)
    glossy = tree.nodes.new("ShaderNodeBsdfGlossy" if "ShaderNodeBsdfGlossy" in dir(bpy.types)
                            else "ShaderNodeBsdfAnisotropic")
    glossy.distribution = "GGX"
    glossy.inputs["Color"].default_value = tuple(specular) + (1.0,)
    glossy.inputs["Roughness"].default_value = roughness
    add = tree.nodes.new("ShaderNodeAddShader")
    tree.links.new(diffuse_node.outputs[0], add.inputs[0])
    tree.links.new(glossy.outputs[0], add.inputs[1])
    tree.links.new(add.outputs[0], output.inputs["Surface"])


def render_seconds(scene, write_to=None):
    """Wall time of one render; with write_to, also saves the result as a float EXR there."""
    import bpy

    if write_to:
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        scene.render.filepath = write_to
    start = time.perf_counter()
    bpy.ops.render.render(write_still=bool(write_to))
    return time.perf_counter() - start


def read_exr(path):
    """(H, W, 4) float32 pixels of an EXR, row 0 at the bottom like the engine's passes."""
    import bpy
    import numpy as np

    image = bpy.data.images.load(path)
    width, height = image.size
    pixels = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--redraws", type=int, default=5)
    parser.add_argument("--eevee-samples", type=int, nargs="*", default=[1, 16])
    args = parser.parse_args(argv)

    import bpy
    import sg_prt_addon
    from sg_prt_addon.engine import render_engine

    scene, triangles = build_scene(args.size) if hasattr(bpy.types.Material, "sgprt") else (None, 0)
    if scene is None:
        sg_prt_addon.register()
        scene, triangles = build_scene(args.size)
    scene.render.engine = "SG_PRT"
    render_engine.debug["timed_redraws"] = args.redraws
    first = render_seconds(scene)
    render_engine.debug["timed_redraws"] = 0
    result = render_engine.last_render
    if "error" in result:
        raise SystemExit(result["error"])
    frame = statistics.median(result["timings"]["frames"])
    sg_prt_image = result["passes"]["Combined"]
    second = render_seconds(scene)             # environment cached, shaders recompiled (background mode)
    render_engine.debug["capture_gbuffer"] = True
    render_seconds(scene)                      # material ids: compare the Suzanne pixels on their own
    render_engine.debug["capture_gbuffer"] = False
    gbuffer = render_engine.last_render["passes"]
    monkey_id = gbuffer["material_ids"]["glossy"]
    monkey = (gbuffer["gbuffer_uv"][..., 3] > 0.5) & (abs(gbuffer["gbuffer_uv"][..., 2] - monkey_id) < 0.25)
    rows = [("SG-PRT first render (prefilter, compile, upload)", first),
            ("SG-PRT later render (bpy.ops.render.render)", second),
            ("SG-PRT steady-state frame (draw + read 3 passes)", frame)]
    eevee_engine = "BLENDER_EEVEE_NEXT" if bpy.app.version < (5, 0, 0) else "BLENDER_EEVEE"
    scene.render.engine = eevee_engine
    comparisons = []
    for index, samples in enumerate(args.eevee_samples):
        scene.eevee.taa_render_samples = samples
        if index == 0:      # EEVEE compiles its shaders on the first render: report it apart
            rows.append((f"EEVEE first render, {samples} sample(s), with compile", render_seconds(scene)))
        path = os.path.join(tempfile.gettempdir(), f"sgprt_eevee_{samples}.exr")
        rows.append((f"EEVEE {samples} sample(s) (bpy.ops.render.render)", render_seconds(scene, path)))
        eevee_image = read_exr(path)
        comparisons.append((samples, image_difference(sg_prt_image, eevee_image),
                            image_difference(sg_prt_image[monkey], eevee_image[monkey])))
    print(f"\n{args.size}x{args.size}, {triangles} triangles, Blender {bpy.app.version_string}")
    print(f"{'':52s} {'seconds':>9s} {'x SG-PRT frame':>15s}")
    for name, seconds in rows:
        print(f"{name:52s} {seconds:9.3f} {seconds / frame:15.1f}")
    for samples, whole, monkey_only in comparisons:
        print(f"SG-PRT vs EEVEE {samples} sample(s), relative RMS difference / mean ratio: "
              f"whole image {whole[0]:.3f} / {whole[1]:.3f}, Suzanne pixels {monkey_only[0]:.3f} / "
              f"{monkey_only[1]:.3f} (SG-PRT has no shadows yet)")
    return rows


def image_difference(image, reference):
    """(relative RMS difference, ratio of mean luminance) of two linear RGB images."""
    import numpy as np

    a, b = image[..., :3].astype(np.float64), reference[..., :3].astype(np.float64)
    relative_rms = float(np.sqrt(np.mean((a - b) ** 2)) / max(np.sqrt(np.mean(b * b)), 1e-30))
    return relative_rms, float(a.mean() / max(b.mean(), 1e-30))


if __name__ == "__main__":
    main()
