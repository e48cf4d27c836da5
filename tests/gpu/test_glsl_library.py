"""shaders/lib as a library: each file compiles with only the dependencies that
shaders/lib/README.md lists, and all of them together in the README's order
(no name collisions between files)."""
import os
import re

import pytest

from sg_prt_addon.techniques import material_textures, shader_sources
from sg_prt_addon.techniques.sg import sg_lobes
from sg_prt_addon.visibility.per_vertex import MAX_ROWS
from validation import glsl_harness

QUADRATURE_DEFINES = "".join(f"#define {name} {value}\n" for name, value in sg_lobes.quadrature_defines().items())
LIB_DIR = os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "shaders", "lib")
# file -> the files it needs before it (README.md's table)
DEPENDENCIES = {
    "sg.glsl": [],
    "hemisphere.glsl": ["sg.glsl"],
    "clamped_cosine.glsl": ["sg.glsl", "hemisphere.glsl"],
    "clamped_cosine_table.glsl": ["sg.glsl"],
    "brdf.glsl": ["sg.glsl"],
    "warp.glsl": ["sg.glsl"],
    "lights.glsl": ["sg.glsl"],
    "env_prefilter.glsl": ["sg.glsl"],
    "hemisphere_map.glsl": ["sg.glsl"],
    "ssdf.glsl": ["sg.glsl", "hemisphere.glsl", "hemisphere_map.glsl", f"#define SSDF_MAX_LAYERS {MAX_ROWS}\n"],
    "ssdf_quadrature.glsl": ["sg.glsl", "hemisphere.glsl", QUADRATURE_DEFINES],
    "shadow_maps.glsl": [shader_sources.shadow_map_constants()],
    "node_functions.glsl": [material_textures.noise_offsets_source()],
    "voronoi.glsl": [],
}
ORDER = ["sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl", "clamped_cosine_table.glsl", "brdf.glsl", "warp.glsl",
         "lights.glsl", "env_prefilter.glsl", "hemisphere_map.glsl", "ssdf.glsl", "ssdf_quadrature.glsl",
         "shadow_maps.glsl", "node_functions.glsl", "voronoi.glsl"]


def test_every_file_is_listed():
    assert sorted(f for f in os.listdir(LIB_DIR) if f.endswith(".glsl")) == sorted(DEPENDENCIES)
    with open(os.path.join(LIB_DIR, "README.md"), encoding="utf-8") as handle:
        readme = handle.read()
    listed = re.findall(r"\|\s*\d+\s*\|\s*`([a-z_]+\.glsl)`", readme)
    assert listed == ORDER


@pytest.mark.parametrize("file_name", sorted(DEPENDENCIES))
def test_file_compiles_with_its_dependencies(glsl, file_name):
    out = glsl(DEPENDENCIES[file_name] + [file_name], "vec4(a.x)", {"a": [1.0, 2.0]}, 1)
    assert list(out) == [1.0, 2.0]


def test_all_files_together(glsl):
    call = ("vec4(sg_sphere_integral(a.x, 1.0), fh(0.0, a.x), clamped_cosine_from_cosine(1.0, a.x),"
            " ggx_ndf_lobe(0.5).x)")
    out = glsl(ORDER[:-5] + [f"#define SSDF_MAX_LAYERS {MAX_ROWS}\n", "ssdf.glsl", QUADRATURE_DEFINES,
                             "ssdf_quadrature.glsl", shader_sources.shadow_map_constants(), "shadow_maps.glsl",
                             material_textures.noise_offsets_source(), "node_functions.glsl", "voronoi.glsl"],
               call, {"a": [0.0, 1.0]}, 4)
    assert out.shape == (2, 4)
    # lambda = 0: 4 pi, half of it, pi
    assert abs(out[0, 0] - 4 * 3.14159265) < 1e-5 and abs(out[0, 1] - 2 * 3.14159265) < 1e-5
    assert abs(out[0, 2] - 3.14159265) < 1e-5


def test_library_has_no_uniforms_or_samplers_outside_parameters():
    """Pure functions: no global uniform/sampler/in/out declarations."""
    for file_name in ORDER:
        source = "".join(glsl_harness.load_library(file_name))
        code = re.sub(r"/\*.*?\*/", "", source, flags=re.S)
        # global declarations start at column 0; `out` parameters of functions are indented
        assert not re.search(r"^(uniform|in|out|buffer|layout)\b", code, flags=re.M), file_name
