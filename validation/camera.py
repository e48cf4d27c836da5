"""Pinhole (or orthographic) camera from OpenGL view and projection matrices.

view_matrix maps world -> camera space (camera looks down -z, y up);
projection_matrix maps camera space -> clip space, NDC in [-1, 1]^3 with
z = -1 on the near plane.  These are exactly Blender's
``camera.matrix_world.inverted()`` and ``camera.calc_matrix_camera(...)``, so
rays built here go through the same pixels the GPU rasterises:

    Camera(np.array(cam.matrix_world.inverted()),
           np.array(cam.calc_matrix_camera(depsgraph, x=W, y=H)), W, H)

(checked once against bpy_extras.object_utils.world_to_camera_view with bpy
5.0.1, lens shift included: 5e-8 apart in normalised image coordinates).

Pixels: (x, y) with x to the right and y DOWN (numpy row 0 is the top row);
pixel (x, y) covers [x, x+1) x [y, y+1) and its centre is (x + 0.5, y + 0.5).
NDC y = +1 is the top edge of the image.
"""
import numpy as np


def _normalized(v):
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(length > 0, length, 1.0)


class Camera:
    def __init__(self, view_matrix, projection_matrix, width, height):
        self.view_matrix = np.asarray(view_matrix, dtype=np.float64).reshape(4, 4)
        self.projection_matrix = np.asarray(projection_matrix, dtype=np.float64).reshape(4, 4)
        self.width = int(width)
        self.height = int(height)
        self.view_projection = self.projection_matrix @ self.view_matrix
        self.inverse_view_projection = np.linalg.inv(self.view_projection)
        self.camera_to_world = np.linalg.inv(self.view_matrix)
        self.position = self.camera_to_world[:3, 3].copy()

    @classmethod
    def look_at(cls, position, target, up, fov_y_degrees, width, height, near=0.01, far=1000.0):
        """Perspective camera at ``position`` looking at ``target``; fov_y is the full vertical angle."""
        position = np.asarray(position, dtype=np.float64)
        backward = _normalized(position - np.asarray(target, dtype=np.float64))   # camera +z
        right = _normalized(np.cross(np.asarray(up, dtype=np.float64), backward))
        if not np.any(right):
            raise ValueError("up is parallel to the viewing direction")
        true_up = np.cross(backward, right)
        view = np.eye(4)
        view[:3, :3] = np.stack([right, true_up, backward])
        view[:3, 3] = -view[:3, :3] @ position
        focal = 1.0 / np.tan(np.radians(fov_y_degrees) / 2)
        aspect = width / height
        projection = np.zeros((4, 4))
        projection[0, 0] = focal / aspect
        projection[1, 1] = focal
        projection[2, 2] = (far + near) / (near - far)
        projection[2, 3] = 2 * far * near / (near - far)
        projection[3, 2] = -1.0
        return cls(view, projection, width, height)

    def pixel_to_ndc(self, pixel_xy):
        """Continuous pixel coordinates (..., 2) (x right, y down) -> NDC (..., 2) (y up)."""
        pixel_xy = np.asarray(pixel_xy, dtype=np.float64)
        ndc_x = 2.0 * pixel_xy[..., 0] / self.width - 1.0
        ndc_y = 1.0 - 2.0 * pixel_xy[..., 1] / self.height
        return np.stack([ndc_x, ndc_y], axis=-1)

    def _unproject(self, ndc_xy, ndc_z):
        clip = np.concatenate([ndc_xy, np.full(ndc_xy.shape[:-1] + (1,), ndc_z), np.ones(ndc_xy.shape[:-1] + (1,))], -1)
        world = clip @ self.inverse_view_projection.T
        return world[..., :3] / world[..., 3:4]

    def rays_through(self, pixel_xy):
        """Rays through continuous pixel positions (..., 2): origins on the near plane, unit directions.

        Starting on the near plane (not at the eye) keeps geometry the
        rasteriser clips away out of the reference too, and makes
        orthographic projections work unchanged.
        """
        ndc = self.pixel_to_ndc(pixel_xy)
        near_points = self._unproject(ndc, -1.0)
        far_points = self._unproject(ndc, 1.0)
        return near_points, _normalized(far_points - near_points)

    def primary_rays(self, jitter=None):
        """Rays for every pixel: origins (H, W, 3), directions (H, W, 3).

        jitter: None for pixel centres, or (H, W, 2) offsets in [0, 1) pixel units
        (x right, y down) replacing the 0.5 centre offset.
        """
        y, x = np.mgrid[0:self.height, 0:self.width].astype(np.float64)
        offset = np.full((self.height, self.width, 2), 0.5) if jitter is None else np.asarray(jitter, np.float64)
        return self.rays_through(np.stack([x, y], axis=-1) + offset)

    def project(self, points):
        """World points (..., 3) -> continuous pixel coordinates (..., 2) (x right, y down) and NDC depth (...)."""
        points = np.asarray(points, dtype=np.float64)
        homogeneous = np.concatenate([points, np.ones(points.shape[:-1] + (1,))], -1)
        clip = homogeneous @ self.view_projection.T
        ndc = clip[..., :3] / clip[..., 3:4]
        pixel_x = (ndc[..., 0] + 1.0) * 0.5 * self.width
        pixel_y = (1.0 - ndc[..., 1]) * 0.5 * self.height
        return np.stack([pixel_x, pixel_y], axis=-1), ndc[..., 2]
