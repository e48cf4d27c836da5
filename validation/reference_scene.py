"""The scene the engine sees, as input for the Monte Carlo reference renderer.

The engine's own export (engine.scene_state.SceneState) is converted, so the
reference and the engine score the same geometry, materials, textures (same
pixels, colour space and bilinear sampler), lights, world and camera; only the
light transport differs.
"""
import numpy as np

from sg_prt_addon.biscale import effective_brdf
from sg_prt_addon.blender import export
from sg_prt_addon.reflectance import brdf, models
from sg_prt_addon.techniques.biscale import biscale_shading
from sg_prt_addon.techniques.sg import sg_shading
from validation import biscale_reference, reference
from validation.camera import Camera


def _texture_lookup(params, images):
    """uv -> per-point colours and model for a material with textures (the engine's sampling)."""
    def lookup(uv):
        uv = sg_shading.material_uv(params, uv)
        count = len(uv)
        values = {}
        for name in ("diffuse_color", "specular_color"):
            colour = np.broadcast_to(np.asarray(getattr(params, name), np.float64), (count, 3))
            if name in images:
                colour = colour * sg_shading.sample_material_texture(images[name], uv)[:, :3]
            values[name] = colour
        model_parameters = {}
        for name in models.BY_NAME[params.model].parameters:
            value = np.full(count, float(getattr(params, name)))
            if name in images:
                value = value * sg_shading.sample_material_texture(images[name], uv)[:, 0]
            model_parameters[name] = value
        values["specular_model"] = brdf.model_from_name(params.model, **model_parameters)
        return values
    return lookup


def small_scale_brdf(params):
    """A bi-scale material's small-scale BRDF: its stored lobe fit (one texel: a fit to one measured file), else
    its model with its constant parameters."""
    if getattr(params, "fitted", None) is not None:
        if params.fitted.layers.shape[1:3] != (1, 1):
            raise ValueError(f"material '{params.name}': the reference renders a bi-scale lobe fit of one texel only")
        texel, diffuse = sg_shading.fitted_texel_values(params.fitted, np.zeros((1, 2)))
        return effective_brdf.FittedSmallScale.from_arrays(
            diffuse[0], texel["eta"][0], texel["axis"][0], texel["sharpness"][0], texel["colour"][0],
            texel["shadowing_theta"], texel["shadowing"][0])
    return effective_brdf.SmallScaleMaterial(
        tuple(params.diffuse_color), tuple(params.specular_color), params.model,
        tuple((name, float(getattr(params, name))) for name in models.BY_NAME[params.model].parameters))


def reference_material(params, texture_pixels, biscale_geometry=None):
    """validation.reference.Material of an export.MaterialParams; texture_pixels(texture, slot, decode) gives
    what the shader samples for that slot (export.slot_pixels of an image name or Expression), or None for a
    missing image.  A bi-scale material (params.biscale) renders its ray-traced tile: biscale_geometry(name,
    second) gives the material's biscale.microgeometry tile (or the second one its mask chooses)."""
    if getattr(params, "biscale", None) is not None and biscale_geometry is not None:
        small = small_scale_brdf(params)
        first = biscale_reference.TracedEffectiveBRDF(biscale_geometry(params.name, False), small)
        material = reference.Material((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), first)
        if biscale_shading.MASK_SLOT in params.textures:       # two tiles, chosen by the mask
            second = biscale_reference.TracedEffectiveBRDF(biscale_geometry(params.name, True), small, seed=12)
            mask = texture_pixels(params.textures[biscale_shading.MASK_SLOT], biscale_shading.MASK_SLOT)

            def lookup(uv):
                uv = sg_shading.material_uv(params, uv)
                weight = np.clip(sg_shading.sample_material_texture(mask, uv)[:, 0].astype(np.float64), 0.0, 1.0)
                return {"specular_model": biscale_reference.BlendedTiles(first, second, weight)}

            material.textures = lookup
        return material
    constant = {name: float(getattr(params, name)) for name in models.BY_NAME[params.model].parameters}
    material = reference.Material(np.asarray(params.diffuse_color, float), np.asarray(params.specular_color, float),
                                  brdf.model_from_name(params.model, **constant))
    images = {slot: texture_pixels(value, slot, True if slot in params.decoded_slots else None)
              for slot, value in params.textures.items() if slot != "normal_map"}
    images = {slot: pixels for slot, pixels in images.items() if pixels is not None}
    if images:
        material.textures = _texture_lookup(params, images)
    return material


def reference_lights(light_exports):
    lights = []
    for light in light_exports:
        if light.kind == "SUN":
            lights.append(reference.DirectionalLight(-np.asarray(light.direction), np.asarray(light.colour_intensity),
                                                     angular_radius=0.5 * light.angle))
        elif light.kind == "AREA":
            lights.append(reference.AreaLight(np.asarray(light.position), np.asarray(light.edge_u),
                                              np.asarray(light.edge_v), np.asarray(light.direction),
                                              np.asarray(light.colour_intensity), light.shape, light.spread))
        else:
            spot = dict(spot_direction=np.asarray(light.direction), spot_size=light.spot_size,
                        spot_blend=light.spot_blend) if light.is_spot else {}
            lights.append(reference.PointLight(np.asarray(light.position), np.asarray(light.colour_intensity),
                                               radius=light.radius,
                                               soft_falloff=getattr(light, "soft_falloff", False), **spot))
    return lights


