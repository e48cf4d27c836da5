"""Scenes for the engine tests, built from Blender primitives with real bpy."""
import contextlib
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
    from sg_prt_addon import registration

    if not hasattr(bpy.types.Material, "sgprt"):
        sg_prt_addon.register()
    for cls in registration.ENGINE_CLASSES:
        if not getattr(cls, "is_registered", False):
            bpy.utils.register_class(cls)


def new_scene(name, width=256, height=256):
    import bpy

    scene = bpy.data.scenes.new(name)
    scene.render.engine = "SG_PRT"
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    # the Monte Carlo references shade pixel centres; the tests of the footprint sampling and of Render Samples
    # turn them on
    scene.sgprt.specular_anti_aliasing = False
    scene.sgprt.render_samples = 1
    # the tests of the SSDF's light shadows (and the mirrors of their variants) keep them; test_light_shadows.py
    # and the stress tests turn the shadow maps on
    scene.sgprt.light_shadows = "SSDF"
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
    bm.loops.layers.uv.new("UVMap")         # calc_uvs fills an existing layer, it makes none
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
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_grid(bm, x_segments=4, y_segments=4, size=size / 2, calc_uvs=True)
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    return add_object(scene, obj)


def material(name, **settings):
    """A new material with these material.sgprt settings; a dict sets a technique's group (sh={"order": 7})."""
    import bpy

    mat = bpy.data.materials.new(name)
    for key, value in settings.items():
        if isinstance(value, dict):
            for inner, inner_value in value.items():
                setattr(getattr(mat.sgprt, key), inner, inner_value)
        else:
            setattr(mat.sgprt, key, value)
    return mat


def svbrdf_table_file(folder):
    """A generated 8 x 8 SVBRDF table (spatially varying kd, eta, roughness; seed 5), written to folder/table.npz:
    what the fitted-lobe tests fit."""
    from sg_prt_addon.measured import svbrdf_table
    from validation import brdf_generators

    path = str(folder / "table.npz")
    table, _ = brdf_generators.generate_svbrdf_table(size=8, seed=5)
    svbrdf_table.write_svbrdf_table(path, table)
    return path


def fit_lobes(material, path, **options):
    """Fit Lobes (bpy.ops.sgprt.fit_lobes) of the file at path on material; it must finish."""
    import bpy

    with bpy.context.temp_override(material=material):
        assert bpy.ops.sgprt.fit_lobes(filepath=path, **options) == {"FINISHED"}


def waves(side=8):
    """(side, side, 4) pixels of three slow waves, one a channel (a smooth colour image the tests read back)."""
    u, v = np.meshgrid((np.arange(side) + 0.5) / side, (np.arange(side) + 0.5) / side)
    pixels = np.ones((side, side, 4), np.float32)
    pixels[..., 0] = 0.5 + 0.4 * np.sin(2 * np.pi * u)
    pixels[..., 1] = 0.5 + 0.4 * np.cos(2 * np.pi * v)
    pixels[..., 2] = 0.2 + 0.6 * u * v
    return pixels


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


@contextlib.contextmanager
def recorded_variant_keys():
    """A list that collects the variant key of every surface shader asked for (shader_cache.get_shader)
    inside the block: what a render really drew with."""
    from sg_prt_addon.engine import shader_cache

    keys, get_shader = [], shader_cache.get_shader
    shader_cache.get_shader = lambda technique, key: keys.append(key) or get_shader(technique, key)
    try:
        yield keys
    finally:
        shader_cache.get_shader = get_shader


