"""Factor BRDF operator (sgprt.factor_brdf) and its storage: real bpy, a generated MERL file (Oren-Nayar +
GGX + Fresnel + retro-reflection, with corrupt samples), real .blend files saved and reopened."""
import bpy
import numpy as np
import pytest

from sg_prt_addon.measured import homomorphic, merl, svbrdf_table
from sg_prt_addon.techniques.homomorphic.blender import factorization as bf
from validation import brdf_generators


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    directory = tmp_path_factory.mktemp("factor_brdf")
    path = str(directory / "analytic.binary")
    brdf_generators.generate_merl(path, corrupt_fraction=1e-4)
    clean = str(directory / "clean.binary")
    brdf_generators.generate_merl(clean, corrupt_fraction=0.0)
    table = str(directory / "table.npz")
    svbrdf_table.write_svbrdf_table(table, brdf_generators.generate_svbrdf_table(size=3)[0])
    return dict(directory=directory, merl=path, clean=clean, table=table)


@pytest.fixture
def material(addon):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.render.engine = "SG_PRT"
    bpy.ops.mesh.primitive_cube_add()
    material = bpy.data.materials.new("Measured")
    bpy.context.active_object.data.materials.append(material)
    yield material
    bf.progress_hook = None


def _snapshot(material):
    settings = material.sgprt.factorization
    names = ("format_version", "source_file", "source_texel", "form", "resolution", "lobe_sharpness", "samples",
             "masked", "error", "date")
    meta = {name: getattr(settings, name) for name in names}
    meta["alpha_scale"] = tuple(settings.alpha_scale)
    pixels = {}
    for item in settings.images:
        buffer = np.empty(len(item.image.pixels), np.float32)
        item.image.pixels.foreach_get(buffer)
        pixels[item.role] = buffer.view(np.uint32)
    return meta, pixels


def _same(a, b):
    return a[0] == b[0] and a[1].keys() == b[1].keys() and all(np.array_equal(a[1][k], b[1][k]) for k in a[1])


def test_factors_are_stored_and_survive_save_and_reopen(material, data, tmp_path):
    assert bpy.ops.sgprt.factor_brdf(filepath=data["merl"], form="pqpr", resolution=32) == {"FINISHED"}
    settings = material.sgprt.factorization
    assert bf.factorization_status(material)[0] == "VALID" and material.sgprt.technique == "FACTORED"
    assert [item.role for item in settings.images] == ["p", "q", "r", "albedo"]
    assert all(item.image.is_float and item.image.packed_file is not None for item in settings.images)
    # the generated BRDF (retro-reflection, Fresnel, Oren-Nayar): relative RMS 0.66 at 256 x 256 samples
    # (docs/ACCURACY.md, homomorphic: 0.66 for the analytic form); MERL's nearest-bin lookup adds its own
    assert 0 < settings.error < 0.8 and settings.masked > 0
    before = _snapshot(material)
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "factors.blend"))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "factors.blend"))
    reopened = bpy.data.materials["Measured"]
    assert _same(before, _snapshot(reopened)), "metadata or pixels changed"
    tables = bf.stored_tables(reopened)
    assert tables is not None and tables.factorization.form == "pqpr" and tables.maps["r"].shape == (1, 32, 4)


def test_a_table_texel_is_factorized_as_one_brdf(material, data, tmp_path):
    """Texel 5 of a 3 x 3 SVBRDF table: the stored maps are the direct factorization of that texel's BRDF
    (float32), its index survives save and reopen; a texel outside the table is refused, nothing lost."""
    assert bpy.ops.sgprt.factor_brdf(filepath=data["table"], form="pqpr", resolution=16, texel=5) == {"FINISHED"}
    settings = material.sgprt.factorization
    assert settings.source_texel == 5 and "table.npz texel 5" in bf.factorization_status(material)[1]
    table = svbrdf_table.read_svbrdf_table(data["table"])
    direct = homomorphic.factorize(*homomorphic.sample_table_texel(table, 5, bf.SAMPLES), form="pqpr", resolution=16)
    stored = bf.stored_tables(material)
    for role in ("p", "q", "r"):
        np.testing.assert_allclose(stored.maps[role][..., :3], direct.log_factors[role], rtol=0, atol=1e-5)
    # texels differ (the table's roughness varies): texel 5's BRDF, not texel 0's
    other = homomorphic.factorize(*homomorphic.sample_table_texel(table, 0, 64), form="pqpr", resolution=16)
    assert np.max(np.abs(other.log_factors["q"] - direct.log_factors["q"])) > 0.1
    assert 0 < settings.error < 0.5
    before = _snapshot(material)
    with pytest.raises(RuntimeError, match="texel 9 is outside the table's 3 x 3 = 9 texels"):
        bpy.ops.sgprt.factor_brdf(filepath=data["table"], texel=9, resolution=16)
    assert _same(_snapshot(material), before)
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "texel.blend"))
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "texel.blend"))
    assert bpy.data.materials["Measured"].sgprt.factorization.source_texel == 5


