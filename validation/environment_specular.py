"""The SG technique's environment specular on a sphere's visible half against the exact integral (numpy).

Used by tests/core/test_environment_specular.py (a procedural sky) and benchmarks/accuracy/warp.py
(courtyard.exr): a GGX (or anisotropic GGX) surface seen from every angle of a sphere's visible half (an orthographic camera),
the reference summing L(i) rho(o, i) max(0, n.i) over every texel of the map (single-scattering GGX, what
the slice lobes, their energy cap and the environment tail model), the engine reading its prefiltered
layers at the slice lobes (techniques.sg.sg_shading.shade, the mirror of sg_shading.glsl).  The shading alone:
the warp's lobe shape, the prefiltered lookups, the tail; no visibility.
"""
from dataclasses import dataclass

import numpy as np

from sg_prt_addon.lighting import env_prefilter, equirect
from sg_prt_addon.lighting.scene_lighting import EnvironmentData, LightData
from sg_prt_addon.reflectance import brdf
from sg_prt_addon.techniques.sg import sg_shading
from sg_prt_addon.visibility import hemisphere_map

VIEW = np.array([-0.47, 0.83, -0.31])          # the camera's forward direction
VIEW_BANDS = ((0, 45), (45, 70), (70, 85))     # degrees between the view and the normal


def procedural_sky(height=64):
    """(H, 2H, 3) equirect radiance, row 0 at the top: sky brighter towards the zenith, a dim ground, a sun."""
    directions = equirect.texel_directions(height, 2 * height)
    z = directions[..., 2:]
    sky = np.where(z > 0, np.array([0.35, 0.5, 0.9]) * (0.6 + 0.8 * z), np.array([0.25, 0.18, 0.1]) * (1 + z))
    sun_axis = np.array([0.5, 0.6, 0.62])
    sun = 40.0 * np.exp(300.0 * (directions @ (sun_axis / np.linalg.norm(sun_axis)) - 1))[..., None]
    return (sky + sun * np.array([1.0, 0.9, 0.7])).astype(np.float32)


def environment(image, layer_size=64):
    """EnvironmentData of an equirect image as the engine makes it for the specular (no diffuse fit)."""
    return EnvironmentData(colour=np.zeros(3, np.float32),
                           prefiltered=env_prefilter.prefilter_environment(image, size=layer_size), radiance=image)


def visible_normals(count=36, view=VIEW):
    """(normals (N, 3), forward (3,)): the half of a sphere a camera looking along ``view`` sees, on a square
    grid of its image."""
    forward = np.asarray(view, np.float64) / np.linalg.norm(view)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    x, y = np.meshgrid(np.linspace(-1, 1, count), np.linspace(-1, 1, count))
    keep = x ** 2 + y ** 2 < 0.995
    x, y = x[keep], y[keep]
    return x[:, None] * right + y[:, None] * up - np.sqrt(1 - x ** 2 - y ** 2)[:, None] * forward, forward


def tangent_frames(normals, axis):
    """(N, 3, 3) local frames (rows t, b, n) whose tangent is ``axis`` on the surface (an anisotropic material's
    object axis; it must not be parallel to a normal)."""
    axis = np.asarray(axis, np.float64) / np.linalg.norm(axis)
    tangent = axis - normals * (normals @ axis)[:, None]
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    return np.stack([tangent, np.cross(normals, tangent), normals], axis=1)


@dataclass(frozen=True, eq=False)
class LobeNDFAnisotropic(brdf.GGXAnisotropic):
    """Anisotropic GGX with its NDF replaced by SG lobes (axis (K, 3), sharpness (K,), amplitude (K,)) in the
    local frame, everything else exact: what the lobes alone cost, without the warp or the prefiltered reads."""
    lobes: tuple = ()

    def ndf(self, h):
        h = np.asarray(h)
        axis, sharpness, amplitude = (np.asarray(a, np.float64) for a in self.lobes)
        # the dot-product form, not sg.mixture_evaluate: its difference vectors would hold three times the
        # memory over a chunk of normals times every texel of the map
        value = np.sum(amplitude * np.exp(sharpness * (h @ axis.T - 1)), axis=-1)
        return np.where(h[..., 2] > 0, value, 0)


def exact_specular(image, normals, forward, roughness, chunk=64, alphas=None, tangent_axis=None, ndf_lobes=None):
    """Sum over the map's texels of L(i) rho(o, i) max(0, n.i) d omega, per normal: (N, 3).  rho: GGX of the
    roughness, or with ``alphas`` (alpha_x, alpha_y) anisotropic GGX with its tangent along ``tangent_axis``,
    its NDF replaced by ``ndf_lobes`` if given (LobeNDFAnisotropic)."""
    height, width = image.shape[:2]
    directions = equirect.texel_directions(height, width).reshape(-1, 3)
    solid_angle = np.broadcast_to(equirect.texel_solid_angles(height, width), (height, width)).reshape(-1)
    radiance = image.reshape(-1, 3).astype(np.float64) * solid_angle[:, None]
    if alphas is None:
        model, all_frames = brdf.GGX(roughness=roughness), hemisphere_map.local_frame(normals)
    else:
        model = brdf.GGXAnisotropic(alpha_x=alphas[0], alpha_y=alphas[1]) if ndf_lobes is None else \
            LobeNDFAnisotropic(alpha_x=alphas[0], alpha_y=alphas[1], lobes=tuple(ndf_lobes))
        all_frames = tangent_frames(normals, tangent_axis)
    out = np.empty((len(normals), 3))
    for start in range(0, len(normals), chunk):
        frames = all_frames[start:start + chunk]                                     # rows t, b, n
        wo = np.einsum("kij,j->ki", frames, -forward)
        wi = np.einsum("kij,dj->kdi", frames, directions)
        weight = model.specular(np.broadcast_to(wo[:, None], wi.shape), wi) * np.maximum(wi[..., 2], 0)
        out[start:start + chunk] = weight @ radiance
    return out


def engine_specular(environment_data, normals, forward, roughness, alphas=None, tangent_axis=None, lobe_count=4):
    """The SG technique's specular at the normals (the default warp): (N, 3).  GGX of the roughness (its two NDF
    lobes), or with ``alphas`` anisotropic GGX of ``lobe_count`` lobes, its tangent along ``tangent_axis``."""
    count = len(normals)
    if alphas is None:
        model, lobe_count, frames = "GGX", 2, hemisphere_map.local_frame(normals)
        params = {"roughness": np.full(count, roughness, np.float32)}
    else:
        model, frames = "GGX_ANISO", tangent_frames(normals, tangent_axis)
        params = {"alpha_x": np.full(count, alphas[0], np.float32), "alpha_y": np.full(count, alphas[1], np.float32)}
    _, specular = sg_shading.shade(normals, normals, frames[:, 0], forward, False, model, params,
                                   np.zeros((count, 3)), np.ones((count, 3)), LightData(), environment_data,
                                   lobe_count=lobe_count)
    return specular.astype(np.float64)


def band_errors(engine, reference, normals, forward, bands=VIEW_BANDS):
    """Relative RMSE (RMS error over the band's mean reference) per band of view angle."""
    view_angle = np.degrees(np.arccos(np.clip(normals @ -forward, 0, 1)))
    errors = []
    for low, high in bands:
        band = (view_angle >= low) & (view_angle < high)
        errors.append(float(np.sqrt(np.mean((engine[band] - reference[band]) ** 2)) / np.mean(reference[band])))
    return errors
