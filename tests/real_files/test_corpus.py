"""Every corpus file (Debian's assimp-testmodels: .blend files of Blender 2.48-2.79 and glTF 2 files, made by
others) opened or imported, rendered unbaked, baked with Bake Visibility at its defaults and rendered again:
no render fails, no pixel is NaN, and every warning names what it is about (a datablock or node of the file).
Files Blender itself cannot load are skipped with its reason; files of more than BAKE_VERTEX_LIMIT rendered
vertices are rendered but not baked here (`python -m validation.real_files` bakes them)."""
import pytest

from validation import real_files

BAKE_VERTEX_LIMIT = 60000
# the bake operator's own refusal, for files whose meshes have no faces (glTF point and line primitives)
NO_FACES = "none of the objects can be baked"


def test_a_real_file_renders_unbaked_and_baked(addon, corpus_file):
    models, name = corpus_file
    run = real_files.run_file(models, name, bake_vertex_limit=BAKE_VERTEX_LIMIT)
    if run.refused is not None:
        pytest.skip(f"Blender refuses it: {run.refused}")
    assert run.unbaked_error is None, run.unbaked_error
    assert run.baked_error is None, run.baked_error
    assert run.nan_pixels == 0
    if run.bake_outcome == "ERROR":
        assert any(NO_FACES in report or "no visible mesh object" in report for report in run.bake_reports), run
    else:
        assert run.bake_outcome == "FINISHED" or run.bake_outcome.startswith("SKIPPED"), run
    if run.bake_outcome == "FINISHED":
        assert run.baked_objects > 0, run
    names = real_files.datablock_names()
    for warning in run.unbaked_warnings + run.baked_warnings:
        quoted = real_files.quoted_names(warning)
        assert quoted and any(item in names for item in quoted), warning