def test_corrupt_samples_change_the_count_not_the_factors(material, data):
    """NaN/Inf bins of a MERL file are masked and counted (the clean file has its own invalid bins: MERL marks
    bins whose centre lies below the horizon, which grazing pairs reach); the factored BRDF moves by < 1%."""
    results = {}
    for key in ("clean", "merl"):
        assert bpy.ops.sgprt.factor_brdf(filepath=data[key], form="pqpr", resolution=16) == {"FINISHED"}
        results[key] = (bf.stored_tables(material), material.sgprt.factorization.masked)
    assert results["merl"][1] > results["clean"][1]
    wo, wi, _ = homomorphic.sample_brdf(lambda o, i: np.zeros(len(o)), 48, 48)

    def evaluate(tables):
        from sg_prt_addon.techniques.homomorphic import factored_shading
        factorization = tables.factorization
        return tables.scale * factored_shading.factored_brdf(factorization.log_factors, factorization.form, wo, wi)

    clean, corrupt = evaluate(results["clean"][0]), evaluate(results["merl"][0])
    assert np.sqrt(np.mean((corrupt - clean) ** 2) / np.mean(clean ** 2)) < 0.01
    assert merl.read_merl(data["merl"]).counts != {"negative": 0, "nan": 0, "inf": 0}


def test_bad_files_are_reported_and_previous_factors_kept(material, data, tmp_path):
    assert bpy.ops.sgprt.factor_brdf(filepath=data["merl"], resolution=16) == {"FINISHED"}
    before = _snapshot(material)
    garbage = tmp_path / "garbage.binary"
    garbage.write_bytes(b"\x01\x02\x03" * 100)
    table = tmp_path / "table.npz"
    table.write_bytes(b"PK\x03\x04" + b"\x00" * 64)
    for path, message in ((tmp_path / "missing.binary", "not found"), (garbage, "not a valid MERL"),
                          (table, "not a valid SVBRDF table")):
        with pytest.raises(RuntimeError, match=message):
            bpy.ops.sgprt.factor_brdf(filepath=str(path), resolution=16)
        assert _same(_snapshot(material), before)


def test_cancelled_factorization_keeps_the_previous_factors(material, data):
    assert bpy.ops.sgprt.factor_brdf(filepath=data["merl"], resolution=16) == {"FINISHED"}
    before = _snapshot(material)
    bf.progress_hook = lambda fraction, message: fraction >= 0.2
    assert bpy.ops.sgprt.factor_brdf(filepath=data["clean"], resolution=16) == {"CANCELLED"}
    assert _same(_snapshot(material), before)


def test_clear_removes_the_images_and_the_technique(material, data):
    assert bpy.ops.sgprt.factor_brdf(filepath=data["merl"], resolution=16) == {"FINISHED"}
    names = [item.image.name for item in material.sgprt.factorization.images]
    assert bpy.ops.sgprt.clear_factorization() == {"FINISHED"}
    assert bf.factorization_status(material)[0] == "NONE" and material.sgprt.technique == "SG_PARAMETRIC"
    assert not any(name in bpy.data.images for name in names)


@pytest.mark.parametrize("technique", ["SG_BISCALE", "SH"])
def test_clear_gives_back_the_technique_the_factors_replaced(material, data, capfd, technique):
    """Factor BRDF then Clear BRDF Factors on a bi-scale (or SH) material: it renders as before, and says so;
    factoring twice keeps the first technique."""
    material.sgprt.technique = technique
    assert bpy.ops.sgprt.factor_brdf(filepath=data["merl"], resolution=16) == {"FINISHED"}
    assert bpy.ops.sgprt.factor_brdf(filepath=data["clean"], resolution=16) == {"FINISHED"}
    assert material.sgprt.technique == "FACTORED"
    capfd.readouterr()
    assert bpy.ops.sgprt.clear_factorization() == {"FINISHED"}
    assert material.sgprt.technique == technique
    assert f"'{material.name}' renders with" in "".join(capfd.readouterr())
    assert material.sgprt.factorization.previous_technique == ""
