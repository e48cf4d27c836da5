"""Blender scene -> plain numpy arrays and small dataclasses (no `gpu` here).

Everything the engine draws goes through this module, so the GPU side and the
numpy mirror (techniques/sg/sg_shading.py) see exactly the same numbers:

- meshes: one vertex per face corner (loop), so split normals, UV seams and
  tangent sign flips need no vertex splitting logic; triangles index corners;
  positions/normals/tangents are in object space, with the object's
  matrix_world alongside (a transform edit then needs no re-export);
  `to_world` gives the world-space arrays; `corner_vertex` maps each corner to its Blender
  mesh vertex (per-vertex data such as the visibility bake's coefficients is shared by the
  vertex's corners) and `vertex_normals` are the smooth vertex normals (the bake's frames);
- materials: `material.sgprt` read into `MaterialParams` (defaults when the
  material has no settings or the slot is empty);
- lights in Blender units, converted to the quantities lighting/lights.py takes;
- the world: an Environment Texture's equirect pixels, else the world colour.

`export_counter` counts mesh exports: the viewport's update logic is tested
with it (a material edit must not re-export meshes).
"""
import threading
from dataclasses import dataclass, field

import numpy as np

from .. import techniques
from ..reflectance import layering, models, principled
from . import technique_sides
from .images import image_has_pixels, image_pixels

# Mesh exports since import; tests read it to check what an update re-exported.
export_counter = {"meshes": 0}

# --------------------------------------------------------------------------- bad input

# Bad input met (and repaired) while exporting: NaN/Inf texels, zero-length normals, textures or UV
# tangents on meshes without UVs.  The messages go to the list given to collect_warnings() in the
# calling thread: SceneState.sync() gives its SceneState.warnings, so the texture reads of the upload
# that follows in the same render add to it too (the final render and the viewport run in different
# threads, each with its own list).
_warning_target = threading.local()


def collect_warnings(messages):
    """Send this thread's export warnings to the list `messages` (returned); None stops collecting."""
    _warning_target.messages = messages
    return messages


def warn(message):
    messages = getattr(_warning_target, "messages", None)
    if messages is not None and message not in messages:
        messages.append(message)


# Texel values beyond this magnitude are clamped to it: a few float32 texels near 3e38 summed by the
# environment prefilter (or scaled by the lighting) overflow to Inf.
MAX_TEXEL_VALUE = 1e30


def finite_texels(pixels, what):
    """pixels (..., C) with every texel holding a NaN or +-Inf set to 0 (all channels) and values
    beyond +-MAX_TEXEL_VALUE clamped (a copy only when needed), with a warning each:
    `what: N NaN/Inf texels replaced by 0`, `what: N texels beyond 1e+30 clamped`."""
    if pixels.size == 0 or (pixels.max() <= MAX_TEXEL_VALUE and pixels.min() >= -MAX_TEXEL_VALUE):
        return pixels                                        # (a NaN fails both comparisons)
    bad = ~np.isfinite(pixels).all(axis=-1)
    huge = ~bad & (np.abs(pixels) > MAX_TEXEL_VALUE).any(axis=-1)
    pixels = np.where(bad[..., None], np.float32(0.0), pixels)
    pixels = np.clip(pixels, -MAX_TEXEL_VALUE, MAX_TEXEL_VALUE).astype(np.float32)
    if bad.any():
        warn(f"{what}: {int(np.count_nonzero(bad))} NaN/Inf texels replaced by 0")
    if huge.any():
        warn(f"{what}: {int(np.count_nonzero(huge))} texels beyond {MAX_TEXEL_VALUE:g} clamped")
    return pixels

SCALAR_PARAMETERS = models.SCALAR_PARAMETERS
COLOUR_PARAMETERS = ("diffuse_color", "specular_color")
TEXTURED_PARAMETERS = COLOUR_PARAMETERS + SCALAR_PARAMETERS


@dataclass
class MeshExport:
    """Triangles over face corners, object space, float32/uint32 arrays."""
    positions: np.ndarray          # (V, 3) corner positions
    normals: np.ndarray            # (V, 3) split (corner) normals, unit
    tangents: np.ndarray           # (V, 4) unit tangent xyz, bitangent sign w (+-1)
    uvs: np.ndarray                # (V, 2) active UV map (zeros without one)
    triangles: np.ndarray          # (T, 3) uint32 corner indices, sorted by material index
    material_ranges: list          # [(material_index, first_triangle, triangle_count)]
    has_uv: bool = False
    # corner (loop) -> Blender mesh vertex (mesh.vertices index): corners of a vertex share its
    # per-vertex data (the visibility bake's coefficients); vertex_normals (vertex_count, 3) are the
    # smooth vertex normals (MeshVertex.normal, object space), the bake's local frames
    corner_vertex: np.ndarray = None   # (V,) uint32
    vertex_count: int = 0
    vertex_normals: np.ndarray = None  # (vertex_count, 3) float32


