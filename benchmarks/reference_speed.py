"""Speed of the Monte Carlo reference renderer on a procedural ~20k-triangle scene.

A subdivided icosphere (20 * 4^5 = 20480 triangles) on a ground quad, lit by
a procedural sky (gradient + a bright sun patch) and one small sphere light.
A short pilot render estimates the per-sample noise, then the renderer takes
enough samples for the target mean relative standard error.

    .venv/bin/python -m benchmarks.reference_speed [--size 256] [--noise 0.01] [--max-spp 4096]
    .venv/bin/python -m benchmarks.reference_speed --cycles     # conventions vs Cycles

Measured (2 cores shared with other jobs, load average 5): 256x256, 20482
triangles, 89 spp x 16 environment pairs -> mean relative standard error
1.03% (median 0.93%) over surface pixels in 180 s wall / 108 s CPU, 25 rays
per pixel sample, 0.82 M rays/s wall including shading.  --cycles: mean
per channel within 0.1% of Cycles 1024 spp (direct light only).
"""
import argparse
import time

import numpy as np

from sg_prt_addon.visibility.raytrace import RayTracer
from validation.camera import Camera
from validation.reference import DirectionalLight, Material, PointLight, Scene, mean_relative_error, render_reference


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
    from sg_prt_addon.lighting.equirect import texel_directions
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


