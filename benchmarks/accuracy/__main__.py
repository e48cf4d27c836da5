"""Regenerate docs/ACCURACY.md from every benchmarks/accuracy/<topic>.py.

Each topic module defines measure() -> list of dicts with keys
name, reference, metric, max_error, mean_error and optionally paper, note.

    .venv/bin/python -m benchmarks.accuracy            # all topics
    .venv/bin/python -m benchmarks.accuracy warp fh    # some topics, others kept as before
"""
import importlib
import pkgutil
import platform
import sys
import time
from pathlib import Path

import benchmarks.accuracy as package

OUTPUT = Path(__file__).resolve().parents[2] / "docs" / "ACCURACY.md"
COMMAND = ".venv/bin/python -m benchmarks.accuracy"


def _format(value):
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    return f"{value:.3g}"


def _table(topic, rows):
    lines = [f"## {topic}", "",
             "| approximation | reference | metric | max error | mean error | paper's version | note |",
             "|---|---|---|---|---|---|---|"]
    for row in rows:
        cells = [row["name"], row["reference"], row["metric"], _format(row["max_error"]),
                 _format(row["mean_error"]), _format(row.get("paper")), row.get("note", "")]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _existing_sections():
    sections = {}
    if OUTPUT.exists():
        current = None
        for line in OUTPUT.read_text().splitlines(keepends=True):
            if line.startswith("## "):
                current = line[3:].strip()
                sections[current] = ""
            if current:
                sections[current] += line
    return sections


def main(selected):
    topics = sorted(m.name for m in pkgutil.iter_modules(package.__path__) if not m.name.startswith("_"))
    sections = _existing_sections()
    for topic in topics:
        if selected and topic not in selected:
            continue
        start = time.perf_counter()
        rows = importlib.import_module(f"benchmarks.accuracy.{topic}").measure()
        sections[topic] = _table(topic, rows) + "\n"
        print(f"{topic}: {len(rows)} rows in {time.perf_counter() - start:.1f} s", flush=True)
    header = ("# Accuracy\n\nEvery approximation's measured error against an exact or high-precision\n"
              f"reference. Regenerate with `{COMMAND}` (machine: {platform.machine()},\n"
              f"Python {platform.python_version()}).\n\n")
    # sections of other generators (benchmarks/truth_suite.py's) are kept, after the topics
    others = [text for name, text in sections.items() if name not in topics]
    OUTPUT.write_text(header + "".join(sections[t] for t in topics if t in sections) + "".join(others))


if __name__ == "__main__":
    main(set(sys.argv[1:]))
