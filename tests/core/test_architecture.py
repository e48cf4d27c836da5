"""The package's shape: no import cycles (imports inside functions count: one placed there cannot hide a
cycle), the layers import only downwards, the maths never imports bpy or gpu, and nothing shipped
imports the validation code."""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = "sg_prt_addon"
# Lowest first: a package may import those before it, never those after (the maths packages among
# themselves: no cycle, checked below)
MATHS = ("spherical", "reflectance", "lighting", "harmonics", "measured", "visibility", "biscale")
LAYERS = MATHS + ("techniques", "blender", "engine", "registration", "render")
NO_BLENDER = MATHS + ("techniques",)        # importable without Blender: no bpy; gpu only inside functions


def _modules():
    """dotted name -> (path, is a package __init__) of every module of the package."""
    modules = {}
    for path in (ROOT / PACKAGE).rglob("*.py"):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        modules[".".join(parts)] = (path, path.name == "__init__.py")
    return modules


def _imports(name, path, is_package, modules):
    """[(imported module or external name, inside a function)] of one module."""
    package = name if is_package else name.rsplit(".", 1)[0]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    nested = {id(node) for function in ast.walk(tree) if isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef))
              for node in ast.walk(function) if node is not function}
    found = []
    for node in ast.walk(tree):
        inside = id(node) in nested
        if isinstance(node, ast.Import):
            found += [(alias.name, inside) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = ".".join(base[:len(base) - node.level + 1] + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            for alias in node.names:
                submodule = f"{base}.{alias.name}"
                found.append((submodule if submodule in modules else base, inside))
    return found


@pytest.fixture(scope="module")
def graph():
    modules = _modules()
    return {name: _imports(name, path, is_package, modules) for name, (path, is_package) in modules.items()}


def _layer(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def test_no_import_cycles(graph):
    """Tarjan over the module graph; importing a submodule runs its packages' __init__, which is not an
    edge of its own (an __init__ importing its submodules is no cycle)."""
    edges = {name: sorted({target for target, _ in imports if target in graph and target != name
                           and not name.startswith(target + ".")}) for name, imports in graph.items()}
    index, low, stack, on_stack, cycles = {}, {}, [], set(), []

    def connect(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in edges[node]:
            if target not in index:
                connect(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for node in edges:
        if node not in index:
            connect(node)
    assert not cycles, f"import cycles: {cycles}"


def test_layers_import_downwards(graph):
    bad = []
    for name, imports in graph.items():
        layer = _layer(name)
        if layer not in LAYERS:
            continue
        for target, _ in imports:
            target_layer = _layer(target) if target.startswith(PACKAGE + ".") else None
            if target_layer in LAYERS and target_layer != layer:
                if LAYERS.index(target_layer) > LAYERS.index(layer) and not (layer in MATHS and target_layer in MATHS):
                    bad.append(f"{name} imports {target}")
    assert not bad, "\n".join(bad)


def test_maths_packages_form_no_cycle(graph):
    """The maths packages import each other one way only."""
    depends = {layer: set() for layer in MATHS}
    for name, imports in graph.items():
        if _layer(name) in MATHS:
            depends[_layer(name)] |= {_layer(target) for target, _ in imports
                                      if target.startswith(PACKAGE + ".") and _layer(target) in MATHS} - {_layer(name)}
    both_ways = sorted(f"{a} <-> {b}" for a in MATHS for b in depends[a] if a < b and a in depends[b])
    assert not both_ways, both_ways


def test_maths_and_techniques_need_no_blender(graph):
    bad = []
    for name, imports in graph.items():
        if _layer(name) not in NO_BLENDER:
            continue
        for target, inside in imports:
            top = target.split(".")[0]
            if top in ("bpy", "mathutils", "bmesh") or (top in ("gpu", "gpu_extras") and not inside):
                bad.append(f"{name} imports {target}" + (" inside a function" if inside else ""))
    assert not bad, "\n".join(bad)


def test_nothing_shipped_imports_validation(graph):
    bad = [f"{name} imports {target}" for name, imports in graph.items() for target, _ in imports
           if target.split(".")[0] in ("validation", "tests", "benchmarks", "examples", "tools")]
    assert not bad, "\n".join(bad)
