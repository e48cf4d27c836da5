"""benchmarks/frame_profile.py's edits of the SG surface shader: each still finds its text in the shader files (a
rewritten shader fails here, not in the middle of a profile run), and the edit helper refuses a missing text."""
import subprocess
import sys
from pathlib import Path

import pytest

from benchmarks import frame_profile

ROOT = Path(__file__).resolve().parents[2]


def _shader_text():
    return "\n".join(path.read_text(encoding="utf-8") for path in sorted((ROOT / "shaders").rglob("*.glsl")))


def test_every_edit_finds_its_text_once_in_the_shaders():
    text = _shader_text()
    for part, _, edits in frame_profile.PARTS:
        for old, new in edits:
            assert text.count(old) == 1, f"{part}: {old.strip().splitlines()[0]!r}"
            assert new != old, part


def test_edited_replaces_and_refuses_a_missing_text():
    assert frame_profile.edited("a b c", [("b", "x"), ("c", "y")]) == "a x y"
    with pytest.raises(frame_profile.MissingEdit, match="absent"):
        frame_profile.edited("a b c", [("b", "x"), ("absent", "y")])


def test_importing_the_benchmarks_does_not_import_bpy():
    code = ("import sys; import benchmarks.frame_profile, benchmarks.frame_against_commit; "
            "assert 'bpy' not in sys.modules, 'bpy imported'")
    subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True)


def test_parts_measured_with_the_grid_off_are_taken_against_the_grid_off_frame():
    bases = {part: frame_profile.base_of(edits) for part, _, edits in frame_profile.PARTS}
    assert bases[frame_profile.GRID_PART] is None
    assert bases["SSDF decodes (grid off)"] == frame_profile.GRID_PART
    assert bases["all shading (the frame's floor)"] is None
    assert all((base is not None) == part.endswith("(grid off)") for part, base in bases.items())
