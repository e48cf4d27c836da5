"""The model registry (reflectance/models.py) is the one list: every model has an exact form, GLSL lobes
and its parameters among the material's fields; the anisotropic ones are the ones with lobe tables."""
from pathlib import Path

import pytest

from sg_prt_addon.reflectance import brdf, models

SHADERS = Path(__file__).resolve().parents[2] / "shaders"


@pytest.mark.slow_maths
def test_every_model_has_an_exact_form_and_glsl_lobes():
    shading = (SHADERS / "techniques" / "sg" / "sg_models.glsl").read_text()
    for model in models.MODELS:
        exact = brdf.model_from_name(model.name)
        assert exact is not None and f"defined(MODEL_{model.name})" in shading, model.name
        assert set(model.parameters) <= set(models.SCALAR_PARAMETERS)
        if model.anisotropic:       # several lobes from an anisotropy table
            assert exact.ndf_lobes(3)[1].shape[-1] == 3
    assert models.ANISOTROPIC == ("WARD_ANISO", "ASHIKHMIN_SHIRLEY", "GGX_ANISO")
    assert [item[0] for item in models.enum_items()] == list(models.NAMES)
    assert all(model.panel_parameters[-1] == "lobe_count" for model in models.MODELS if model.anisotropic)


def test_the_model_enum_keeps_its_order():
    """A .blend stores material.sgprt.model by position: new models are appended, never inserted."""
    assert models.NAMES == ("GGX", "COOK_TORRANCE", "BLINN_PHONG", "WARD_ISO", "WARD_ANISO", "ASHIKHMIN_SHIRLEY",
                            "GGX_ANISO", "BECKMANN")


@pytest.mark.slow_maths
def test_anisotropic_ggx_lobes_against_its_ndf():
    """Anisotropic GGX's lobes, fitted together to its two isotropic lobes stretched (ndf_fit.ggx_anisotropy_table),
    relative L2 of the NDF at 4 and 8 lobes: measured 0.447 / 0.201, 0.243 / 0.153, 0.036 / 0.036 (the isotropic
    two-lobe fit), 0.265 / 0.102.  Before, GGX's two lobes were each made of half the count from Ward's table:
    0.530 / 0.328, 0.271 / 0.154, 0.036 / 0.036, 0.345 / 0.150 (the image error, test_environment_specular.py)."""
    from sg_prt_addon.reflectance import ndf_fit

    for (alpha_x, alpha_y), measured in (((0.35, 0.06), (0.447, 0.201)), ((0.5, 0.2), (0.243, 0.153)),
                                         ((0.16, 0.16), (0.036, 0.036)), ((0.17, 0.0476), (0.265, 0.102))):
        model = brdf.GGXAnisotropic(alpha_x=alpha_x, alpha_y=alpha_y)
        for lobe_count, bound in zip((4, 8), measured):
            assert ndf_fit.ndf_l2_error(model, model.ndf_lobes(lobe_count)) < bound + 0.01
    isotropic = ndf_fit.ndf_l2_error(brdf.GGX(roughness=0.4), brdf.GGX(roughness=0.4).ndf_lobes(2))
    anisotropic = brdf.GGXAnisotropic(alpha_x=0.16, alpha_y=0.16)
    assert ndf_fit.ndf_l2_error(anisotropic, anisotropic.ndf_lobes(2)) < isotropic + 0.002
    isotropic, anisotropic = brdf.GGX(roughness=0.4), brdf.GGXAnisotropic(alpha_x=0.16, alpha_y=0.16)
    import numpy as np
    directions = np.random.default_rng(0).normal(size=(1000, 3))
    directions[:, 2] = np.abs(directions[:, 2])
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    view = np.broadcast_to([0.3, 0.2, np.sqrt(0.87)], directions.shape)
    np.testing.assert_allclose(anisotropic.specular(view, directions), isotropic.specular(view, directions),
                               rtol=1e-9)


def test_lobes_of_gives_an_anisotropic_model_its_default_where_the_material_says_auto():
    assert models.lobes_of("GGX_ANISO", 0) == 6
    assert models.lobes_of("ASHIKHMIN_SHIRLEY", 0) == models.lobes_of("WARD_ANISO", 0) == 4
    assert models.lobes_of("ASHIKHMIN_SHIRLEY", 7) == models.lobes_of("GGX_ANISO", 7) == 7
    # isotropic models (and names outside the table, as the fitted model's) have one NDF lobe whatever Lobes says
    assert models.lobes_of("GGX", 5) == models.lobes_of("COOK_TORRANCE", 0) == models.lobes_of("FITTED", 3) == 1
    assert all(model.default_lobes >= 2 for model in models.MODELS if model.anisotropic)
