"""The engine's fitted-lobe variant (MODEL_FITTED) against its numpy mirror (techniques.sg.sg_shading).

A small generated SVBRDF table (validation.brdf_generators.generate_svbrdf_table, 8 x 8 texels:
spatially varying kd, eta, roughness) is fitted by ``bpy.ops.sgprt.fit_lobes`` into a
material's stored images; the engine renders it from the nearest texel's lobes (texelFetch),
warped to the view, times M_o with S decoded from the stored shadowing PCA; the mirror shades
the same G-buffer pixels from export.FittedLobes.  A material without a valid fit (here the
floor, and the same material once its fit is switched off) renders with its model as before.
"""
import engine_fixtures as fx
import numpy as np
import pytest

TOLERANCE = 1e-3


@pytest.fixture(scope="module")
def fitted_material(blender, tmp_path_factory):
    from sg_prt_addon.blender import lobe_fit

    fx.ensure_registered()
    material = fx.material("mat_fitted_table", model="GGX", roughness=0.4)
    fx.fit_lobes(material, fx.svbrdf_table_file(tmp_path_factory.mktemp("fitted")), lobe_count=2,
                 shadowing_components=5)
    assert lobe_fit.fit_status(material)[0] == "VALID" and material.sgprt.technique == "SG_FITTED"
    return material


def _mirror(result):
    from sg_prt_addon import techniques

    passes, state = result["passes"], result["state"]
    camera = passes["camera"]
    uv = passes["gbuffer_uv"]
    covered = uv[..., 3] > 0.5
    material_of_id = {i: name for name, i in passes["material_ids"].items()}
    expected = {name: np.zeros(uv.shape[:2] + (3,), np.float32) for name in ("Diffuse", "Specular")}
    view_origin = camera.position if camera.is_perspective else camera.forward
    for material_id in np.unique(uv[covered][:, 2]).astype(int):
        mask = covered & (np.abs(uv[..., 2] - material_id) < 0.25)
        params = state.materials[material_of_id[material_id]]
        diffuse, specular = techniques.for_material(params).mirror(
            params, {}, passes["gbuffer_position"][mask][:, :3],
            passes["gbuffer_normal"][mask][:, :3], passes["gbuffer_tangent"][mask], fx.mirror_uv(uv[mask]), view_origin,
            camera.is_perspective, state.light_data(), state.environment)
        expected["Diffuse"][mask] = diffuse
        expected["Specular"][mask] = specular
    return expected, covered


def _errors(result, mask=None):
    assert "error" not in result, result.get("error")
    expected, covered = _mirror(result)
    mask = covered if mask is None else (covered & mask)
    errors = {}
    for name in ("Diffuse", "Specular"):
        actual = result["passes"][name][..., :3][mask]
        assert np.all(np.isfinite(actual))
        assert expected[name][mask].max() > 0
        errors[name] = float(fx.relative_error(actual, expected[name][mask]).max())
    return errors


def test_fitted_lobes_engine_matches_mirror(fitted_material):
    
    scene = fx.new_scene("fitted_mirror", 128, 128)
    fx.world_texture(scene, fx.studio_world_path(), strength=0.6)
    sphere = fx.uv_sphere(scene, "fitted_sphere", (0.0, 0.0, 1.0), radius=1.0)
    sphere.data.materials.append(fitted_material)
    fx.plane(scene, "floor", (0.0, 0.0, 0.0))
    fx.point_light(scene, "point", (2.0, -3.0, 3.0), 600.0, radius=0.1)
    sun = fx.point_light(scene, "sun", (0.0, 0.0, 5.0), 2.0, kind="SUN")
    sun.rotation_euler = (0.5, 0.3, 0.0)
    result = fx.render(scene, gbuffer=True)
    params = result["state"].materials[fitted_material.name]
    assert params.fitted is not None and params.fitted.layers.shape[1:3] == (8, 8)
    key = fx.variant_key(params, True, True, True)
    assert key.model == "FITTED" and key.technique == "SG_FITTED" and key.ndf_lobes == 2 and key.shadowing_components == 5

    material_id = result["passes"]["material_ids"][fitted_material.name]
    on_sphere = np.abs(result["passes"]["gbuffer_uv"][..., 2] - material_id) < 0.25
    assert on_sphere.mean() > 0.1
    errors = _errors(result)
    print("fitted engine vs mirror, max relative error", errors)
    for name, error in errors.items():
        assert error <= TOLERANCE, f"{name}: max relative error {error:.2e} > {TOLERANCE}"
    # the texels differ: the sphere shows the table's spatial variation
    diffuse = result["passes"]["Diffuse"][..., :3][on_sphere]
    assert np.std(diffuse[:, 0] / np.maximum(diffuse.sum(axis=1), 1e-6)) > 0.01

    fitted_specular = result["passes"]["Specular"][on_sphere].copy()
    # the fit switched off: the material's own model again (the GGX variant), still matching its mirror
    fitted_material.sgprt.technique = "SG_PARAMETRIC"
    try:
        plain = fx.render(scene, gbuffer=True)
        assert plain["state"].materials[fitted_material.name].fitted is None
        plain_errors = _errors(plain)
        print("fit switched off (GGX): max relative error", plain_errors)
        assert max(plain_errors.values()) <= TOLERANCE
        assert not np.allclose(plain["passes"]["Specular"][on_sphere], fitted_specular)
    finally:
        fitted_material.sgprt.technique = "SG_FITTED"
