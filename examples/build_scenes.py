"""Build the example scenes from Blender's own primitives and bundled HDRIs.

    .venv/bin/python examples/build_scenes.py out/scenes      # writes one .blend per scene
    .venv/bin/python examples/build_scenes.py out/scenes suzanne_courtyard     # that one only
    blender -b --python examples/build_scenes.py -- out/scenes                 # with a Blender binary

Each builder starts from an empty file and returns the scene; `save_scene`
writes it with every image packed, so the .blend is self-contained.
"""
import math
import sys
from pathlib import Path

import bpy
import numpy as np
from mathutils import Vector

ENGINE_ID = "SG_PRT"


def bundled_hdri(name):
    """Path of one of the HDRIs that ship inside Blender (courtyard, forest, city, interior, ...)."""
    path = Path(bpy.utils.system_resource("DATAFILES", path="studiolights/world")) / f"{name}.exr"
    if not path.is_file():
        raise FileNotFoundError(f"Blender's bundled HDRI {path} is missing")
    return path


def _empty_file():
    # the home file, not the factory settings: those would turn off the add-ons of a Blender that has SG-PRT
    # installed as an extension
    bpy.ops.wm.read_homefile(use_empty=True)
    return bpy.context.scene


def _apply_modifiers(obj):
    """Bake the modifier stack into the mesh, so per-vertex bakes address the final vertices."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = bpy.data.meshes.new_from_object(obj.evaluated_get(depsgraph))
    obj.modifiers.clear()
    old, obj.data = obj.data, mesh
    bpy.data.meshes.remove(old)


def _add_camera(scene, location, target, lens=50.0):
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.lens = lens
    camera.location = location
    camera.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(camera)
    scene.camera = camera
    return camera


def _world_with_hdri(scene, hdri_path, strength=1.0):
    world = bpy.data.worlds.new("World")
    if bpy.app.version < (5, 0, 0):      # Blender 5 worlds always use nodes
        world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = next(node for node in nodes if node.type == "BACKGROUND")
    background.inputs["Strength"].default_value = strength
    environment = nodes.new("ShaderNodeTexEnvironment")
    environment.image = bpy.data.images.load(str(hdri_path), check_existing=True)
    links.new(environment.outputs["Color"], background.inputs["Color"])
    scene.world = world
    return world


def _world_with_colour(scene, colour):
    world = bpy.data.worlds.new("World")
    if bpy.app.version < (5, 0, 0):      # Blender 5 worlds always use nodes
        world.use_nodes = True
    background = next(node for node in world.node_tree.nodes if node.type == "BACKGROUND")
    background.inputs["Color"].default_value = (*colour, 1.0)
    world.color = colour
    scene.world = world
    return world


def _image_from_array(name, rgb):
    """A packed 8-bit image from an (H, W, 3) array in [0, 1], row 0 at the top."""
    height, width = rgb.shape[:2]
    image = bpy.data.images.new(name, width, height, alpha=False)
    rgba = np.concatenate([rgb, np.ones((height, width, 1))], axis=-1)[::-1]  # Blender rows start at the bottom
    image.pixels.foreach_set(np.ascontiguousarray(rgba, np.float32).ravel())
    image.pack()
    return image


def _tile_pattern(size=256, tiles=8, seed=1):
    """Deterministic tiles with per-tile colour and roughness, for a visibly spatially-varying material."""
    rng = np.random.default_rng(seed)
    tile_colour = rng.uniform(0.15, 0.85, (tiles, tiles, 3))
    tile_roughness = rng.uniform(0.15, 1.0, (tiles, tiles))
    index = (np.arange(size) * tiles) // size
    colour = tile_colour[index[:, None], index[None, :]]
    roughness = tile_roughness[index[:, None], index[None, :]]
    grout = ((np.arange(size) * tiles) % size < size // (tiles * 8))
    grout = grout[:, None] | grout[None, :]
    colour[grout] = 0.05
    roughness[grout] = 1.0
    return colour, np.repeat(roughness[..., None], 3, axis=-1)


def _material(name, **settings):
    """A material with its SG-PRT settings."""
    material = bpy.data.materials.new(name)
    for key, value in settings.items():
        setattr(material.sgprt, key, value)
    return material


def _grid(name, size, subdivisions):
    """A floor grid, tessellated finely enough to carry per-vertex visibility."""
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=subdivisions, y_subdivisions=subdivisions, size=size)
    obj = bpy.context.active_object
    obj.name = name
    return obj


def build_suzanne_courtyard(resolution=512):
    """Subdivided Suzanne on a tiled floor under courtyard.exr, textured Cook-Torrance."""
    scene = _empty_file()
    scene.render.engine = ENGINE_ID
    scene.render.resolution_x = scene.render.resolution_y = resolution
    _world_with_hdri(scene, bundled_hdri("courtyard"))

    colour, roughness = _tile_pattern()
    floor_material = _material("Tiles", model="COOK_TORRANCE", diffuse_color=(1.0, 1.0, 1.0),
                               diffuse_color_texture=_image_from_array("tiles_colour", colour),
                               specular_color=(0.3, 0.3, 0.3), roughness=0.5,
                               roughness_texture=_image_from_array("tiles_roughness", roughness))
    suzanne_material = _material("Glaze", model="COOK_TORRANCE", diffuse_color=(0.6, 0.12, 0.05),
                                 specular_color=(0.5, 0.5, 0.5), roughness=0.2)

    floor = _grid("Floor", size=6.0, subdivisions=64)
    floor.data.materials.append(floor_material)

    bpy.ops.mesh.primitive_monkey_add(size=2.0, location=(0.0, 0.0, 1.0))
    suzanne = bpy.context.active_object
    suzanne.name = "Suzanne"
    suzanne.rotation_euler = (math.radians(-20), 0.0, math.radians(20))
    suzanne.modifiers.new("Subdivision", "SUBSURF").levels = 2
    _apply_modifiers(suzanne)
    suzanne.data.shade_smooth()
    suzanne.data.materials.append(suzanne_material)

    _add_camera(scene, location=(4.5, -5.5, 3.2), target=(0.0, 0.0, 0.8))
    return scene


def build_brushed_metal(resolution=512):
    """An anisotropic Ashikhmin-Shirley torus lit by a point light in a dark room."""
    scene = _empty_file()
    scene.render.engine = ENGINE_ID
    scene.render.resolution_x = scene.render.resolution_y = resolution
    _world_with_colour(scene, (0.02, 0.02, 0.025))

    metal = _material("Brushed Metal", model="ASHIKHMIN_SHIRLEY", diffuse_color=(0.02, 0.02, 0.02),
                      specular_color=(0.9, 0.85, 0.75), nu=50.0, nv=800.0, lobe_count=6,
                      tangent_source="OBJECT_AXIS", tangent_axis=(0.0, 0.0, 1.0))
    floor_material = _material("Floor", model="GGX", diffuse_color=(0.4, 0.4, 0.4),
                               specular_color=(0.1, 0.1, 0.1), roughness=0.4)

    floor = _grid("Floor", size=8.0, subdivisions=64)
    floor.data.materials.append(floor_material)

    bpy.ops.mesh.primitive_torus_add(major_radius=1.2, minor_radius=0.45, major_segments=96, minor_segments=48,
                                     location=(0.0, 0.0, 1.0), rotation=(math.radians(70), 0.0, 0.0))
    torus = bpy.context.active_object
    torus.name = "Torus"
    torus.data.shade_smooth()
    torus.data.materials.append(metal)

    light = bpy.data.objects.new("Key Light", bpy.data.lights.new("Key Light", "POINT"))
    light.data.energy = 1500.0
    light.data.shadow_soft_size = 0.1
    light.location = (2.5, -2.0, 4.0)
    scene.collection.objects.link(light)

    _add_camera(scene, location=(0.0, -6.5, 2.6), target=(0.0, 0.0, 0.9))
    return scene


def _hammered_heights(size=64, dents=40, seed=3):
    """A tileable field of overlapping round dents (heights in tile widths), as a hammered metal sheet."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:size, 0:size] / size
    heights = np.zeros((size, size))
    for cx, cy, radius in zip(rng.random(dents), rng.random(dents), rng.uniform(0.08, 0.16, dents)):
        dx = (x - cx + 0.5) % 1.0 - 0.5             # periodic distance: the sheet tiles
        dy = (y - cy + 0.5) % 1.0 - 0.5
        depth = np.sqrt(np.maximum(radius * radius - dx * dx - dy * dy, 0.0)) - 0.85 * radius   # rims at 32 degrees
        heights = np.minimum(heights, -np.maximum(depth, 0.0))
    return heights


