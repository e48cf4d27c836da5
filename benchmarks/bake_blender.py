"""Visibility bake of the example Suzanne scene through the operator (bpy.ops.sgprt.bake_visibility).

examples/build_scenes.build_suzanne_courtyard: subdivided Suzanne (about 8k
vertices, 15.7k triangles) over a 64 x 64 floor grid (4k vertices); both are
baked, the whole scene occludes.  Prints the scene size, the operator's wall
time (export + rays + SSDF + PCA + storing the attributes), the terms and RMS
error per mesh, and the save + reopen time of the baked .blend and its size.

    .venv/bin/python -m benchmarks.bake_blender                 # resolution 32, error target 0.02 rad
    .venv/bin/python -m benchmarks.bake_blender 16              # another resolution
"""
import os
import sys
import tempfile
import time

import bpy
import numpy as np

import sg_prt_addon
from examples.build_scenes import build_suzanne_courtyard
from sg_prt_addon.blender import visibility_bake


def main(resolution=32):
    if not hasattr(bpy.types.Scene, "sgprt_bake"):
        sg_prt_addon.register()
    scene = build_suzanne_courtyard(resolution=64)
    scene.sgprt_bake.resolution = resolution
    meshes = [obj for obj in scene.objects if obj.type == "MESH"]
    vertices = sum(len(obj.data.vertices) for obj in meshes)
    triangles = 0
    for obj in meshes:
        obj.data.calc_loop_triangles()
        triangles += len(obj.data.loop_triangles)
    print(f"scene: {', '.join(f'{o.name} {len(o.data.vertices)} vertices' for o in meshes)}; "
          f"{triangles} triangles; resolution {resolution}, refinement {scene.sgprt_bake.refinement}, "
          f"error target {scene.sgprt_bake.error_target:.3f} rad, max terms {scene.sgprt_bake.max_terms}")
    started = time.perf_counter()
    assert bpy.ops.sgprt.bake_visibility(target="ALL") == {"FINISHED"}
    seconds = time.perf_counter() - started
    print(f"operator: {seconds:.1f} s for {vertices} vertices ({vertices / seconds:.0f} vertices/s)")
    for obj in meshes:
        stored = visibility_bake.load_visibility_bake(obj.data)
        print(f"  {obj.name}: {stored.terms} terms, RMS error {np.degrees(stored.rms_error):.2f} deg, "
              f"bake {stored.seconds:.1f} s")
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "baked.blend")
        started = time.perf_counter()
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.open_mainfile(filepath=path)
        for obj in bpy.data.objects:
            if obj.type == "MESH":
                assert visibility_bake.load_visibility_bake(obj.data).usable
        print(f"save + reopen + load: {time.perf_counter() - started:.2f} s, "
              f"file {os.path.getsize(path) / 1e6:.1f} MB (images packed)")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
