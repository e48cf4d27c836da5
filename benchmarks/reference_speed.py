"""Speed of the Monte Carlo reference renderer on a procedural ~20k-triangle scene.

A subdivided icosphere (20 * 4^5 = 20480 triangles) on a ground quad, lit by
a procedural sky (gradient + a bright sun patch) and one small sphere light.
A short pilot render estimates the per-sample noise, then the renderer takes
enough samples for the target mean relative standard error.

    .venv/bin/python -m benchmarks.reference_speed [--size 256] [--noise 0.01] [--max-spp 4096]
"""
import argparse
import time

import numpy as np

from sg_prt_addon.core.camera import Camera
from sg_prt_addon.core.raytrace import RayTracer
from sg_prt_addon.core.reference import (DirectionalLight, Material, PointLight, Scene, mean_relative_error,
                                         render_reference)


def make_icosphere(subdivisions, radius=1.0, center=(0.0, 0.0, 0.0)):
    """Icosphere: vertices (V, 3), triangles (20 * 4^subdivisions, 3) counter-clockwise from outside,
    unit normals (V, 3)."""
    t = (1.0 + 5.0 ** 0.5) / 2.0
    vertices = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
                         [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    triangles = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                          [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                          [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]], np.int64)
    vertices /= np.linalg.norm(vertices, axis=1, keepdims=True)
    for _ in range(subdivisions):
        # One midpoint per undirected edge, shared by its two triangles.
        edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
        unique_edges, edge_id = np.unique(np.sort(edges, axis=1), axis=0, return_inverse=True)
        edge_id = edge_id.reshape(-1)
        midpoints = vertices[unique_edges].mean(axis=1)
        midpoints /= np.linalg.norm(midpoints, axis=1, keepdims=True)
        count = len(triangles)
        a, b, c = triangles.T
        ab, bc, ca = (len(vertices) + edge_id[k * count:(k + 1) * count] for k in range(3))
        vertices = np.concatenate([vertices, midpoints])
        triangles = np.concatenate([np.stack(x, axis=1) for x in
                                    ([a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca])])
    normals = vertices.copy()
    return vertices * radius + np.asarray(center, float), triangles, normals


def make_sky(height=64, width=128):
    """Procedural equirect sky: blue-white gradient above, dark ground below, a bright sun patch."""
    from sg_prt_addon.core.equirect import texel_directions
    directions = texel_directions(height, width)
    up = directions[..., 2:3]
    sky = np.where(up > 0, np.array([0.5, 0.7, 1.0]) * (0.4 + 0.6 * (1 - up)), np.array([0.15, 0.12, 0.1]))
    sun = np.array([0.5, 0.3, 0.6]) / np.linalg.norm([0.5, 0.3, 0.6])
    sky = sky + 60.0 * (directions @ sun > np.cos(np.radians(4.0)))[..., None] * np.array([1.0, 0.95, 0.85])
    return sky


def make_benchmark_scene(subdivisions=5):
    sphere_vertices, sphere_triangles, sphere_normals = make_icosphere(subdivisions, 1.0, (0.0, 0.0, 1.0))
    ground_vertices = np.array([[-4, -4, 0], [4, -4, 0], [4, 4, 0], [-4, 4, 0]], float)
    ground_triangles = np.array([[0, 1, 2], [0, 2, 3]]) + len(sphere_vertices)
    vertices = np.concatenate([sphere_vertices, ground_vertices])
    triangles = np.concatenate([sphere_triangles, ground_triangles])
    normals = np.concatenate([sphere_normals, np.tile([0.0, 0.0, 1.0], (4, 1))])
    material_index = np.concatenate([np.zeros(len(sphere_triangles), int), [1, 1]])
    materials = [Material((0.7, 0.3, 0.2)), Material((0.6, 0.6, 0.6))]
    lights = [PointLight(position=(2.0, -2.0, 3.0), intensity=(8.0, 8.0, 8.0), radius=0.2),
              DirectionalLight(direction=(-0.3, 0.2, 1.0), irradiance=(0.5, 0.5, 0.5), angular_radius=0.01)]
    return Scene(vertices, triangles, normals, materials, material_index, lights=lights, environment=make_sky())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--noise", type=float, default=0.01, help="target mean relative standard error")
    parser.add_argument("--pilot-spp", type=int, default=8)
    parser.add_argument("--max-spp", type=int, default=4096)
    parser.add_argument("--subdivisions", type=int, default=5)
    args = parser.parse_args()

    scene = make_benchmark_scene(args.subdivisions)
    camera = Camera.look_at((0.0, -5.0, 3.0), (0.0, 0.0, 0.7), (0.0, 0.0, 1.0), 40.0, args.size, args.size)
    tracer = RayTracer(scene.vertices, scene.triangles)
    print(f"{len(scene.triangles)} triangles, {args.size}x{args.size} pixels")

    start = time.perf_counter()
    image, error = render_reference(scene, camera, args.pilot_spp, seed=1, tracer=tracer)
    pilot_noise = mean_relative_error(image, error)
    spp = int(np.clip(np.ceil(args.pilot_spp * (pilot_noise / args.noise) ** 2), 2, args.max_spp))
    print(f"pilot {args.pilot_spp} spp: {time.perf_counter() - start:.1f} s, mean relative error {pilot_noise:.4f}"
          f" -> {spp} spp")

    tracer.rays_traced = 0
    start, cpu_start = time.perf_counter(), time.process_time()
    image, error = render_reference(scene, camera, spp, seed=2, tracer=tracer)
    seconds, cpu_seconds = time.perf_counter() - start, time.process_time() - cpu_start
    # CPU seconds make figures comparable on a shared machine (wall time depends on the load).
    print(f"render {spp} spp: {seconds:.1f} s wall, {cpu_seconds:.1f} s CPU, "
          f"{tracer.rays_traced / seconds / 1e6:.2f} M rays/s wall "
          f"({tracer.rays_traced / (spp * args.size ** 2):.2f} rays per pixel sample), "
          f"relative standard error over surface pixels: mean {mean_relative_error(image, error):.4f}, "
          f"median {mean_relative_error(image, error, np.median):.4f}")
    assert np.all(np.isfinite(image)) and np.all(np.isfinite(error))
    return image, error


if __name__ == "__main__":
    main()
