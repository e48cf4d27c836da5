"""What wang2009's two techniques share: SG shading of lights and a prefiltered environment, the view warp
of the NDF lobes, and SSDF visibility from a per-vertex bake (shaders/techniques/sg/, mirrored by
techniques.sg.sg_shading).  sg_parametric gives the lobes of an analytic BRDF model, sg_fitted those of a stored
lobe fit; both subclass SGLobes and fill in the model's part through its hooks.

A variant is keyed by what changes the code (not the values): the model, its NDF lobe count, whether
lights / an environment texture are present, which material textures are bound, whether the debug
G-buffer is written, and which of the material's diffuse and specular terms can be non-zero.  A
variant leaves out what its scene does not need: no lights, no light loop; a world colour, no
prefiltered-environment fetch; no visibility bake, no SSDF decode; a zero specular colour (without its
texture), no BRDF slice (NDF lobes, warp, light x slice products, prefiltered fetch and their SSDF
decodes); a zero diffuse colour (without its texture), no irradiance (environment SG mixture, the
lights' diffuse terms and their decodes).  A skipped term is exactly zero in the full variant (its
colour is zero), so the image does not change.

Fragment source = constants from the maths + their GLSL mirrors (shaders/lib) + what surfaces share
(techniques/common/surface_common.glsl) + the technique's pieces (anisotropic_lobes, ggx_two_lobes,
lobe_visibility, sg_shading) + the per-vertex rows' copy
+ surface.frag.glsl.
"""
from dataclasses import dataclass

from ...reflectance import brdf
from ...spherical import clamped_cosine_table, warp
from ...visibility import broad_lobes
from .. import material_textures, shader_sources, surface_layering
from ..base import SURFACE_TEXTURES, Technique
from ..material_textures import NodeValues
from ..shader_sources import MAX_ENV_LOBES, MAX_LAYERS, PerVertexInput
from . import sg_shading
from .fitted_texels import FITTED_MODEL

GLSL_DIR = "sg"
# Library files in dependency order (shaders/lib), then the technique's own (shaders/techniques/sg)
LIBRARY_FILES = ("sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl", "clamped_cosine_table.glsl", "lights.glsl",
                 "shadow_maps.glsl", "brdf.glsl", "warp.glsl", "env_prefilter.glsl")
# (directory under shaders/techniques, file) in order: lobe_visibility is shared with other techniques
TECHNIQUE_FILES = (("sg", "anisotropic_lobes.glsl"), ("sg", "ggx_two_lobes.glsl"), ("common", "lobe_visibility.glsl"),
                   ("common", "fitted_texels.glsl"), ("sg", "sg_models.glsl"))
# After those, the technique's lobe source (SGLobes.lobe_source), then the stages that shade with it
SHADING_FILE = ("sg", "sg_shading.glsl")
# The per-vertex precomputation this technique reads (visibility.per_vertex kinds)
VISIBILITY_KIND = "ssdf"
# texels a vertex of the SSDF's coverage at the quadrature points (vertex_coverage.frag.glsl), four points each
COVERAGE_TEXELS = broad_lobes.QUADRATURE_POINTS // 4
TEXTURE_SLOTS = ("diffuse_color", "specular_color", "roughness", "ior", "exponent",
                 "alpha_x", "alpha_y", "nu", "nv", "normal_map", *SURFACE_TEXTURES)


