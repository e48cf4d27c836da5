"""Benchmarks write their own sections of docs/*.md, so the figures there are regenerated, never typed."""
from pathlib import Path

PERFORMANCE_DOC = Path(__file__).resolve().parents[1] / "docs" / "PERFORMANCE.md"
ACCURACY_DOC = Path(__file__).resolve().parents[1] / "docs" / "ACCURACY.md"
BAKE_DOC = Path(__file__).resolve().parents[1] / "docs" / "BAKE_PERFORMANCE.md"


def replace_section(text, title, section):
    """`text` (markdown) with the level-2 section headed `title` replaced by `section` (up to the next
    level-2 heading), or `section` appended when there is none."""
    lines = text.splitlines(keepends=True)
    start = next((i for i, line in enumerate(lines) if line.rstrip() == title), None)
    if start is None:
        return text.rstrip("\n") + "\n\n" + section
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    tail = "".join(lines[end:])
    return "".join(lines[:start]) + section + ("\n" + tail if tail else "")


def update_file(path, title, section):
    with open(path, encoding="utf-8") as handle:
        text = handle.read()
    with open(path, "w", encoding="utf-8") as handle:
        handle.write(replace_section(text, title, section))
