"""Numpy mirror of shaders/techniques/biscale/biscale.glsl: a bi-scale material's effective lobes (iwasaki2012
eq. 15) as the SG technique's BRDF slice, and its diffuse factor; and the GPU layout of a biscale.bvndf.BVNDF
(or of two tiles a mask chooses between, bvndf.MaskedTiles).

The small-scale BRDF is the material's own model and parameters (per pixel, textures included), or its stored
lobe fit (model FITTED: the fit's lobes, colours and M at each pixel's texel), so editing it needs no
recomputation; the tile's BVNDF (lobes and tables) changes only with the geometry.
"""
import numpy as np

from ...biscale import bvndf as bvndf_tables
from ...biscale import effective_brdf
from ...reflectance import brdf, models
from ...spherical import sg, warp
from ..sg import sg_shading
from ..sg.fitted_texels import FITTED_MODEL, fitted_m_factor

MASK_SLOT = "biscale_mask"      # the texture slot of a bi-scale material's mask between its two tiles

FLOAT = np.float32
# Small-scale models: the isotropic ones (iwasaki2012 sec. 7: as its previous method, isotropic small-scale BRDFs)
SMALL_SCALE_MODELS = tuple(model.name for model in models.MODELS if not model.anisotropic)


def small_lobe_count(model, fitted=None):
    """The small-scale BRDF's SG lobes: a stored fit's (fitted: its export.FittedLobes), GGX's two-lobe fit (its
    tail holds a quarter of its mass at roughness 0.5), one for the other models."""
    if fitted is not None:
        return int(fitted.lobe_count)
    return 2 if model == "GGX" else 1


def small_lobes(model, params):
    """(sharpness (N, S), amplitude (N, S)) of the small-scale NDF lobes per pixel (biscale_set_small_lobes): a
    model's with their projected mass made 1, as the NDF's (biscale.effective_brdf.SmallScaleMaterial.ndf_lobes);
    a fit's as they are, amplitude 1 (their colours are slice_colours')."""
    if model == FITTED_MODEL:
        sharpness = np.asarray(params["sharpness"], np.float64)
        return sharpness, np.ones_like(sharpness)
    if model not in SMALL_SCALE_MODELS:
        raise ValueError(f"a bi-scale material's small-scale model must be isotropic, not {model}")
    instance = brdf.model_from_name(model, **{k: np.asarray(v, FLOAT) for k, v in params.items()})
    return effective_brdf.small_scale_lobes(instance, model, small_lobe_count(model))


def slice_colours(tables, model, params, nodes):
    """(N, J S nodes, 3) RGB factor of each slice lobe with a fitted small scale: lobe j S + s takes the fit's
    lobe s colour; None for a model (its ks is the specular colour)."""
    if model != FITTED_MODEL:
        return None
    colour = np.tile(np.asarray(params["colour"], FLOAT), (1, tables.lobe_count, 1))
    return np.repeat(colour, nodes, axis=1)


def facet_m_factor(model, params):
    """M of the small-scale BRDF on facets, f(normals, wi, wo) with (K', N, 3) arrays, the pixel index second."""
    if model == FITTED_MODEL:
        def fitted(normals, wi, wo):
            local_i, local_o = effective_brdf.facet_directions(normals, wi, wo)
            return fitted_m_factor(params, local_o, local_i)
        return fitted
    instance = brdf.model_from_name(model, **{k: np.asarray(v, FLOAT)[None] for k, v in params.items()})
    return lambda normals, wi, wo: effective_brdf.facet_m_factor(instance, normals, wi, wo)


def effective_lobes(tables, small_sharpness, small_amplitude):
    """biscale_lobe for every pixel, BVNDF lobe j and small-scale lobe s (index j S + s): axis (N, J S, 3),
    sharpness (N, J S), amplitude (N, J S)."""
    count, small = small_sharpness.shape
    eta_j = np.repeat(np.asarray(tables.sharpness, np.float64), small)[None, :]
    eta_s = np.tile(small_sharpness, (1, tables.lobe_count))
    mu_s = np.tile(small_amplitude, (1, tables.lobe_count))
    sharpness, amplitude = sg.convolution_lobe(eta_j, 1.0, eta_s, mu_s)
    axes = np.repeat(sg.normalize(np.asarray(tables.axes, np.float64)), small, axis=0)
    return np.broadcast_to(axes[None], (count,) + axes.shape), sharpness, amplitude


