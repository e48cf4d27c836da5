"""Accuracy of the lights' shadow maps (lighting.shadow_maps, mirrored by shaders/lib/shadow_maps.glsl): a square
blocker 2 m over the floor, lit from 4 m (validation/shadow_map_scene.py, the atlas drawn by ray casting each
texel): the visible fraction along the floor across the blocker's edge against the exact one, for a point light
(hard), a sun straight above (hard) and sphere lights whose penumbra the filter holds (PCSS)."""
import numpy as np

from sg_prt_addon.lighting import shadow_maps
from validation import shadow_map_scene as scene


def _row(name, max_error, mean_error, metric, note=""):
    return dict(name=name, reference="the exact visible fraction of the light behind a straight edge", metric=metric,
                max_error=float(max_error), mean_error=float(mean_error), note=note)


def measure():
    rows = []
    for size in (512, 1024, 2048):
        for kind, edge in (("point light", 2.0), ("sun", 1.0)):
            lights = scene.lights() if kind == "point light" else scene.lights(sun_radius=0.0)
            shadow_plan = shadow_maps.plan(lights, scene.BOUNDS, size)
            texel = 2.0 * scene.LIGHT_HEIGHT / (shadow_plan.size * shadow_plan.inner) if kind == "point light" else \
                float(shadow_plan.sun_texel[0])
            xs, position, normal = scene.receivers(edge - 0.5, edge + 0.5, 401)
            visible = shadow_maps.light_visibility(scene.draw_atlas(shadow_plan), shadow_plan, lights, position,
                                                   normal)[:, 0, 0]
            crossing = float(np.interp(0.5, visible, xs))         # visible rises across the edge
            wrong = np.abs(visible - (xs > edge))[np.abs(xs - edge) >= 2 * texel]
            rows.append(_row(f"shadow map {size}, {kind} (hard), edge", abs(crossing - edge) / texel, wrong.max(),
                             "max: the edge's offset in texels; mean column: the largest error 2 texels or more "
                             "from it"))
        for radius in (0.03, 0.05, 0.1):
            lights = scene.lights(radius=radius)
            shadow_plan = shadow_maps.plan(lights, scene.BOUNDS, size)
            xs, position, normal = scene.receivers(2.0 - 1.5 * radius, 2.0 + 1.5 * radius, 201)
            result = shadow_maps.light_visibility(scene.draw_atlas(shadow_plan), shadow_plan, lights, position,
                                                  normal)[:, 0]
            error = np.abs(result[:, 0] - scene.disc_fraction(2.0 - xs, radius))
            softness = float(result[:, 1].max())
            rows.append(_row(f"shadow map {size}, sphere light radius {radius:g} at 4 m, penumbra", error.max(),
                             error[np.abs(xs - 2.0) < radius].mean(),
                             "visible fraction, absolute error (max; mean over the penumbra)",
                             f"softness up to {softness:.2f} (a baked object blends its SSDF in by it)" if softness
                             else ""))
    return rows