@dataclass
class MaterialParams:
    """material.sgprt as plain values; textures as (name, (H, W, 4) float32 array, row 0 at the bottom)."""
    name: str = ""
    model: str = "GGX"
    diffuse_color: tuple = (0.5, 0.5, 0.5)
    specular_color: tuple = (0.25, 0.25, 0.25)
    roughness: float = 0.3
    ior: float = 1.5
    exponent: float = 100.0
    alpha_x: float = 0.2
    alpha_y: float = 0.05
    nu: float = 100.0
    nv: float = 1000.0
    lobe_count: int = 0             # an anisotropic model's NDF lobes; 0: its default (models.lobes_of)
    warp_mode: str = "split3"      # spherical.warp mode (its DEFAULT_MODE) of the view slice (material.sgprt.sg.view_warp)
    sh_order: int = 5              # the SH technique's order and window (material.sgprt.sh: harmonics.projection's
                                   # names, or "none")
    sh_window: str = "none"
    # the glossy layer (reflectance.layering): Schlick Fresnel on the specular colour, Multiscatter GGX's gain,
    # the F0 of a dielectric layer over the diffuse (below 0: none); emitted radiance (Combined only)
    fresnel: str = "NONE"
    multiscatter: bool = False
    layered_f0: float = -1.0
    emission: tuple = (0.0, 0.0, 0.0)
    source: str = "SETTINGS"       # what the look was read from: material.sgprt.source (NODE_TREE, SETTINGS)
    # texture coordinates from the UV map: u' = a u + b v + c, v' = d u + e v + f (a node tree's Mapping node)
    uv_transform: tuple = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    decoded_slots: tuple = ()      # data slots whose sRGB images are decoded to linear (node trees: as Blender)
    normal_strength: float = 1.0
    tangent_source: str = "UV_MAP"
    tangent_axis: tuple = (1.0, 0.0, 0.0)
    tangent_rotation: float = 0.0
    # parameter name or "normal_map" -> image name, or (node trees) a reflectance.texture_expression.Expression of
    # images that export.slot_pixels evaluates
    textures: dict = field(default_factory=dict)
    technique: str = techniques.DEFAULT    # the registered technique that renders it (techniques/)
    fitted: object = None          # FittedLobes with the fitted-lobes technique and a VALID stored fit
    factorization: object = None   # the factored technique's FactoredTables of its VALID stored factors
    biscale: object = None         # biscale.bvndf.BVNDF of the material's small-scale tile (bi-scale technique)
    # datablocks the look is computed from besides its texture images, ("IMAGE" | "OBJECT" | "MESH", name): the
    # scene state exports the material again when one changes (a bi-scale tile's height image or mesh)
    reads: tuple = ()
    # a technique's own settings without a field above, name -> hashable value (its Blender side's read() sets them)
    options: dict = field(default_factory=dict)

    def values_key(self):
        """Everything but textures, hashable: the material UBO is rebuilt when this changes."""
        def hashable(name, value):
            if name == "options":
                return tuple(sorted(value.items()))
            return value.signature if name in ("fitted", "factorization", "biscale") and value is not None else value

        return tuple((k, hashable(k, v)) for k, v in self.__dict__.items() if k != "textures")


