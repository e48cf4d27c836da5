"""mccool2001's homomorphic factorization as a technique: the material's BRDF as p(o) q(h) p(i) r(o.h) texture
lookups per light (measured/homomorphic.py fits them; shaders/techniques/factored/ renders them;
techniques/homomorphic/factored_shading.py is the mirror).

The specular BRDF of the material's model is factorized once per set of model parameters (about 2 s,
cached for the process): model parameters are uniform over the material (their textures do not apply;
the export warns), the colours and the normal map are per pixel.  Beyond the paper, which lights with
point sources only: every light is taken at its SG's axis with its clamped-cosine integral (a sphere
light's size enters the energy, not the lobe), and the environment lights the diffuse term through its SG
mixture and the glossy term as the factored BRDF's directional albedo times the prefiltered radiance
around the mirror direction, at the sharpness of the factored lobe (FactoredTables.lobe_sharpness).
With a visibility bake each light, environment lobe and the glossy lookup is shadowed by the SSDF
visibility of its lobe (common/lobe_visibility.glsl, as the SG techniques' diffuse terms).
"""
import collections
from dataclasses import dataclass

import numpy as np

from ...measured import homomorphic
from ...reflectance import brdf, models
from ...spherical import lattice
from .. import material_textures, shader_sources, surface_layering
from ..base import SURFACE_TEXTURES, Technique
from ..material_textures import NodeValues
from ..sg import sg_lobes
from . import factored_shading

NAME = "FACTORED"
GLSL_DIR = "factored"
FORM = "pqpr"
RESOLUTION = 64
SAMPLES = 256                   # views x lights of the fit: SAMPLES^2 pairs
TEXTURE_SLOTS = ("diffuse_color", "specular_color", "normal_map", *SURFACE_TEXTURES)
LIBRARY_FILES = ("sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl", "lights.glsl", "env_prefilter.glsl",
                 "hemisphere_map.glsl", "ssdf.glsl")
VISIBILITY_KIND = "ssdf"        # the per-vertex precomputation it reads (visibility.per_vertex kinds)
CACHE_SIZE = 16


@dataclass(frozen=True)
class FactoredKey:
    technique: str = NAME
    form: str = FORM
    textures: tuple = ()
    node_values: NodeValues = NodeValues()   # what a node tree computes (material_textures.node_values)
    has_lights: bool = False
    has_environment: bool = False
    gbuffer: bool = False
    visibility_layers: int = 0      # vec4 of SSDF coefficients per vertex (0: no visibility bake)
    layering: tuple = ()            # surface_layering.flags of the material
    diffuse_visibility_rows: int = 0    # vec4 a vertex of the diffuse lobes' visibility (sg_lobes' per-vertex pass)

    def describe(self):
        parts = [homomorphic.FORM_LABELS[self.form], "lights" if self.has_lights else "no lights",
                 "environment texture" if self.has_environment else "world colour"]
        if self.textures:
            parts.append("textures: " + ", ".join(self.textures))
        if self.gbuffer:
            parts.append("G-buffer")
        if self.visibility_layers:
            parts.append(f"visibility ({self.visibility_layers} coefficient vec4)")
        if self.diffuse_visibility_rows:
            parts.append(f"per-vertex diffuse visibility ({self.diffuse_visibility_rows} vec4)")
        if self.layering:
            parts.append("layering: " + ", ".join(self.layering))
        return ", ".join(parts)


@dataclass(frozen=True, eq=False)
class FactoredTables:
    """The GPU tables of one factorization: log-factor maps (H, W, 4) float32 (p, q, r), the directional
    albedo map of the factored BRDF (R, R, 4) over views (parabolic), the RGB scale alpha A and the
    sharpness of its glossy environment lookup.  Compared by identity; stored factors carry a signature
    (export.MaterialParams.values_key reads it)."""
    factorization: object
    maps: dict
    albedo: np.ndarray
    scale: np.ndarray
    lobe_sharpness: float
    signature: tuple = ()           # hashable identity of stored factors (blender.brdf_factorization)


def _rgba(values):
    values = np.asarray(values, np.float32)
    out = np.zeros(values.shape[:-1] + (4,), np.float32)
    out[..., :3] = values if values.shape[-1] == 3 else values[..., :1]
    return out


