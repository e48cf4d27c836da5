"""The SH technique's tables in the engine's disk cache (DrawContext.cached_arrays, engine/disk_cache.py): a lobe
fit's tables (harmonics/fitted_table.py, seconds a fit) and a parametric model's (harmonics/brdf_table.py, about
1 s) are built once, read back bit-exact by the next process without building them, and a changed fit or
parameter is a miss."""
import collections
import types

import numpy as np
import pytest

pytest.importorskip("bpy")


@pytest.fixture()
def context(monkeypatch, tmp_path):
    """A DrawContext of the engine's with its disk cache in tmp_path (no GPU: the tables are numpy here)."""
    from sg_prt_addon.engine import renderer

    monkeypatch.setenv("SG_PRT_CACHE_DIR", str(tmp_path))
    draw_context = renderer._DrawContext.__new__(renderer._DrawContext)
    draw_context.renderer = renderer.Renderer()
    draw_context.inputs = types.SimpleNamespace(environment=None)
    return draw_context


class Counted:
    """A function wrapped to count its calls."""

    def __init__(self, function):
        self.function, self.calls = function, 0

    def __call__(self, *args, **kwargs):
        self.calls += 1
        return self.function(*args, **kwargs)


def _fit(sharpest=60.0):
    """An export.FittedLobes of 4 x 4 texels, 2 lobes about the normal, 3 shadowing components."""
    from sg_prt_addon.blender.export import FittedLobes

    rng = np.random.default_rng(2)
    lobes, components, shadowing_nodes = 2, 3, 16
    layers = np.zeros((1 + 2 * lobes + 1, 4, 4, 4), np.float32)
    layers[0, ..., :3], layers[0, ..., 3] = rng.uniform(0.1, 0.5, (4, 4, 3)), 1.5
    for k, (low, high) in enumerate(((2.0, 8.0), (20.0, sharpest))):
        layers[1 + 2 * k, ..., 2], layers[1 + 2 * k, ..., 3] = 1.0, rng.uniform(low, high, (4, 4))
        layers[2 + 2 * k, ..., :3] = rng.uniform(0.1, 1.0, (4, 4, 3))
    layers[-1, ..., :components] = rng.normal(0.0, 0.05, (4, 4, components))
    table = np.zeros((components + 2, shadowing_nodes, 4), np.float32)
    table[0, :, 0] = np.linspace(0.0, 1.5, shadowing_nodes)
    table[1, :, 0] = np.linspace(1.0, 0.3, shadowing_nodes)
    table[2:, :, 0] = rng.normal(0.0, 0.1, (components, shadowing_nodes))
    return FittedLobes(lobes, components, layers, table)


def test_a_fitted_table_is_read_from_disk_bit_exact_and_a_changed_fit_is_a_miss(context, monkeypatch, tmp_path):
    from sg_prt_addon.harmonics import fitted_table
    from sg_prt_addon.techniques.sh import spherical_harmonics

    project = Counted(fitted_table.project_texels)
    monkeypatch.setattr(fitted_table, "project_texels", project)
    monkeypatch.setattr(fitted_table, "_cache", collections.OrderedDict())
    built = spherical_harmonics.fitted_table_for(_fit(), 3, context.cached_arrays)
    assert project.calls == 1 and len(list(tmp_path.glob("sh_fitted_table-*.npz"))) == 1

    monkeypatch.setattr(fitted_table, "_cache", collections.OrderedDict())          # a new process
    read = spherical_harmonics.fitted_table_for(_fit(), 3, context.cached_arrays)
    assert project.calls == 1 and read is not built
    np.testing.assert_array_equal(read.coefficients, built.coefficients)
    assert read.coefficients.dtype == built.coefficients.dtype == np.float32
    assert (read.order, read.shape, read.seconds) == (built.order, built.shape, built.seconds)

    spherical_harmonics.fitted_table_for(_fit(sharpest=80.0), 3, context.cached_arrays)    # another fit
    spherical_harmonics.fitted_table_for(_fit(), 4, context.cached_arrays)                 # another order
    assert project.calls == 3 and len(list(tmp_path.glob("sh_fitted_table-*.npz"))) == 3


def test_a_parametric_table_is_read_from_disk_bit_exact_and_other_parameters_are_misses(context, monkeypatch,
                                                                                         tmp_path):
    from sg_prt_addon.harmonics import brdf_table

    project = Counted(brdf_table.project_product)
    monkeypatch.setattr(brdf_table, "project_product", project)
    monkeypatch.setattr(brdf_table, "_cache", collections.OrderedDict())
    options = dict(order=3, resolution=8, parameter_count=3, samples=64, store=context.cached_arrays)
    built = brdf_table.table_for("GGX", roughness=0.3, **options)
    assert project.calls == 3 and len(list(tmp_path.glob("sh_brdf_table-*.npz"))) == 1     # a call a node

    monkeypatch.setattr(brdf_table, "_cache", collections.OrderedDict())
    read = brdf_table.table_for("GGX", roughness=0.3, **options)
    assert project.calls == 3 and read is not built
    np.testing.assert_array_equal(read.coefficients, built.coefficients)
    np.testing.assert_array_equal(read.parameter_nodes, built.parameter_nodes)
    assert read.coefficients.dtype == np.float32 and read.fixed == built.fixed

    anisotropic = dict(options, order=3, resolution=4)
    brdf_table.table_for("ASHIKHMIN_SHIRLEY", nu=20.0, nv=200.0, **anisotropic)
    brdf_table.table_for("ASHIKHMIN_SHIRLEY", nu=20.0, nv=100.0, **anisotropic)          # a fixed parameter
    assert project.calls == 5 and len(list(tmp_path.glob("sh_brdf_table-*.npz"))) == 3
