"""reflectance.layering (Fresnel, Multiscatter GGX and the layered diffuse as factors at the view) and
reflectance.principled (Blender's BSDF inputs in the engine's terms), against direct quadrature."""
import numpy as np
import pytest

from sg_prt_addon.reflectance import brdf, ggx_albedo, layering, principled
from sg_prt_addon.spherical import lattice

LATTICE = lattice.hemisphere_points(400_000)          # uniform over the hemisphere: weight 2 pi / n each


def _lobe_cosine(cos_o, roughness):
    """(rho_s(o, i) (n.i) per lattice direction, o.h per direction) of brdf.GGX (no Fresnel)."""
    o = np.array([np.sqrt(1 - cos_o ** 2), 0.0, cos_o])
    model = brdf.GGX(roughness=roughness)
    wo = np.broadcast_to(o, LATTICE.shape)
    values = model.specular(wo, LATTICE) * LATTICE[:, 2]
    h = brdf.half_vector(wo, LATTICE)
    return values, np.sum(wo * h, axis=-1)


@pytest.mark.slow_maths
def test_table_against_a_finer_quadrature():
    """E and E_w at every texel against 4x the nodes (E_avg is checked through the furnace below)."""
    table = layering.layering_table()
    grid = ggx_albedo.texel_centres()
    fine = ggx_albedo.directional_albedo(grid[None, :], grid[:, None], nodes_u=256, nodes_phi=128)
    fine_w = ggx_albedo.directional_albedo(grid[None, :], grid[:, None], nodes_u=256, nodes_phi=128,
                                           schlick_weight=True)
    # measured: 4.9e-3 and 2.0e-3, at the grazing column (cos 0, clipped to 1e-4) of the sharpest rows; 3.3e-3
    # and 8.2e-4 at every other view
    assert np.abs(table[..., 0] - fine).max() < 6e-3
    assert np.abs(table[..., 1] - fine_w).max() < 3e-3
    assert np.abs(table[:, 1:, 0] - fine[:, 1:]).max() < 4e-3


@pytest.mark.parametrize("roughness", [0.3, 0.5, 0.8])
@pytest.mark.parametrize("cos_o", [0.25, 0.6, 0.95])
def test_fresnel_average_is_the_integral_of_schlick(roughness, cos_o):
    """factors' specular x E(o) equals the albedo with Schlick inside the integral (the white furnace)."""
    values, o_dot_h = _lobe_cosine(cos_o, roughness)
    for f0 in (0.04, 0.5, 0.95):
        exact = np.sum(values * layering.schlick(f0, o_dot_h)) * 2 * np.pi / len(LATTICE)
        factor, _ = layering.factors(np.full((1, 3), f0), layering.NO_LAYER, np.array([cos_o]),
                                     np.array([roughness]), fresnel=True, multiscatter=False)
        albedo = layering.table_values(np.array([cos_o], np.float32), np.array([roughness], np.float32))[0]
        # measured: within 1.5e-3 (the table's bilinear fetch and the lattice)
        assert abs(factor[0, 0] * albedo[0] - exact) < 3e-3 + 0.01 * exact, (f0, factor, albedo, exact)


@pytest.mark.parametrize("roughness", [0.1, 0.4, 0.9])
def test_multiscatter_keeps_white_energy(roughness):
    """Cycles' gain makes a white (F = 1) GGX lobe reflect everything at every view: E x gain = 1."""
    cos_o = np.linspace(0.05, 1.0, 12).astype(np.float32)
    rough = np.full_like(cos_o, roughness)
    albedo = layering.table_values(cos_o, rough)[0]
    for fresnel in (True, False):
        factor, _ = layering.factors(np.ones((12, 3)), layering.NO_LAYER, cos_o, rough, fresnel, True)
        np.testing.assert_allclose(factor[:, 0] * albedo, 1.0, atol=2e-6)
    # and a coloured one keeps less than white, more than single scattering
    factor, _ = layering.factors(np.full((12, 3), 0.5), layering.NO_LAYER, cos_o, rough, False, True)
    assert np.all(factor[:, 0] >= 0.5) and np.all(factor[:, 0] * albedo <= 1.0)


def test_layered_diffuse_loses_what_the_coat_reflects():
    cos_o = np.array([1.0, 0.5, 0.1], np.float32)
    rough = np.full(3, 0.5, np.float32)
    specular, diffuse = layering.factors(np.full((3, 3), 0.04), 0.04, cos_o, rough, True, False)
    albedo = layering.table_values(cos_o, rough)[0]
    np.testing.assert_allclose(diffuse, 1.0 - specular[:, 0] * albedo, rtol=1e-6)
    assert diffuse[0] > diffuse[1] > diffuse[2] > 0.5          # more is reflected at grazing views
    assert np.all(layering.factors(np.full((3, 3), 0.04), layering.NO_LAYER, cos_o, rough, True, False)[1] == 1.0)


