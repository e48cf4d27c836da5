"""Shadow maps of the scene's lights in one depth atlas: which lights get one, each tile's projection, and the
lookup the surface shaders make (shaders/lib/shadow_maps.glsl), mirrored here in numpy.

Why: the SSDF visibility of wang2009 widens a small light's shadow edge 1.5-1.8x (docs/ACCURACY.md, "Shadow edge"):
fh's smooth profile stands for the light's disc.  A depth map from the light resolves the edge at its texel
size, and a percentage-closer filter sized by the blocker's distance (PCSS) gives a sphere light's or the sun's
penumbra.  Point and spot lights take six cube faces (drawn where the spot's cone and the casters' box reach), a
sun one orthographic tile over what the camera sees of the casters' box.  Area lights' patches keep the SSDF (a map each would be 16 lights),
and so do lights wider than MAX_LIGHT_ANGLE; where a map's penumbra outgrows its filter, a baked object blends in
the SSDF's visibility (the lookup's softness).

Tile layout: tiles of `size` texels, `columns` a row; each tile keeps a guard band of MARGIN texels beyond its
face (the projection maps the face to the inner size - 2 MARGIN texels), so the filter's taps near a face's
edge read the scene beyond it, not the neighbouring tile.

Depths: a cube face stores the window depth of a perspective projection (near, far) along its axis; a sun's tile
the depth along the light's direction, linear over the casters' range.  The lookup compares window depths and
averages the blockers' linear ones.
"""
import math
from dataclasses import dataclass, field

import numpy as np

FLOAT = np.float32
MARGIN = 16                     # texels of guard band around each face
MAX_SHADOW_MAPS = 8             # lights with a map: the shader's shadow slots (common/surface_common.glsl)
MAX_SIDE = 16384                # the atlas' side where the GPU's limit is not given (llvmpipe's)
MAX_TEXELS = 64 * 1024 * 1024   # 256 MB of DEPTH_COMPONENT32F
DEFAULT_SIZE = 1024
SEARCH_TAPS = 4                 # blocker search: SEARCH_TAPS^2 nearest texels over the search square
FILTER_TAPS = 4                 # filter: at most FILTER_TAPS^2 bilinear comparisons over the filter square
DEPTH_BIAS = 1.5                # texels of depth subtracted from the receiver's
NORMAL_OFFSET = 1.0             # texels the receiver moves along its normal before the lookup
# lights wider than this (radians of angular radius from the casters' centre, or from half their box's diagonal
# when nearer) keep the SSDF: a sphere light of radius 0.75 at 3.2 m (the truth suite's diffuse_sphere_light) scored
# 0.118 against Cycles with a map, 0.102 without: its penumbra outgrows the filter's guard band, and the SSDF's
# smooth profile suits a wide light
MAX_LIGHT_ANGLE = 0.1
FACE_CORNER_ANGLE = math.atan(math.sqrt(2.0))   # a cube face's corner from its axis (54.7 degrees)


