"""Lobe fit operator (sgprt.fit_lobes) and its storage: real bpy, real .blend files saved and reopened.

Test data are generated once per module into a temporary directory: a MERL file of the
default AnalyticMaterial (about 1.5 s) and a 6 x 5 SVBRDF table (not square: a transposed
layout would show).
"""
import os

import bpy
import numpy as np
import pytest

from sg_prt_addon.blender import lobe_fit as lf
from sg_prt_addon.measured import merl, microfacet_fit, svbrdf_table
from validation import brdf_generators


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    directory = tmp_path_factory.mktemp("lobe_fit")
    merl_path = str(directory / "analytic.binary")
    brdf_generators.generate_merl(merl_path)
    table, _ = brdf_generators.generate_svbrdf_table(size=6)
    # a 6 x 5 table: drop the last column
    cut = {name: getattr(table, name)[:, :5] for name in ("diffuse", "specular", "eta", "ndf", "shadowing")}
    table = svbrdf_table.SvbrdfTable(**{**table.__dict__, **cut}).validate()
    table_path = str(directory / "table.npz")
    svbrdf_table.write_svbrdf_table(table_path, table)
    return dict(directory=directory, merl=merl_path, table=table_path)


@pytest.fixture
def material(addon):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.render.engine = "SG_PRT"
    bpy.ops.mesh.primitive_cube_add()
    material = bpy.data.materials.new("Measured")
    bpy.context.active_object.data.materials.append(material)
    yield material
    lf.progress_hook = None


def _reopen(path):
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))


def _bits(array):
    return np.ascontiguousarray(array, np.float32).view(np.uint32)


def _same_fit(stored, direct, names):
    """The stored fit is the direct fit's float32, up to rounding: BLAS sums in an order that
    depends on threads and alignment, so two fits of one file may differ in the last bits
    (an axis's zero components came out 1e-16 and 5e-16)."""
    for name in names:
        expected = np.float32(getattr(direct, name))
        assert np.allclose(getattr(stored, name), expected, rtol=1e-5, atol=1e-6), name


def _snapshot(material):
    """Everything a fit stores: metadata and the raw pixels of each image, by role."""
    settings = material.sgprt.lobe_fit
    meta = {name: getattr(settings, name) for name in ("format_version", "source_file", "source_kind", "lobe_count",
                                                        "width", "height", "fit_error", "date", "seconds")}
    pixels = {}
    for item in settings.images:
        buffer = np.empty(len(item.image.pixels), np.float32)
        item.image.pixels.foreach_get(buffer)
        pixels[item.role] = (item.image.name, buffer)
    return meta, pixels


def _same_snapshot(a, b):
    assert a[0] == b[0]
    assert a[1].keys() == b[1].keys()
    for role in a[1]:
        assert a[1][role][0] == b[1][role][0]
        assert np.array_equal(_bits(a[1][role][1]), _bits(b[1][role][1])), role