def fresnel_shape_error(cos_o, roughness, f0):
    """Relative L2 over the hemisphere between rho (n.i) with Schlick inside and the same lobe times its
    average Fresnel: what taking Fresnel out of the integral changes in the lobe's shape."""
    values, o_dot_h = _lobe_cosine(cos_o, roughness)
    inside = values * layering.schlick(f0, o_dot_h)
    average = np.sum(inside) / max(np.sum(values), 1e-30)
    return float(np.linalg.norm(inside - average * values) / np.linalg.norm(inside))


@pytest.mark.parametrize("cos_o, roughness, f0, measured", [
    (0.95, 0.5, 0.04, 0.005), (0.6, 0.5, 0.04, 0.245), (0.25, 0.5, 0.04, 0.502), (0.25, 0.8, 0.04, 0.62),
    (0.25, 0.5, 0.5, 0.094), (0.25, 0.5, 0.9, 0.012), (0.6, 0.3, 0.9, 0.001)])
def test_fresnel_out_of_the_integral_error(cos_o, roughness, f0, measured):
    """Small for metals and for dielectrics seen face-on; at grazing views a dielectric's Fresnel rises
    across its lobe (F0 0.04 to 1), so the lobe's shape is off by half (its energy stays exact)."""
    assert fresnel_shape_error(cos_o, roughness, f0) < 1.1 * measured + 0.002


def test_dielectric_f0_and_its_inverse():
    assert principled.dielectric_f0(1.5) == pytest.approx(0.04)
    assert principled.dielectric_f0(1.5, 1.0) == pytest.approx(0.08)
    assert principled.dielectric_f0(1.5, 0.0) == 0.0
    assert principled.ior_of_f0(0.04) == pytest.approx(1.5)


def test_principled_mapping():
    dielectric = principled.principled(base_color=(0.8, 0.2, 0.1), metallic=0.0, roughness=0.4, ior=1.5)
    assert dielectric["model"] == "GGX" and dielectric["roughness"] == pytest.approx(0.4)
    assert dielectric["diffuse_color"] == pytest.approx((0.8, 0.2, 0.1))
    assert dielectric["specular_color"] == pytest.approx((0.04, 0.04, 0.04))
    assert dielectric["layered_f0"] == pytest.approx(0.04) and dielectric["fresnel"] == "SCHLICK"
    gold = principled.principled(base_color=(1.0, 0.77, 0.34), metallic=1.0, roughness=0.3, multiscatter=False)
    assert gold["diffuse_color"] == pytest.approx((0.0, 0.0, 0.0)) and gold["layered_f0"] < 0
    assert gold["specular_color"] == pytest.approx((1.0, 0.77, 0.34)) and not gold["multiscatter"]
    half = principled.principled(base_color=(1.0, 0.5, 0.0), metallic=0.5, transmission=0.5,
                                 specular_tint=(1.0, 0.5, 0.5))
    assert half["diffuse_color"] == pytest.approx((0.25, 0.125, 0.0))
    assert half["specular_color"] == pytest.approx((0.52, 0.26, 0.01))
    aniso = principled.principled(roughness=0.5, anisotropic=0.8, anisotropic_rotation=0.25)
    aspect = np.sqrt(1 - 0.72)
    assert aniso["model"] == "GGX_ANISO"
    assert (aniso["alpha_x"], aniso["alpha_y"]) == pytest.approx((0.25 / aspect, 0.25 * aspect))
    assert aniso["tangent_rotation"] == pytest.approx(np.pi / 2)
    assert principled.principled(emission_color=(1, 0.5, 0), emission_strength=2)["emission"] == (2, 1, 0)


def test_glossy_mapping():
    assert principled.glossy((0.5, 0.5, 0.5), 0.3, "MULTI_GGX")["multiscatter"]
    assert principled.glossy((0.5, 0.5, 0.5), 0.3, "GGX")["fresnel"] == "NONE"
    beckmann = principled.glossy((1, 1, 1), 0.5, "BECKMANN")
    assert beckmann["model"] == "BECKMANN" and beckmann["roughness"] == 0.5
    assert principled.glossy((1, 1, 1), 0.5, "BECKMANN", anisotropy=0.5)["model"] == "WARD_ANISO"
    assert principled.glossy((1, 1, 1), 0.5, "SHARP")["roughness"] == principled.MIN_ROUGHNESS
    shirley = principled.glossy((1, 1, 1), 0.5, "ASHIKHMIN_SHIRLEY")
    assert shirley["nu"] == shirley["nv"] == pytest.approx(2 / 0.0625 - 2)