@dataclass(frozen=True)
class VariantKey:
    technique: str = "SG_PARAMETRIC"
    model: str = "GGX"
    ndf_lobes: int = 1
    has_lights: bool = False
    has_environment: bool = False
    textures: tuple = ()            # sorted names from TEXTURE_SLOTS
    node_values: NodeValues = NodeValues()   # what a node tree computes (material_textures.node_values)
    gbuffer: bool = False
    visibility_layers: int = 0      # vec4 of SSDF coefficients per vertex (0: no visibility bake)
    shadowing_components: int = 0   # sg_fitted: PCA components of the stored shadowing
    has_diffuse: bool = True        # False: zero diffuse colour, no texture: no irradiance code
    has_specular: bool = True       # False: zero specular colour, no texture: no BRDF slice code
    # vec4 of broad diffuse lobe visibility a vertex, from the per-vertex pass (0: none, or decoded per pixel)
    diffuse_visibility_rows: int = 0
    # light x slice products take the light's visibility (techniques.sg.sg_shading.shares_light_visibility; with a bake,
    # lights and a specular term)
    shared_light_visibility: bool = False
    shadow_maps: bool = False       # with lights: the scene's lights have shadow maps (lighting.shadow_maps)
    warp_mode: str = warp.DEFAULT_MODE      # of the view slice (MaterialParams.warp_mode); with a specular term
    layering: tuple = ()            # surface_layering.flags of the material
    biscale_resolution: int = 0     # sg_biscale: the tables' lattice R (0: not bi-scale)
    biscale_first_lobes: int = 0    # sg_biscale: the first tile's BVNDF lobes (all of them with one tile)
    biscale_small_lobes: int = 0    # sg_biscale: the small-scale BRDF's lobes (a BVNDF lobe's effective lobes)

    @property
    def has_visibility(self):
        return self.visibility_layers > 0

    def describe(self):
        parts = [self.model, f"{self.ndf_lobes} lobe(s)", "lights" if self.has_lights else "no lights",
                 "environment texture" if self.has_environment else "world colour"]
        if self.textures:
            parts.append("textures: " + ", ".join(self.textures))
        if self.gbuffer:
            parts.append("G-buffer")
        if self.shadowing_components:
            parts.append(f"{self.shadowing_components} shadowing component(s)")
        if self.visibility_layers:
            parts.append(f"visibility ({self.visibility_layers} coefficient vec4)")
        if self.diffuse_visibility_rows:
            parts.append(f"per-vertex diffuse visibility ({self.diffuse_visibility_rows} vec4)")
        if self.shared_light_visibility:
            parts.append("light visibility shared by its products")
        if self.shadow_maps:
            parts.append("shadow maps")
        if self.has_specular and self.warp_mode != warp.DEFAULT_MODE:
            parts.append(f"warp {self.warp_mode}")
        if self.layering:
            parts.append("layering: " + ", ".join(self.layering))
        if self.biscale_resolution:
            parts.append(f"bi-scale tables at {self.biscale_resolution} x {self.biscale_resolution}")
        if not self.has_diffuse:
            parts.append("no diffuse")
        if not self.has_specular:
            parts.append("no specular")
        return ", ".join(parts)


