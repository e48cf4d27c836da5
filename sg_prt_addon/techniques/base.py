"""The seam every rendering method plugs into: a Technique and what the engine hands it.

A technique renders the surfaces of the materials that pick it (material.sgprt.technique).  For one
material on one object it says:

- ``variant_key(params, inputs)``: a hashable key of what changes its shader's code (not the values),
  with ``describe()`` for messages;
- ``create_info_calls(key)``: what the GPUShaderCreateInfo of that variant is made of, as (method,
  arguments) calls in order (``shader_sources.surface_calls`` gives the parts every surface shares);
  the engine compiles and caches the shader by a hash of these calls;
- ``bind(shader, key, context)``: binds its textures and blocks through a DrawContext;
- ``prepare_object(keys, context)`` (optional): GPU passes of its own before the surfaces are drawn;
- ``mirror``: the numpy function that computes what its shader does, for the tests.

The engine (draw loop, shader cache, scene state) knows no technique by name: it reads the registry
(techniques/__init__.py).  The DrawContext is the engine's side of the seam (engine/renderer.py); its
methods are listed in the DrawContext docstring below.
"""
import functools

import numpy as np

# The texture slots every technique applies the same way (shaders/techniques/common/surface_io.glsl): the
# emitted radiance's colour (surface_write), the coverage (surface_coverage: Principled Alpha, a Transparent
# BSDF), the holdout's share of the drawn surface (surface_write's alpha) and a node tree's shading normal
# (surface_geometry: a Bump node's, computed per pixel)
EMISSION_TEXTURE = "emission"
ALPHA_TEXTURE = "alpha"
HOLDOUT_TEXTURE = "holdout"
SHADING_NORMAL_TEXTURE = "shading_normal"
SURFACE_TEXTURES = (EMISSION_TEXTURE, ALPHA_TEXTURE, HOLDOUT_TEXTURE, SHADING_NORMAL_TEXTURE)


class ObjectInputs:
    """What a variant may depend on besides its material: the scene and the object drawn.

    light_data: lighting.scene_lighting.LightData; environment: its EnvironmentData; gbuffer: the draw
    writes the G-buffer outputs; per_vertex: per-vertex kind ("ssdf", "transfer") -> vec4 rows a vertex of
    the object's usable precomputation (absent: none), per_vertex_data: kind -> its
    visibility.per_vertex.PerVertexData (numpy); bounds: (2, 3) local box or None; matrix_world (4, 4);
    shadow_maps: the frame's lights have shadow maps (lighting.shadow_maps, DrawContext.shadow_atlas);
    vertex_colors: the mesh has a colour attribute (its vertex stream, shader_sources.surface_calls); second_uv:
    it has a second UV map (likewise).
    Derived values a technique computes once per object go in ``memo``.  Everything but matrix_world is the
    frame's or the mesh's: reading matrix_world sets ``matrix_world_read``, and the engine reuses a variant key
    for the other objects drawing the same mesh and material only when it was made without reading it."""

    def __init__(self, light_data, environment, gbuffer=False, per_vertex=None, bounds=None, matrix_world=None,
                 per_vertex_data=None, shadow_maps=False, vertex_colors=False, second_uv=False):
        self.light_data = light_data
        self.vertex_colors = bool(vertex_colors)
        self.second_uv = bool(second_uv)
        self.shadow_maps = bool(shadow_maps)
        self.environment = environment
        self.gbuffer = bool(gbuffer)
        self.per_vertex = dict(per_vertex or {})
        self.per_vertex_data = dict(per_vertex_data or {})
        self.bounds = bounds
        self._matrix_world = np.eye(4) if matrix_world is None else np.asarray(matrix_world)
        self.matrix_world_read = False
        self.memo = {}

    @property
    def matrix_world(self):
        self.matrix_world_read = True
        return self._matrix_world

    @functools.cached_property
    def has_lights(self):
        return self.light_data.count > 0

    @functools.cached_property
    def has_environment(self):
        return self.environment.prefiltered is not None


