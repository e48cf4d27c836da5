"""Where the visibility bake's time goes, a vertex at a time (sg_prt_addon/visibility).

The bake of bake_speed's scene (an icosphere over a floor), on one thread, in the
pipeline's batches: each batch's ``adaptive_visibility`` (its rays and the
bookkeeping around them: directions, the horizon probe's edges, which fine
texels to trace, the fine grid) and ``ssdf_from_fine`` (the boundary points and
the nearest one to each stored sample) are timed, and Embree's own seconds are
read from the tracer; then the PCA of all the rows.  Then ``bake_ssdf`` whole,
on one thread and on two, alternated, for what the second core adds.

The figures bound what any tuning of the numpy around Embree can give: the bake
reaches raw Embree's ray rate only when everything but the rays is gone.

    .venv/bin/python -m benchmarks.bake_profile [20000] [--update-doc]
"""
import os
import sys
import textwrap
import time

import numpy as np

from benchmarks.bake_speed import raw_rate, sphere_over_floor
from sg_prt_addon.visibility import BakeOptions, binary_visibility, hemisphere_map, pca, ssdf
from sg_prt_addon.visibility.pipeline import bake_ssdf, one_blas_thread
from sg_prt_addon.visibility.raytrace import RayTracer

SECTION_TITLE = "## Where the bake's time goes"


def stage_seconds(vertices, normals, tracer, options):
    """Seconds of each stage over all vertices on one thread, and the SSDF rows (V, R * R)."""
    frames = hemisphere_map.local_frame(normals)
    origins = vertices + tracer.offset * frames[:, 2]
    seconds = {"rays (Embree)": 0.0, "refinement bookkeeping": 0.0, "SSDF distances": 0.0, "PCA": 0.0}
    rows = np.empty((len(vertices), options.resolution ** 2), np.float16)
    with one_blas_thread():                 # as bake_ssdf runs its batches
        _time_batches(vertices, origins, frames, tracer, options, seconds, rows)
    started = time.perf_counter()
    model = pca.fit(rows, options.terms, options.error_target, options.max_terms)
    pca.project(model, rows)
    seconds["PCA"] = time.perf_counter() - started
    return seconds, rows


def _time_batches(vertices, origins, frames, tracer, options, seconds, rows):
    """Adds each batch's seconds by stage to `seconds` and its SSDF rows to `rows`."""
    for start in range(0, len(vertices), options.batch_vertices):
        part = slice(start, start + options.batch_vertices)
        tracing_before = tracer.seconds_tracing
        started = time.perf_counter()
        fine, _ = binary_visibility.adaptive_visibility(tracer, origins[part], frames[part], options.resolution,
                                                        options.refinement)
        traced = time.perf_counter()
        rows[part] = ssdf.ssdf_from_fine(fine, options.resolution).reshape(len(fine), -1)
        seconds["SSDF distances"] += time.perf_counter() - traced
        embree = tracer.seconds_tracing - tracing_before
        seconds["rays (Embree)"] += embree
        seconds["refinement bookkeeping"] += traced - started - embree


def thread_seconds(vertices, normals, tracer, rounds=2):
    """Median seconds of bake_ssdf on 1 and on 2 threads, alternated."""
    times = {1: [], 2: []}
    for _ in range(rounds):
        for threads in (1, 2):
            started = time.perf_counter()
            bake_ssdf(vertices, normals, tracer, BakeOptions(threads=threads))
            times[threads].append(time.perf_counter() - started)
    return {threads: float(np.median(values)) for threads, values in times.items()}


def run(target_vertices):
    vertices, triangles, normals = sphere_over_floor(target_vertices)
    options = BakeOptions()
    raw = raw_rate(vertices, triangles, normals)
    tracer = RayTracer(vertices, triangles, threads=1, chunk_rays=1 << 15, relative_offset=options.relative_offset)
    try:
        rays_before = tracer.rays_traced
        seconds, _ = stage_seconds(vertices, normals, tracer, options)
        rays = tracer.rays_traced - rays_before
        threads = thread_seconds(vertices, normals, tracer)
    finally:
        tracer.close()
    return {"vertices": len(vertices), "rays_per_vertex": rays / len(vertices), "stages": seconds,
            "embree_rate": rays / seconds["rays (Embree)"], "raw_rate": raw, "threads": threads,
            "load": os.getloadavg()[0]}


def section(figures, requested):
    stages, count = figures["stages"], figures["vertices"]
    total = sum(stages.values())
    embree_share = stages["rays (Embree)"] / total
    speedup = figures["threads"][1] / figures["threads"][2]
    intro = (f"`.venv/bin/python -m benchmarks.bake_profile {requested} --update-doc` ({time.strftime('%Y-%m-%d')}; "
             f"written by the benchmark): bake_speed's scene ({count:,} vertices), operator defaults, one thread, "
             "the pipeline's "
             "batches; Embree's seconds read from the tracer, the rest of `adaptive_visibility` (directions, "
             "the horizon probe's edges, which fine texels to trace, the fine grid) is the refinement's "
             "bookkeeping, `ssdf_from_fine` the SSDF's distances.  Two threads: `bake_ssdf` whole on one "
             "thread and on two, alternated, medians of 2.")
    lines = [SECTION_TITLE, "", textwrap.fill(intro, 110), "",
             "| stage | ms a vertex | share |", "|---|---|---|"]
    for name, value in stages.items():
        lines.append(f"| {name} | {1000 * value / count:.3f} | {value / total:.0%} |")
    lines.append(f"| all | {1000 * total / count:.3f} | 100% |")
    lines += ["",
              f"{figures['rays_per_vertex']:,.0f} rays a vertex; Embree inside the bake casts "
              f"{figures['embree_rate'] / 1e6:.2f} M rays/s on one thread, raw Embree "
              f"{figures['raw_rate'] / 1e6:.2f} M rays/s on two (random rays).  On one thread the bake's rate is "
              f"{embree_share:.0%} of its Embree rate; the second core makes `bake_ssdf` {speedup:.2f}x faster "
              f"({figures['threads'][1]:.1f} s -> {figures['threads'][2]:.1f} s).  Load average at the end "
              f"{figures['load']:.1f}.", ""]
    return "\n".join(lines)


def main(argv=None):
    arguments = sys.argv[1:] if argv is None else argv
    sizes = [int(a) for a in arguments if not a.startswith("--")] or [20000]
    figures = run(sizes[0])
    text = section(figures, sizes[0])
    print(text)
    if "--update-doc" in arguments:
        from benchmarks import markdown_sections
        markdown_sections.update_file(markdown_sections.BAKE_DOC, SECTION_TITLE, text)
    return figures


if __name__ == "__main__":
    main()
