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
    """A module's layer: its top package, except a technique's Blender side (techniques/<package>/blender/),
    which is Blender glue."""
    parts = module.split(".")
    if len(parts) > 3 and parts[1] == "techniques" and parts[3] == "blender":
        return "blender"
    return parts[1] if len(parts) > 1 else None


def _package(module):
    """The package a module belongs to for the package graph: the maths packages, each technique's package
    and its Blender side, and the other layers."""
    parts = module.split(".")
    if len(parts) > 2 and parts[1] == "techniques" and (ROOT / PACKAGE / "techniques" / parts[2]).is_dir():
        return ".".join(parts[1:4] if len(parts) > 3 and parts[3] == "blender" else parts[1:3])
    if parts[1:] == ["techniques"]:
        return "techniques registry"        # its __init__: it imports the techniques, they import what they share
    return parts[1] if len(parts) > 1 else None


def test_no_import_cycles(graph):
    """Importing a submodule runs its packages' __init__, which is not an edge of its own (an __init__
    importing its submodules is no cycle)."""
    edges = {name: {target for target, _ in imports if target in graph and target != name
                    and not name.startswith(target + ".")} for name, imports in graph.items()}
    cycles = _cycles(edges)
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


def _cycles(edges):
    """The strongly connected components of more than one node of a graph {node: set of nodes} (Tarjan)."""
    index, low, stack, on_stack, cycles = {}, {}, [], set(), []

    def connect(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in sorted(edges.get(node, ())):
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

    for node in sorted(edges):
        if node not in index:
            connect(node)
    return cycles


def test_packages_form_no_cycle(graph):
    """The packages (the maths ones, each technique's and its Blender side, the glue and the engine) import
    each other without a cycle of any length, as the modules do."""
    edges = {}
    for name, imports in graph.items():
        source = _package(name)
        if source is None:
            continue
        edges.setdefault(source, set())
        edges[source] |= {_package(target) for target, _ in imports
                          if target.startswith(PACKAGE + ".") and _package(target) not in (None, source)}
    assert "techniques.sh" in edges and "techniques.sg.blender" in edges
    cycles = _cycles(edges)
    assert not cycles, f"package cycles: {cycles}"


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


def test_the_renderer_reads_arrays_not_blender_data(graph):
    """Data flows one way: the scene state hands the GPU upload arrays (its texture_pixels included); the
    renderer never reads Blender's data itself."""
    bad = [target for target, _ in graph[f"{PACKAGE}.engine.renderer"] if target.split(".")[0] in ("bpy", "mathutils")]
    assert not bad, bad
