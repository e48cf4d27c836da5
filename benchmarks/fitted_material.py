"""Fitted materials end to end: fitting throughput through the operator, and the rendered error.

    .venv/bin/python -m benchmarks.fitted_material [--table-size 16] [--lobes 2]

1. bpy.ops.sgprt.fit_lobes (synchronous execute(): read, factorize or fit, measure the fit error,
   store packed float images) on a generated MERL file (one texel: 1.46M bins factorized) and on
   generated SVBRDF tables (validation.brdf_generators.generate_svbrdf_table) of a few sizes: seconds
   and texels/s, the stored fit_error.
2. The 64 x 64 sphere of tests/gpu/test_fitted_reference.py: a GGX-like AnalyticMaterial tabulated
   as MERL, fitted with 2 lobes, rendered by the engine from the fit under courtyard.exr, scored
   against the Monte Carlo reference of the analytic BRDF (relative RMSE, bias, noise floor).
"""
import argparse
import os
import sys
import tempfile
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
for path in (REPO_ROOT, os.path.join(REPO_ROOT, "tests", "gpu")):
    if path not in sys.path:
        sys.path.insert(0, path)


def _fit(path, lobes, **options):
    import bpy

    material = bpy.data.materials.new("benchmark_fit")
    start = time.perf_counter()
    with bpy.context.temp_override(material=material):
        assert bpy.ops.sgprt.fit_lobes(filepath=path, lobe_count=lobes, **options) == {"FINISHED"}
    seconds = time.perf_counter() - start
    settings = material.sgprt.lobe_fit
    return seconds, settings.width * settings.height, settings.fit_error


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--table-size", type=int, nargs="+", default=[8, 16])
    parser.add_argument("--lobes", type=int, default=2)
    args = parser.parse_args(argv)

    import engine_fixtures as fx
    from test_fitted_reference import ANALYTIC, score_fitted_sphere

    from sg_prt_addon.measured import svbrdf_table
    from validation import brdf_generators

    fx.ensure_registered()
    with tempfile.TemporaryDirectory() as folder:
        merl_path = os.path.join(folder, "analytic_ggx.binary")
        brdf_generators.generate_merl(merl_path, brdf_generators.AnalyticMaterial(**ANALYTIC), seed=3)
        print("fit through bpy.ops.sgprt.fit_lobes (execute, one thread of work):")
        seconds, texels, error = _fit(merl_path, args.lobes)
        print(f"  {'MERL (1 texel, 1.46M bins)':<28} {args.lobes} lobes  {seconds:6.2f} s  fit error {error:.3f}")
        for size in args.table_size:
            table_path = os.path.join(folder, f"table_{size}.npz")
            table, _ = brdf_generators.generate_svbrdf_table(size=size, seed=5)
            svbrdf_table.write_svbrdf_table(table_path, table)
            seconds, texels, error = _fit(table_path, args.lobes)
            print(f"  {f'SVBRDF table {size}x{size}':<28} {args.lobes} lobes  {seconds:6.2f} s  "
                  f"{texels / seconds:8.1f} texels/s  fit error {error:.3f} (mean over texels)")
        start = time.perf_counter()
        rmse, bias, noise_floor, _ = score_fitted_sphere(merl_path, name="benchmark_fitted_reference")
        print(f"rendered 64x64 sphere (engine, fitted {args.lobes} lobes) vs Monte Carlo reference of the analytic BRDF:"
              f" relative RMSE {rmse:.4f}, bias {bias:+.4f}, reference noise floor {noise_floor:.4f} "
              f"({time.perf_counter() - start:.1f} s incl. the fit and the reference)")


if __name__ == "__main__":
    main()