@dataclass
class ShadowPlan:
    """The atlas of a frame: tile side, columns, each mapped light's slot and tiles, and the tiles' matrices.

    point_slot (P,) / sun_slot (S,): the light's slot in light_shadow, -1 without a map; point_first_tile (P,):
    its six faces' first tile (face f at first + f); point_near_far (P, 2); sun_tile (S,); sun_rows (S, 3, 4):
    ndc x, ndc y and depth01 of a world point p as rows @ (p, 1); sun_texel (S,): a texel's world size; sun_range
    (S,): the world depth of depth01 1; sun_tan_radius (S,): the tangent of each sun's angular radius (its
    penumbra's slope).  tiles: [(tile, (4, 4) world -> clip matrix)] to render (faces a spot's cone
    or the casters' box misses are left out: their tiles keep the clear, far)."""
    size: int = 0
    columns: int = 1
    rows: int = 1
    point_slot: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))
    point_first_tile: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))
    point_near_far: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), FLOAT))
    sun_slot: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))
    sun_tile: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))
    sun_rows: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 4), FLOAT))
    sun_texel: np.ndarray = field(default_factory=lambda: np.zeros(0, FLOAT))
    sun_range: np.ndarray = field(default_factory=lambda: np.zeros(0, FLOAT))
    sun_tan_radius: np.ndarray = field(default_factory=lambda: np.zeros(0, FLOAT))
    slot_lights: list = field(default_factory=list)      # light index per slot (points, then suns after P)
    tiles: list = field(default_factory=list)

    @property
    def active(self):
        return self.size > 0 and bool(self.slot_lights)

    @property
    def inner(self):
        """The face's share of its tile."""
        return (self.size - 2 * MARGIN) / self.size

    @property
    def atlas_shape(self):
        """(width, height) texels."""
        return self.columns * self.size, self.rows * self.size

    def tile_origin(self, tile):
        """(x, y) texel of tile's corner (row 0 at the bottom, the GPU's)."""
        return (tile % self.columns) * self.size, (tile // self.columns) * self.size


def face_frame(face):
    """Rows (right, up, back) of cube face `face` (0..5: +x, -x, +y, -y, +z, -z): local x, y of a direction d
    are d[(k+1)%3], d[(k+2)%3] and it looks along s e_k (k = face // 2, s = +1 for even faces)."""
    k, sign = face // 2, 1.0 - 2.0 * (face % 2)
    frame = np.zeros((3, 3))
    frame[0, (k + 1) % 3] = 1.0
    frame[1, (k + 2) % 3] = 1.0
    frame[2, k] = -sign
    return frame


def perspective_rows(near, far, inner):
    """(4, 4) clip from a face's camera space: the face's 90 degrees onto inner of the tile."""
    a, b = -(far + near) / (far - near), -2.0 * far * near / (far - near)
    return np.array([[inner, 0, 0, 0], [0, inner, 0, 0], [0, 0, a, b], [0, 0, -1, 0]], np.float64)


def _orthonormal_basis(axis):
    axis = np.asarray(axis, np.float64) / max(np.linalg.norm(axis), 1e-30)
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    right = np.cross(helper, axis)
    right /= np.linalg.norm(right)
    return right, np.cross(axis, right)


def box_corners(boxes):
    """(N, 8, 3) corners of boxes (N, 2, 3) (low, high)."""
    boxes = np.asarray(boxes, np.float64).reshape(-1, 2, 3)
    return np.stack([np.stack([boxes[:, x, 0], boxes[:, y, 1], boxes[:, z, 2]], -1)
                     for x in (0, 1) for y in (0, 1) for z in (0, 1)], 1)


def _faces_of_spot(direction, spot_size):
    """Cube faces a spot's cone (full angle spot_size, negative: a point light) reaches."""
    if spot_size < 0 or spot_size >= math.pi:
        return list(range(6))
    direction = np.asarray(direction, np.float64) / max(np.linalg.norm(direction), 1e-30)
    half = 0.5 * spot_size
    faces = []
    for face in range(6):
        axis = -face_frame(face)[2]
        angle = math.acos(float(np.clip(axis @ direction, -1.0, 1.0)))
        if angle <= half + FACE_CORNER_ANGLE + 1e-3:
            faces.append(face)
    return faces


def in_tile(tile_matrix, corners):
    """(N,) whether each box of corners (N, 8, 3) may reach the tile of world -> clip `tile_matrix`: False only
    when one clip plane has all 8 corners outside (a box with a non-finite corner: True)."""
    clip = np.concatenate([corners, np.ones(corners.shape[:2] + (1,))], -1) @ np.asarray(tile_matrix, np.float64).T
    x, y, z, w = clip[..., 0], clip[..., 1], clip[..., 2], clip[..., 3]
    with np.errstate(invalid="ignore"):
        outside = [x > w, x < -w, y > w, y < -w, z > w, z < -w]
        culled = np.zeros(len(corners), bool)
        for plane in outside:
            culled |= np.all(plane, axis=1)
    return ~culled | ~np.all(np.isfinite(corners), axis=(1, 2))


def view_corners(view_projection, bounds):
    """(8, 3) world corners of the camera's frustum (world -> clip `view_projection`) from its near plane to the
    farthest corner of `bounds` in front of it, or None (the box is behind the camera, or a matrix is singular):
    what the camera can see of the box lies inside them."""
    view_projection = np.asarray(view_projection, np.float64)
    clip = np.c_[box_corners(bounds)[0], np.ones(8)] @ view_projection.T
    front = clip[:, 3] > 1e-12
    if not front.any():
        return None
    far = float(np.clip((clip[front, 2] / clip[front, 3]).max(), -1.0, 1.0))
    try:
        inverse = np.linalg.inv(view_projection)
    except np.linalg.LinAlgError:
        return None
    ndc = np.array([[x, y, z, 1.0] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, far)])
    world = ndc @ inverse.T
    if np.any(np.abs(world[:, 3]) < 1e-30):
        return None
    corners = world[:, :3] / world[:, 3:]
    return corners if np.all(np.isfinite(corners)) else None


