"""Scenes for the engine tests, built from Blender primitives with real bpy."""
import math
import os

import numpy as np

def studio_world_path(name="courtyard.exr"):
    import bpy
    return os.path.join(bpy.utils.system_resource("DATAFILES"), "studiolights", "world", name)


def ensure_registered():
    """The add-on (material settings, panels, engine), registered once per process: through
    sg_prt_addon.register() unless another tier's fixture already did it."""
    import bpy
    import sg_prt_addon
    from sg_prt_addon import engine

    if not hasattr(bpy.types.Material, "sgprt"):
        sg_prt_addon.register()
    for cls in engine.classes:
        if not getattr(cls, "is_registered", False):
            bpy.utils.register_class(cls)


def new_scene(name, width=256, height=256):
    import bpy

    scene = bpy.data.scenes.new(name)
    scene.render.engine = "SG_PRT"
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    camera = bpy.data.objects.new(name + "_camera", bpy.data.cameras.new(name + "_camera"))
    scene.collection.objects.link(camera)
    camera.location = (0.0, -6.0, 1.0)
    camera.rotation_euler = (math.radians(85.0), 0.0, 0.0)
    scene.camera = camera
    return scene


def add_object(scene, obj):
    scene.collection.objects.link(obj)
    return obj


def uv_sphere(scene, name, location, radius=1.0, segments=32, rings=16):
    """A smooth UV sphere with its UV map (bmesh, no operator context needed)."""
    import bmesh
    import bpy

    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius, calc_uvs=True)
    bm.to_mesh(mesh)
    bm.free()
    for polygon in mesh.polygons:
        polygon.use_smooth = True
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    return add_object(scene, obj)


def plane(scene, name, location, size=6.0):
    import bmesh
    import bpy

    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_grid(bm, x_segments=4, y_segments=4, size=size / 2, calc_uvs=True)
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    return add_object(scene, obj)


def material(name, **settings):
    import bpy

    mat = bpy.data.materials.new(name)
    for key, value in settings.items():
        setattr(mat.sgprt, key, value)
    return mat


def image(name, pixels):
    """A float image from (H, W, 4) pixels in Blender's row order (row 0 at the bottom)."""
    import bpy

    height, width = pixels.shape[:2]
    img = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
    img.colorspace_settings.name = "Non-Color"
    img.pixels.foreach_set(np.ascontiguousarray(pixels, np.float32).ravel())
    return img


def point_light(scene, name, location, power, radius=0.0, colour=(1.0, 1.0, 1.0), kind="POINT"):
    import bpy

    data = bpy.data.lights.new(name, kind)
    data.energy = power
    data.color = colour
    data.shadow_soft_size = radius
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    return add_object(scene, obj)


def world_colour(scene, colour):
    import bpy

    world = bpy.data.worlds.new(scene.name + "_world")
    world.color = colour
    if world.node_tree is not None:     # what renders (Blender 5 worlds always use nodes)
        for node in world.node_tree.nodes:
            if node.type == "BACKGROUND":
                node.inputs["Color"].default_value = tuple(colour) + (1.0,)
    scene.world = world
    return world


def world_texture(scene, path, strength=1.0):
    import bpy

    world = bpy.data.worlds.new(scene.name + "_world")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    nodes = world.node_tree.nodes
    background = next(node for node in nodes if node.type == "BACKGROUND")
    background.inputs["Strength"].default_value = strength
    environment = nodes.new("ShaderNodeTexEnvironment")
    environment.image = bpy.data.images.load(path, check_existing=True)
    world.node_tree.links.new(environment.outputs["Color"], background.inputs["Color"])
    scene.world = world
    return world


def render(scene, gbuffer=False):
    """Final render of `scene` with the engine; returns render_engine.last_render."""
    import bpy
    from sg_prt_addon.engine import render_engine

    render_engine.debug["capture_gbuffer"] = gbuffer
    try:
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(scene=scene.name, write_still=False)
    finally:
        render_engine.debug["capture_gbuffer"] = False
    return render_engine.last_render


def relative_error(actual, expected, floor_fraction=1e-3):
    """|a - e| / max(|e|, floor_fraction * max |e|), per element."""
    floor = floor_fraction * max(float(np.max(np.abs(expected))), 1e-30)
    return np.abs(actual - expected) / np.maximum(np.abs(expected), floor)
