"""The model registry (reflectance/models.py) is the one list: every model has an exact form, GLSL lobes
and its parameters among the material's fields; the anisotropic ones are the ones with lobe tables."""
from pathlib import Path

from sg_prt_addon.reflectance import brdf, models

SHADERS = Path(__file__).resolve().parents[2] / "shaders"


def test_every_model_has_an_exact_form_and_glsl_lobes():
    shading = (SHADERS / "techniques" / "sg" / "sg_shading.glsl").read_text()
    for model in models.MODELS:
        exact = brdf.model_from_name(model.name)
        assert exact is not None and f"defined(MODEL_{model.name})" in shading, model.name
        assert set(model.parameters) <= set(models.SCALAR_PARAMETERS)
        if model.anisotropic:       # several lobes from the anisotropy table
            assert exact.ndf_lobes(3)[1].shape[-1] == 3
    assert models.ANISOTROPIC == ("WARD_ANISO", "ASHIKHMIN_SHIRLEY")
    assert [item[0] for item in models.enum_items()] == list(models.NAMES)
    assert all(model.panel_parameters[-1] == "lobe_count" for model in models.MODELS if model.anisotropic)