@dataclass(eq=False)
class FittedLobes:
    """A material's stored lobe fit (blender.lobe_fit, format 1) as the engine uploads it.

    layers (L, H, W, 4) float32, Blender row order (row 0 at the bottom, texture t = 0): 0 base
    (kd RGB, eta), 1 + 2k lobe k (axis xyz, sharpness), 2 + 2k lobe k amplitude RGB, then the
    shadowing PCA coefficient layers (4 a layer); table (C + 2, S, 4): row 0 theta_s, row 1 the
    mean, rows 2.. the basis (value in R).  signature: hashable identity of the fit."""
    lobe_count: int
    components: int
    layers: np.ndarray
    table: np.ndarray
    signature: tuple = ()

    @property
    def shadowing_layers(self):
        return -(-self.components // 4)


def export_fitted_lobes(material):
    """FittedLobes of a material's VALID stored fit, else None."""
    from . import lobe_fit

    if getattr(material, "sgprt", None) is None or lobe_fit.fit_status(material)[0] != "VALID":
        return None
    fit = material.sgprt.lobe_fit
    arrays = lobe_fit.lobe_fit_images(material)
    count, components = int(fit.lobe_count), int(fit.shadowing_components)
    roles = ["base"] + [f"lobe_{k}_{part}" for k in range(count) for part in ("axis", "amplitude")]
    roles += [f"shadowing_{j}" for j in range(-(-components // 4))]
    layers = np.stack([arrays[role][::-1] for role in roles]).astype(np.float32)
    signature = (fit.date, fit.source_path, fit.seconds, count, components, fit.width, fit.height,
                 tuple(item.image.name for item in fit.images if item.image is not None))
    return FittedLobes(count, components, np.ascontiguousarray(layers),
                       np.ascontiguousarray(arrays["shadowing_table"], np.float32), signature)


@dataclass
class LightExport:
    """One light: kind 'POINT' (point, spot), 'AREA' or 'SUN'."""
    name: str
    kind: str
    position: tuple                # world position (POINT, AREA: the centre)
    direction: tuple               # world direction the light points along (-Z of the object)
    colour_intensity: tuple        # POINT: radiant intensity W/sr per channel; SUN: irradiance per channel;
                                   # AREA: power W per channel
    radius: float = 0.0            # POINT sphere radius
    angle: float = 0.0             # SUN full angular diameter
    spot_size: float = np.pi       # >= pi: no cone
    spot_blend: float = 0.0
    is_spot: bool = False
    shape: str = "SQUARE"          # AREA: lighting.lights.AREA_SHAPES
    edge_u: tuple = (0.0, 0.0, 0.0)  # AREA: world vectors spanning the light (size along local x and y)
    edge_v: tuple = (0.0, 0.0, 0.0)
    spread: float = np.pi          # AREA: full spread angle


@dataclass
class WorldExport:
    """A constant colour, or an equirect image (H, W, 3) float32 in numpy orientation (row 0 at the top)."""
    colour: tuple = (0.05, 0.05, 0.05)
    image_name: str = ""
    equirect: np.ndarray = None
    strength: float = 1.0


# --------------------------------------------------------------------------- meshes

def _tangents_from_uv(positions, normals, uvs, triangles):
    """Per-corner tangents by accumulating each triangle's UV gradient at the vertices it shares
    position with; for meshes calc_tangents refuses (n-gons).  Sign from the UV handedness."""
    p = positions[triangles]                       # (T, 3, 3)
    t = uvs[triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    safe = np.where(np.abs(det) > 1e-20, det, 1.0)
    tangent = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) / safe[:, None]
    bitangent = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) / safe[:, None]
    per_corner = np.zeros_like(positions)
    per_corner_b = np.zeros_like(positions)
    for k in range(3):
        np.add.at(per_corner, triangles[:, k], tangent)
        np.add.at(per_corner_b, triangles[:, k], bitangent)
    tangent = per_corner - normals * np.sum(per_corner * normals, axis=1, keepdims=True)
    length = np.linalg.norm(tangent, axis=1, keepdims=True)
    fallback = _any_perpendicular(normals)
    tangent = np.where(length > 1e-12, tangent / np.maximum(length, 1e-30), fallback)
    sign = np.where(np.sum(np.cross(normals, tangent) * per_corner_b, axis=1) < 0, -1.0, 1.0)
    return np.concatenate([tangent, sign[:, None]], axis=1)


def _any_perpendicular(normals):
    helper = np.where(np.abs(normals[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    t = np.cross(normals, helper)
    return t / np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-30)


# Vertex coordinates beyond this (object space) are treated as NaN/Inf: float32 transforms overflow.
MAX_COORDINATE = 1e30


def mesh_corner_normals(mesh, vertex_index, name=None):
    """(C, 3) float32 unit corner (split) normals of a bpy Mesh, object space, degenerate ones repaired (the
    shading's normals, and the local frames of per-corner bakes); vertex_index: the corners' vertices."""
    normals = np.empty(len(mesh.loops) * 3, np.float32)
    if hasattr(mesh, "corner_normals"):            # Blender 4.1+
        mesh.corner_normals.foreach_get("vector", normals)
    else:
        mesh.calc_normals_split()
        mesh.loops.foreach_get("normal", normals)
    return _usable_normals(normals.reshape(-1, 3), vertex_index, mesh, name or mesh.name)


def export_mesh_data(mesh, name=None):
    """MeshExport of a bpy Mesh (already evaluated), object space; `name` (the object's) in warnings."""
    export_counter["meshes"] += 1
    mesh.calc_loop_triangles()
    loop_count = len(mesh.loops)
    triangle_count = len(mesh.loop_triangles)
    vertex_co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", vertex_co)
    vertex_index = np.empty(loop_count, np.int64)
    mesh.loops.foreach_get("vertex_index", vertex_index)
    positions = vertex_co.reshape(-1, 3)[vertex_index] if loop_count else np.zeros((0, 3), np.float32)

    normals = mesh_corner_normals(mesh, vertex_index, name)

    triangles = np.empty(triangle_count * 3, np.int64)
    mesh.loop_triangles.foreach_get("loops", triangles)
    triangles = triangles.reshape(-1, 3)
    material_index = np.empty(triangle_count, np.int64)
    mesh.loop_triangles.foreach_get("material_index", material_index)
    finite = (np.abs(positions) <= MAX_COORDINATE).all(axis=1)          # (False with a NaN)
    if not finite.all():
        # NaN/Inf coordinates (scripts, broken modifiers; Blender stores Inf as 3.4e38): leave their
        # triangles out (the vertex transform would overflow), zero the positions
        keep = finite[triangles].all(axis=1)
        triangles, material_index = triangles[keep], material_index[keep]
        triangle_count = len(triangles)
        positions = np.where(finite[:, None], positions, np.float32(0.0))
        warn(f"object '{name or mesh.name}': {len(np.unique(vertex_index[~finite]))} vertices with NaN/Inf "
             f"coordinates (or beyond {MAX_COORDINATE:g}): their {int((~keep).sum())} triangle(s) left out")

    # the UV map renders use (camera icon in the UI), else the active one
    uv_layer = next((layer for layer in mesh.uv_layers if layer.active_render), mesh.uv_layers.active)
    uvs = np.zeros((loop_count, 2), np.float32)
    tangents = None
    if uv_layer is not None and loop_count:
        flat = np.empty(loop_count * 2, np.float32)
        uv_layer.data.foreach_get("uv", flat)
        uvs = flat.reshape(-1, 2)
        try:
            mesh.calc_tangents(uvmap=uv_layer.name)
            tangent = np.empty(loop_count * 3, np.float32)
            sign = np.empty(loop_count, np.float32)
            mesh.loops.foreach_get("tangent", tangent)
            mesh.loops.foreach_get("bitangent_sign", sign)
            tangents = np.concatenate([tangent.reshape(-1, 3), sign[:, None]], axis=1)
            mesh.free_tangents()
        except RuntimeError:                        # n-gons: compute our own
            tangents = None
        if tangents is None:
            tangents = _tangents_from_uv(positions.astype(np.float64), normals.astype(np.float64),
                                         uvs.astype(np.float64), triangles)
    if tangents is None:
        tangents = np.concatenate([_any_perpendicular(normals.astype(np.float64)),
                                   np.ones((loop_count, 1))], axis=1)
    else:
        tangents = _usable_tangents(tangents, normals)

    order = np.argsort(material_index, kind="stable")
    triangles = triangles[order]
    material_index = material_index[order]
    ranges = []
    if triangle_count:
        starts = np.flatnonzero(np.diff(material_index, prepend=-1))
        ends = np.append(starts[1:], triangle_count)
        ranges = [(int(material_index[s]), int(s), int(e - s)) for s, e in zip(starts, ends)]
    return MeshExport(
        positions=np.ascontiguousarray(positions, np.float32),
        normals=np.ascontiguousarray(normals, np.float32),
        tangents=np.ascontiguousarray(tangents, np.float32),
        uvs=np.ascontiguousarray(uvs, np.float32),
        triangles=np.ascontiguousarray(triangles, np.uint32),
        material_ranges=ranges,
        has_uv=uv_layer is not None,
        corner_vertex=np.ascontiguousarray(vertex_index, np.uint32),
        vertex_count=len(mesh.vertices),
        vertex_normals=_vertex_normals(mesh),
    )


def _usable_normals(normals, vertex_index, mesh, name):
    """Corner normals with the zero-length or non-finite ones (degenerate faces: Blender gives them
    (0, 0, 0)) replaced by their vertex's normal, else object +Z; warns with the count."""
    length = np.linalg.norm(normals, axis=1)
    bad = ~(length > 1e-12)                       # zero, NaN
    bad |= ~np.isfinite(length)
    if not bad.any():
        return normals
    normals = normals.copy()
    vertex_normals = _vertex_normals(mesh)[vertex_index[bad]] if len(mesh.vertices) else np.zeros((0, 3))
    vertex_length = np.linalg.norm(vertex_normals, axis=1)
    usable = np.isfinite(vertex_length) & (vertex_length > 1e-12)
    replacement = np.tile(np.array([0.0, 0.0, 1.0], np.float32), (int(bad.sum()), 1))
    replacement[usable] = vertex_normals[usable] / vertex_length[usable, None]
    normals[bad] = replacement
    warn(f"object '{name}': {int(bad.sum())} corner normal(s) of zero length or not finite (degenerate "
         f"faces) replaced by the vertex normal ({int(usable.sum())}) or object +Z ({int((~usable).sum())})")
    return normals


def _usable_tangents(tangents, normals):
    """UV tangents (calc_tangents) with the zero-length or non-finite ones (degenerate UVs or faces)
    replaced by a unit vector perpendicular to the normal, sign +1."""
    tangents = np.asarray(tangents)
    length = np.linalg.norm(tangents[:, :3], axis=1)
    bad = ~(np.isfinite(length) & (length > 1e-12)) | ~np.isfinite(tangents[:, 3])
    if not bad.any():
        return tangents
    tangents = np.array(tangents, np.float64)
    tangents[bad, :3] = _any_perpendicular(np.asarray(normals, np.float64)[bad])
    tangents[bad, 3] = 1.0
    return tangents


def _vertex_normals(mesh):
    normals = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("normal", normals)
    if not np.isfinite(normals).all():             # vertices at NaN/Inf: zero (the shaders' fallback: +Z)
        normals = np.where(np.isfinite(normals), normals, np.float32(0.0))
    return normals.reshape(-1, 3)


def to_world(mesh, matrix_world):
    """The MeshExport in world space (positions, normals by the inverse transpose, tangents with
    the bitangent sign flipped by mirroring transforms), e.g. for ray tracing the scene."""
    matrix = np.asarray(matrix_world, np.float64)
    linear = matrix[:3, :3]
    normal_matrix = np.linalg.inv(linear).T
    handedness = -1.0 if np.linalg.det(linear) < 0 else 1.0

    def unit(v):
        return v / np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-30)

    tangents = np.concatenate([unit(mesh.tangents[:, :3] @ linear.T), mesh.tangents[:, 3:] * handedness], axis=1)
    return MeshExport(
        positions=np.ascontiguousarray(mesh.positions @ linear.T + matrix[:3, 3], np.float32),
        normals=np.ascontiguousarray(unit(mesh.normals @ normal_matrix.T), np.float32),
        tangents=np.ascontiguousarray(tangents, np.float32),
        uvs=mesh.uvs, triangles=mesh.triangles, material_ranges=list(mesh.material_ranges), has_uv=mesh.has_uv,
        corner_vertex=mesh.corner_vertex, vertex_count=mesh.vertex_count,
        vertex_normals=None if mesh.vertex_normals is None else np.ascontiguousarray(
            unit(mesh.vertex_normals @ normal_matrix.T), np.float32))


def export_object_mesh(object_eval):
    """MeshExport of an evaluated object (mesh, curve, text... anything with to_mesh)."""
    mesh = object_eval.to_mesh()
    try:
        exported = export_mesh_data(mesh, object_eval.name)
    finally:
        object_eval.to_mesh_clear()
    if not exported.has_uv and len(exported.triangles):
        _warn_missing_uvs(object_eval)
    return exported


def _warn_missing_uvs(object_eval):
    """A mesh without a UV map whose materials sample textures (they read texel (0, 0) everywhere)
    or take anisotropy tangents from the UV map (they get tangents from the object's axes)."""
    for slot in getattr(object_eval, "material_slots", ()):
        material = slot.material
        settings = getattr(material, "sgprt", None) if material is not None else None
        if settings is None:
            continue
        textures = [name for name in TEXTURED_PARAMETERS if getattr(settings, name + "_texture", None) is not None]
        if settings.normal_map is not None:
            textures.append("normal_map")
        if textures:
            warn(f"object '{object_eval.name}' has no UV map: material '{material.name}' samples its textures "
                 f"({', '.join(textures)}) at UV (0, 0)")
        if settings.model in models.ANISOTROPIC and settings.tangent_source == "UV_MAP":
            warn(f"object '{object_eval.name}' has no UV map: material '{material.name}' (anisotropic, tangent "
                 f"source UV Map) gets tangents from the object's axes instead")


def matrix_to_numpy(matrix):
    return np.array([list(row) for row in matrix], np.float64)


# --------------------------------------------------------------------------- materials

def export_material(material):
    """MaterialParams of a bpy Material (None, or without `sgprt`: the defaults): its SG-PRT settings, or its
    node tree's reading when its Source is the node tree."""
    from . import properties

    params = MaterialParams()
    if material is None:
        return params
    params.name = material.name
    settings = getattr(material, "sgprt", None)
    if settings is None:
        return params
    params.model = settings.model
    params.diffuse_color = tuple(settings.diffuse_color)
    params.specular_color = tuple(settings.specular_color)
    for name in SCALAR_PARAMETERS:
        setattr(params, name, float(getattr(settings, name)))
    params.lobe_count = int(settings.lobe_count)
    technique_sides.read(material, params)
    params.normal_strength = float(settings.normal_strength)
    params.tangent_source = settings.tangent_source
    params.tangent_axis = tuple(settings.tangent_axis)
    params.tangent_rotation = float(settings.tangent_rotation)
    params.fresnel = settings.fresnel
    params.multiscatter = bool(settings.multiscatter)
    params.layered_f0 = principled.dielectric_f0(settings.ior) if settings.layered_diffuse else layering.NO_LAYER
    params.emission = tuple(float(c) * float(settings.emission_strength) for c in settings.emission_color)
    for name in TEXTURED_PARAMETERS:
        image = getattr(settings, name + "_texture", None)
        if image is not None:
            params.textures[name] = image.name
    if settings.normal_map is not None:
        params.textures["normal_map"] = settings.normal_map.name
    if properties.resolved_source(settings) == "NODE_TREE":
        _read_node_tree(material, params)
    params.technique, warnings = technique_sides.resolve(material, params)
    for message in warnings:
        warn(message)
    _finite_settings(params)
    return params


# What a node tree's reading replaces of the SG-PRT settings: the look (the technique's own controls, the
# lobe count and the view warp stay the material's)
NODE_TREE_FIELDS = COLOUR_PARAMETERS + SCALAR_PARAMETERS + (
    "model", "fresnel", "multiscatter", "layered_f0", "emission", "normal_strength", "tangent_source",
    "tangent_axis", "tangent_rotation", "uv_transform")


def _read_node_tree(material, params):
    """The node tree's reading (blender/node_reader.py) in place of the appearance settings (what it does not
    set takes the defaults, not the settings it replaces); its notes in one warning."""
    from . import node_reader

    reading = node_reader.read_material(material)
    params.source = "NODE_TREE"
    defaults = MaterialParams()
    for name in NODE_TREE_FIELDS:
        setattr(params, name, getattr(defaults, name))
    for name, value in reading.fields.items():
        setattr(params, name, value)
    params.textures = dict(reading.textures)
    params.decoded_slots = reading.decoded_slots
    if reading.notes:
        warn(f"material '{material.name}' (node tree): " + "; ".join(reading.notes))


def _finite_settings(params):
    """Non-finite scalar or colour settings (scripts can store them) -> the defaults, warned."""
    defaults = MaterialParams()
    for name in COLOUR_PARAMETERS + SCALAR_PARAMETERS + ("normal_strength", "tangent_rotation", "tangent_axis",
                                                         "layered_f0", "emission"):
        value = getattr(params, name)
        if not np.all(np.isfinite(value)):
            setattr(params, name, getattr(defaults, name))
            warn(f"material '{params.name}': {name} {value} not finite, the default {getattr(defaults, name)} used")
    if params.fitted is not None:
        params.fitted.layers = finite_texels(params.fitted.layers, f"material '{params.name}': stored lobe fit")
        params.fitted.table = finite_texels(params.fitted.table, f"material '{params.name}': stored lobe fit table")


COLOUR_SLOTS = ("diffuse_color", "specular_color")
# What a texture whose image has no pixels (a missing or unreadable file) samples, and what the warning calls it:
# Blender's magenta for colours (what its own engines show), a flat normal for the normal map, 1 for scalars.
MISSING_TEXEL = {"colour": ((1.0, 0.0, 1.0, 1.0), "magenta"), "normal_map": ((0.5, 0.5, 1.0, 1.0), "a flat normal"),
                 "scalar": ((1.0, 1.0, 1.0, 1.0), "the factor alone")}


def _no_pixels_reason(image):
    return f"file '{image.filepath}' missing or unreadable" if image.filepath else "no pixels"


def srgb_to_linear(values):
    """The sRGB transfer function inverted (IEC 61966-2-1), elementwise."""
    values = np.asarray(values, np.float32)
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4).astype(np.float32)


def texture_pixels(image, slot, decode=None):
    """What the shader samples for `slot`: image_pixels, with the RGB of colour slots made
    scene-linear when the image holds sRGB-encoded bytes (float images are linear already;
    data slots such as roughness or the normal map are used as stored, like Non-Color, unless
    `decode`: a node tree's data slot, decoded as Blender decodes it).  NaN/Inf texels become 0,
    with a warning (finite_texels): the upload reads each image once."""
    if not image_has_pixels(image):
        texel, what = MISSING_TEXEL["colour" if slot in COLOUR_SLOTS else "normal_map" if slot == "normal_map"
                                    else "scalar"]
        warn(f"image '{image.name}': {_no_pixels_reason(image)}: {what} used for {slot}")
        return np.array(texel, np.float32).reshape(1, 1, 4)
    if image.source == "TILED" and len(image.tiles) > 1:
        warn(f"image '{image.name}': a UDIM set of {len(image.tiles)} tiles, of which SG-PRT reads tile "
             f"{image.tiles[0].number} alone over every UV (Cycles reads each tile where the UVs reach it)")
    pixels = finite_texels(image_pixels(image), f"image '{image.name}'")
    if decode is None:
        decode = slot in COLOUR_SLOTS
    if decode and not image.is_float and image.colorspace_settings.name == "sRGB":
        pixels = pixels.copy()
        pixels[..., :3] = srgb_to_linear(pixels[..., :3])
    return pixels


def texture_sources(value):
    """The image names a slot's texture reads: its image, or an Expression's (reflectance.texture_expression)."""
    return (value,) if isinstance(value, str) else value.images


def slot_pixels(value, slot, decode=None):
    """What the shader samples for a slot's texture (MaterialParams.textures[slot]): an image's texture_pixels,
    or an Expression evaluated from its images, each decoded as Blender decodes it (a node tree's value)."""
    import bpy

    if isinstance(value, str):
        return texture_pixels(bpy.data.images[value], slot, decode)
    images = {name: texture_pixels(bpy.data.images[name], slot, decode=True) for name in value.images}
    return value.evaluate(images)


# --------------------------------------------------------------------------- lights

# Radiant intensity [W/sr] (point, spot, area) and irradiance [W/m^2] (sun) beyond this are clamped to
# it: the shader multiplies them by the light's SG amplitude (up to ~1e17 at a shading point on the
# light) and the BRDF lobe's, and float32 ends at 3.4e38.  1e20 W/sr is a 1.3e21 W lamp.
MAX_LIGHT_INTENSITY = 1e20


def _clamped_intensity(values, name):
    """Per-channel intensity (or irradiance) with NaN set to 0 and magnitudes beyond
    MAX_LIGHT_INTENSITY (Inf included) clamped to it, warned."""
    values = np.asarray(values, np.float64)
    if np.all(np.abs(values) <= MAX_LIGHT_INTENSITY):           # (False with a NaN)
        return values
    warn(f"light '{name}': intensity {tuple(float(v) for v in values)} clamped to "
         f"+-{MAX_LIGHT_INTENSITY:g} (NaN to 0): float32 shading would overflow")
    return np.clip(np.nan_to_num(values, nan=0.0), -MAX_LIGHT_INTENSITY, MAX_LIGHT_INTENSITY)


def _finite_setting(value, default, what):
    """float(value), or `default` with a warning when it is NaN/Inf (Blender stores what scripts set)."""
    value = float(value)
    if np.isfinite(value):
        return value
    warn(f"{what} {value} not finite, {default:g} used")
    return default


# narrower area light spreads are beams from the patch centres (lighting.lights.MIN_SPREAD)
AREA_SPREAD_WARNING = np.radians(30.0)


def export_light(object_eval, matrix_world=None):
    """LightExport of an evaluated light object in Blender's units, at matrix_world (an instance's; default
    the object's); None for unsupported types (and for a light whose transform is not finite).  Intensities
    are finite and at most MAX_LIGHT_INTENSITY in magnitude, sizes and angles finite (warned otherwise)."""
    from ..lighting import lights as core_lights

    light = object_eval.data
    matrix = matrix_to_numpy(object_eval.matrix_world if matrix_world is None else matrix_world)
    if not np.all(np.isfinite(matrix)):
        warn(f"light '{object_eval.name}': transform not finite, left out")
        return None
    what = f"light '{object_eval.name}':"
    position = tuple(matrix[:3, 3])
    direction = -matrix[:3, 2]
    direction = tuple(direction / max(np.linalg.norm(direction), 1e-30))
    power = _emitted_power(light)
    normalized = bool(getattr(light, "normalize", True))
    if light.type == "SUN":
        angle = _finite_setting(light.angle, 0.0, what + " angle")
        if not normalized and angle > 0.0:
            # Cycles: an unnormalized sun's strength is its radiance, over its disc's projected area
            # pi sin^2(angle / 2) (measured: 1.385x at 1 rad); a sun of angle 0 stays a delta of irradiance S
            power = power * np.pi * np.sin(0.5 * angle) ** 2
        irradiance = _clamped_intensity(power * float(core_lights.blender_sun_irradiance(1.0)), object_eval.name)
        return LightExport(object_eval.name, "SUN", position, direction, tuple(irradiance), angle=angle)
    if light.type in ("POINT", "SPOT"):
        radius = _finite_setting(getattr(light, "shadow_soft_size", 0.0), 0.0, what + " radius")
        # Cycles: an unnormalized sphere has the radiance P / pi, whatever its size (radius 0: intensity P / pi)
        unnormalized = 4 * np.pi * radius * radius if radius > 0 else 4.0
        intensity = _clamped_intensity(power * float(core_lights.blender_point_light_intensity(1.0))
                                       * (1.0 if normalized else unnormalized), object_eval.name)
        export = LightExport(object_eval.name, "POINT", position, direction, tuple(intensity), radius=radius)
        if light.type == "SPOT":
            export.is_spot = True
            export.spot_size = _finite_setting(light.spot_size, np.pi, what + " spot size")
            export.spot_blend = _finite_setting(light.spot_blend, 0.0, what + " spot blend")
        return export
    if light.type == "AREA":
        # a one-sided emitter of its shape, cut into patches by the scene state (lights.area_light_patches)
        shape = light.shape
        size_x = _finite_setting(light.size, 0.0, what + " size")
        size_y = _finite_setting(light.size_y, 0.0, what + " size y") if shape in ("RECTANGLE", "ELLIPSE") else size_x
        edge_u, edge_v = matrix[:3, 0] * size_x, matrix[:3, 1] * size_y
        spread = _finite_setting(getattr(light, "spread", np.pi), np.pi, what + " spread")
        if spread < AREA_SPREAD_WARNING:
            warn(f"{what} a spread of {np.degrees(spread):.0f} degrees is rendered as a beam from each of its "
                 f"patches: the edge of its shaft of light is approximate (Cycles: exact)")
        if not normalized:      # Cycles: the radiance P / pi, whatever the area, so the power P A
            power = power * core_lights.area_light_area(shape, np.linalg.norm(edge_u), np.linalg.norm(edge_v))
        return LightExport(object_eval.name, "AREA", position, direction,
                           tuple(_clamped_intensity(power, object_eval.name)), shape=shape,
                           edge_u=tuple(edge_u), edge_v=tuple(edge_v), spread=spread)
    return None


def _emitted_power(light):
    """A light's power (a sun's strength) per colour as Cycles takes it: colour x energy x 2^exposure, the
    colour tinted by the blackbody colour of its temperature where that is on (Blender 4.5+)."""
    colour = np.asarray(light.color, np.float64)
    if getattr(light, "use_temperature", False):
        colour = colour * np.asarray(light.temperature_color, np.float64)[:3]
    exposure = float(getattr(light, "exposure", 0.0))
    return colour * float(light.energy) * 2.0 ** (exposure if np.isfinite(exposure) else 0.0)


# --------------------------------------------------------------------------- world

def export_world(world):
    """WorldExport of a bpy World from its node tree (blender/world_reader.py: a Background's colour or
    Environment Texture, turned by a Mapping node, and its strength), else its colour."""
    if world is None:
        return WorldExport(colour=(0.0, 0.0, 0.0))
    import bpy

    from . import world_reader

    colour = tuple(world.color)
    # Blender 5 always renders worlds with nodes (use_nodes is deprecated there)
    uses_nodes = world.node_tree is not None and (bpy.app.version >= (5, 0, 0) or world.use_nodes)
    reading = world_reader.read_world(world) if uses_nodes else world_reader.WorldReading()
    if reading.notes:
        warn(f"world '{world.name}' (node tree): " + "; ".join(reading.notes))
    strength = _finite_setting(reading.strength, 0.0, f"world '{world.name}': strength")
    if reading.colour is not None:
        colour = tuple(reading.colour)[:3]
    if not np.all(np.isfinite(colour[:3])):
        warn(f"world '{world.name}': colour {tuple(colour[:3])} not finite, 0 used there")
        colour = tuple(float(c) if np.isfinite(c) else 0.0 for c in colour[:3])
    image = reading.image
    if image is not None and not image_has_pixels(image):
        warn(f"world '{world.name}': image '{image.name}': {_no_pixels_reason(image)}: the "
             f"world colour {tuple(round(float(c), 4) for c in colour[:3])} used")
    elif image is not None:
        pixels = image_pixels(image)[::-1, :, :3]      # numpy orientation, row 0 at the top
        with np.errstate(over="ignore", invalid="ignore"):      # huge x strength: Inf, repaired below
            pixels = pixels * np.float32(strength)
        pixels = finite_texels(pixels, f"world '{world.name}': image '{image.name}'")
        if reading.matrix is not None and not np.allclose(reading.matrix, np.eye(3)):
            from ..lighting import equirect
            pixels = equirect.rotated(pixels, reading.matrix)
        return WorldExport(colour=colour, image_name=image.name, equirect=np.ascontiguousarray(pixels, np.float32),
                           strength=strength)
    return WorldExport(colour=tuple(float(c) * strength for c in colour[:3]), strength=strength)


# --------------------------------------------------------------------------- what renders

@dataclass
class RenderRoles:
    """What a render does with a view layer's objects, by (original) name (render_roles)."""
    hidden: set         # disabled in renders: on the object, or on every collection path that holds it
    holdout: set        # in a Holdout collection (through any path), or the object's own Holdout
    indirect: set       # in an Indirect Only collection (through any path): not seen by the camera


def render_roles(view_layer):
    """RenderRoles of a view layer's collections and objects.  A holdout occludes and cuts the film's alpha; an
    indirect-only object is not seen by the camera (this engine renders direct light only: it only shadows,
    through bakes); a hidden one is left out of renders and of bakes (the viewport's depsgraph still lists
    it)."""
    shown, holdout, indirect = set(), set(), set()

    def walk(layer_collection, in_holdout, in_indirect):
        if layer_collection.collection.hide_render:
            return
        in_holdout = in_holdout or layer_collection.holdout
        in_indirect = in_indirect or layer_collection.indirect_only
        names = [obj.name for obj in layer_collection.collection.objects]
        shown.update(names)
        if in_holdout:
            holdout.update(names)
        if in_indirect:
            indirect.update(names)
        for child in layer_collection.children:
            walk(child, in_holdout, in_indirect)

    walk(view_layer.layer_collection, False, False)
    objects = list(view_layer.objects)
    hidden = {obj.name for obj in objects if obj.hide_render or obj.name not in shown}
    holdout.update(obj.name for obj in objects if getattr(obj, "is_holdout", False))
    return RenderRoles(hidden, holdout - hidden, indirect - hidden)


# --------------------------------------------------------------------------- camera

@dataclass
class CameraExport:
    view: np.ndarray               # 4x4 world -> camera
    projection: np.ndarray         # 4x4 camera -> clip
    position: tuple
    forward: tuple                 # camera -Z in world
    is_perspective: bool = True
    shading_footprint: float = 0.0  # pixels a side each pixel's specular averages over (anti_aliasing.specular_footprint)
    footprint_grid_limit: int = 4   # at most this many specular samples a side of that footprint (sg_shading.glsl)


def camera_from_view(view_matrix, projection_matrix, is_perspective):
    """CameraExport from a view (world -> camera) and projection matrix, e.g. a 3D viewport's
    region_data.view_matrix / window_matrix."""
    view = matrix_to_numpy(view_matrix)
    camera_to_world = np.linalg.inv(view)
    forward = -camera_to_world[:3, 2]
    return CameraExport(view=view, projection=matrix_to_numpy(projection_matrix),
                        position=tuple(camera_to_world[:3, 3]),
                        forward=tuple(forward / max(np.linalg.norm(forward), 1e-30)),
                        is_perspective=bool(is_perspective))


def export_camera(camera_object, depsgraph, width, height, scale_x=1.0, scale_y=1.0):
    """Render camera of the scene: view = matrix_world^-1, projection from calc_matrix_camera."""
    matrix_world = camera_object.matrix_world
    projection = camera_object.calc_matrix_camera(depsgraph, x=width, y=height, scale_x=scale_x, scale_y=scale_y)
    world = matrix_to_numpy(matrix_world)
    forward = -world[:3, 2]
    return CameraExport(view=matrix_to_numpy(matrix_world.inverted()), projection=matrix_to_numpy(projection),
                        position=tuple(world[:3, 3]),
                        forward=tuple(forward / max(np.linalg.norm(forward), 1e-30)),
                        is_perspective=camera_object.data.type != "ORTHO")
