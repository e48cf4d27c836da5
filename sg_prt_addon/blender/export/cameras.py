"""The camera's view and projection, from a camera object or a viewport's matrices."""
from dataclasses import dataclass

import numpy as np

from .meshes import matrix_to_numpy

# --------------------------------------------------------------------------- camera

@dataclass
class CameraExport:
    view: np.ndarray               # 4x4 world -> camera
    projection: np.ndarray         # 4x4 camera -> clip
    position: tuple
    forward: tuple                 # camera -Z in world
    is_perspective: bool = True
    shading_footprint: float = 0.0  # pixels a side each pixel's specular averages over (anti_aliasing.specular_footprint)
    footprint_grid_limit: int = 4   # at most this many specular samples a side of that footprint (sg_shading.glsl)
    texture_footprint: float = 1.0  # pixels a side each pixel's material textures are read over (anti_aliasing)
    coverage_offset: float = 0.0    # added to the dithered coverage's thresholds: each jittered frame its own


def camera_from_view(view_matrix, projection_matrix, is_perspective):
    """CameraExport from a view (world -> camera) and projection matrix, e.g. a 3D viewport's
    region_data.view_matrix / window_matrix."""
    view = matrix_to_numpy(view_matrix)
    camera_to_world = np.linalg.inv(view)
    forward = -camera_to_world[:3, 2]
    return CameraExport(view=view, projection=matrix_to_numpy(projection_matrix),
                        position=tuple(camera_to_world[:3, 3]),
                        forward=tuple(forward / max(np.linalg.norm(forward), 1e-30)),
                        is_perspective=bool(is_perspective))


def export_camera(camera_object, depsgraph, width, height, scale_x=1.0, scale_y=1.0):
    """Render camera of the scene: view = matrix_world^-1, projection from calc_matrix_camera."""
    matrix_world = camera_object.matrix_world
    projection = camera_object.calc_matrix_camera(depsgraph, x=width, y=height, scale_x=scale_x, scale_y=scale_y)
    world = matrix_to_numpy(matrix_world)
    forward = -world[:3, 2]
    return CameraExport(view=matrix_to_numpy(matrix_world.inverted()), projection=matrix_to_numpy(projection),
                        position=tuple(world[:3, 3]),
                        forward=tuple(forward / max(np.linalg.norm(forward), 1e-30)),
                        is_perspective=camera_object.data.type != "ORTHO")