def test_merl_fit_stores_packed_float_images_that_survive_save_and_reopen(material, data, capfd, tmp_path):
    capfd.readouterr()
    assert bpy.ops.sgprt.fit_lobes(filepath=data["merl"], lobe_count=2) == {"FINISHED"}
    printed = capfd.readouterr().out
    assert "[sg-prt] fit " in printed and "100%" in printed and "%" in printed.splitlines()[0]

    settings = material.sgprt.lobe_fit
    assert material.sgprt.technique == "SG_FITTED"
    assert settings.format_version == lf.FORMAT_VERSION and settings.source_kind == "MERL"
    assert settings.source_file == "analytic.binary" and settings.lobe_count == 2
    assert (settings.width, settings.height) == (1, 1) and settings.shadowing_components == 1
    assert 0 < settings.fit_error < 0.4 and 0 < settings.ndf_error < 0.1 and settings.date.startswith("20")
    assert [item.role for item in settings.images] == lf.expected_roles(2, 1)
    for item in settings.images:
        image = item.image
        assert image.is_float and image.packed_file is not None and image.channels == 4
    assert lf.fit_status(material)[0] == "VALID"

    # the stored numbers are the float32 of a direct fit of the same file
    direct = microfacet_fit.fit_merl(merl.read_merl(data["merl"]), 2)
    stored = lf.stored_lobe_fit(material)
    _same_fit(stored, direct, ("diffuse", "eta", "axis", "sharpness", "amplitude", "shadowing_theta",
                               "shadowing_mean", "shadowing_basis", "shadowing_coefficients", "ndf_error"))
    # the lobes are the microfacet model's: two lobes on z+, sharper second
    assert np.allclose(stored.axis[0, :, 2], 1) and stored.sharpness[0, 0] < stored.sharpness[0, 1]

    before = _snapshot(material)
    _reopen(tmp_path / "merl.blend")
    reopened = bpy.data.materials["Measured"]
    _same_snapshot(before, _snapshot(reopened))
    assert lf.fit_status(reopened)[0] == "VALID" and reopened.sgprt.technique == "SG_FITTED"
    assert all(item.image.packed_file is not None for item in reopened.sgprt.lobe_fit.images)
    # the fitted BRDF from the reopened file matches the direct fit's within float32 rounding
    wo, wi, _ = microfacet_fit.half_difference_samples(8, 4, 4, offset=0.3)
    assert np.allclose(lf.stored_lobe_fit(reopened).evaluate(wo, wi), direct.evaluate(wo, wi), rtol=1e-4, atol=1e-6)


def test_table_fit_per_texel_layout_and_round_trip(material, data, tmp_path):
    assert bpy.ops.sgprt.fit_lobes(filepath=data["table"], lobe_count=3, shadowing_components=5) == {"FINISHED"}
    settings = material.sgprt.lobe_fit
    assert (settings.width, settings.height, settings.lobe_count) == (5, 6, 3)
    assert settings.source_kind == "SVBRDF_TABLE" and settings.free_axes and settings.shadowing_components == 5
    assert [item.role for item in settings.images] == lf.expected_roles(3, 5)
    roles = {item.role: item.image for item in settings.images}
    assert tuple(roles["base"].size) == (5, 6) and tuple(roles["shadowing_table"].size) == (90, 7)

    table = svbrdf_table.read_svbrdf_table(data["table"])
    direct = microfacet_fit.fit_lobes(table, 3, 5)
    # Blender row 0 (bottom) holds the table's last row: diffuse and eta straight from the file
    base = np.empty(6 * 5 * 4, np.float32)
    roles["base"].pixels.foreach_get(base)
    base = base.reshape(6, 5, 4)
    assert np.array_equal(base[::-1, :, :3], table.diffuse) and np.array_equal(base[::-1, :, 3], table.eta)
    stored = lf.stored_lobe_fit(material)
    _same_fit(stored, direct, ("axis", "sharpness", "amplitude", "shadowing_coefficients", "shadowing_basis"))
    # per-texel: roughness grows along x, so the sharpest lobe is sharper at column 0 than at column 4
    sharpest = stored.sharpness[:, -1].reshape(6, 5)
    assert np.all(sharpest[:, 0] > sharpest[:, 4])
    errors = lf.lobe_fit_images(material)["error"][..., 2]
    assert errors.shape == (6, 5) and np.all(np.isfinite(errors)) and np.all(errors > 0)
    assert np.isclose(settings.fit_error, errors.mean(), rtol=1e-6)

    before = _snapshot(material)
    _reopen(tmp_path / "table.blend")
    reopened = bpy.data.materials["Measured"]
    _same_snapshot(before, _snapshot(reopened))
    again = lf.stored_lobe_fit(reopened)
    assert np.array_equal(again.amplitude, stored.amplitude) and np.array_equal(again.axis, stored.axis)