def _height_image(name, heights):
    """A packed float image of heights (row 0 at the top), Non-Color."""
    size = heights.shape[0]
    image = bpy.data.images.new(name, size, size, alpha=False, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    rgba = np.repeat(heights[::-1, :, None], 4, axis=-1)
    rgba[..., 3] = 1.0
    image.pixels.foreach_set(np.ascontiguousarray(rgba, np.float32).ravel())
    image.pack()
    return image


def build_hammered_metal(resolution=512):
    """A hammered gold sphere (a bi-scale material, iwasaki2012: a height field of dents under a glossy GGX)
    beside a smooth one of the same small-scale BRDF, on a floor under courtyard.exr."""
    scene = _empty_file()
    scene.render.engine = ENGINE_ID
    scene.render.resolution_x = scene.render.resolution_y = resolution
    _world_with_hdri(scene, bundled_hdri("courtyard"))
    gold = dict(model="GGX", diffuse_color=(0.0, 0.0, 0.0), specular_color=(1.0, 0.78, 0.34), roughness=0.2)
    hammered = _material("Hammered Gold", technique="SG_BISCALE", **gold)
    hammered.sgprt.biscale.height_image = _height_image("hammered_heights", _hammered_heights())
    hammered.sgprt.biscale.height_scale = 1.0
    smooth = _material("Smooth Gold", **gold)
    floor_material = _material("Floor", model="GGX", diffuse_color=(0.35, 0.35, 0.35),
                               specular_color=(0.05, 0.05, 0.05), roughness=0.6)

    floor = _grid("Floor", size=8.0, subdivisions=64)
    floor.data.materials.append(floor_material)
    for name, material, x in (("Hammered", hammered, -1.15), ("Smooth", smooth, 1.15)):
        bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0, location=(x, 0.0, 1.0))
        sphere = bpy.context.active_object
        sphere.name = name
        sphere.data.shade_smooth()
        sphere.data.materials.append(material)

    _add_camera(scene, location=(0.0, -6.0, 2.4), target=(0.0, 0.0, 0.9))
    return scene


