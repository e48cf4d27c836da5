"""What the scene-by-scene setting benchmarks share (benchmarks/specular_aa.py, shadow_maps_speed.py,
edge_samples.py): building a scene of the examples or of the truth suite at a size, their command line,
measuring the scenes asked for, and printing and writing their sections of docs/."""
import argparse


def build(name, builder, size):
    """Scene `name` of `builder` ("examples" or "truth_suite") at size x size pixels, made current."""
    import bpy

    if builder == "examples":
        from examples import build_scenes
        scene = build_scenes.SCENES[name](size)
    else:
        from benchmarks import truth_suite
        truth_suite.SCENES[name].build(size)
        scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    return scene


def parse(argv, description, scenes, rounds):
    """--scenes (names of `scenes`, (name, builder, size) tuples), --redraws, --rounds, --update-doc."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--scenes", nargs="*", default=[name for name, _, _ in scenes])
    parser.add_argument("--redraws", type=int, default=5)
    parser.add_argument("--rounds", type=int, default=rounds)
    parser.add_argument("--update-doc", action="store_true")
    return parser.parse_args(argv)


def measure(scenes, args, measure_scene):
    """measure_scene(name, builder, size, redraws, rounds) of each of `scenes` that args.scenes names, printed as
    it comes; the add-on registered first."""
    from sg_prt_addon import render as addon

    addon.ensure_registered()
    results = []
    for name, builder, size in scenes:
        if name in args.scenes:
            results.append(measure_scene(name, builder, size, args.redraws, args.rounds))
            print(results[-1], flush=True)
    return results


def command(module, args):
    """The command line that reproduces a run of benchmarks.<module>."""
    return f".venv/bin/python -m benchmarks.{module}" + (" --update-doc" if args.update_doc else "")


def main(module, description, scenes, rounds, measure_scene, sections, argv=None):
    """A scene benchmark's command line: measure the scenes asked for, print the sections that
    sections(results, command, args) gives ([(markdown_sections doc path, title, text)]), and write them with
    --update-doc; returns the results."""
    args = parse(argv, description, scenes, rounds)
    results = measure(scenes, args, measure_scene)
    written = sections(results, command(module, args), args)
    for _doc, _title, text in written:
        print(text)
    if args.update_doc:
        from benchmarks import markdown_sections
        for doc, title, text in written:
            markdown_sections.update_file(doc, title, text)
    return results