def compare_with_cycles(size=64, cycles_samples=1024, reference_samples=64, glossy_roughness=None):
    """Cross-check of conventions (camera matrices, equirect mapping, light units): the
    benchmark scene built from Blender primitives, rendered by Cycles with direct light only
    (max_bounces 0, box pixel filter, closest-texel world texture) and by render_reference
    from the exported meshes and Blender's own camera matrices.  Needs the pip bpy."""
    import tempfile

    import bpy
    import mathutils

    from sg_prt_addon.lighting.lights import blender_point_light_intensity
    from sg_prt_addon.reflectance.brdf import GGX

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device, cycles.samples, cycles.seed = "CPU", cycles_samples, 3
    cycles.use_adaptive_sampling = cycles.use_denoising = False
    cycles.max_bounces = 0
    cycles.pixel_filter_type, cycles.filter_width = "BOX", 1.0
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100

    def diffuse_material(name, colour, roughness=None):
        material = bpy.data.materials.new(name)
        material.use_nodes = True
        nodes = material.node_tree.nodes
        for node in list(nodes):
            if node.type != "OUTPUT_MATERIAL":
                nodes.remove(node)
        if roughness is None:
            bsdf = nodes.new("ShaderNodeBsdfDiffuse")
        else:
            bsdf = nodes.new("ShaderNodeBsdfGlossy")
            bsdf.distribution = "GGX"
            bsdf.inputs["Roughness"].default_value = roughness
        bsdf.inputs["Color"].default_value = (*colour, 1.0)
        material.node_tree.links.new(bsdf.outputs[0], nodes["Material Output"].inputs["Surface"])
        return material

    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=1.0, location=(0.0, 0.0, 1.0))
    sphere = bpy.context.object
    bpy.ops.object.shade_smooth()
    sphere.data.materials.append(diffuse_material("sphere", (0.7, 0.3, 0.2), glossy_roughness))
    bpy.ops.mesh.primitive_plane_add(size=8.0)
    ground = bpy.context.object
    ground.data.materials.append(diffuse_material("ground", (0.6, 0.6, 0.6)))

    sky = make_sky(32, 64)
    image = bpy.data.images.new("sky", 64, 32, float_buffer=True, alpha=True)
    image.pixels.foreach_set(np.concatenate([sky[::-1], np.ones((32, 64, 1))], -1).astype(np.float32).ravel())
    world = bpy.data.worlds.new("world")
    scene.world = world
    world.use_nodes = True
    texture = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
    texture.image, texture.interpolation = image, "Closest"
    world.node_tree.links.new(texture.outputs["Color"], world.node_tree.nodes["Background"].inputs["Color"])

    point = bpy.data.objects.new("point", bpy.data.lights.new("point", "POINT"))
    point.data.energy, point.data.shadow_soft_size = 100.0, 0.2
    point.location = (2.0, -2.0, 3.0)
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy, sun.data.angle = 0.5, 0.02
    to_sun = np.array([-0.3, 0.2, 1.0]) / np.linalg.norm([-0.3, 0.2, 1.0])
    sun.rotation_euler = mathutils.Vector(to_sun).to_track_quat("Z", "Y").to_euler()   # shines along -Z
    camera_object = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera_object.location = (0.0, -5.0, 3.0)
    camera_object.rotation_euler = (mathutils.Vector((0.0, 0.0, 0.7)) - camera_object.location).to_track_quat(
        "-Z", "Y").to_euler()
    for obj in (point, sun, camera_object):
        scene.collection.objects.link(obj)
    scene.camera = camera_object
    bpy.context.view_layer.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()

    vertices, triangles, normals, material_index = [], [], [], []
    for index, obj in enumerate((sphere, ground)):
        evaluated = obj.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh()
        mesh.calc_loop_triangles()
        world_matrix = np.array(obj.matrix_world)
        local = np.array([v.co for v in mesh.vertices])
        triangles.append(np.array([lt.vertices[:] for lt in mesh.loop_triangles]) + sum(map(len, vertices)))
        vertices.append(local @ world_matrix[:3, :3].T + world_matrix[:3, 3])
        normals.append(np.array([v.normal for v in mesh.vertices]) @ np.linalg.inv(world_matrix[:3, :3]))
        material_index.append(np.full(len(triangles[-1]), index))
        evaluated.to_mesh_clear()
    ours = Scene(np.concatenate(vertices), np.concatenate(triangles), np.concatenate(normals),
                 [Material((0.7, 0.3, 0.2)) if glossy_roughness is None else
                  Material((0, 0, 0), (0.7, 0.3, 0.2), GGX(roughness=glossy_roughness)),
                  Material((0.6, 0.6, 0.6))], np.concatenate(material_index),
                 lights=[PointLight(tuple(point.location), (float(blender_point_light_intensity(100.0)),) * 3, 0.2),
                         DirectionalLight(to_sun, (0.5,) * 3, angular_radius=0.01)],
                 environment=sky)
    camera = Camera(np.array(camera_object.matrix_world.inverted()),
                    np.array(camera_object.calc_matrix_camera(depsgraph, x=size, y=size)), size, size)
    reference, error = render_reference(ours, camera, reference_samples, seed=1)

    with tempfile.TemporaryDirectory() as folder:
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.filepath = folder + "/cycles.exr"
        bpy.ops.render.render(write_still=True)
        result = bpy.data.images.load(scene.render.filepath)
        cycles_image = np.array(result.pixels[:], dtype=np.float64).reshape(size, size, 4)[::-1, :, :3]
    ratio = cycles_image.mean(axis=(0, 1)) / reference.mean(axis=(0, 1))
    on_sphere = np.zeros((size, size), bool)
    hits = RayTracer(ours.vertices, ours.triangles).intersect(*(a.reshape(-1, 3) for a in camera.primary_rays()))
    on_sphere.ravel()[:] = hits.hit & (ours.material_index[np.maximum(hits.triangle, 0)] == 0)
    sphere_ratio = cycles_image[on_sphere].mean(axis=0) / reference[on_sphere].mean(axis=0)
    sphere_error = np.sqrt(np.sum(error[on_sphere] ** 2, axis=0)) / on_sphere.sum() / reference[on_sphere].mean(axis=0)
    relative = np.abs(cycles_image - reference) / np.maximum(reference, 1e-3)
    print(f"Cycles {cycles_samples} spp / reference {reference_samples} spp, mean per channel: {np.round(ratio, 4)} "
          f"(sphere pixels {np.round(sphere_ratio, 4)}, reference standard error {np.round(sphere_error, 4)}); "
          f"per-pixel |difference| median {np.median(relative):.4f}, 90th percentile {np.percentile(relative, 90):.4f}; "
          f"reference median relative standard error {mean_relative_error(reference, error, np.median):.4f}")
    return ratio


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--noise", type=float, default=0.01, help="target mean relative standard error")
    parser.add_argument("--pilot-spp", type=int, default=8)
    parser.add_argument("--max-spp", type=int, default=4096)
    parser.add_argument("--subdivisions", type=int, default=5)
    parser.add_argument("--cycles", action="store_true", help="cross-check against Cycles (64x64, needs bpy)")
    parser.add_argument("--glossy", type=float, default=None, help="with --cycles: GGX sphere of this roughness")
    args = parser.parse_args()
    if args.cycles:
        return compare_with_cycles(glossy_roughness=args.glossy)

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