def variant_key(params, has_lights=False, has_environment=False, gbuffer=False, visibility_layers=0,
                diffuse_rows=0, shared_light_visibility=False):
    """The variant key of an export.MaterialParams's technique for a scene described by its facts (not by
    lights and an environment): diffuse_rows and shared_light_visibility stand in for what the SG
    technique derives from the environment, the lights and the object's bounds."""
    from sg_prt_addon import techniques
    from sg_prt_addon.lighting.scene_lighting import EnvironmentData, LightData

    inputs = techniques.ObjectInputs(LightData(), EnvironmentData(), gbuffer,
                                     {"ssdf": visibility_layers} if visibility_layers else {})
    inputs.has_lights, inputs.has_environment = bool(has_lights), bool(has_environment)
    inputs.memo.update(diffuse_rows=diffuse_rows, shared_light_visibility=bool(shared_light_visibility))
    return techniques.for_material(params).variant_key(params, inputs)


def technique_of(key):
    """The registered technique a variant key belongs to."""
    from sg_prt_addon import techniques
    return techniques.get(key.technique)


def variant_defines(key):
    """name -> value of every define of a variant's shader (the scene limits included)."""
    return {arguments[0]: arguments[1] for method, arguments in technique_of(key).create_info_calls(key)
            if method == "define"}


def variant_fragment(key):
    """The assembled fragment source of a variant's shader."""
    return next(arguments[0] for method, arguments in technique_of(key).create_info_calls(key)
                if method == "fragment_source")


def content_hash(key):
    from sg_prt_addon.engine import shader_cache
    return shader_cache.content_hash(technique_of(key).create_info_calls(key))


def render(scene, gbuffer=False, environment_layer_size=None):
    """Final render of `scene` with the engine; returns render_engine.last_render.
    environment_layer_size: the prefilter's layer size for this render (small: fast), else the
    current setting."""
    import bpy

    from sg_prt_addon.engine import render_engine

    layer_size = render_engine.debug["environment_layer_size"]
    render_engine.debug["capture_gbuffer"] = gbuffer
    if environment_layer_size is not None:
        render_engine.debug["environment_layer_size"] = environment_layer_size
    try:
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(scene=scene.name, write_still=False)
    finally:
        render_engine.debug["capture_gbuffer"] = False
        render_engine.debug["environment_layer_size"] = layer_size
    return render_engine.last_render


@contextlib.contextmanager
def tracked_state(scene, view_layer):
    """A SceneState synced to the evaluated `view_layer` (dirty set consumed), fed every later edit of
    `scene` through a depsgraph_update_post handler, as view_update feeds it; yields the state."""
    import bpy

    from sg_prt_addon.engine import scene_state

    view_layer.update()             # evaluate the scene once, before tracking edits
    state = scene_state.SceneState()
    state.sync(view_layer.depsgraph)
    state.consume_dirty()

    def on_update(updated_scene, depsgraph):
        if updated_scene == scene:
            state.update(depsgraph)

    bpy.app.handlers.depsgraph_update_post.append(on_update)
    try:
        yield state
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(on_update)


def relative_error(actual, expected, floor_fraction=1e-3):
    """|a - e| / max(|e|, floor_fraction * max |e|), per element."""
    floor = floor_fraction * max(float(np.max(np.abs(expected))), 1e-30)
    return np.abs(actual - expected) / np.maximum(np.abs(expected), floor)


# --------------------------------------------------------------------------- visibility bakes

def grid(scene, name, location, size=6.0, segments=64):
    """A flat square grid of segments x segments quads (a finely tessellated floor for shadows)."""
    import bmesh
    import bpy

    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_grid(bm, x_segments=segments, y_segments=segments, size=size / 2, calc_uvs=True)
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    return add_object(scene, obj)