@pytest.mark.parametrize("anisotropy, alpha_x, alpha_y", [
    (0.5, 0.125, 0.5),              # positive: narrow along the tangent, the highlight stretched across it
    (-0.5, 0.5, 0.125),             # negative: the other way
    (2.0, 0.0025, 1.0),             # clamped to 0.99 (Cycles' alpha_y 25, beyond the model's 1)
])
def test_glossy_anisotropy_is_cycles_glossy_mapping(anisotropy, alpha_x, alpha_y):
    """The Glossy BSDF's Anisotropy is not the Principled BSDF's (alpha (1 -+ a) and alpha / (1 -+ a) along the
    tangent, not alpha / sqrt(1 - 0.9 a)): a Principled mapping here turned the lobe a quarter turn and
    narrowed it (Cycles' highlight on a plane at Anisotropy 1: 2 pixels across where ours was 6)."""
    ggx = principled.glossy((1, 1, 1), 0.5, "GGX", anisotropy)
    assert ggx["model"] == "GGX_ANISO"
    assert (ggx["alpha_x"], ggx["alpha_y"]) == pytest.approx((max(alpha_x, principled.MIN_ROUGHNESS), alpha_y))
    ward = principled.glossy((1, 1, 1), 0.5, "BECKMANN", anisotropy)
    assert ward["model"] == "WARD_ANISO" and (ward["alpha_x"], ward["alpha_y"]) == pytest.approx(
        (ggx["alpha_x"], ggx["alpha_y"]))
    shirley = principled.glossy((1, 1, 1), 0.5, "ASHIKHMIN_SHIRLEY", anisotropy)
    assert shirley["nu"] == pytest.approx(min(2 / ggx["alpha_x"] ** 2 - 2, 1e5))
    assert shirley["nv"] == pytest.approx(max(2 / ggx["alpha_y"] ** 2 - 2, 1.0))
    assert principled.glossy((1, 1, 1), 0.5, "GGX", 5e-5)["model"] == "GGX"     # Cycles: isotropic below 1e-4


def test_equivalent_roughness():
    assert layering.equivalent_roughness("GGX", {"roughness": 0.4}) == pytest.approx(0.4)
    assert layering.equivalent_roughness("WARD_ANISO", {"alpha_x": 0.25, "alpha_y": 0.04}) == pytest.approx(0.316, 1e-2)
    assert layering.equivalent_roughness("WARD_ISO", {"alpha_x": 0.16}) == pytest.approx(0.4)


def test_the_mirror_replaces_the_specular_colour():
    """sg_shading.surface_layers (the shaders' order of operations): a constant colour stays itself, Schlick from
    F0 gives F_E (about F0 face-on, not F0 times it), the diffuse is scaled."""
    from types import SimpleNamespace

    from sg_prt_addon.techniques.sg import sg_shading

    position = np.array([[0.0, 0.0, 0.0]] * 2, np.float32)
    normal = np.array([[0.0, 0.0, 1.0], [0.0, 0.8, 0.6]], np.float32)
    colour = np.array([[0.9, 0.5, 0.2]] * 2, np.float32)
    diffuse = np.full((2, 3), 0.5, np.float32)

    def layered(**settings):
        material = SimpleNamespace(model="GGX", roughness=0.3, layered_f0=-1.0, fresnel="NONE", multiscatter=False)
        material.__dict__.update(settings)
        return sg_shading.surface_layers(material, None, None, diffuse, colour, normal, position, (0.0, 0.0, 5.0),
                                         True)

    assert layered()[1] is colour and layered(fresnel="NONE")[0] is diffuse
    kd, ks = layered(fresnel="SCHLICK")
    np.testing.assert_allclose(ks[0], colour[0], rtol=0.02)              # face-on: F_E(o) ~ F0
    assert np.all(ks[1] > colour[1])                                      # towards grazing: whiter
    kd, ks = layered(fresnel="SCHLICK", layered_f0=0.04)
    assert np.all(kd < diffuse) and np.all(kd > 0.9 * diffuse)


@pytest.mark.parametrize("alpha_t, alpha_b", [(0.196, 0.05), (0.05, 0.196), (0.17, 0.048), (0.3, 0.3)])
def test_matched_glossy_node_makes_our_alphas(alpha_t, alpha_b):
    """The truth suite's Cycles materials (benchmarks.matched_materials): the Glossy node's roughness and
    Anisotropy it chooses give back our alphas through Cycles' mapping."""
    from benchmarks import matched_materials

    roughness, anisotropy = matched_materials.glossy_node_anisotropy(alpha_t, alpha_b)
    assert principled.glossy_anisotropic_alphas(roughness, anisotropy) == pytest.approx((alpha_t, alpha_b))
