"""Ghost-free interpolation (wang2009 Fig. 5): blending SSDFs moves one sharp edge, blending
binary visibility leaves two half-steps.

Two vertices see a half-plane of directions, bounded by great circles through the
zenith at azimuths 0 and 60 degrees (no rays: visibility is set on the fine grid).
Along the ring of directions at 45 degrees elevation we measure (1) the fraction
of directions where the blend is neither visible nor occluded (binary: the 60
degree wedge between the two edges; SSDF through a sharp fh: only the lobe's
own blur) and (2) the azimuth of the SSDF blend's single zero crossing against
the closed-form crossing of the two exact signed distances.
"""
import numpy as np
from scipy import optimize

from sg_prt_addon.spherical import hemisphere
from sg_prt_addon.visibility import decode, hemisphere_map, ssdf

RESOLUTION, REFINEMENT = 32, 5
ELEVATION = np.radians(45.0)
AZIMUTHS = np.radians([0.0, 60.0])


def _edge_normal(azimuth):
    """Visible = {i.m < 0}: the boundary great circle passes the zenith at this azimuth."""
    return np.array([-np.sin(azimuth), np.cos(azimuth), 0.0])


def _ssdf_images():
    fine = hemisphere_map.texel_directions(RESOLUTION * REFINEMENT)
    visible = np.stack([fine @ _edge_normal(a) < 0 for a in AZIMUTHS])
    return ssdf.ssdf_from_fine(visible, RESOLUTION), visible


def _ring(count=3600):
    phi = np.linspace(-np.pi, np.pi, count, endpoint=False)
    return phi, np.stack([np.cos(ELEVATION) * np.cos(phi), np.cos(ELEVATION) * np.sin(phi),
                          np.full_like(phi, np.sin(ELEVATION))], 1)


def _expected_crossing(weight):
    """Zero of w d_0 + (1 - w) d_1 with d_k = -asin(i.m_k), the exact distances near the edges."""
    def blend(phi):
        i = np.array([np.cos(ELEVATION) * np.cos(phi), np.cos(ELEVATION) * np.sin(phi), np.sin(ELEVATION)])
        return -sum(w * np.arcsin(i @ _edge_normal(a)) for w, a in zip((weight, 1 - weight), AZIMUTHS))
    return optimize.brentq(blend, AZIMUTHS[0] - 0.1, AZIMUTHS[1] + 0.1, xtol=1e-12)


def test_ssdf_blend_has_one_sharp_edge_binary_blend_has_two_half_steps():
    images, _ = _ssdf_images()
    phi, ring = _ring()
    values = np.stack([decode.decode_image(image, ring) for image in images])
    # binary visibility of each vertex on the ring
    binary = np.stack([(ring @ _edge_normal(a) < 0).astype(float) for a in AZIMUTHS])
    window = (phi > -np.pi / 2) & (phi < np.pi / 2 + AZIMUTHS[1])   # the edges' side of the ring
    sharpness = 1000.0                                                # a sharp light lobe
    for weight in (0.25, 0.5, 0.75):
        binary_blend = weight * binary[0] + (1 - weight) * binary[1]
        ssdf_blend = weight * values[0] + (1 - weight) * values[1]
        shadow = hemisphere.fh_normalized(ssdf_blend, sharpness)
        intermediate_binary = np.mean((binary_blend[window] > 0.05) & (binary_blend[window] < 0.95))
        intermediate_ssdf = np.mean((shadow[window] > 0.05) & (shadow[window] < 0.95))
        # binary: the whole 60 degree wedge between the edges is part-lit
        assert abs(intermediate_binary - AZIMUTHS[1] / (np.pi + AZIMUTHS[1])) < 0.01
        # SSDF: only fh's own transition (about 2 / sqrt(lambda) wide in theta_d), as with exact distances
        exact = -sum(w * np.arcsin(ring @ _edge_normal(a)) for w, a in zip((weight, 1 - weight), AZIMUTHS))
        shadow_exact = hemisphere.fh_normalized(exact, sharpness)
        intermediate_exact = np.mean((shadow_exact[window] > 0.05) & (shadow_exact[window] < 0.95))
        assert abs(intermediate_ssdf - intermediate_exact) < 0.003, (intermediate_ssdf, intermediate_exact)
        assert intermediate_ssdf < intermediate_binary / 5
        # one edge: a single sign change in the window, where the exact distances put it
        sign = np.sign(ssdf_blend[window])
        crossings = np.nonzero(sign[1:] != sign[:-1])[0]
        assert len(crossings) == 1
        k = crossings[0]
        p = phi[window]
        v = ssdf_blend[window]
        measured = p[k] - v[k] * (p[k + 1] - p[k]) / (v[k + 1] - v[k])
        expected = _expected_crossing(weight)
        assert abs(measured - expected) < 0.01, (weight, measured, expected)
        # and it lies strictly between the two edges, at the blend's orientation
        assert AZIMUTHS[0] + 0.1 < measured < AZIMUTHS[1] - 0.1