def diffuse_visibility_rows(environment):
    """vec4 a vertex of the per-vertex pass (vertex_visibility.frag.glsl) for a lighting.scene_lighting.EnvironmentData:
    its diffuse SG lobes four to a vec4, or the constant world's one lobe."""
    if environment.prefiltered is None:
        return 1
    return -(-min(len(environment.lobe_sharpness), MAX_ENV_LOBES) // 4)


def warp_mode_of(material_params):
    """The material's spherical.warp mode (MaterialParams.warp_mode; objects without it: the default)."""
    mode = getattr(material_params, "warp_mode", warp.DEFAULT_MODE)
    if mode not in warp.MODES:
        raise ValueError(f"unknown view warp {mode!r} (spherical.warp.MODES: {', '.join(warp.MODES)})")
    return mode


def warp_function(mode):
    """(GLSL function, lobes per NDF lobe) of a spherical.warp mode (the mirror warps with the same)."""
    return f"warp_lobes_{mode}", warp.nodes_per_lobe(mode)


def scene_fields(inputs, has_diffuse=True, has_specular=True):
    """The VariantKey fields an object's scene decides (base.ObjectInputs): lights, environment, G-buffer,
    the bake's layers, the per-vertex diffuse pass (with a diffuse term), shared light visibility
    (with lights and a specular term) and the lights' shadow maps.  The per-object values are kept in inputs.memo."""
    layers = int(inputs.per_vertex.get(VISIBILITY_KIND, 0))
    memo = inputs.memo
    if "diffuse_rows" not in memo:
        memo["diffuse_rows"] = diffuse_visibility_rows(inputs.environment)
    shared = False
    if layers and inputs.has_lights and has_specular:
        if "shared_light_visibility" not in memo:
            memo["shared_light_visibility"] = inputs.bounds is not None and bool(sg_shading.shares_light_visibility(
                inputs.light_data, sg_shading.world_bounds(inputs.bounds, inputs.matrix_world)))
        shared = memo["shared_light_visibility"]
    return dict(has_lights=bool(inputs.has_lights), has_environment=bool(inputs.has_environment),
                gbuffer=inputs.gbuffer, visibility_layers=layers,
                diffuse_visibility_rows=int(memo["diffuse_rows"]) if layers and has_diffuse else 0,
                shared_light_visibility=bool(shared), shadow_maps=bool(inputs.has_lights and inputs.shadow_maps))


def _constants_source():
    """Constants taken from the numpy side at assembly time, so GLSL and numpy cannot drift apart."""
    rf0 = brdf.AshikhminShirley.__dataclass_fields__["rf0"].default
    literal = shader_sources.float_literal
    return (f"const float BRDF_AS_RF0 = {literal(rf0)};\n"
            f"const float VISIBILITY_SKIP_FRACTION = {literal(sg_shading.VISIBILITY_SKIP_FRACTION)};\n"
            f"const float COSINE_LOOKUP_FULL = {literal(sg_shading.COSINE_LOOKUP_SHARPNESS[0])};\n"
            f"const float COSINE_LOOKUP_NONE = {literal(sg_shading.COSINE_LOOKUP_SHARPNESS[1])};\n"
            f"const float VISIBLE_SIDE_STEP = {literal(sg_shading.VISIBLE_SIDE_STEP)};\n"
            f"const float VISIBLE_SIDE_MAX_FRACTION = {literal(sg_shading.VISIBLE_SIDE_MAX_FRACTION)};\n"
            f"const int VISIBLE_SIDE_LAYERS = {int(sg_shading.VISIBLE_SIDE_LAYERS)};\n"
            f"const float VISIBLE_PART_MAX_TURN = {literal(sg_shading.VISIBLE_PART_MAX_TURN)};\n"
            f"const float VISIBLE_PART_MIN_VARIANCE = {literal(sg_shading.VISIBLE_PART_MIN_VARIANCE)};\n"
            + shader_sources.shadow_map_constants())


def uses_clamped_cosine_table(key):
    """Whether a variant integrates lobes of per-pixel sharpness against the clamped cosine (lights,
    slice lobes, their products): those read spherical.clamped_cosine_table."""
    return key.has_lights or key.has_specular


def per_vertex_inputs(key):
    """The variant's per-vertex rows (shader_sources.PerVertexInput): the bake's SSDF coefficients and the
    per-vertex pass's diffuse fractions, in the arrays lobe_visibility.glsl and sg_shading.glsl declare."""
    if not key.visibility_layers:
        return ()
    inputs = [PerVertexInput("visibility_coefficients", key.visibility_layers, "ssdf_coefficients",
                             "visibility_rows")]
    if key.diffuse_visibility_rows:
        inputs.append(PerVertexInput("diffuse_visibility", key.diffuse_visibility_rows, "diffuse_fractions",
                                     "diffuse_fractions"))
    return tuple(inputs)


class SGLobes(Technique):
    """wang2009's shading; subclasses give the model's lobes through the model_* hooks."""

    paper = "wang2009"
    mirror = staticmethod(sg_shading.shade_fragments)
    blender_side = ".blender"

    # ------------------------------------------------------------- model hooks

    def model_defines(self, key):
        """Defines of the model's part of the BRDF slice (with a specular term)."""
        return {}

    def model_files(self, key):
        """Technique files (TECHNIQUE_FILES) the model needs besides lobe_visibility and sg_shading."""
        return ()

    def model_samplers(self, key):
        """(kind, name) samplers of the model, bound by bind_model."""
        return []

    def bind_model(self, shader, key, context):
        """Bind the samplers of model_samplers."""

    # ------------------------------------------------------------- assembly

    def defines(self, key):
        out = {}
        if key.has_specular:        # the model only shapes the BRDF slice
            out["HAS_SPECULAR"] = 1
            out["WARP_FUNCTION"], out["WARP_NODES"] = warp_function(key.warp_mode)
            out["MODEL_" + key.model] = 1
            out["NDF_LOBES"] = key.ndf_lobes
        if key.has_diffuse:
            out["HAS_DIFFUSE"] = 1
        if key.has_lights:
            out["HAS_LIGHTS"] = 1
        if key.has_environment:
            out["HAS_ENVIRONMENT"] = 1
            if key.has_specular:    # the prefiltered fetch; diffuse reads the SG mixture in the scene block
                out["ENV_PREFILTER_MAX_LAYERS"] = MAX_LAYERS
        for name in key.textures:
            out["HAS_NORMAL_MAP" if name == "normal_map" else "HAS_TEXTURE_" + name.upper()] = 1
        if key.gbuffer:
            out["GBUFFER"] = 1
        if key.visibility_layers:
            out["HAS_VISIBILITY"] = 1
            out["SSDF_MAX_LAYERS"] = key.visibility_layers
        if key.diffuse_visibility_rows:
            out["DIFFUSE_VISIBILITY_ROWS"] = key.diffuse_visibility_rows
        if key.shared_light_visibility:
            out["SHARED_LIGHT_VISIBILITY"] = 1
        if key.shadow_maps:
            out["LIGHT_SHADOW_MAPS"] = 1
        out.update(surface_layering.layering_defines(key.layering, surface_layering.textured_roughness(key.model,
                                                                                                key.textures)))
        out.update(self.model_defines(key))
        return out

    def library_files(self, key):
        """shaders/lib files of a variant, in dependency order: the BRDF, warp and prefiltered environment
        only for the specular term, the lights only with lights, the SSDF decode only with a bake."""
        skip = set()
        if not key.has_specular:
            skip |= {"brdf.glsl", "warp.glsl"}
        if not key.has_lights:
            skip.add("lights.glsl")
        if not key.shadow_maps:
            skip.add("shadow_maps.glsl")
        if not uses_clamped_cosine_table(key):
            skip.add("clamped_cosine_table.glsl")
        if not (key.has_environment and key.has_specular):
            skip.add("env_prefilter.glsl")
        files = [name for name in LIBRARY_FILES if name not in skip]
        return files + (["hemisphere_map.glsl", "ssdf.glsl"] if key.visibility_layers else [])

    def lobe_source(self, key):
        """(folder, file) of the GLSL that gives sg_shading.glsl's stages the technique's lobes (the interface:
        shaders/techniques/sg/lobes_model.glsl): a stored fit's, else the model's own."""
        return ("sg", "lobes_fitted.glsl") if key.model == FITTED_MODEL else ("sg", "lobes_model.glsl")

    def technique_files(self, key):
        wanted = set(self.model_files(key) if key.has_specular else ()) | {"sg_models.glsl"}
        if key.visibility_layers:
            wanted.add("lobe_visibility.glsl")
        if key.model == FITTED_MODEL:
            wanted.add("fitted_texels.glsl")
        files = [(folder, name) for folder, name in TECHNIQUE_FILES if name in wanted]
        return files + [self.lobe_source(key), SHADING_FILE]

    def fragment_source(self, key):
        parts = [_constants_source()]
        parts += [shader_sources.library_source(name) for name in self.library_files(key)]
        parts += material_textures.sources(key)
        if key.layering:
            parts.append(surface_layering.source())
        parts += [shader_sources.technique_source(folder, name) for folder, name in self.technique_files(key)]
        if key.visibility_layers:
            parts.append(shader_sources.per_vertex_copy_source(per_vertex_inputs(key)))
        parts.append(shader_sources.technique_source(GLSL_DIR, "surface.frag.glsl"))
        return "\n".join(parts)

    def samplers(self, key):
        samplers = []
        if key.has_environment:
            samplers.append(("FLOAT_2D_ARRAY", "environment_texture"))
            if key.has_specular:        # the map itself, for slice lobes sharper than the top prefiltered layer
                samplers.append(("FLOAT_2D", "equirect_texture"))
        samplers += self.model_samplers(key)
        if uses_clamped_cosine_table(key):
            samplers.append(("FLOAT_2D", "clamped_cosine_table"))
        samplers += material_textures.samplers(key)
        if key.layering:
            samplers.append(surface_layering.SAMPLER)
        if key.visibility_layers:
            samplers.append(("FLOAT_2D", "visibility_coefficients"))       # read in the vertex shader
            samplers.append(("FLOAT_2D_ARRAY", "visibility_basis"))
        if key.diffuse_visibility_rows:
            samplers.append(("FLOAT_2D", "diffuse_visibility"))             # read in the vertex shader
        if key.shadow_maps:
            samplers.append(("FLOAT_2D", "shadow_atlas"))
        return samplers

    def create_info_calls(self, key):
        return shader_sources.surface_calls(self.defines(key), self.fragment_source(key), self.samplers(key),
                                            key.gbuffer, per_vertex_inputs(key),
                                            node_values=key.node_values,
                                            node_constants=len(material_textures.constant_rows(key)))

    # ------------------------------------------------------------- drawing

    def bind_reads_object(self, key):
        # the bake's rows (the mesh's) and the per-vertex pass's target (the object's); the model hooks bind
        # the material's tables only
        return key.visibility_layers > 0

    def bind(self, shader, key, context):
        if key.visibility_layers:
            buffers = context.per_vertex(VISIBILITY_KIND)
            shader.uniform_sampler("visibility_coefficients", buffers.rows_texture)
            shader.uniform_sampler("visibility_basis", buffers.basis_texture)
        if key.diffuse_visibility_rows:
            shader.uniform_sampler("diffuse_visibility", context.object_texture("diffuse_visibility"))
        shader.uniform_block("scene", context.scene_buffer)
        shader.uniform_block("material", context.material_buffer)
        if key.has_environment:
            layers, equirect = context.environment_textures()
            shader.uniform_sampler("environment_texture", layers)
            if key.has_specular:
                shader.uniform_sampler("equirect_texture", equirect)
        self.bind_model(shader, key, context)
        if uses_clamped_cosine_table(key):
            shader.uniform_sampler("clamped_cosine_table",
                                   context.table("clamped_cosine", clamped_cosine_table.clamped_cosine_table))
        material_textures.bind(shader, key, context)
        if key.layering:
            surface_layering.bind(shader, context)
        if key.shadow_maps:
            shader.uniform_sampler("shadow_atlas", context.shadow_atlas())

    def prepare_object(self, keys, context):
        draw_diffuse_visibility(keys, context)


def draw_diffuse_visibility(keys, context):
    """The broad diffuse lobes' visibility at the vertices of an object whose variants read it (keys with
    diffuse_visibility_rows: a bake and a diffuse term; the SG techniques' and the factored one's): the SSDF's
    coverage at the quadrature points (vertex_coverage.frag.glsl), then each lobe's visible fraction
    (vertex_visibility.frag.glsl), in the coefficient texture's rows."""
    rows = max((key.diffuse_visibility_rows for key in keys), default=0)
    if not rows:
        return
    key = next(key for key in keys if key.diffuse_visibility_rows)
    buffers = context.per_vertex(VISIBILITY_KIND)
    import gpu  # the gpu module exists only in Blender's GPU context

    # the coverage depends on the bake alone: drawn again only for new buffers (a new bake or mesh)
    coverage, coverage_framebuffer, current = context.object_target(
        "quadrature_coverage", (buffers.vertices_per_row * COVERAGE_TEXELS, buffers.rows_texture.height), (buffers,))
    if not current:
        shader = context.fixed_shader(("vertex_coverage", key.visibility_layers),
                                      lambda: vertex_coverage_calls(key.visibility_layers))
        with coverage_framebuffer.bind():
            gpu.state.depth_test_set("NONE")
            gpu.state.blend_set("NONE")
            shader.bind()
            shader.uniform_sampler("visibility_coefficients", buffers.rows_texture)
            shader.uniform_sampler("visibility_basis", buffers.basis_texture)
            context.full_screen_batch(shader, "vertex_coverage").draw(shader)
        context.object_target_drawn("quadrature_coverage", (buffers,))

    _, framebuffer, _ = context.object_target(
        "diffuse_visibility", (buffers.vertices_per_row * rows, buffers.rows_texture.height))
    shader = context.fixed_shader(("vertex_visibility", key.visibility_layers, rows, key.has_environment),
                                  lambda: vertex_visibility_calls(key.visibility_layers, rows, key.has_environment))
    with framebuffer.bind():
        gpu.state.depth_test_set("NONE")
        gpu.state.blend_set("NONE")
        shader.bind()
        shader.uniform_sampler("vertex_coverage", coverage)
        if key.has_environment:      # the constant world's cosine lobe needs neither (the SSDF's normal)
            shader.uniform_float("model_matrix", context.model_matrix)
            shader.uniform_block("scene", context.scene_buffer)
            shader.uniform_sampler("visibility_coefficients", buffers.rows_texture)
            shader.uniform_sampler("vertex_normals", buffers.normal_texture)
            shader.uniform_sampler("visibility_basis", buffers.basis_texture)
        context.full_screen_batch(shader, "vertex_visibility").draw(shader)


def quadrature_defines():
    """The quadrature's constants (visibility.broad_lobes) for lib/ssdf_quadrature.glsl."""
    return {"SSDF_QUADRATURE_POINTS": broad_lobes.QUADRATURE_POINTS,
            "SSDF_QUADRATURE_SHARPNESS_START": repr(float(broad_lobes.QUADRATURE_SHARPNESS_START)),
            "SSDF_QUADRATURE_SHARPNESS_END": repr(float(broad_lobes.QUADRATURE_SHARPNESS_END))}


def vertex_coverage_calls(visibility_layers):
    """Create-info calls of the pass of the SSDF's quadrature points at the vertices
    (vertex_coverage.frag.glsl): a full-screen triangle over its target, COVERAGE_TEXELS texels a vertex."""
    defines = {"HAS_VISIBILITY": 1, "SSDF_MAX_LAYERS": visibility_layers, "COVERAGE_TEXELS": COVERAGE_TEXELS,
               **quadrature_defines()}
    calls = shader_sources.full_screen_calls("sgprt_vertex_coverage_interface", defines)
    # the scene block, unused and unbound: without a uniform block Blender 5.3's OpenGL backend drew nothing
    # from this pass once it sampled its textures (the coverage came out zero; 5.0 drew it either way)
    calls += [("uniform_buf", (0, "SceneData", "scene")), ("sampler", (0, "FLOAT_2D", "visibility_coefficients")),
              ("sampler", (1, "FLOAT_2D_ARRAY", "visibility_basis")), ("fragment_out", (0, "VEC4", "out_coverage"))]
    sources = [shader_sources.library_source(name)
               for name in ("sg.glsl", "hemisphere.glsl", "hemisphere_map.glsl", "ssdf.glsl", "ssdf_quadrature.glsl")]
    sources += ["vec4 visibility_rows[SSDF_MAX_LAYERS];",
                shader_sources.technique_source(GLSL_DIR, "vertex_coverage.frag.glsl")]
    calls.append(("fragment_source", ("\n".join(sources),)))
    return calls


def vertex_visibility_calls(visibility_layers, rows, has_environment):
    """Create-info calls of the per-vertex pass of the broad diffuse lobes (vertex_visibility.frag.glsl),
    drawn as one full-screen triangle over its target (one texel a vertex and vec4)."""
    defines = {"HAS_VISIBILITY": 1, "SSDF_MAX_LAYERS": visibility_layers, "DIFFUSE_VISIBILITY_ROWS": rows,
               **quadrature_defines()}
    if has_environment:
        defines["HAS_ENVIRONMENT"] = 1
    calls = shader_sources.full_screen_calls("sgprt_vertex_visibility_interface", defines)
    if has_environment:
        calls.append(("push_constant", ("MAT4", "model_matrix")))
    calls += [("uniform_buf", (0, "SceneData", "scene")),
              ("sampler", (0, "FLOAT_2D", "visibility_coefficients")), ("sampler", (1, "FLOAT_2D", "vertex_normals")),
              ("sampler", (2, "FLOAT_2D_ARRAY", "visibility_basis")), ("sampler", (3, "FLOAT_2D", "vertex_coverage")),
              ("fragment_out", (0, "VEC4", "out_fractions"))]
    sources = [shader_sources.library_source(name)
               for name in ("sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl", "hemisphere_map.glsl", "ssdf.glsl",
                            "ssdf_quadrature.glsl")]
    sources += [shader_sources.technique_source("common", "lobe_visibility.glsl"),
                shader_sources.technique_source(GLSL_DIR, "vertex_visibility.frag.glsl")]
    calls.append(("fragment_source", ("\n".join(sources),)))
    return calls