def _parabolic_directions(resolution):
    """(R, R, 3) local directions at the texel centres of a parabolic map (outside the disk: its rim)."""
    centres = (np.arange(resolution) + 0.5) / resolution
    u, v = np.meshgrid(centres, centres)
    s, t = 2 * u - 1, 2 * v - 1
    r2 = s * s + t * t
    inside = r2 <= 1
    scale = np.where(inside, 1.0, 1 / np.sqrt(np.maximum(r2, 1e-30)))
    s, t = s * scale, t * scale
    r2 = np.minimum(r2, 1.0)
    z = (1 - r2) / (1 + r2)
    xy = np.stack([s, t], -1) * (1 + z)[..., None]
    return np.concatenate([xy, z[..., None]], -1)


def tables_of(factorization, albedo_samples=1024):
    """FactoredTables of a homomorphic.Factorization: the maps padded to RGBA, its directional albedo
    int f(o, i) cos(i) di at every texel's view (albedo_samples lattice lights), and the lobe sharpness
    1 / E[1 - i.n] of f(n, i) cos(i) (the glossy environment lookup's; a Gaussian lobe of sharpness
    lambda has E[1 - cos] = 1 / lambda)."""
    maps = {name: _rgba(log_map) for name, log_map in factorization.log_factors.items()}
    lights = lattice.hemisphere_points(albedo_samples)
    views = _parabolic_directions(factorization.resolution).reshape(-1, 3)

    def unscaled(wo, wi):
        return factored_shading.factored_brdf(factorization.log_factors, factorization.form, wo, wi)

    values = np.stack([unscaled(np.broadcast_to(view, lights.shape), lights) for view in views])   # (V, L, C)
    albedo = np.sum(values * lights[None, :, 2:3], axis=1) * (2 * np.pi / albedo_samples)
    normal_view = unscaled(np.broadcast_to([0.0, 0.0, 1.0], lights.shape), lights).mean(axis=-1) * lights[:, 2]
    mean_angle = np.sum(normal_view * (1 - lights[:, 2])) / max(np.sum(normal_view), 1e-30)
    scale = np.broadcast_to(factorization.alpha * factorization.scale, (3,)).astype(np.float32)
    return FactoredTables(factorization, maps, _rgba(albedo.reshape(factorization.resolution, factorization.resolution,
                                                                    -1)), scale, float(1 / max(mean_angle, 1e-3)))


_cache = collections.OrderedDict()


def tables_for(params):
    """The FactoredTables a material renders with: its stored factors (a measured BRDF factorized by the
    Factor BRDF operator: MaterialParams.factorization), else its model's."""
    stored = getattr(params, "factorization", None)
    return stored if stored is not None else model_tables(params)


def model_tables(params):
    """FactoredTables of an export.MaterialParams' specular model (its uniform parameters), cached."""
    model = models.BY_NAME[params.model]
    values = tuple((name, float(getattr(params, name))) for name in model.parameters)
    key = (params.model, values, FORM, RESOLUTION, SAMPLES)
    tables = _cache.get(key)
    if tables is None:
        exact = brdf.model_from_name(params.model, **dict(values))
        wo, wi, samples = homomorphic.sample_brdf(exact.specular, SAMPLES, SAMPLES)
        tables = _cache[key] = tables_of(homomorphic.factorize(wo, wi, samples, form=FORM, resolution=RESOLUTION))
        while len(_cache) > CACHE_SIZE:
            _cache.popitem(last=False)
    else:
        _cache.move_to_end(key)
    return tables


