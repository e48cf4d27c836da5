"""Blender scene -> plain numpy arrays and small dataclasses (no `gpu` here), a module for each kind of data
(meshes, materials, textures, lights, world, cameras, view_layer; messages: the bad input met on the way).

Everything the engine draws goes through this package, so the GPU side and the
numpy mirror (techniques/sg/sg_shading.py) see exactly the same numbers:

- meshes: one vertex per face corner (loop), so split normals, UV seams and
  tangent sign flips need no vertex splitting logic; triangles index corners;
  positions/normals/tangents are in object space, with the object's
  matrix_world alongside (a transform edit then needs no re-export);
  `to_world` gives the world-space arrays; `corner_vertex` maps each corner to its Blender
  mesh vertex (per-vertex data such as the visibility bake's coefficients is shared by the
  vertex's corners) and `vertex_normals` are the smooth vertex normals (the bake's frames);
- materials: `material.sgprt` read into `MaterialParams` (defaults when the
  material has no settings or the slot is empty);
- lights in Blender units, converted to the quantities lighting/lights.py takes;
- the world: an Environment Texture's equirect pixels, else the world colour.

`export_counter` counts mesh exports: the viewport's update logic is tested
with it (a material edit must not re-export meshes).
"""
from .cameras import CameraExport, camera_from_view, export_camera
from .lights import LightExport, export_light
from .materials import (
    COLOUR_PARAMETERS,
    SCALAR_PARAMETERS,
    TEXTURED_PARAMETERS,
    FittedLobes,
    MaterialParams,
    default_surface,
    export_fitted_lobes,
    export_material,
)
from .meshes import (
    MeshExport,
    export_counter,
    export_mesh_data,
    export_object_mesh,
    matrix_to_numpy,
    mesh_corner_normals,
    to_world,
)
from .messages import collect_warnings, finite_texels, warn
from .textures import COLOUR_SLOTS, images_present, slot_pixels, srgb_to_linear, texture_pixels, texture_sources
from .view_layer import RenderRoles, render_roles
from .world import WorldExport, export_world

__all__ = ["COLOUR_PARAMETERS", "COLOUR_SLOTS", "SCALAR_PARAMETERS", "TEXTURED_PARAMETERS", "CameraExport", "FittedLobes",
           "LightExport", "MaterialParams", "MeshExport", "RenderRoles", "WorldExport", "camera_from_view",
           "collect_warnings", "default_surface", "export_camera", "export_counter", "export_fitted_lobes", "export_light",
           "export_material", "export_mesh_data", "export_object_mesh", "export_world", "finite_texels",
           "images_present", "matrix_to_numpy", "mesh_corner_normals", "render_roles", "slot_pixels",
           "srgb_to_linear", "texture_pixels", "texture_sources", "to_world", "warn"]