def tile_weights(tables, mask, count):
    """(N, T) weight of each tile per pixel: 1 for one tile; (1 - m, m) for two by the mask m (biscale_mask)."""
    if tables.diffuse_tiles.shape[0] == 1:
        return np.ones((count, 1))
    if mask is None:
        raise ValueError("two bi-scale tiles need the mask's value at each pixel")
    m = np.clip(np.asarray(mask, np.float64), 0.0, 1.0)
    return np.stack([1.0 - m, m], axis=1)


def lobe_weights(tables, mask, count):
    """(N, J): each BVNDF lobe's tile weight (the second tile's lobes follow the first's)."""
    tile_of_lobe = (np.arange(tables.lobe_count) >= tables.first_lobes).astype(np.int64)
    weights = tile_weights(tables, mask, count)
    return weights[:, np.minimum(tile_of_lobe, weights.shape[1] - 1)]


def m_factor_rows(tables, model, params, small_sharpness, nodes, mask=None):
    """m_factor(wo, wi) for warp.brdf_slice_lobes: rows (effective lobe j S + s's nodes one after the other,
    leading) times mu_j at lobe j's mirror direction and the view, and M at the product axis
    n* = normalize(eta_j xi_j + eta_s h) (biscale_m_factor)."""
    small_m_factor = facet_m_factor(model, params)
    small = small_sharpness.shape[1]
    effective_of_row = np.repeat(np.arange(tables.lobe_count * small), nodes)
    lobe_of_row = effective_of_row // small
    axes = sg.normalize(np.asarray(tables.axes, np.float64))[lobe_of_row][:, None, :]          # (K', 1, 3)
    eta_j = np.asarray(tables.sharpness, np.float64)[lobe_of_row][:, None, None]
    eta_s = small_sharpness.T[effective_of_row % small][..., None]                              # (K', N, 1)
    weight = lobe_weights(tables, mask, small_sharpness.shape[0]).T[lobe_of_row]                  # (K', N)

    def m_factor(wo, wi):          # (K', N, 3) each
        wo = sg.normalize(np.asarray(wo, np.float64))
        wi = sg.normalize(np.asarray(wi, np.float64))
        facet = sg.normalize(eta_j * axes + eta_s * sg.normalize(wo + wi))
        # mu_j read once a BVNDF lobe, at its mirror direction (biscale_set_lobe_amplitude)
        mirror = 2.0 * np.sum(wo * axes, axis=-1, keepdims=True) * axes - wo
        amplitude = paired_amplitudes(tables, lobe_of_row, mirror, wo) * weight
        above = (wo[..., 2] > 0) & (wi[..., 2] > 0)
        return np.where(above, amplitude * small_m_factor(facet, wi, wo), 0.0)

    return m_factor


def paired_amplitudes(tables, lobe_of_row, wi, wo):
    """mu_j(wi, wo) with a table per row: (K', N)."""
    values = np.empty(wi.shape[:-1])
    for lobe in range(tables.lobe_count):
        rows = lobe_of_row == lobe
        values[rows] = bvndf_tables.interpolate(tables.amplitudes[lobe:lobe + 1], wi[rows], wo[rows],
                                                tables.resolution)[0]
    return values


def slice_lobes(tables, model, params, view_local, warp_mode=None, mask=None):
    """The BRDF slice of a bi-scale material (biscale.glsl, the lobe source of sg_shading.glsl's slice_lobes): axis
    (N, K', 3) local, sharpness (N, K'), amplitude (N, K'); mask (N,) the mask's value per pixel with two tiles."""
    mode = warp_mode or warp.DEFAULT_MODE
    small_sharpness, small_amplitude = small_lobes(model, params)
    axis, sharpness, amplitude = effective_lobes(tables, small_sharpness, small_amplitude)
    sharpness, amplitude = sg_shading.spread_lobes(sharpness, amplitude, params.get("normal_spread"))
    m_factor = m_factor_rows(tables, model, params, small_sharpness, warp.nodes_per_lobe(mode), mask)
    return warp.brdf_slice_lobes(axis, sharpness, amplitude, view_local, m_factor, mode=mode)


def diffuse_factor(tables, directions_local, view_local, mask=None):
    """D(i, o) at local incident directions (N, P, 3) for each pixel's view (N, 3): (N, P) (biscale_diffuse)."""
    directions_local = np.asarray(directions_local, np.float64)
    view = np.broadcast_to(np.asarray(view_local, np.float64)[:, None, :], directions_local.shape)
    values = bvndf_tables.interpolate(np.asarray(tables.diffuse_tiles), directions_local, view,
                                      tables.resolution)                                         # (T, N, P)
    weights = tile_weights(tables, mask, len(view_local))
    blended = np.einsum("tnp,nt->np", values, weights)
    return np.where(directions_local[..., 2] > 0, blended, 0.0).astype(FLOAT)


