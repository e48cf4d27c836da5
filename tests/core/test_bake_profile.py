"""benchmarks/bake_profile.py times the bake a stage at a time by calling its stages itself: the rows it bakes
must be the pipeline's, bit for bit, or its figures are of some other bake."""
import numpy as np

from benchmarks import bake_profile
from benchmarks.bake_speed import sphere_over_floor
from sg_prt_addon.visibility import BakeOptions
from sg_prt_addon.visibility.pipeline import bake_ssdf
from sg_prt_addon.visibility.raytrace import RayTracer


def test_the_profiled_stages_bake_the_pipelines_rows():
    vertices, triangles, normals = sphere_over_floor(300)
    options = BakeOptions(batch_vertices=64)
    tracer = RayTracer(vertices, triangles, threads=1)
    try:
        seconds, rows = bake_profile.stage_seconds(vertices, normals, tracer, options)
        expected = bake_ssdf(vertices, normals, tracer, BakeOptions(batch_vertices=64, threads=1))
    finally:
        tracer.close()
    np.testing.assert_array_equal(rows, expected)
    assert set(seconds) == {"rays (Embree)", "refinement bookkeeping", "SSDF distances", "PCA"}
    assert all(value >= 0 for value in seconds.values()) and seconds["rays (Embree)"] > 0


def test_section_states_the_shares_and_the_second_cores_gain():
    figures = {"vertices": 1000, "rays_per_vertex": 2600.0, "raw_rate": 10e6, "embree_rate": 8e6, "load": 1.0,
               "stages": {"rays (Embree)": 0.4, "refinement bookkeeping": 0.3, "SSDF distances": 0.3, "PCA": 0.0},
               "threads": {1: 1.0, 2: 0.8}}
    text = bake_profile.section(figures, 1000)
    assert "| rays (Embree) | 0.400 | 40% |" in text
    assert "| all | 1.000 | 100% |" in text
    assert "1.25x faster" in text and "40% of its Embree rate" in text
