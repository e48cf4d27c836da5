"""Visibility bake speed and error, and the PCA's error vs terms (sg_prt_addon/visibility).

Procedural scenes (numpy only): a subdivided icosphere resting over a
subdivided floor grid, about 5k, 20k and 100k vertices; every vertex is
baked and the whole scene occludes.  Prints, per size: bake time (rays + SSDF
+ PCA), rays per vertex, rays/s of the bake, and the raw occlusion rate of
RayTracer.occluded on the same scene (one big batch of random hemisphere rays
from the same vertices, both cores) in the same run, and their ratio; the
bake's SSDF error at 64 vertices against the SSDF of a dense 160 x 160 ray grid
(adaptive rays and PCA together); the process's peak memory; then the PCA's RMS
angular error against the number of terms (plot: benchmarks/ssdf_pca_error.png).

    .venv/bin/python -m benchmarks.bake_speed [5000 20000 100000] [--update-doc]
"""
import os
import resource
import sys
import textwrap
import time

import numpy as np

from sg_prt_addon.visibility import BakeOptions, bake_visibility, binary_visibility, hemisphere_map, ssdf
from sg_prt_addon.visibility.raytrace import RayTracer


def icosphere(subdivisions):
    """Unit icosphere: (vertices (V, 3), triangles (T, 3)), outward winding."""
    t = (1 + 5 ** 0.5) / 2
    vertices = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
                (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    vertices = np.array(vertices, np.float64)
    vertices /= np.linalg.norm(vertices, axis=1, keepdims=True)
    faces = np.array(faces, np.int64)
    for _ in range(subdivisions):
        edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
        unique, inverse = np.unique(edges, axis=0, return_inverse=True)
        midpoints = vertices[unique[:, 0]] + vertices[unique[:, 1]]
        midpoints /= np.linalg.norm(midpoints, axis=1, keepdims=True)
        mid = inverse.reshape(3, -1) + len(vertices)   # mid[0]: edge (0,1), mid[1]: (1,2), mid[2]: (2,0)
        a, b, c = faces.T
        faces = np.concatenate([np.stack([a, mid[0], mid[2]], 1), np.stack([b, mid[1], mid[0]], 1),
                                np.stack([c, mid[2], mid[1]], 1), np.stack([mid[0], mid[1], mid[2]], 1)])
        vertices = np.concatenate([vertices, midpoints])
    return vertices, faces


def grid(count_per_side, half_size):
    """Floor z = 0 over [-half_size, half_size]^2: (vertices, triangles), normals +z."""
    coords = np.linspace(-half_size, half_size, count_per_side)
    x, y = np.meshgrid(coords, coords, indexing="ij")
    vertices = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)
    index = np.arange(x.size).reshape(count_per_side, count_per_side)
    a, b, c, d = index[:-1, :-1].ravel(), index[1:, :-1].ravel(), index[1:, 1:].ravel(), index[:-1, 1:].ravel()
    return vertices, np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])


def sphere_over_floor(target_vertices):
    """An icosphere (radius 1, resting at height 0.05) over a 6 x 6 floor, about target_vertices in all.
    Returns (vertices, triangles, normals)."""
    subdivisions = int(np.clip(np.round(np.log(max(target_vertices / 2 / 10, 1)) / np.log(4)), 0, 8))
    sphere_v, sphere_t = icosphere(subdivisions)
    floor_side = int(round(np.sqrt(max(target_vertices - len(sphere_v), 4))))
    floor_v, floor_t = grid(floor_side, 3.0)
    vertices = np.concatenate([sphere_v + [0.0, 0.0, 1.05], floor_v])
    triangles = np.concatenate([sphere_t, floor_t + len(sphere_v)])
    normals = np.concatenate([sphere_v, np.tile([0.0, 0.0, 1.0], (len(floor_v), 1))])
    return vertices, triangles, normals


def raw_rate(vertices, triangles, normals, rays=2_000_000, seed=0):
    """RayTracer.occluded rays/s on one big batch of random upper-hemisphere rays from the vertices."""
    rng = np.random.default_rng(seed)
    tracer = RayTracer(vertices, triangles, threads=2, chunk_rays=1 << 15)
    pick = rng.integers(0, len(vertices), rays)
    frames = hemisphere_map.local_frame(normals[pick])
    local = hemisphere_map.square_to_hemisphere(rng.uniform(-1, 1, (rays, 2)))
    directions = np.einsum("nc,ncw->nw", local, frames)
    origins = vertices[pick] + tracer.offset * normals[pick]
    started = time.perf_counter()
    tracer.occluded(origins, directions)
    seconds = time.perf_counter() - started
    tracer.close()
    return rays / seconds


def dense_ssdf_error(result, vertices, triangles, normals, count=64, seed=0):
    """RMS (rad) of the bake's decompressed SSDF at `count` vertices against the SSDF of a dense 160 x 160 ray
    grid there: what the adaptive rays and the PCA cost together."""
    pick = np.random.default_rng(seed).choice(len(vertices), min(count, len(vertices)), replace=False)
    tracer = RayTracer(vertices, triangles, threads=2)
    frames = hemisphere_map.local_frame(normals[pick])
    dense = binary_visibility.dense_visibility(tracer, vertices[pick] + tracer.offset * frames[:, 2], frames,
                                               result.resolution * BakeOptions().refinement)
    tracer.close()
    reference = ssdf.ssdf_from_fine(dense, result.resolution)
    return float(np.sqrt(np.mean(np.square(result.ssdf(pick) - reference))))


