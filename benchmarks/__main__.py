"""The one runner of the benchmarks and studies: what each measures, and running one by name.

    .venv/bin/python -m benchmarks                    # every benchmark, with the first line of its docstring
    .venv/bin/python -m benchmarks NAME [ARGS ...]    # run benchmarks/NAME.py (or benchmarks/NAME/) with ARGS

Most need pip bpy (the .venv); they print figures and ratios against a baseline measured in the same run, and
the ones with --update-doc rewrite their section of docs/PERFORMANCE.md or docs/ACCURACY.md.
"""
import ast
import runpy
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
# Modules other benchmarks import, not run on their own
LIBRARIES = {"__init__", "__main__", "markdown_sections", "scene_benchmark"}


def benchmarks():
    """{name: first line of its docstring} of every runnable benchmark, by name."""
    found = {}
    for path in sorted(HERE.iterdir()):
        source = path / "__main__.py" if path.is_dir() else path
        name = path.stem if path.suffix == ".py" else path.name
        if name in LIBRARIES or not source.is_file() or source.suffix != ".py":
            continue
        docstring = ast.get_docstring(ast.parse(source.read_text(encoding="utf-8"))) or ""
        found[name] = (docstring.strip().splitlines() or [""])[0]
    return found


def main(argv):
    listed = benchmarks()
    if not argv or argv[0] in ("-h", "--help", "list"):
        width = max(map(len, listed))
        print(__doc__.strip().splitlines()[0] + "\n")
        for name, line in listed.items():
            print(f"  {name:<{width}}  {line}")
        return 0
    name = argv[0].replace("-", "_")
    if name not in listed:
        print(f"no benchmark {argv[0]!r}; `python -m benchmarks` lists them", file=sys.stderr)
        return 2
    sys.argv = [f"benchmarks.{name}"] + argv[1:]
    runpy.run_module(f"benchmarks.{name}", run_name="__main__", alter_sys=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
