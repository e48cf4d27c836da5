"""The viewport's latency after an edit of a node material: from the edit to the next frame drawn (the
material exported again as view_update does, the variant's shader found or compiled, uploaded, drawn, one
pixel read back), median of --edits edits, each to a value not drawn before (so a shader compiled for one
is never reused by another).  The scene: a sphere whose Principled BSDF's Base Color mixes a Noise Texture
with a colour by a Value node (a computed slot), its Roughness a plain number, under a point light.

- value in a computed slot: the Value node's value;
- plain value: the Principled BSDF's Roughness;
- graph change: the Mix node's blend (a new graph: its shader compiles);
- nothing changed: a redraw without an edit (the baseline of the same run).

    .venv/bin/python -m benchmarks.node_edit_latency [--size 512] [--edits 5]
"""
import argparse
import os
import statistics
import sys

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

BLENDS = ("MULTIPLY", "SCREEN", "OVERLAY", "ADD", "SUBTRACT", "DIFFERENCE", "DARKEN", "LIGHTEN", "DODGE", "BURN",
          "SOFT_LIGHT", "LINEAR_LIGHT", "EXCLUSION", "DIVIDE", "HUE", "SATURATION", "VALUE", "COLOR")


def build(size):
    """The scene (see the module's docstring); returns (material, its Value node, Principled BSDF, Mix node)."""
    import bpy

    from benchmarks import truth_suite

    scene = truth_suite._start(size)
    scene.sgprt.render_samples = 1
    truth_suite._black_world(scene)
    truth_suite._light(scene, "POINT", **truth_suite.POINT_LIGHT)
    material = bpy.data.materials.new("edited")
    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    principled = next(node for node in tree.nodes if node.type == "BSDF_PRINCIPLED")
    noise, mix, value = (tree.nodes.new(kind) for kind in ("ShaderNodeTexNoise", "ShaderNodeMix", "ShaderNodeValue"))
    mix.data_type = "RGBA"
    value.outputs[0].default_value = 0.3
    tree.links.new(value.outputs[0], mix.inputs["Factor"])
    tree.links.new(noise.outputs["Color"], mix.inputs["A"])
    mix.inputs["B"].default_value = (0.8, 0.2, 0.1, 1.0)
    tree.links.new(mix.outputs["Result"], principled.inputs["Base Color"])
    truth_suite._sphere(material)
    truth_suite._sphere_camera(scene)
    return material, value, principled, mix


def measure(size, edits):
    """{kind: median seconds} of the edits (see the module's docstring) in the viewport at size x size."""
    from benchmarks import engine_vs_eevee
    from sg_prt_addon.blender import export
    from sg_prt_addon.engine import render_engine
    from validation import viewport_timing

    material, value, principled, mix = build(size)
    counter = iter(range(1, 10 ** 6))
    edits_of = {
        "value in a computed slot": lambda: setattr(value.outputs[0], "default_value", 0.3 + 0.01 * next(counter)),
        "plain value": lambda: setattr(principled.inputs["Roughness"], "default_value", 0.2 + 0.01 * next(counter)),
        "graph change": lambda: setattr(mix, "blend_type", BLENDS[next(counter) % len(BLENDS)]),
    }

    def timed(depsgraph, state, renderer, camera):
        width, height = renderer.size
        _, unchanged, _, _ = viewport_timing.time_viewport_redraws(state, camera, width, height, edits)
        figures = {"nothing changed": statistics.median(unchanged)}
        for kind, edit in edits_of.items():
            def edited(edited_state, edit=edit):
                edit()
                edited_state.materials[material.name] = export.export_material(material)    # view_update's
                edited_state.dirty.materials.add(material.name)

            _, seconds, _, _ = viewport_timing.time_viewport_redraws(state, camera, width, height, edits,
                                                                     edit=edited)
            figures[kind] = statistics.median(seconds)
        return figures

    render_engine.debug["after_frame"] = timed
    try:
        engine_vs_eevee.render_seconds()
    finally:
        render_engine.debug["after_frame"] = None
    return render_engine.last_render["after_frame"]


def main(argv=None):
    import bpy  # noqa: F401  (pip bpy: the engine registers into it)

    import sg_prt_addon

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--edits", type=int, default=5)
    args = parser.parse_args(argv)
    sg_prt_addon.register()
    figures = measure(args.size, args.edits)
    print(f"viewport {args.size} x {args.size}, median of {args.edits} edits (seconds to the next frame):")
    for kind, seconds in figures.items():
        print(f"  {kind:26s} {seconds:.3f} s  ({seconds / figures['nothing changed']:.1f}x the unchanged redraw)")


if __name__ == "__main__":
    main()