def _sun_extent(coordinate_of_bounds, coordinate_of_view):
    """(low, high) of a sun tile's axis: the casters' range, narrowed to the camera's view where it overlaps."""
    low, high = float(coordinate_of_bounds.min()), float(coordinate_of_bounds.max())
    if coordinate_of_view is not None:
        narrowed = max(low, float(coordinate_of_view.min())), min(high, float(coordinate_of_view.max()))
        if narrowed[0] < narrowed[1]:
            return narrowed
    return low, high


def plan(light_data, bounds, size=DEFAULT_SIZE, view=None, max_side=MAX_SIDE):
    """The ShadowPlan of lighting.scene_lighting.LightData for casters within world `bounds` ((2, 3) or None: no
    geometry, no maps); view: view_corners' frustum or None: a sun's tile covers only what of the box it may show
    (its casters are those above, within the box's depth).  Suns first, then point and spot lights in LightData's
    order (the brightest first), MAX_SHADOW_MAPS in all; area light patches and lights wider than MAX_LIGHT_ANGLE
    get none.  The tile side is `size` unless the atlas would pass max_side (the GPU's) or MAX_TEXELS."""
    points, suns = len(light_data.point_radius), len(light_data.sun_sharpness)
    result = ShadowPlan(point_slot=np.full(points, -1, np.int32), point_first_tile=np.zeros(points, np.int32),
                        point_near_far=np.zeros((points, 2), FLOAT), sun_slot=np.full(suns, -1, np.int32),
                        sun_tile=np.zeros(suns, np.int32), sun_rows=np.zeros((suns, 3, 4), FLOAT),
                        sun_texel=np.zeros(suns, FLOAT), sun_range=np.zeros(suns, FLOAT))
    sun_radius = np.asarray(light_data.sun_radius if len(light_data.sun_radius) else np.zeros(suns), np.float64)
    result.sun_tan_radius = np.tan(np.minimum(sun_radius, 1.5)).astype(FLOAT)
    if bounds is None or size <= 2 * MARGIN or not np.all(np.isfinite(bounds)):
        return result
    mapped_suns = [s for s in range(suns) if sun_radius[s] <= MAX_LIGHT_ANGLE][:MAX_SHADOW_MAPS]
    centre = 0.5 * (np.asarray(bounds[0], np.float64) + bounds[1])
    half_diagonal = 0.5 * float(np.linalg.norm(np.asarray(bounds[1], np.float64) - bounds[0]))
    mapped_points = []
    for p in range(points):
        position = np.asarray(light_data.point_position[p], np.float64)
        # a light among the casters (a lamp in a room) sees them at about the room's size
        distance = max(float(np.linalg.norm(position - centre)), half_diagonal) if np.all(np.isfinite(position)) \
            else 0.0
        narrow = distance > 0 and math.atan2(float(light_data.point_radius[p]), distance) <= MAX_LIGHT_ANGLE
        if narrow and light_data.point_emitter[p][0] < 0.5:        # area light patches keep the SSDF
            mapped_points.append(p)
    mapped_points = mapped_points[:MAX_SHADOW_MAPS - len(mapped_suns)]
    tile_count = 6 * len(mapped_points) + len(mapped_suns)
    if tile_count == 0:
        return result
    columns = math.ceil(math.sqrt(tile_count))
    rows = math.ceil(tile_count / columns)
    side = min(int(size), int(max_side) // max(columns, rows), int(math.sqrt(MAX_TEXELS / (columns * rows))))
    side -= side % 4
    if side <= 2 * MARGIN:
        return result
    result.size, result.columns, result.rows = side, columns, rows
    inner = result.inner
    corners = box_corners(bounds)[0]
    tile = 0
    for slot, s in enumerate(mapped_suns):
        forward = -np.asarray(light_data.sun_axis[s], np.float64)
        forward /= max(np.linalg.norm(forward), 1e-30)
        right, up = _orthonormal_basis(forward)
        z = corners @ forward
        u_range = _sun_extent(corners @ right, None if view is None else view @ right)
        v_range = _sun_extent(corners @ up, None if view is None else view @ up)
        half = max(0.5 * max(u_range[1] - u_range[0], v_range[1] - v_range[0]), 1e-6) * 1.01
        centre_u, centre_v = 0.5 * (u_range[0] + u_range[1]), 0.5 * (v_range[0] + v_range[1])
        pad = 0.01 * max(z.max() - z.min(), half) + 1e-6
        z0, z1 = z.min() - pad, z.max() + pad
        result.sun_rows[s] = [np.append(right * inner / half, -centre_u * inner / half),
                              np.append(up * inner / half, -centre_v * inner / half),
                              np.append(forward / (z1 - z0), -z0 / (z1 - z0))]
        result.sun_texel[s] = 2.0 * half / (side * inner)
        result.sun_range[s] = z1 - z0
        result.sun_slot[s], result.sun_tile[s] = slot, tile
        clip = np.eye(4)
        clip[:2] = result.sun_rows[s][:2]
        clip[2] = 2.0 * result.sun_rows[s][2] - np.array([0, 0, 0, 1.0])
        result.tiles.append((tile, clip))
        tile += 1
    for slot, p in enumerate(mapped_points, start=len(mapped_suns)):
        position = np.asarray(light_data.point_position[p], np.float64)
        distances = np.linalg.norm(corners - position, axis=1)
        far = max(float(distances.max()) * 1.01, 1e-3)
        outside = np.maximum(np.maximum(bounds[0] - position, position - bounds[1]), 0.0)
        near = max(0.5 * float(np.linalg.norm(outside)), far * 1e-4)
        result.point_slot[p], result.point_first_tile[p] = slot, tile
        result.point_near_far[p] = near, far
        translate = np.eye(4)
        translate[:3, 3] = -position
        for face in _faces_of_spot(light_data.spot_direction[p], float(light_data.spot_size[p])):
            face_view = np.eye(4)
            face_view[:3, :3] = face_frame(face)
            matrix = perspective_rows(near, far, inner) @ face_view @ translate
            if in_tile(matrix, corners[None])[0]:       # a face that sees none of the casters' box is not drawn
                result.tiles.append((tile + face, matrix))
        tile += 6
    result.slot_lights = [int(s) + points for s in mapped_suns] + mapped_points
    return result


# ----------------------------------------------------------------- the lookup (shaders/lib/shadow_maps.glsl)

def _linear_depth(window, near, far):
    ndc = 2.0 * window - 1.0
    return 2.0 * far * near / np.maximum((far + near) - ndc * (far - near), 1e-30)


def _window_depth(linear, near, far):
    """The window depth a cube face stores at linear depth `linear` (_linear_depth's inverse, increasing)."""
    return 0.5 * ((far + near) / (far - near) - 2.0 * far * near / ((far - near) * np.maximum(linear, 1e-30))) + 0.5


def _fetch(atlas, shadow_plan, tile, texel):
    """Window depth of texel (N, 2) (integer, clamped to the tile) of tiles (N,)."""
    origin = np.stack([tile % shadow_plan.columns, tile // shadow_plan.columns], -1) * shadow_plan.size
    texel = np.clip(texel, 0, shadow_plan.size - 1) + origin
    return atlas[texel[:, 1], texel[:, 0]].astype(np.float64)


def filter_turn(taps):
    """(cos, sin) of atan(1 / taps): a taps x taps grid turned so, its taps' projections on either axis are taps^2
    evenly spaced values, and an edge along an axis crosses them one at a time (a square grid's columns flip
    together: measured as 0.25 steps across a penumbra with 4 x 4)."""
    return taps / math.hypot(taps, 1.0), 1.0 / math.hypot(taps, 1.0)


def tile_visibility(atlas, shadow_plan, tile, ndc, receiver, texel_world, penumbra, linearize, window_of):
    """(visible fraction, softness), (N,) each, at tile-space ndc (N, 2) of receivers at linear depth `receiver`
    (N,): the blocker search, then the filter sized by penumbra(receiver, blocker) (world radius) over
    texel_world (N,); the tile stores window depths (linearize: to linear, window_of: back).  The comparisons are
    made on window depths (the test depth converted once), the blockers' mean on linear ones.  The search reads the
    centre, and a SEARCH_TAPS^2 grid where it spans a texel or more; every tap of that grid blocked: the umbra (0).
    The filter takes a n x n grid of bilinear comparisons, n = ceil(radius) up to FILTER_TAPS (taps at most 2
    texels apart).
    softness: 0 while the penumbra fits the filter, 1 once it reaches the guard band (the filter is clamped there;
    the surface shaders blend a baked object's SSDF visibility in by it)."""
    size = shadow_plan.size
    coords = (0.5 + 0.5 * ndc) * size - 0.5               # continuous texel of the texel centres
    test = receiver - DEPTH_BIAS * texel_world
    test_window = window_of(test)
    search = np.clip(penumbra(receiver, np.zeros_like(receiver)) / texel_world, 0.0, MARGIN - 1.0)
    wide = search >= 1.0
    total = np.zeros_like(receiver)
    count = np.zeros_like(receiver)
    # the centre, then a grid over the search square (a thin blocker at the centre is never missed)
    offsets = [np.zeros(2)] + [(np.array([i, j], FLOAT) + 0.5) / SEARCH_TAPS * 2.0 - 1.0
                               for j in range(SEARCH_TAPS) for i in range(SEARCH_TAPS)]
    for index, offset in enumerate(offsets):
        window = _fetch(atlas, shadow_plan, tile, np.floor(coords + 0.5 + offset * search[:, None]).astype(int))
        blocked = (window < test_window) & (wide if index else True)
        total += np.where(blocked, linearize(window), 0.0)
        count += blocked
    taps = np.where(wide, len(offsets), 1)
    blocker = total / np.maximum(count, 1.0)
    needed = penumbra(receiver, blocker) / texel_world
    radius = np.clip(needed, 0.5, MARGIN - 1.0)
    grid_side = np.clip(np.ceil(radius), 1, FILTER_TAPS).astype(int)
    lit = np.zeros_like(receiver)
    for side in range(1, FILTER_TAPS + 1):
        rows = np.nonzero(grid_side == side)[0]
        if not len(rows):
            continue
        turn = filter_turn(side)
        for j in range(side):
            for i in range(side):
                grid = (np.array([i, j], FLOAT) + 0.5) / side * 2.0 - 1.0
                offset = np.array([turn[0] * grid[0] - turn[1] * grid[1], turn[1] * grid[0] + turn[0] * grid[1]])
                at = coords[rows] + offset * radius[rows, None]
                base = np.floor(at)
                fraction = at - base
                base = base.astype(int)
                corners = [_fetch(atlas, shadow_plan, tile[rows], base + np.array(d)) >= test_window[rows]
                           for d in ((0, 0), (1, 0), (0, 1), (1, 1))]
                bottom = corners[0] + (corners[1].astype(FLOAT) - corners[0]) * fraction[:, 0]
                top = corners[2] + (corners[3].astype(FLOAT) - corners[2]) * fraction[:, 0]
                lit[rows] += (bottom + (top - bottom) * fraction[:, 1]) / side ** 2
    lit = np.where(wide & (count >= taps), 0.0, lit)          # every tap of a wide search blocked: the umbra
    softness = np.clip(2.0 * needed / (MARGIN - 1.0) - 1.0, 0.0, 1.0)
    return np.where(count > 0, lit, 1.0), np.where(count > 0, softness, 0.0)


def point_visibility(atlas, shadow_plan, light_data, p, position, normal):
    """(visible fraction, softness) (N,) of point light p at world positions (N, 3) with normals (N, 3)."""
    near, far = (float(v) for v in shadow_plan.point_near_far[p])
    light = np.asarray(light_data.point_position[p], np.float64)
    radius = float(light_data.point_radius[p])
    inner_texels = shadow_plan.size * shadow_plan.inner
    position = np.asarray(position, np.float64)
    normal = np.asarray(normal, np.float64)
    d = position - light
    z = np.max(np.abs(d), axis=1)
    towards = np.where(np.sum(normal * -d, axis=1, keepdims=True) < 0, -normal, normal)
    d = d + towards * (NORMAL_OFFSET * 2.0 * z / inner_texels)[:, None]
    k = np.argmax(np.abs(d), axis=1)
    rows = np.arange(len(d))
    z = np.maximum(np.abs(d[rows, k]), 1e-30)
    face = 2 * k + (d[rows, k] < 0)
    ndc = np.stack([d[rows, (k + 1) % 3], d[rows, (k + 2) % 3]], -1) / z[:, None] * shadow_plan.inner
    texel_world = 2.0 * z / inner_texels
    tile = shadow_plan.point_first_tile[p] + face
    return tile_visibility(atlas, shadow_plan, tile, ndc, z, texel_world,
                           lambda receiver, blocker: radius * (receiver - blocker) / np.maximum(blocker, near),
                           lambda window: _linear_depth(window, near, far),
                           lambda linear: _window_depth(linear, near, far))


def sun_visibility(atlas, shadow_plan, s, position, normal):
    """(visible fraction, softness) (N,) of sun s at world positions (N, 3) with normals (N, 3)."""
    tan_radius = float(shadow_plan.sun_tan_radius[s])
    rows = np.asarray(shadow_plan.sun_rows[s], np.float64)
    texel = float(shadow_plan.sun_texel[s])
    depth_range = float(shadow_plan.sun_range[s])
    position = np.asarray(position, np.float64)
    normal = np.asarray(normal, np.float64)
    forward = rows[2, :3] * depth_range
    towards = np.where((normal @ forward)[:, None] > 0, -normal, normal)
    moved = position + towards * NORMAL_OFFSET * texel
    homogeneous = np.concatenate([moved, np.ones((len(moved), 1))], 1)
    ndc = homogeneous @ rows[:2].T
    receiver = (homogeneous @ rows[2]) * depth_range
    inside = np.all(np.abs(ndc) <= 1.0, axis=1)
    visible, softness = tile_visibility(atlas, shadow_plan, np.full(len(position), shadow_plan.sun_tile[s]), ndc,
                                        receiver, np.full(len(position), texel), lambda r, b: tan_radius * (r - b),
                                        lambda window: window * depth_range, lambda linear: linear / depth_range)
    return np.where(inside, visible, 1.0), np.where(inside, softness, 0.0)


def light_visibility(atlas, shadow_plan, light_data, position, normal):
    """(N, P + S, 2) each light's shadow-map (visible fraction, softness) at world positions (N, 3) with normals
    (N, 3), NaN for a light without a map: the surface shaders' light_shadow (common/surface_common.glsl
    shadow_maps_evaluate)."""
    points, suns = len(light_data.point_radius), len(light_data.sun_sharpness)
    out = np.full((len(position), points + suns, 2), np.nan, FLOAT)
    for p in range(points):
        if shadow_plan.point_slot[p] >= 0:
            out[:, p] = np.stack(point_visibility(atlas, shadow_plan, light_data, p, position, normal), -1)
    for s in range(suns):
        if shadow_plan.sun_slot[s] >= 0:
            out[:, points + s] = np.stack(sun_visibility(atlas, shadow_plan, s, position, normal), -1)
    return out
