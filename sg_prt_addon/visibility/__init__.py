"""Visibility bake: ray-traced hemispheres -> SSDF -> PCA (wang2009 section 5). Numpy only, no bpy.

    from sg_prt_addon.visibility import bake_visibility, BakeOptions, BakeCancelled
    result = bake_visibility(vertices, triangles, normals, scene_vertices, scene_triangles,
                             BakeOptions(resolution=32), progress=lambda f, msg: cancel_requested)

Modules: hemisphere_map (square <-> hemisphere, local frames), visibility
(adaptive ray grids), ssdf (eq. 23), pca (eq. 24), decode (numpy mirror of
shaders/lib/ssdf.glsl), pipeline (the bake).
"""
from .pipeline import BakeCancelled, BakeOptions, BakeResult, bake_visibility, topology_hash

__all__ = ["BakeCancelled", "BakeOptions", "BakeResult", "bake_visibility", "topology_hash"]