def albedo(tables, view_local, mask=None):
    """A(o) for each pixel's view (N,) (biscale_albedo): the albedo row read at o as the GPU reads it."""
    nodes = len(tables.directions)
    texture = np.broadcast_to(np.asarray(tables.albedo_tiles)[:, None, :], (len(tables.albedo_tiles), nodes, nodes))
    up = np.array([0.0, 0.0, 1.0])
    values = bvndf_tables.interpolate(texture, up, np.asarray(view_local, np.float64), tables.resolution)  # (T, N)
    return np.sum(values.T * tile_weights(tables, mask, len(view_local)), axis=1).astype(FLOAT)


class BiScaleLobes:
    """The bi-scale technique's lobe source for sg_shading.shade (biscale.glsl's): the effective lobes of the
    tables (a BVNDF or MaskedTiles) under the small-scale model, their colours, and the tile's diffuse factor;
    mask (N,): the mask's value per pixel with two tiles, else None."""
    scales_diffuse = True
    glossy_layer = False        # the variant has no glossy layer: the small-scale BRDF is the look

    def __init__(self, tables, mask=None):
        self.tables = tables
        self.mask = mask

    def slice(self, model, params, lobe_count, view_local, warp_mode):
        return slice_lobes(self.tables, model, params, view_local, warp_mode, self.mask)

    def colours(self, model, params, slice_count, warp_mode):
        return slice_colours(self.tables, model, params, warp.nodes_per_lobe(warp_mode or warp.DEFAULT_MODE))

    def albedo(self, model, params, view_local):
        return None             # no environment tail (GGX's own)

    def light_tail(self, model):
        return False

    def diffuse_factor(self, local, view_local):
        return diffuse_factor(self.tables, local, view_local, self.mask)

    def world_albedo(self, view_local):
        return albedo(self.tables, view_local, self.mask)


def shade_fragments(material, textures, position, normal, tangent, uv, view_origin, is_perspective, light_data,
                    environment, visibility=None, light_shadow=None):
    """The bi-scale technique's mirror: sg_shading.shade_fragments with the material's tiles (material.biscale) as
    the lobe source, the mask's red channel sampled at uv where it has one."""
    mask = (sg_shading.sample_material_texture(textures[MASK_SLOT], uv)[:, 0] if MASK_SLOT in textures else None)
    return sg_shading.shade_fragments(material, textures, position, normal, tangent, uv, view_origin, is_perspective,
                                      light_data, environment, visibility=visibility, light_shadow=light_shadow,
                                      lobes=BiScaleLobes(material.biscale, mask))


# ---------------------------------------------------------------- GPU layout

def lobe_layers(lobe_count):
    return -(-lobe_count // 4)


def table_texture(tables):
    """(layers, R^2, R^2, 4) float32 of biscale.glsl's biscale_tables: texel (row o_b R + i_b, column o_a R + i_a)
    of layer t channel c is mu_{4t+c}(i, o); the last layer holds (D(i, o), A(o)) of the first tile, then of the
    second (0 with one tile)."""
    resolution = tables.resolution
    nodes = resolution * resolution
    count = tables.lobe_count
    layers = lobe_layers(count)
    values = np.zeros((layers * 4 + 4, nodes, nodes), np.float32)                   # [channel, i node, o node]
    values[:count] = tables.amplitudes
    for tile, (diffuse, tile_albedo) in enumerate(zip(tables.diffuse_tiles, tables.albedo_tiles)):
        values[layers * 4 + 2 * tile] = diffuse
        values[layers * 4 + 2 * tile + 1] = np.asarray(tile_albedo)[None, :]
    # node index b R + a -> (b, a) for i and o, then rows (o_b, i_b) and columns (o_a, i_a)
    grid = values.reshape(layers + 1, 4, resolution, resolution, resolution, resolution)  # l, c, ib, ia, ob, oa
    texture = grid.transpose(0, 4, 2, 5, 3, 1).reshape(layers + 1, nodes, nodes, 4)
    return np.ascontiguousarray(texture)


def lobe_texture(tables):
    """(1, J, 4) float32 of biscale_lobes: (axis xyz, sharpness) of each BVNDF lobe."""
    return np.concatenate([np.asarray(tables.axes, np.float32), np.asarray(tables.sharpness, np.float32)[:, None]],
                          axis=1)[None]
