"""What each skip saves: frame and update times with the skipped work forced back in, same run.

Scene (build_scene): Suzanne subdivided twice + a floor (15.7k triangles), GGX roughness 0.3 and
0.6, one point light, Blender's courtyard.exr, at 512x512.  Each frame row renders the
scene set up so the variant skips a feature, then with the feature forced back in, and compares the
steady-state frame (median of render_engine.debug["timed_redraws"] redraws: draw + read back the 3
passes); the ratio is the median over rounds of skipped / with, each pair rendered back to back
(the order alternating each round), its range printed beside it:

- specular path: both materials with a zero specular colour; forced: has_specular=True
- diffuse path: both materials with a zero diffuse colour; forced: has_diffuse=True
- light loop: the light hidden; forced: has_lights=True (a loop over no lights)
- prefiltered environment fetch: a world colour; with it: an equirect of that one colour (the same
  image, through the prefiltered map and the SG mixture)
- SSDF decode: no bake; with it: an all-visible bake (19 PCA terms, 5 vec4 a vertex, every ratio 1)

Forcing monkeypatches the techniques' variant_key (a benchmark may; the tests do not): the key of
each draw goes through dataclasses.replace(key, **fields).

Update rows, timed inside one render (the GPU context): a viewport-style update where nothing
changed (SceneState.update of a depsgraph with no updates + Renderer.upload: the scene uniform
block only) vs a full sync + upload into
a new Renderer (the prefilter cache warm); and an environment change (export_world + environment_data
+ upload) switching between courtyard.exr and forest.exr with the prefilter cache hit vs cleared.

    .venv/bin/python -m benchmarks.skip_speed [--size 512] [--redraws 5] [--rounds 2]
"""
import argparse
import contextlib
import dataclasses
import math
import os
import platform
import statistics
import sys
import time
import types

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

WORLD_COLOUR = (0.35, 0.38, 0.42)
BAKE_TERMS = 19


def build_scene(size):
    """(scene, triangles): Suzanne (subdivision 2, smooth) over a floor, materials "glossy" and "floor",
    the point light "key", courtyard.exr as the world."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "SG_PRT"
    scene.sgprt.render_samples = 1      # the frame, one sample (as EEVEE's); Render Samples: edge_samples.py
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    bpy.ops.mesh.primitive_monkey_add(size=2.0, location=(0.0, 0.0, 1.0))
    monkey = bpy.context.object
    subdivision = monkey.modifiers.new("subdivision", "SUBSURF")
    subdivision.levels = subdivision.render_levels = 2
    bpy.ops.object.shade_smooth()
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, -0.2))
    floor = bpy.context.object
    for obj, name, settings in ((monkey, "glossy", dict(roughness=0.3, diffuse_color=(0.5, 0.35, 0.25))),
                                (floor, "floor", dict(roughness=0.6))):
        material = bpy.data.materials.new(name)
        material.sgprt.model = "GGX"
        material.sgprt.specular_color = (0.25, 0.25, 0.25)
        for key, value in settings.items():
            setattr(material.sgprt, key, value)
        obj.data.materials.append(material)
    light = bpy.data.lights.new("key", "POINT")
    light.energy = 1000.0
    light.shadow_soft_size = 0.25
    light_object = bpy.data.objects.new("key", light)
    light_object.location = (3.0, -3.0, 4.0)
    scene.collection.objects.link(light_object)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    camera.location = (0.0, -6.5, 2.0)
    camera.rotation_euler = (math.radians(80.0), 0.0, 0.0)
    scene.camera = camera
    scene.world = world_with_image("courtyard", bpy.data.images.load(
        os.path.join(bpy.utils.system_resource("DATAFILES"), "studiolights", "world", "courtyard.exr")))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    triangles = sum(len(obj.evaluated_get(depsgraph).data.loop_triangles) for obj in (monkey, floor))
    return scene, triangles


@contextlib.contextmanager
def variants(force=None, seen=None):
    """Every technique's variant_key with `force` fields replaced; every key drawn is added to `seen`."""
    from sg_prt_addon import techniques

    def patched(original):
        def variant_key(*args, **kwargs):
            key = original(*args, **kwargs)
            if force:
                key = dataclasses.replace(key, **force)
            if seen is not None:
                seen.add(key)
            return key
        return variant_key

    registered = [techniques.get(name) for name in techniques.names()]
    for technique in registered:
        technique.variant_key = patched(technique.variant_key)
    try:
        yield
    finally:
        for technique in registered:
            del technique.variant_key          # the class's method again


def all_visible_provider():
    """visibility_provider whose bakes see everything: SSDF mean 2 pi (above every horizon), zero
    basis, random coefficients (decoded like a real bake's, every visibility ratio clamps to 1)."""
    import numpy as np

    rng = np.random.default_rng(1)
    resolution = 16

    def provider(object_eval):
        count = len(object_eval.data.vertices)       # the evaluated mesh: what the engine exports
        return types.SimpleNamespace(
            coefficients=rng.normal(size=(count, BAKE_TERMS)).astype(np.float32),
            mean=np.full((resolution, resolution), 2 * np.pi, np.float32),
            basis=np.zeros((BAKE_TERMS, resolution, resolution), np.float32), terms=BAKE_TERMS)
    return provider