def run(target_vertices, options=None):
    vertices, triangles, normals = sphere_over_floor(target_vertices)
    options = options or BakeOptions()
    raw = raw_rate(vertices, triangles, normals)
    result = bake_visibility(vertices, triangles, normals, vertices, triangles, options, point_triangles=triangles)
    figures = {"vertices": len(vertices), "triangles": len(triangles), "seconds": result.seconds,
               "rays_per_vertex": result.rays_traced / len(vertices), "bake_rate": result.rays_traced / result.seconds,
               "raw_rate": raw, "terms": result.terms, "pca_rms": result.rms_error,
               # Embree's own rate inside the bake: its rays over its thread-seconds, times the bake's threads
               "casting_rate": result.rays_traced / result.seconds_tracing * options.threads,
               "tracing_share": result.seconds_tracing / (options.threads * result.seconds),
               "dense_rms": dense_ssdf_error(result, vertices, triangles, normals),
               "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, "load": os.getloadavg()[0]}
    print(f"{figures['vertices']:6d} vertices, {figures['triangles']:6d} triangles: bake {result.seconds:6.1f} s, "
          f"{figures['rays_per_vertex']:6.0f} rays/vertex, {figures['bake_rate'] / 1e6:5.2f} M rays/s "
          f"(raw RayTracer.occluded {raw / 1e6:5.2f} M rays/s, bake/raw {figures['bake_rate'] / raw:4.2f}; casting "
          f"inside the bake {figures['casting_rate'] / 1e6:5.2f} M rays/s, {figures['casting_rate'] / raw:4.2f} of raw, "
          f"{figures['tracing_share']:.0%} of the cores' time); "
          f"PCA {result.terms} terms, RMS {result.rms_error:.4f} rad; against dense rays {figures['dense_rms']:.4f} rad; "
          f"peak memory {figures['peak_mib']:.0f} MiB", flush=True)
    return result, figures


def plot_pca_error(result, path="benchmarks/ssdf_pca_error.png"):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    errors = result.rms_error_by_terms
    figure, axes = plt.subplots(figsize=(5, 3.5))
    axes.semilogy(np.arange(len(errors)), errors, marker=".")
    axes.set_xlabel("PCA terms")
    axes.set_ylabel("RMS SSDF error (rad)")
    axes.set_title(f"SSDF PCA, {result.vertex_count} vertices, {result.resolution}^2 texels")
    axes.grid(True, which="both", alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=100)


SECTION_TITLE = "## Visibility bake"


def section(sizes, rows, errors):
    intro = (f"`.venv/bin/python -m benchmarks.bake_speed {' '.join(map(str, sizes))} --update-doc` "
             f"({time.strftime('%Y-%m-%d')}; written by the benchmark): an icosphere over a floor grid, every vertex "
             "baked, the whole scene occludes, operator defaults (resolution 32, refinement 5, PCA error target "
             f"{BakeOptions().error_target} rad), its triangles passed as the operator passes them (64 probe rays a vertex for buried points, "
             "visibility.buried: none here).  Raw rate: RayTracer.occluded on 2M random hemisphere rays from the same vertices, both "
             "cores, in the same run.  SSDF error: the bake's decompressed SSDF at 64 vertices against the SSDF of "
             "a dense 160 x 160 ray grid there.  Casting: Embree's rate inside the bake (its rays over the "
             "thread-seconds spent in its queries, times the 2 threads) and the share of the two cores' bake time "
             "spent there (the rest is the SSDF's boundary search, the PCA and numpy).  Peak memory: the "
             "process's (it grows with the largest size run).")
    lines = [SECTION_TITLE, "", textwrap.fill(intro, 110), "",
             "| vertices | bake (rays + SSDF + buried probe + PCA) | rays/vertex | bake rays/s | raw rays/s | bake / raw | casting "
             "rays/s (/ raw) | time in Embree | PCA terms, RMS | SSDF error vs dense rays | peak memory | load |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['vertices']:,} | {r['seconds']:.1f} s | {r['rays_per_vertex']:,.0f} | "
                     f"{r['bake_rate'] / 1e6:.2f} M | {r['raw_rate'] / 1e6:.2f} M | {r['bake_rate'] / r['raw_rate']:.2f} | "
                     f"{r['casting_rate'] / 1e6:.2f} M ({r['casting_rate'] / r['raw_rate']:.2f}) | "
                     f"{r['tracing_share']:.0%} | "
                     f"{r['terms']}, {r['pca_rms']:.4f} rad | {r['dense_rms']:.4f} rad | {r['peak_mib']:.0f} MiB | "
                     f"{r['load']:.1f} |")
    lines += ["", "PCA RMS angular error by terms (largest size): " + ", ".join(
        f"{n}: {errors[n]:.3f}" for n in (0, 4, 8, 16, 24, 32) if n < len(errors))
        + " rad (plot: benchmarks/ssdf_pca_error.png).", ""]
    return "\n".join(lines)


def main(argv=None):
    arguments = sys.argv[1:] if argv is None else argv
    sizes = [int(a) for a in arguments if not a.startswith("--")] or [5000, 20000, 100000]
    rows, last = [], None
    for size in sizes:
        last, figures = run(size)
        rows.append(figures)
    errors = last.rms_error_by_terms
    print("PCA RMS error (rad) by terms: " + ", ".join(f"{n}:{errors[n]:.4f}" for n in
                                                      (0, 1, 2, 4, 8, 12, 16, 24, 32, 48) if n < len(errors)))
    plot_pca_error(last)
    text = section(sizes, rows, errors)
    print(text)
    if "--update-doc" in arguments:
        from benchmarks import markdown_sections
        markdown_sections.update_file(markdown_sections.BAKE_DOC, SECTION_TITLE, text)
    return rows


if __name__ == "__main__":
    main()