def anisotropy_tangents(mesh, entry, materials):
    """(corners, 3) world tangents of a world-space MeshExport as the engine shades with them: per
    material, the UV tangent or (tangent_source OBJECT_AXIS) the object's axis in world space, on the
    surface, turned by tangent_rotation about the normal (surface.frag.glsl, rotate_tangent)."""
    tangents = np.array(mesh.tangents[:, :3], np.float64)
    normals = np.asarray(mesh.normals, np.float64)
    linear = np.asarray(entry.matrix_world, np.float64)[:3, :3]
    for slot, first, count in mesh.material_ranges:
        params = materials[entry.material_names[min(slot, len(entry.material_names) - 1)]]
        object_axis = getattr(params, "tangent_source", "UV_MAP") == "OBJECT_AXIS"
        angle = float(getattr(params, "tangent_rotation", 0.0))
        if not object_axis and not angle:
            continue
        corners = np.unique(mesh.triangles[first:first + count]).astype(np.int64)
        n = normals[corners]
        tangent = np.broadcast_to(linear @ np.asarray(params.tangent_axis, np.float64), n.shape) if object_axis \
            else tangents[corners]
        tangents[corners] = sg_shading.rotate_tangent(n, tangent, angle)
    return tangents


def reference_scene(state, texture_pixels, biscale_geometry=None):
    """validation.reference.Scene of a synced engine SceneState; texture_pixels and biscale_geometry as
    reference_material takes them."""
    material_names = list(state.materials)
    materials = [reference_material(state.materials[name], texture_pixels, biscale_geometry)
                 for name in material_names]
    vertices, normals, uvs, tangents, triangles, material_index = [], [], [], [], [], []
    offset = 0
    for entry in state.objects.values():
        mesh = export.to_world(state.meshes[entry.mesh_key], entry.matrix_world)
        per_triangle = np.zeros(len(mesh.triangles), np.int64)
        for slot, first, count in mesh.material_ranges:
            name = entry.material_names[min(slot, len(entry.material_names) - 1)]
            per_triangle[first:first + count] = material_names.index(name)
        vertices.append(mesh.positions)
        normals.append(mesh.normals)
        uvs.append(mesh.uvs)
        tangents.append(anisotropy_tangents(mesh, entry, state.materials))
        triangles.append(mesh.triangles.astype(np.int64) + offset)
        material_index.append(per_triangle)
        offset += len(mesh.positions)
    if not triangles:
        raise ValueError("the scene has no visible mesh to render")
    world = state.world
    return reference.Scene(
        vertices=np.concatenate(vertices).astype(np.float64), triangles=np.concatenate(triangles),
        normals=np.concatenate(normals).astype(np.float64), materials=materials,
        material_index=np.concatenate(material_index), uvs=np.concatenate(uvs).astype(np.float64),
        tangents=np.concatenate(tangents).astype(np.float64), lights=reference_lights(state.lights),
        environment=None if world.equirect is None else np.asarray(world.equirect, np.float64),
        background=np.asarray(world.colour[:3], np.float64))


def reference_inputs(depsgraph, width, height):
    """(validation.reference.Scene, validation.camera.Camera) of an evaluated depsgraph, as the engine sees it."""
    import bpy

    from sg_prt_addon.engine.scene_state import SceneState

    state = SceneState()
    state.sync(depsgraph)

    def texture_pixels(value, slot, decode=None):
        if not all(name in bpy.data.images for name in export.texture_sources(value)):
            return None
        return export.slot_pixels(value, slot, decode)

    def biscale_geometry(material_name, second):
        from sg_prt_addon.techniques.biscale.blender import biscale_source

        return biscale_source.geometry(bpy.data.materials[material_name], second)

    scene = depsgraph.scene
    camera = export.export_camera(scene.camera.evaluated_get(depsgraph), depsgraph, width, height)
    return reference_scene(state, texture_pixels, biscale_geometry), Camera(camera.view, camera.projection, width,
                                                                            height)


class AnalyticSpecular:
    """validation.reference's specular-model protocol for a validation.brdf_generators.AnalyticMaterial's
    glossy part (F_eta(i.h) x GGX, height-correlated Smith): specular(wo, wi) is its exact
    specular_scalar; sample / pdf are GGX's visible-normal sampling with its exact density
    (the estimator is unbiased whatever the proposal, as long as pdf is the proposal's)."""

    def __init__(self, analytic):
        self.analytic = analytic
        self.proposal = brdf.GGX(roughness=float(analytic.roughness))

    def specular(self, wo, wi):
        return self.analytic.specular_scalar(wo, wi)

    def sample(self, wo, u):
        return self.proposal.sample(wo, u)

    def pdf(self, wo, wi):
        return self.proposal.pdf(wo, wi)


def analytic_reference_material(analytic):
    """validation.reference.Material rendering an AnalyticMaterial exactly, for the materials the
    reference's (kd, ks x scalar specular) form holds: Lambert diffuse (oren_nayar_sigma 0) and
    no retro-reflection; ValueError otherwise."""
    if float(np.max(analytic.oren_nayar_sigma)) != 0.0 or float(np.max(analytic.retro)) != 0.0:
        raise ValueError("the reference renders AnalyticMaterial with oren_nayar_sigma = 0 and retro = 0 only")
    return reference.Material(np.asarray(analytic.diffuse, float), np.asarray(analytic.specular, float),
                              AnalyticSpecular(analytic))