def world_with_image(name, image):
    import bpy

    world = bpy.data.worlds.new(name)
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    nodes = world.node_tree.nodes
    environment = nodes.new("ShaderNodeTexEnvironment")
    environment.image = image
    background = next(node for node in nodes if node.type == "BACKGROUND")
    world.node_tree.links.new(environment.outputs["Color"], background.inputs["Color"])
    return world


def colour_world(name, colour):
    import bpy

    world = bpy.data.worlds.new(name)
    world.color = colour
    if world.node_tree is not None:
        for node in world.node_tree.nodes:
            if node.type == "BACKGROUND":
                node.inputs["Color"].default_value = tuple(colour) + (1.0,)
    return world


def constant_image(name, colour, width=64, height=32):
    import bpy
    import numpy as np

    image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
    pixels = np.ones((height, width, 4), np.float32)
    pixels[..., :3] = colour
    image.pixels.foreach_set(pixels.ravel())
    return image


class Cases:
    """The scene set up for each frame row: (setup, restore) around the skipped and the full render."""

    def __init__(self, scene):
        import bpy

        self.scene = scene
        self.materials = [bpy.data.materials["glossy"], bpy.data.materials["floor"]]
        self.light = bpy.data.objects["key"]
        self.courtyard = scene.world
        self.colour_world = colour_world("skip_colour", WORLD_COLOUR)
        self.constant_world = world_with_image("skip_constant", constant_image("skip_constant", WORLD_COLOUR))

    @contextlib.contextmanager
    def colours(self, attribute):
        saved = [tuple(getattr(material.sgprt, attribute)) for material in self.materials]
        for material in self.materials:
            setattr(material.sgprt, attribute, (0.0, 0.0, 0.0))
        try:
            yield
        finally:
            for material, value in zip(self.materials, saved):
                setattr(material.sgprt, attribute, value)

    @contextlib.contextmanager
    def hidden_light(self):
        self.light.hide_render = True
        try:
            yield
        finally:
            self.light.hide_render = False

    @contextlib.contextmanager
    def world(self, world):
        self.scene.world = world
        try:
            yield
        finally:
            self.scene.world = self.courtyard

    @contextlib.contextmanager
    def bake(self, provider):
        from sg_prt_addon.engine import scene_state

        scene_state.visibility_provider = provider
        try:
            yield
        finally:
            scene_state.visibility_provider = None

    def rows(self):
        """(name, what is skipped, skipped: (context, force), with the feature: (context, force))."""
        none = contextlib.nullcontext
        return [
            ("specular path", "diffuse-only materials (specular colour 0)",
             (lambda: self.colours("specular_color"), None),
             (lambda: self.colours("specular_color"), {"has_specular": True})),
            ("diffuse path", "specular-only materials (diffuse colour 0)",
             (lambda: self.colours("diffuse_color"), None),
             (lambda: self.colours("diffuse_color"), {"has_diffuse": True})),
            ("light loop", "no lights (courtyard only)",
             (self.hidden_light, None), (self.hidden_light, {"has_lights": True})),
            ("prefiltered environment fetch", "world colour vs an equirect of that colour",
             (lambda: self.world(self.colour_world), None), (lambda: self.world(self.constant_world), None)),
            ("SSDF decode", f"no bake vs an all-visible bake ({BAKE_TERMS} terms)",
             (none, None), (lambda: self.bake(all_visible_provider()), None)),
        ]


def render_frames(scene, redraws, force=None):
    """(steady-state frame times, variant keys drawn) of one final render."""
    import bpy

    from sg_prt_addon.engine import render_engine

    seen = set()
    render_engine.debug["timed_redraws"] = redraws
    try:
        with variants(force, seen), bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(scene=scene.name, write_still=False)
    finally:
        render_engine.debug["timed_redraws"] = 0
    result = render_engine.last_render
    if "error" in result:
        raise SystemExit(result["error"])
    return list(result["timings"]["frames"]), seen