class DrawContext:
    """What the engine offers a technique's bind() and prepare_object() (engine/renderer.py implements it).

    scene_buffer, material_buffer: the SceneData and MaterialData uniform buffers of the draw;
    inputs: the object's ObjectInputs (what its variant keys were made from: the lights, the environment);
    per_vertex(kind): the object's engine.per_vertex.PerVertexBuffers of that kind;
    environment_textures(): (prefiltered layers, equirect map) GPU textures of the scene's environment;
    shadow_atlas(): the depth texture of the lights' shadow maps (inputs.shadow_maps; lighting.shadow_maps);
    table(name, build): a GPU texture of build()'s float32 array ((H, W, 4) or (L, H, W, 4)), made once
      for the renderer and kept on disk (engine/disk_cache): build() must depend on the code alone, and
      name say which table it is; material_table(name, build): the same in memory only, remade when the
      material changes; environment_table(name, build): remade when the scene's environment changes;
    material_uniforms(rows): a uniform block of the (k, 4) float32 rows for the material, kept until it changes
      (a node tree's numbers: material_textures.constant_rows);
    cached_arrays(kind, key, build): build()'s dict of named numpy arrays, kept on disk for the next process
      (engine/disk_cache) under kind (a word) and key (what they are made of, by content: parts that are
      bytes or have a stable repr); the maths modules take it as their tables' `store`;
    image(slot): the material's image texture of a texture slot;
    node_image(name): the texture of an image a computed slot reads (techniques/material_textures.py);
    generated_transform: (scale, offset) RGBA lists taking the object-space position to Blender's Generated
      coordinates (the mesh's texture space);
    object_table(name, sources, build): a GPU texture of build()'s array for the object, remade when any of
      the objects in the tuple `sources` is not the one it was made from, dropped with the object;
    object_target(name, size, sources=()): a float RGBA (texture, framebuffer, current) of the object, kept while
      it lives; current: the target was kept and object_target_drawn(name, sources) said it was drawn from the
      same `sources` (by identity; never with none), so a pass drawn from them alone need not be drawn again;
    object_target_drawn(name, sources): after a pass drew the target from `sources`;
    object_texture(name): the texture of object_target(name, ...), or None;
    fixed_shader(cache_key, create_info_calls): a compiled shader of a pass of the technique's own;
    full_screen_batch(shader, name): a triangle covering the target for the pass `name`, position in NDC.
    """


class Technique:
    """A rendering method.  Subclasses set the class attributes and implement the methods."""

    name = ""            # identifier, stored in material.sgprt.technique
    label = ""           # shown in the material panel
    description = ""
    number = 0           # the enum value stored in .blend files: unique and never reused
    paper = ""           # the reference it implements, e.g. "wang2009"
    mirror = None        # numpy function of what its shader computes (tests compare the two)
    shadow_kind = "ssdf"  # the per-vertex kind its shadows come from (engine/scene_state.py), "" for none
    # Its Blender side, a module relative to its own package ("" for none; blender/technique_sides.py reads it):
    # SETTINGS {attribute: PropertyGroup} at material.sgprt.<attribute>, draw(layout, material, name) the panel's
    # rows, read(material, params) its settings into MaterialParams, resolve(material, params, name) -> (technique
    # name, warnings), CLASSES (its operators and panels); all optional
    blender_side = ""
    # A stored fit it renders by itself ("lobe_fit"): storing one picks the technique, clearing it leaves it
    renders_stored = ""

    def variant_key(self, params, inputs):
        raise NotImplementedError

    def create_info_calls(self, key):
        raise NotImplementedError

    def bind(self, shader, key, context):
        raise NotImplementedError

    def bind_object(self, shader, key, context):
        """Set the object's own push constants its variant reads (every object draw, after bind): the texture
        space of a material's computed values (material_textures.bind_object)."""
        from . import material_textures

        material_textures.bind_object(shader, key, context)

    def bind_reads_object(self, key):
        """Whether bind(shader, key, context) binds anything of the object's own (context.per_vertex,
        object_table, object_texture, inputs' bounds or matrix): the draw loop then calls it for every
        object; otherwise once for a run of objects drawn with the same variant and material (what it
        binds stays bound).  Default: True."""
        return True

    def prepare_object(self, keys, context):
        """GPU work of the technique's own for one object before its surfaces are drawn (keys: the
        variant keys of its material slots that use this technique; what it makes with
        context.object_target is dropped with the object).  Default: none."""