def mesh_world_arrays(obj):
    """World-space (vertices, vertex normals, loop-triangle vertex indices) of a mesh object, as the
    Bake Visibility operator takes them (one SSDF per Blender mesh vertex)."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    matrix = np.array([list(row) for row in obj.matrix_world], np.float64)
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    normals = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("normal", normals)
    triangles = np.empty(len(mesh.loop_triangles) * 3, np.int64)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    vertices = co.reshape(-1, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]
    normals = normals.reshape(-1, 3).astype(np.float64) @ np.linalg.inv(matrix[:3, :3])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    return vertices, normals, triangles.reshape(-1, 3)


def bake_objects(scene, receivers, resolution=16, terms=None, error_target=0.02, max_terms=47):
    """visibility.pipeline.bake_visibility of each receiver object against every mesh object of the scene;
    returns {object name: BakeResult} and installs it as engine.scene_state.visibility_provider
    (standing in for bakes stored in the .blend).  Call clear_bakes() afterwards."""
    from sg_prt_addon.engine import scene_state
    from sg_prt_addon.visibility.pipeline import BakeOptions, bake_visibility

    scene.view_layers[0].update()       # the scene's own: matrix_world of objects made since (not the context's)
    arrays = {obj.name: mesh_world_arrays(obj) for obj in scene.objects if obj.type == "MESH"}
    occluder_vertices, occluder_triangles, offset = [], [], 0
    for vertices, _, triangles in arrays.values():
        occluder_vertices.append(vertices)
        occluder_triangles.append(triangles + offset)
        offset += len(vertices)
    occluder_vertices = np.concatenate(occluder_vertices).astype(np.float32)
    occluder_triangles = np.concatenate(occluder_triangles).astype(np.int32)
    options = BakeOptions(resolution=resolution, terms=terms, error_target=error_target, max_terms=max_terms)
    bakes = {}
    for obj in receivers:
        vertices, normals, triangles = arrays[obj.name]
        bakes[obj.name] = bake_visibility(vertices, triangles, normals, occluder_vertices, occluder_triangles, options)
    scene_state.visibility_provider = lambda object_eval: bakes.get(object_eval.name)
    return bakes


def mirror_uv(gbuffer_uv):
    """The mirrors' texture coordinates of G-buffer uv rows (N, 4): (u, v, the textures' footprint), its w less 1
    (common/surface_io.glsl surface_write)."""
    gbuffer_uv = np.asarray(gbuffer_uv)
    return np.column_stack([gbuffer_uv[:, :2], gbuffer_uv[:, 3] - 1.0])


def clear_bakes():
    from sg_prt_addon.engine import scene_state
    scene_state.visibility_provider = None


def _pixel_corners(result, mask):
    """(object entry, its world-space MeshExport, corner vertices (N, 3), barycentric weights (N, 3)) of the
    G-buffer pixels `mask` (all of one object), as the GPU interpolates: the triangle (position.w - 1) of
    the object (normal.w - 1), the weights from the interpolated world position."""
    from sg_prt_addon.blender import export

    passes, state = result["passes"], result["state"]
    object_index = np.unique(np.rint(passes["gbuffer_normal"][mask][:, 3]).astype(int) - 1)
    assert len(object_index) == 1, "pixels of one object"
    entry = list(state.objects.values())[object_index[0]]
    mesh = export.to_world(state.meshes[entry.mesh_key], entry.matrix_world)
    triangle = np.rint(passes["gbuffer_position"][mask][:, 3]).astype(np.int64) - 1
    corners = mesh.triangles[triangle].astype(np.int64)                    # (N, 3)
    p = mesh.positions.astype(np.float64)[corners]                          # (N, 3, 3)
    x = passes["gbuffer_position"][mask][:, :3].astype(np.float64)
    e1, e2, d = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], x - p[:, 0]
    d11, d12, d22 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    d1, d2 = (d * e1).sum(1), (d * e2).sum(1)
    det = d11 * d22 - d12 * d12
    b1 = (d22 * d1 - d12 * d2) / det
    b2 = (d11 * d2 - d12 * d1) / det
    weights = np.stack([1 - b1 - b2, b1, b2], axis=1)                       # (N, 3)
    return entry, mesh, mesh.corner_vertex.astype(np.int64)[corners], weights


def pixel_per_vertex(result, mask, kind):
    """(rows (N, 4 L) float32 interpolated to the G-buffer pixels `mask` (all of one object), the object's
    visibility.per_vertex.PerVertexData of `kind`), or (None, None) without one."""
    entry, _mesh, vertex, weights = _pixel_corners(result, mask)
    data = result["state"].per_vertex.get(entry.mesh_key, {}).get(kind)
    if data is None:
        return None, None
    return np.einsum("nk,nkc->nc", weights, data.rows[vertex].astype(np.float64)).astype(np.float32), data


def pixel_visibility(result, mask):
    """techniques.sg.sg_shading.Visibility of the G-buffer pixels `mask` (all of one object with a bake), rebuilt
    as the GPU interpolates (_pixel_corners): the corners' vertex rows and SSDF normals, and the broad
    diffuse lobes' visibility decoded at the corners' vertices.  None when the object has no usable bake."""
    from sg_prt_addon.techniques.sg import sg_shading

    state = result["state"]
    entry, mesh, vertex, weights = _pixel_corners(result, mask)
    data = state.visibility.get(entry.mesh_key)
    if data is None:
        return None
    rows = np.einsum("nk,nkc->nc", weights, data.packed[vertex].astype(np.float64))
    normal = np.einsum("nk,nkc->nc", weights, mesh.vertex_normals[vertex].astype(np.float64))
    # the broad diffuse lobes: decoded at the vertices, interpolated (renderer's per-vertex pass)
    at_vertices = sg_shading.vertex_diffuse_visibility(state.environment, sg_shading.Visibility(
        rows=data.packed, normal=mesh.vertex_normals, basis_texture=data.basis_texture))
    diffuse = np.einsum("nk,nke->ne", weights, at_vertices[vertex].astype(np.float64))
    # the renderer's choice for the object: its local box, to world
    shared_light = sg_shading.shares_light_visibility(state.light_data(), sg_shading.world_bounds(
        state.meshes[entry.mesh_key].positions, entry.matrix_world))
    return sg_shading.Visibility(rows=rows.astype(np.float32), normal=normal.astype(np.float32),
                              basis_texture=data.basis_texture, diffuse=diffuse.astype(np.float32),
                              shared_light=shared_light)


def pixel_sh_transfer(result, mask, params):
    """(order, the SH mirror's transfer inputs (sh_shading.transfer_sums' at the pixels)) of the G-buffer pixels
    `mask` (all of one object with a transfer bake), summed as the variant sums them: at the vertices and
    interpolated (spherical_harmonics.vertex_transfer_rows), else of the interpolated weights."""
    from sg_prt_addon.techniques.sh import sh_shading, spherical_harmonics
    from sg_prt_addon.visibility import transfer

    state = result["state"]
    entry, _mesh, vertex, weights = _pixel_corners(result, mask)
    data = state.per_vertex[entry.mesh_key]["transfer"]
    order = min(params.sh_order, spherical_harmonics.transfer_order(data))
    count, has_lights = order * order, state.light_data().count > 0
    rows = spherical_harmonics.vertex_transfer_rows(order, has_lights)
    if not rows:
        pixel_rows = np.einsum("nk,nkc->nc", weights, data.rows[vertex].astype(np.float64)).astype(np.float32)
        return order, sh_shading.transfer_sums(pixel_rows, spherical_harmonics.transfer_radiance_texture(
            data, state.environment, order, params.sh_window), transfer.basis_terms(data.basis_texture), count)
    values = spherical_harmonics.vertex_transfer_values(data, state.environment, order, params.sh_window, rows)
    pixel = np.einsum("nk,nkc->nc", weights, values[vertex].astype(np.float64)).astype(np.float32)
    diffuse_transfer = pixel[:, 3 * count + 3:4 * count + 3] if has_lights else np.zeros((len(pixel), count))
    return order, (pixel[:, :3 * count].reshape(-1, count, 3), pixel[:, 3 * count:3 * count + 3], diffuse_transfer)
