"""Lobe-fitting throughput (texels/s) on generated SVBRDFs, and the extrapolation to 256 x 256.

    .venv/bin/python -m benchmarks.lobe_fit_speed [size]

Stages, each timed on a size x size material (default 16):
  factorize   per-texel samples (a 'measured' SVBRDF: 32x16x16 half/difference pairs a
              texel, 2% noise) -> kd, ks, D, S, with one eta or 5 candidates screened
  iso 1, 2    SG lobes around z+ of the tabulated D (batched Levenberg-Marquardt) + PCA of S
  free 4      4 free-axis lobes (batched Levenberg-Marquardt), on the first 64 texels
"""
import sys
import time

from sg_prt_addon.measured import microfacet_fit
from validation import brdf_generators

FULL = 256 * 256


def _timed(function):
    start_wall, start_cpu = time.perf_counter(), time.process_time()
    result = function()
    return result, time.perf_counter() - start_wall, time.process_time() - start_cpu


def _report(name, texels, wall, cpu):
    rate = texels / wall
    print(f"{name:<28} {texels:6d} texels {wall:7.2f} s wall {cpu:7.2f} s cpu {rate:9.1f} texels/s "
          f"-> 256x256 in {FULL / rate / 60:6.1f} min", flush=True)


def main(size=16):
    params = brdf_generators.spatial_parameters(size)
    material = brdf_generators.AnalyticMaterial(diffuse=params["diffuse"], specular=params["specular"],
                                                roughness=params["roughness"], eta=params["eta"],
                                                oren_nayar_sigma=0.2, retro=(0.01, 0.01, 0.01))
    wo, wi, weights = microfacet_fit.half_difference_samples(32, 16, 16, 1)
    rho = brdf_generators.sample_svbrdf_measurements(material, wo, wi)
    texels = size * size
    print(f"{texels} texels, {len(wo)} direction pairs a texel", flush=True)
    factorization, wall, cpu = _timed(lambda: microfacet_fit.factorize(wo, wi, rho, weights, eta=1.5))
    _report("factorize (1 eta)", texels, wall, cpu)
    _, wall, cpu = _timed(lambda: microfacet_fit.factorize(wo, wi, rho, weights,
                                                           eta=microfacet_fit.DEFAULT_ETA_CANDIDATES))
    _report("factorize (5 eta screened)", texels, wall, cpu)
    table = factorization.to_table((size, size))
    for lobe_count in (1, 2):
        _, wall, cpu = _timed(lambda: microfacet_fit.fit_lobes(table, lobe_count))
        _report(f"iso {lobe_count} lobes + PCA", texels, wall, cpu)
    subset = min(texels, 64)
    small = microfacet_fit.MicrofacetFactorization(
        **{name: (value[:subset] if getattr(value, "ndim", 0) and len(value) == texels else value)
           for name, value in vars(factorization).items()})
    _, wall, cpu = _timed(lambda: microfacet_fit.fit_lobes(small, 4, free_axes=True))
    _report("free 4 lobes + PCA", subset, wall, cpu)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 16)