def _bad_files(data):
    """(name, bytes, expected message) made from a valid file written by measured.merl.write_merl."""
    valid = open(data["merl"], "rb").read()
    header = np.asarray(merl.DIMENSIONS, "<i4").tobytes()
    wrong_dims = np.asarray((90, 90, 360), "<i4").tobytes() + valid[12:]
    table = open(data["table"], "rb").read()
    return [
        ("truncated.binary", valid[:len(valid) // 2], "truncated data"),
        ("header_only.binary", header, "truncated data"),
        ("short.binary", valid[:7], "truncated header"),
        ("empty.binary", b"", "truncated header"),
        ("wrong_dims.binary", wrong_dims, "wrong dimensions"),
        ("trailing.binary", valid + b"\0" * 8, "trailing bytes"),
        ("garbage.binary", os.urandom(4096), "wrong dimensions"),
        ("broken.npz", table[:len(table) // 2], "SVBRDF table"),
        ("all_nan.binary", _merl_bytes(np.full(merl.DIMENSIONS + (3,), np.nan)), "too few to fit"),
        ("half_nan.binary", _merl_bytes(_half_nan(valid)), "too few to fit"),
        ("huge.binary", _merl_bytes(np.full(merl.DIMENSIONS + (3,), 1e300)), "not a measured BRDF"),
        ("zeros.binary", _merl_bytes(np.zeros(merl.DIMENSIONS + (3,))), "nothing to fit"),
    ]


def _merl_bytes(rho):
    """A MERL file of the samples rho (90, 90, 180, 3), as measured.merl.write_merl writes it."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "samples.binary")
        merl.write_merl(path, rho)
        return open(path, "rb").read()


def _half_nan(valid_bytes):
    """The valid file's samples with every other theta_h row NaN (half of them)."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "valid.binary")
        open(path, "wb").write(valid_bytes)
        source = merl.read_merl(path)
    rho = source.rho.copy()
    rho[::2] = np.nan
    return rho


def test_bad_files_are_reported_and_nothing_is_written(material, data, tmp_path):
    assert bpy.ops.sgprt.fit_lobes(filepath=data["table"], lobe_count=1) == {"FINISHED"}
    before = _snapshot(material)
    images = sorted(image.name for image in bpy.data.images)
    for name, content, expected in _bad_files(data):
        path = tmp_path / name
        path.write_bytes(content)
        with pytest.raises(RuntimeError, match=expected) as raised:
            bpy.ops.sgprt.fit_lobes(filepath=str(path), lobe_count=2)
        assert "nothing written" in str(raised.value) and name in str(raised.value)
        _same_snapshot(before, _snapshot(material))
        assert sorted(image.name for image in bpy.data.images) == images
    with pytest.raises(RuntimeError, match="file not found"):
        bpy.ops.sgprt.fit_lobes(filepath=str(tmp_path / "missing.binary"))
    _same_snapshot(before, _snapshot(material))


def test_cancelled_fit_keeps_the_previous_fit(material, data):
    assert bpy.ops.sgprt.fit_lobes(filepath=data["table"], lobe_count=2) == {"FINISHED"}
    before = _snapshot(material)
    images = sorted(image.name for image in bpy.data.images)
    seen = []

    def cancel_midway(fraction, message):
        seen.append(fraction)
        return fraction > 0.3

    lf.progress_hook = cancel_midway
    assert bpy.ops.sgprt.fit_lobes(filepath=data["merl"], lobe_count=2) == {"CANCELLED"}
    assert max(seen) < 0.9 and len(seen) > 2          # the MERL factorization was under way
    _same_snapshot(before, _snapshot(material))
    assert sorted(image.name for image in bpy.data.images) == images
    assert material.sgprt.lobe_fit.source_kind == "SVBRDF_TABLE"


def test_refit_replaces_images_and_clear_removes_them(material, data):
    assert bpy.ops.sgprt.fit_lobes(filepath=data["table"], lobe_count=2) == {"FINISHED"}
    first = {item.image.name for item in material.sgprt.lobe_fit.images}
    assert bpy.ops.sgprt.fit_lobes(filepath=data["table"], lobe_count=1) == {"FINISHED"}
    second = {item.image.name for item in material.sgprt.lobe_fit.images}
    names = {image.name for image in bpy.data.images}
    assert second <= names and not (first - second) & names  # the old fit's extra images are gone
    assert len(material.sgprt.lobe_fit.images) == len(lf.expected_roles(1, 5))
    assert all(item.image.name == lf.image_name(material, item.role) for item in material.sgprt.lobe_fit.images)
    assert bpy.ops.sgprt.clear_lobe_fit() == {"FINISHED"}
    assert lf.fit_status(material)[0] == "NONE" and material.sgprt.technique == "SG_PARAMETRIC"
    assert not second & {image.name for image in bpy.data.images}
    # an 8-bit image in place of a float one, or a removed image, makes a stored fit invalid, not a crash
    assert bpy.ops.sgprt.fit_lobes(filepath=data["table"], lobe_count=1) == {"FINISHED"}
    material.sgprt.lobe_fit.images[1].image = bpy.data.images.new("bytes", 5, 6)
    state, message = lf.fit_status(material)
    assert state == "INVALID" and "not a float image" in message
    assert bpy.ops.sgprt.fit_lobes(filepath=data["table"], lobe_count=1) == {"FINISHED"}
    bpy.data.images.remove(material.sgprt.lobe_fit.images[0].image)
    state, message = lf.fit_status(material)
    assert state == "INVALID" and "base" in message
    with pytest.raises(ValueError):
        lf.stored_lobe_fit(material)


def test_threaded_job_matches_the_synchronous_fit_and_cancels(data):
    job = lf.FitJob(data["table"], 2)
    job.start()
    job.join(30)
    assert not job.running and job.result is not None and job.error is None
    reference = lf.FitJob(data["table"], 2)
    reference.run()
    for role, layer in reference.result["layers"].items():
        assert np.array_equal(layer, job.result["layers"][role]), role
    cancelled = lf.FitJob(data["merl"], 2, hook=lambda fraction, message: fraction > 0.1)
    cancelled.start()
    cancelled.join(30)
    assert cancelled.cancelled and cancelled.result is None


def test_invoke_in_background_runs_synchronously_and_panel_is_registered(material, data):
    assert bpy.ops.sgprt.fit_lobes("INVOKE_DEFAULT", filepath=data["table"], lobe_count=1) == {"FINISHED"}
    assert lf.fit_status(material)[0] == "VALID"
    panel = bpy.types.SGPRT_PT_material_lobe_fit
    assert panel.bl_parent_id == "SGPRT_PT_material" and panel.bl_context == "material"
    with pytest.raises(RuntimeError, match="no file given"):
        bpy.ops.sgprt.fit_lobes(filepath="")


FIT_IN_OTHER_BLENDER = """
import sys
import bpy
import numpy as np
import sg_prt_addon
from sg_prt_addon.blender import lobe_fit
out, table = sys.argv[1], sys.argv[2]
sg_prt_addon.register()
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_cube_add()
material = bpy.data.materials.new("Old")
bpy.context.active_object.data.materials.append(material)
assert bpy.ops.sgprt.fit_lobes(filepath=table, lobe_count=3) == {"FINISHED"}
np.savez(out + "/old.npz", **lobe_fit.lobe_fit_images(material))
bpy.ops.wm.save_as_mainfile(filepath=out + "/old.blend")
import os
os._exit(0)
"""


def test_a_fit_from_blender_4_2_loads_bit_exactly_in_this_blender(addon, data, tmp_path):
    """A .blend fitted by Blender 4.2 LTS (the second venv) opens here with the fit valid and
    every stored float bit-identical."""
    import pathlib
    import subprocess
    root = pathlib.Path(__file__).resolve().parents[2]
    python = root / ".venv-bpy42" / "bin" / "python"
    if not python.exists() or bpy.app.version < (4, 3, 0):
        pytest.skip("needs the bpy 4.2 venv, and a newer Blender running the test")
    script = tmp_path / "fit_old.py"
    script.write_text(FIT_IN_OTHER_BLENDER)
    done = subprocess.run([str(python), str(script), str(tmp_path), data["table"]], cwd=root, capture_output=True,
                          text=True, timeout=120, env={**os.environ, "PYTHONPATH": str(root)})
    assert done.returncode == 0, done.stderr[-2000:]
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "old.blend"))
    material = bpy.data.materials["Old"]
    assert lf.fit_status(material)[0] == "VALID" and material.sgprt.lobe_fit.lobe_count == 3
    expected = np.load(tmp_path / "old.npz")
    arrays = lf.lobe_fit_images(material)
    assert sorted(expected.files) == sorted(arrays) == sorted(lf.expected_roles(3, 5))
    for role in arrays:
        assert np.array_equal(_bits(arrays[role]), _bits(expected[role])), role