def measure_updates(scene, repeats, environment_repeats):
    """Update rows, timed inside one render (render_engine.debug["after_frame"]): see the module docstring."""
    import bpy

    from sg_prt_addon.blender import export
    from sg_prt_addon.engine import render_engine, scene_state
    from sg_prt_addon.engine import renderer as renderer_module

    forest = world_with_image("skip_forest", bpy.data.images.load(
        os.path.join(bpy.utils.system_resource("DATAFILES"), "studiolights", "world", "forest.exr")))
    times = {}

    def after_frame(depsgraph, state, renderer, camera):
        import gpu

        times["gl_renderer"] = gpu.platform.renderer_get()
        # what view_update hands SceneState.update when nothing changed: a depsgraph with no updates
        # (the render depsgraph lists every datablock as updated once)
        quiet = types.SimpleNamespace(updates=[], scene=depsgraph.scene, objects=depsgraph.objects)
        full, unchanged = [], []
        for _ in range(repeats):
            start = time.perf_counter()
            fresh = scene_state.SceneState(environment_layer_size=state.environment_layer_size)
            fresh.sync(depsgraph)
            renderer_module.Renderer().upload(fresh, fresh.consume_dirty(), camera)
            full.append(time.perf_counter() - start)
            start = time.perf_counter()
            state.update(quiet)
            renderer.upload(state, state.consume_dirty(), camera)
            unchanged.append(time.perf_counter() - start)
        times["full sync + upload"], times["nothing changed"] = full, unchanged

        def switch(world):
            start = time.perf_counter()
            state.world = export.export_world(world)
            state.environment = scene_state.environment_data(state.world, state.environment_layer_size)
            renderer.upload(state, state.consume_dirty(), camera)
            return time.perf_counter() - start

        worlds = [forest, scene.world]
        misses, hits = [], []
        for index in range(environment_repeats):
            scene_state._environment_cache.clear()
            misses.append(switch(worlds[index % 2]))
        for world in worlds:            # both in the cache
            switch(world)
        for index in range(2 * environment_repeats):
            hits.append(switch(worlds[index % 2]))
        times["environment miss"], times["environment hit"] = misses, hits

    render_engine.debug["after_frame"] = after_frame
    try:
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(scene=scene.name, write_still=False)
    finally:
        render_engine.debug["after_frame"] = None
    if "error" in render_engine.last_render:
        raise SystemExit(render_engine.last_render["error"])
    return times


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--redraws", type=int, default=5)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--update-repeats", type=int, default=5)
    parser.add_argument("--environment-repeats", type=int, default=2)
    args = parser.parse_args(argv)

    import bpy

    import sg_prt_addon

    if not hasattr(bpy.types.Material, "sgprt"):
        sg_prt_addon.register()
    scene, triangles = build_scene(args.size)
    cases = Cases(scene)
    load_before = os.getloadavg()

    baseline, _ = render_frames(scene, args.redraws)            # first render: prefilter, compile
    baseline, baseline_keys = render_frames(scene, args.redraws)
    frames = {}
    for round_index in range(args.rounds):
        for name, _what, skipped, full in cases.rows():
            order = [("skipped", skipped), ("full", full)]
            if round_index % 2:
                order.reverse()
            entry = frames.setdefault(name, {"skipped": [], "full": [], "keys": {}, "ratios": []})
            medians = {}
            for label, (context, force) in order:
                with context():
                    times, keys = render_frames(scene, args.redraws, force)
                entry[label] += times
                entry["keys"][label] = keys
                medians[label] = statistics.median(times)
            entry["ratios"].append(medians["skipped"] / medians["full"])     # back to back: drift cancels
    more_baseline, _ = render_frames(scene, args.redraws)
    baseline += more_baseline
    updates = measure_updates(scene, args.update_repeats, args.environment_repeats)
    load_after = os.getloadavg()

    base = statistics.median(baseline)
    print(f"\n{args.size}x{args.size}, {triangles} triangles; {os.cpu_count()} cores ({platform.processor() or platform.machine()}), "
          f"{updates['gl_renderer']}, Blender {bpy.app.version_string}; load average {load_before[0]:.1f} -> "
          f"{load_after[0]:.1f}")
    print(f"baseline frame (GGX diffuse + specular, courtyard + point light, no bake): {base:.3f} s "
          f"[{baseline_keys and sorted(key.describe() for key in baseline_keys)[0]}]")
    header = (f"{'skip':32s} {'scene':46s} {'with (s)':>9s} {'skipped (s)':>12s} {'skipped/with':>13s} "
              f"{'(range)':>12s} {'x baseline':>11s}")
    print(header)
    rows = []
    for name, what, _skipped, _full in cases.rows():
        entry = frames[name]
        skipped, full = statistics.median(entry["skipped"]), statistics.median(entry["full"])
        ratios = entry["ratios"]
        ratio = statistics.median(ratios)
        rows.append((name, what, full, skipped, ratio))
        print(f"{name:32s} {what:46s} {full:9.3f} {skipped:12.3f} {ratio:13.2f} "
              f"{f'{min(ratios):.2f}-{max(ratios):.2f}':>12s} {skipped / base:11.2f}")
        for label in ("full", "skipped"):
            for key in sorted(entry["keys"][label], key=lambda k: k.describe()):
                print(f"{'':34s}{label}: {key.describe()}")
    for name, what, full_name, skipped_name in (
            ("update, nothing changed", "vs full sync + upload (prefilter cached)", "full sync + upload",
             "nothing changed"),
            ("environment change", "prefilter cache hit vs miss (+ export, upload)", "environment miss",
             "environment hit")):
        full, skipped = statistics.median(updates[full_name]), statistics.median(updates[skipped_name])
        rows.append((name, what, full, skipped, skipped / full))
        print(f"{name:32s} {what:46s} {full:9.4f} {skipped:12.4f} {skipped / full:13.4f}")
    return rows


if __name__ == "__main__":
    main()