SCENES = {
    "suzanne_courtyard": build_suzanne_courtyard,
    "brushed_metal": build_brushed_metal,
    "hammered_metal": build_hammered_metal,
}


def save_scene(path):
    """Save the current file with every image packed (the HDRI too), so it reopens anywhere."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    for image in bpy.data.images:
        if image.packed_file is None and image.source == "FILE":
            image.pack()
    bpy.ops.wm.save_as_mainfile(filepath=str(path), compress=True)
    return path


def main(output_dir, names=()):
    """Write the scenes `names` (default every one) into output_dir."""
    from sg_prt_addon import render
    render.ensure_registered()          # a Blender with the extension installed has it registered already
    for name in names or SCENES:
        SCENES[name]()
        print(f"wrote {save_scene(Path(output_dir) / f'{name}.blend')}", flush=True)


def script_arguments(argv):
    """The script's own arguments: those after '--' when Blender runs it (`blender -b --python
    examples/build_scenes.py -- out`, where argv holds Blender's too; without '--' none), else everything
    after the script (python examples/build_scenes.py out, argv[0] the script)."""
    if "--" in argv:
        return argv[argv.index("--") + 1:]
    return argv[1:] if argv and argv[0].endswith(".py") else []


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    arguments = script_arguments(sys.argv)
    main(arguments[0] if arguments else "out/scenes", arguments[1:])
