"""A fitted measured material rendered by the engine, scored against the Monte Carlo reference
of the ORIGINAL analytic BRDF it was measured from.

A GGX-like AnalyticMaterial (Lambert kd + F_eta(i.h) GGX with height-correlated Smith, roughness
0.3, eta 1.5) is tabulated into a MERL file (validation.brdf_generators.generate_merl: 2% noise, a few
corrupt bins), fitted with 2 SG lobes by bpy.ops.sgprt.fit_lobes, and the sphere is rendered under
courtyard.exr from the stored fit; the reference renders the analytic BRDF itself
(reference_scene.analytic_reference_material).  The score covers the whole chain: factorization
into eq. 13, the 2-lobe SG fit, the view warp and the SG lighting.  Beside it, against the same reference,
the SH technique tabulating the same fit (SH BRDF: Lobe Fit, harmonics/fitted_table.py) at orders 3 and 5:
the same fitted BRDF under SH lighting instead of SG lobes."""
import engine_fixtures as fx
import pytest
from scipy.ndimage import binary_erosion

from validation import image_error
from validation.reference import render_to_noise

pytestmark = pytest.mark.reference      # against the Monte Carlo reference: the two full tiers run it

SIZE = 64
ANALYTIC = dict(diffuse=(0.35, 0.25, 0.15), oren_nayar_sigma=0.0, specular=(1.0, 1.0, 1.0), roughness=0.3,
                eta=1.5, retro=(0.0, 0.0, 0.0))
RMSE_BOUND = 0.10
# The SH technique on the same fit, measured relative RMSE: order 3 0.304, 5 0.199 (6 0.168, 8 0.120), beside the
# fitted SG lobes' 0.078 (noise floor 0.021): the fit's lobe (GGX roughness 0.3) is sharper than the bands hold,
# and the error falls with the order as the parametric GGX's does (docs/ACCURACY.md, harmonics)
SH_RMSE_BOUNDS = {3: 0.36, 5: 0.24}


def fitted_sphere_scores(merl_path, variants, name="fitted_reference", size=SIZE, seed=7):
    """({variant: (relative RMSE, mean bias)}, reference noise floor, the last engine render) over the sphere's
    interior pixels, a variant "SG_FITTED" or an SH order (the SH technique tabulating the same fit), against
    one Monte Carlo reference of the analytic BRDF."""
    import bpy

    from sg_prt_addon.blender import lobe_fit
    from validation import brdf_generators
    from validation.reference_scene import analytic_reference_material, reference_inputs

    scene = fx.new_scene(name, size, size)
    fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 1.0), radius=1.0, segments=64, rings=32)
    material = fx.material(name + "_material", model="GGX")
    sphere.data.materials.append(material)
    with bpy.context.temp_override(material=material):
        assert bpy.ops.sgprt.fit_lobes(filepath=merl_path, lobe_count=2) == {"FINISHED"}
    assert lobe_fit.fit_status(material)[0] == "VALID" and material.sgprt.technique == "SG_FITTED"
    images = {}
    for variant in variants:
        material.sgprt.technique = "SG_FITTED" if variant == "SG_FITTED" else "SH"
        if variant != "SG_FITTED":
            material.sgprt.sh.brdf, material.sgprt.sh.order = "LOBE_FIT", variant
        result = fx.render(scene)
        assert "error" not in result, result.get("error")
        params = result["state"].materials[material.name]
        assert params.fitted is not None and params.technique == material.sgprt.technique, result["state"].warnings
        images[variant] = result["passes"]["Combined"][::-1, :, :3]
    surface = binary_erosion(result["passes"]["Diffuse"][::-1, :, 3] > 0.5)
    depsgraph = scene.view_layers[0].depsgraph
    depsgraph.update()
    reference_scene, camera = reference_inputs(depsgraph, size, size)
    analytic = brdf_generators.AnalyticMaterial(**ANALYTIC)
    reference_scene.materials = [analytic_reference_material(analytic) for _ in reference_scene.materials]
    reference, error, _ = render_to_noise(reference_scene, camera, relative_error=0.012, max_samples=1024, seed=seed)
    scores = {variant: (image_error.relative_rmse(image, reference, surface),
                        image_error.relative_mean_bias(image, reference, surface)) for variant, image in images.items()}
    return scores, image_error.rmse_noise_floor(error, reference, surface), result


def score_fitted_sphere(merl_path, name="fitted_reference", size=SIZE, seed=7):
    """(relative RMSE, mean bias, reference noise floor, engine render) of the fitted lobes (SG_FITTED)."""
    scores, noise_floor, result = fitted_sphere_scores(merl_path, ("SG_FITTED",), name, size, seed)
    return scores["SG_FITTED"] + (noise_floor, result)


@pytest.fixture(scope="module")
def merl_file(blender, tmp_path_factory):
    from validation import brdf_generators

    fx.ensure_registered()
    path = str(tmp_path_factory.mktemp("fitted_reference") / "analytic_ggx.binary")
    brdf_generators.generate_merl(path, brdf_generators.AnalyticMaterial(**ANALYTIC), seed=3)
    return path


def test_fitted_merl_sphere_matches_the_analytic_reference(merl_file):
    scores, noise_floor, _ = fitted_sphere_scores(merl_file, ("SG_FITTED", 3, 5))
    for variant, (rmse, bias) in scores.items():
        label = "fitted SG lobes" if variant == "SG_FITTED" else f"SH order {variant} tabulating the fit"
        print(f"{label}, 2-lobe MERL fit vs analytic reference: relative RMSE {rmse:.4f} "
              f"(noise floor {noise_floor:.4f}), bias {bias:+.4f}")
    assert noise_floor < 0.025
    rmse, bias = scores["SG_FITTED"]
    assert rmse < RMSE_BOUND
    assert abs(bias) < 0.04
    for order, bound in SH_RMSE_BOUNDS.items():
        assert scores[order][0] < bound, (order, scores)