class Factored(Technique):
    name = NAME
    label = "Factored BRDF (McCool 2001)"
    description = ("The material's BRDF factorized into p(o) q(h) p(i) r(o.h) texture lookups per light "
                   "(McCool et al. 2001), shadowed by the visibility bake")
    number = 2
    blender_side = ".blender"
    renders_stored = "factorization"
    paper = "mccool2001"

    mirror = staticmethod(factored_shading.shade_fragments)

    def variant_key(self, params, inputs):
        textures = tuple(sorted(name for name in params.textures if name in TEXTURE_SLOTS))
        layers = int(inputs.per_vertex.get(VISIBILITY_KIND, 0))
        return FactoredKey(textures=textures, node_values=material_textures.node_values(params, textures, inputs),
                           has_lights=inputs.has_lights, has_environment=inputs.has_environment,
                           gbuffer=inputs.gbuffer, visibility_layers=layers, layering=surface_layering.flags(params),
                           diffuse_visibility_rows=sg_lobes.diffuse_visibility_rows(inputs.environment) if layers else 0)

    def defines(self, key):
        out = {"FACTOR_P_LIGHT": 1} if homomorphic.FORMS[key.form][2] == "p" else {}
        if "r" in homomorphic.FORMS[key.form]:
            out["FACTOR_R"] = 1
        if key.has_lights:
            out["HAS_LIGHTS"] = 1
        if key.has_environment:
            out.update(HAS_ENVIRONMENT=1, HAS_SPECULAR=1, ENV_PREFILTER_MAX_LAYERS=shader_sources.MAX_LAYERS)
        for name in key.textures:
            out["HAS_NORMAL_MAP" if name == "normal_map" else "HAS_TEXTURE_" + name.upper()] = 1
        if key.gbuffer:
            out["GBUFFER"] = 1
        if key.visibility_layers:
            out.update(HAS_VISIBILITY=1, SSDF_MAX_LAYERS=key.visibility_layers)
        if key.diffuse_visibility_rows:
            out["DIFFUSE_VISIBILITY_ROWS"] = key.diffuse_visibility_rows
        out.update(surface_layering.layering_defines(key.layering, False))     # its parameters are uniform
        return out

    def samplers(self, key):
        samplers = [("FLOAT_2D", "factor_p"), ("FLOAT_2D", "factor_q")]
        if "r" in homomorphic.FORMS[key.form]:
            samplers.append(("FLOAT_2D", "factor_r"))
        samplers.append(("FLOAT_2D", "factored_albedo"))
        if key.has_environment:
            samplers += [("FLOAT_2D_ARRAY", "environment_texture"), ("FLOAT_2D", "equirect_texture")]
        samplers += material_textures.samplers(key)
        if key.layering:
            samplers.append(surface_layering.SAMPLER)
        if key.visibility_layers:
            samplers += [("FLOAT_2D", "visibility_coefficients"), ("FLOAT_2D_ARRAY", "visibility_basis")]
        if key.diffuse_visibility_rows:
            samplers.append(("FLOAT_2D", "diffuse_visibility"))             # read in the vertex shader
        return samplers

    def per_vertex_inputs(self, key):
        return sg_lobes.per_vertex_inputs(key)

    def create_info_calls(self, key):
        files = [name for name in LIBRARY_FILES if (name != "lights.glsl" or key.has_lights)
                 and (name != "env_prefilter.glsl" or key.has_environment)
                 and (name not in ("hemisphere_map.glsl", "ssdf.glsl") or key.visibility_layers)]
        sources = [shader_sources.library_source(name) for name in files]
        sources += material_textures.sources(key)
        if key.layering:
            sources.append(surface_layering.source())
        per_vertex = self.per_vertex_inputs(key)
        if per_vertex:
            sources.append(shader_sources.technique_source("common", "lobe_visibility.glsl"))
        sources.append(shader_sources.technique_source(GLSL_DIR, "factored_shading.glsl"))
        if per_vertex:      # after the arrays it fills (diffuse_fractions: factored_shading.glsl)
            sources.append(shader_sources.per_vertex_copy_source(per_vertex))
        sources.append(shader_sources.technique_source(GLSL_DIR, "surface.frag.glsl"))
        return shader_sources.surface_calls(self.defines(key), "\n".join(sources), self.samplers(key), key.gbuffer,
                                            per_vertex, push_constants=(("VEC4", "factor_scale"),),
                                            node_values=key.node_values,
                                            node_constants=len(material_textures.constant_rows(key)))

    def bind_reads_object(self, key):
        return key.visibility_layers > 0        # the bake's rows, the mesh's

    def bind(self, shader, key, context):
        tables = tables_for(context.params)
        shader.uniform_block("scene", context.scene_buffer)
        shader.uniform_block("material", context.material_buffer)
        shader.uniform_float("factor_scale", list(tables.scale) + [tables.lobe_sharpness])
        for name in ("p", "q", "r"):
            if name in tables.maps:
                shader.uniform_sampler(f"factor_{name}", context.material_table(f"factor_{name}",
                                                                                lambda name=name: tables.maps[name]))
        shader.uniform_sampler("factored_albedo", context.material_table("factored_albedo", lambda: tables.albedo))
        if key.has_environment:
            layers, equirect = context.environment_textures()
            shader.uniform_sampler("environment_texture", layers)
            shader.uniform_sampler("equirect_texture", equirect)
        material_textures.bind(shader, key, context)
        if key.layering:
            surface_layering.bind(shader, context)
        if key.visibility_layers:
            buffers = context.per_vertex(VISIBILITY_KIND)
            shader.uniform_sampler("visibility_coefficients", buffers.rows_texture)
            shader.uniform_sampler("visibility_basis", buffers.basis_texture)
        if key.diffuse_visibility_rows:
            shader.uniform_sampler("diffuse_visibility", context.object_texture("diffuse_visibility"))

    def prepare_object(self, keys, context):
        sg_lobes.draw_diffuse_visibility(keys, context)      # the diffuse lobes' visibility, as the SG techniques'


TECHNIQUE = Factored()
