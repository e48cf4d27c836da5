"""Time of one SH rotation (kautz2002's appendix) in numpy and in GLSL (Mesa llvmpipe, the GLSL harness),
beside the block-diagonal matrix product it replaces, with the flop counts of harmonics.rotation.

GLSL: N rows, each rotating a coefficient vector by its own frame (sh_rotate, the zyz method with the
generated x90 blocks) against the same rows doing the matrix product of a fixed block-diagonal matrix (what
a CPU-built rotation would cost the shader), and against a row that only reads its inputs (the harness's
own cost, subtracted); the median of --repeats runs.

    .venv/bin/python -m benchmarks.sh_rotation_speed [--orders 3 5 8] [--rows 262144]
"""
import argparse
import os
import statistics
import sys
import time

import numpy as np

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)


def _glsl_seconds(run, library, body, inputs, repeats):
    run(library, body, inputs, 4)                          # compile
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run(library, body, inputs, 4)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def measure(orders, rows, repeats):
    from scipy.spatial.transform import Rotation

    from sg_prt_addon.harmonics import rotation
    from sg_prt_addon.techniques import shader_sources
    from sg_prt_addon.techniques.sh import sh_glsl
    from validation.glsl_harness import run_glsl

    frames = Rotation.random(rows, random_state=1).as_matrix().astype(np.float32)
    inputs = {"c0": frames[:, :, 0], "c1": frames[:, :, 1], "c2": frames[:, :, 2]}
    sg_source = shader_sources.library_source("sg.glsl")
    library_file = shader_sources.technique_source("sh", "sh_library.glsl")
    results = {}
    for order in orders:
        count = order * order
        coefficients = np.random.default_rng(order).normal(size=count)
        matrix = rotation.rotation_matrix(frames[0].astype(np.float64), order)
        constants = ("const float C[SH_COUNT] = float[](" + ", ".join(f"{v:.6e}" for v in coefficients) + ");\n"
                     + f"const float M[{count * count}] = float[](" + ", ".join(f"{v:.6e}" for v in matrix.ravel())
                     + ");\n")
        library = [sg_source, sh_glsl.constants_source(order, "none") + library_file + constants]
        fill = "float c[SH_COUNT]; for (int i = 0; i < SH_COUNT; i++) { c[i] = C[i] + c0.x * 1e-9; }\n"
        read = "result = vec4(c[0], c[SH_COUNT - 1], c[SH_COUNT / 2], 0.0);"
        base = _glsl_seconds(run_glsl, library, fill + read, inputs, repeats)
        zyz = _glsl_seconds(run_glsl, library, fill + "sh_rotate(c, mat3(c0.xyz, c1.xyz, c2.xyz));\n" + read, inputs,
                            repeats)
        product = ("float r[SH_COUNT];\n"
                   "for (int l = 0; l < SH_ORDER; l++) { int s = l * l; int w = 2 * l + 1;\n"
                   "  for (int i = 0; i < w; i++) { float a = 0.0;\n"
                   "    for (int j = 0; j < w; j++) { a += M[(s + i) * SH_COUNT + s + j] * c[s + j]; }\n"
                   "    r[s + i] = a; } }\n c = r;\n")
        dense = _glsl_seconds(run_glsl, library, fill + product + read, inputs, repeats)
        many = np.broadcast_to(coefficients, (rows, count)).astype(np.float32)
        start = time.perf_counter()
        rotation.rotate_zyz_many(many, frames)
        numpy_many = (time.perf_counter() - start) / rows
        start = time.perf_counter()
        for frame in frames[:200]:
            rotation.rotate(coefficients, frame.astype(np.float64))
        numpy_one = (time.perf_counter() - start) / 200
        results[order] = dict(counts=rotation.flop_counts(order), glsl_zyz=(zyz - base) / rows,
                              glsl_matrix=(dense - base) / rows, numpy_zyz_batched=numpy_many,
                              numpy_recurrence_one=numpy_one)
    return results


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--orders", type=int, nargs="*", default=[3, 5, 8])
    parser.add_argument("--rows", type=int, default=1 << 18)
    parser.add_argument("--repeats", type=int, default=5)
    arguments = parser.parse_args(argv)
    import sg_prt_addon
    sg_prt_addon.register()
    results = measure(arguments.orders, arguments.rows, arguments.repeats)
    print(f"\nns per rotation of one coefficient vector ({arguments.rows} rows, llvmpipe, 2 cores)")
    print(f"{'order':>5s} {'flops zyz':>10s} {'flops matrix':>13s} {'GLSL zyz':>9s} {'GLSL matrix':>12s} "
          f"{'numpy zyz batched':>18s} {'numpy recurrence':>17s}")
    for order, r in results.items():
        print(f"{order:5d} {r['counts']['zyz']:10d} {r['counts']['matrix']:13d} {r['glsl_zyz'] * 1e9:9.1f} "
              f"{r['glsl_matrix'] * 1e9:12.1f} {r['numpy_zyz_batched'] * 1e9:18.1f} "
              f"{r['numpy_recurrence_one'] * 1e9:17.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
