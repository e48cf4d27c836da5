"""The Voronoi Texture in 3D as Cycles computes it (kernel/svm/voronoi.h): feature points jittered in each unit
cell by PCG 3D's integer hash of the cell, F1, F2, smooth F1, the distance to the nearest edge and the n-sphere
radius under each distance metric, and the fractal sum of octaves (Detail, Roughness, Lacunarity, Normalize).
float32 throughout; shaders/lib/voronoi.glsl is its GLSL twin."""
import numpy as np

FLOAT = np.float32
FEATURES = ("F1", "F2", "SMOOTH_F1", "DISTANCE_TO_EDGE", "N_SPHERE_RADIUS")
METRICS = ("EUCLIDEAN", "MANHATTAN", "CHEBYCHEV", "MINKOWSKI")
OUTPUTS = ("Distance", "Color", "Position", "Radius")
# the 3 x 3 x 3 cells around a point's, i fastest (the order ties resolve in), and the 5 x 5 x 5 of smooth F1
NEIGHBOURS = np.array([(i, j, k) for k in (-1, 0, 1) for j in (-1, 0, 1) for i in (-1, 0, 1)], np.int32)
WIDE_NEIGHBOURS = np.array([(i, j, k) for k in range(-2, 3) for j in range(-2, 3) for i in range(-2, 3)], np.int32)
_PCG_MULTIPLIER, _PCG_INCREMENT = np.int32(1664525), np.int32(1013904223)


def pcg3d(cells):
    """PCG 3D of integer cells (..., 3) int32, signed and wrapping, masked to 31 bits."""
    v = np.asarray(cells, np.int32) * _PCG_MULTIPLIER + _PCG_INCREMENT
    x, y, z = (v[..., k].copy() for k in range(3))
    for _ in range(2):
        x += y * z
        y += z * x
        z += x * y
        if _ == 0:
            x, y, z = x ^ (x >> 16), y ^ (y >> 16), z ^ (z >> 16)
    return np.stack([x, y, z], axis=-1) & np.int32(0x7FFFFFFF)


def cell_hash(cells):
    """Cycles' hash_int3_to_float3: PCG 3D over 2^31, in [0, 1)."""
    return pcg3d(cells).astype(FLOAT) * FLOAT(1.0 / 2147483648.0)


def distance(a, b, metric, exponent):
    """The metric's distance between points (..., 3); exponent (...,) for Minkowski."""
    difference = np.abs(np.asarray(a, FLOAT) - np.asarray(b, FLOAT))
    if metric == "EUCLIDEAN":
        return np.sqrt(np.sum(difference * difference, axis=-1))
    if metric == "MANHATTAN":
        return np.sum(difference, axis=-1)
    if metric == "CHEBYCHEV":
        return np.max(difference, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return np.power(np.sum(np.power(difference, exponent[..., None]), axis=-1), FLOAT(1) / exponent)


def _cells(coord):
    cell = np.floor(coord)
    return cell.astype(np.int32), (coord - cell).astype(FLOAT)


def _point(cell, offset, randomness):
    """A neighbour's feature point relative to the point's cell, and its cell."""
    neighbour = cell + offset
    return offset.astype(FLOAT) + cell_hash(neighbour) * randomness[..., None], neighbour


def f1_or_f2(coord, params, second=False):
    """(distance, colour, position) of the nearest (with `second`: the second nearest) feature point."""
    cell, local = _cells(coord)
    shape = local.shape[:-1]
    far = np.full(shape, np.finfo(FLOAT).max, FLOAT)
    nearest = [far, np.zeros(shape + (3,), FLOAT), np.zeros(shape + (3,), np.int32)]     # distance, point, cell
    runner_up = [far.copy(), np.zeros(shape + (3,), FLOAT), np.zeros(shape + (3,), np.int32)]
    for offset in NEIGHBOURS:
        point, neighbour = _point(cell, offset, params["randomness"])
        d = distance(point, local, params["metric"], params["exponent"])
        nearer = d < nearest[0]
        next_nearer = ~nearer & (d < runner_up[0])
        new = (d, point, neighbour)
        for k in range(3):
            where_nearer = nearer if k == 0 else nearer[..., None]
            where_next = next_nearer if k == 0 else next_nearer[..., None]
            runner_up[k] = np.where(where_nearer, nearest[k], np.where(where_next, new[k], runner_up[k]))
            nearest[k] = np.where(where_nearer, new[k], nearest[k])
    found, point, neighbour = runner_up if second else nearest
    return found, cell_hash(neighbour), (point + cell).astype(FLOAT)


def _smoothstep(x):
    t = np.clip(x, 0, 1)
    return t * t * (FLOAT(3) - FLOAT(2) * t)


def smooth_f1(coord, params):
    """(distance, colour, position) of smooth F1: the 5 x 5 x 5 cells' points blended by a smooth minimum."""
    cell, local = _cells(coord)
    smoothness = params["smoothness"]
    shape = local.shape[:-1]
    smooth_distance = np.zeros(shape, FLOAT)
    colour, position = np.zeros(shape + (3,), FLOAT), np.zeros(shape + (3,), FLOAT)
    h = None
    for offset in WIDE_NEIGHBOURS:
        point, neighbour = _point(cell, offset, params["randomness"])
        d = distance(point, local, params["metric"], params["exponent"])
        with np.errstate(divide="ignore", invalid="ignore"):
            h = np.ones(shape, FLOAT) if h is None else \
                _smoothstep(FLOAT(0.5) + FLOAT(0.5) * (smooth_distance - d) / smoothness).astype(FLOAT)
        correction = smoothness * h * (FLOAT(1) - h)
        smooth_distance = smooth_distance + (d - smooth_distance) * h - correction
        correction = correction / (FLOAT(1) + FLOAT(3) * smoothness)
        colour = colour + (cell_hash(neighbour) - colour) * h[..., None] - correction[..., None]
        position = position + (point - position) * h[..., None] - correction[..., None]
    return smooth_distance.astype(FLOAT), colour.astype(FLOAT), (cell + position).astype(FLOAT)


def distance_to_edge(coord, params):
    """The distance to the nearest edge of the nearest point's cell (Euclidean)."""
    cell, local = _cells(coord)
    shape = local.shape[:-1]
    vectors = [(_point(cell, offset, params["randomness"])[0] - local) for offset in NEIGHBOURS]
    closest = np.zeros(shape + (3,), FLOAT)
    least = np.full(shape, np.finfo(FLOAT).max, FLOAT)
    for vector in vectors:
        d = np.sum(vector * vector, axis=-1)
        nearer = d < least
        least = np.where(nearer, d, least)
        closest = np.where(nearer[..., None], vector, closest)
    least = np.full(shape, np.finfo(FLOAT).max, FLOAT)
    for vector in vectors:
        perpendicular = vector - closest
        length_squared = np.sum(perpendicular * perpendicular, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            edge = np.sum((closest + vector) / FLOAT(2) * perpendicular / np.sqrt(length_squared)[..., None], axis=-1)
        least = np.where(length_squared > FLOAT(0.0001), np.minimum(least, edge), least)
    return least.astype(FLOAT)


def n_sphere_radius(coord, params):
    """Half the distance from the nearest point to the point nearest it (Euclidean)."""
    cell, local = _cells(coord)
    shape = local.shape[:-1]
    least = np.full(shape, np.finfo(FLOAT).max, FLOAT)
    closest, closest_offset = np.zeros(shape + (3,), FLOAT), np.zeros(shape + (3,), np.int32)
    for offset in NEIGHBOURS:
        point, _ = _point(cell, offset, params["randomness"])
        d = distance(point, local, "EUCLIDEAN", None)
        nearer = d < least
        least = np.where(nearer, d, least)
        closest = np.where(nearer[..., None], point, closest)
        closest_offset = np.where(nearer[..., None], offset, closest_offset)
    least = np.full(shape, np.finfo(FLOAT).max, FLOAT)
    nearest_to_closest = np.zeros(shape + (3,), FLOAT)
    for offset in NEIGHBOURS:
        if not offset.any():
            continue
        point, _ = _point(cell, offset + closest_offset, params["randomness"])
        d = distance(closest, point, "EUCLIDEAN", None)
        nearer = d < least
        least = np.where(nearer, d, least)
        nearest_to_closest = np.where(nearer[..., None], point, nearest_to_closest)
    return (distance(nearest_to_closest, closest, "EUCLIDEAN", None) / FLOAT(2)).astype(FLOAT)


def _octave(coord, params):
    if params["feature"] == "F2":
        return f1_or_f2(coord, params, second=True)
    if params["feature"] == "SMOOTH_F1":
        smooth = params["smoothness"] != 0
        if np.all(smooth):
            return smooth_f1(coord, params)
        plain, rough = f1_or_f2(coord, params), smooth_f1(coord, params)
        return tuple(np.where(smooth if a.ndim == smooth.ndim else smooth[..., None], b, a)
                     for a, b in zip(plain, rough))
    return f1_or_f2(coord, params)


def _mix(a, b, t):
    return a + (b - a) * t


def _octave_masks(detail, roughness):
    """For each octave of the fractal sum (as fBM Noise sums them), the points where it is (first) the one octave
    (Detail or Roughness 0), (whole) a whole octave, (part) the fractional last one."""
    zero_input = (detail == 0) | (roughness == 0)
    fractional = detail != np.floor(detail)
    for i in range(int(np.ceil(detail.max())) + 1 if detail.size else 1):
        live = (i <= np.ceil(detail)) & ~(zero_input & (i > 0))
        if not live.any():
            return
        yield live & zero_input, live & ~zero_input & (i <= detail), live & ~zero_input & (i > detail) & fractional


def fractal(coord, params):
    """(distance, colour, position) summed over the octaves as fBM sums noise (the position blended, not
    summed), normalized by the amplitudes' sum and the largest distance where Normalize is on."""
    detail, roughness, lacunarity = params["detail"], params["roughness"], params["lacunarity"]
    shape = detail.shape
    amplitude, max_amplitude, scale = np.ones(shape, FLOAT), np.zeros(shape, FLOAT), np.ones(shape, FLOAT)
    out_distance, colour, position = np.zeros(shape, FLOAT), np.zeros(shape + (3,), FLOAT), np.zeros(shape + (3,), FLOAT)
    remainder = detail - np.floor(detail)
    for first, whole, part in _octave_masks(detail, roughness):
        d, c, p = _octave(coord * scale[..., None], params)
        out_distance = np.where(first, d, out_distance)
        colour = np.where(first[..., None], c, colour)
        position = np.where(first[..., None], p, position)
        max_amplitude = np.where(first, FLOAT(1), max_amplitude)
        octave_position = _mix(position, p / scale[..., None], amplitude[..., None])
        new_max = np.where(whole, max_amplitude + amplitude,
                           np.where(part, _mix(max_amplitude, max_amplitude + amplitude, remainder), max_amplitude))
        out_distance = np.where(whole, out_distance + d * amplitude,
                                np.where(part, _mix(out_distance, out_distance + d * amplitude, remainder),
                                         out_distance))
        colour = np.where(whole[..., None], colour + c * amplitude[..., None],
                          np.where(part[..., None], _mix(colour, colour + c * amplitude[..., None], remainder[..., None]),
                                   colour))
        position = np.where(whole[..., None], octave_position,
                            np.where(part[..., None], _mix(position, octave_position, remainder[..., None]), position))
        max_amplitude = new_max
        scale = np.where(whole, scale * lacunarity, scale)
        amplitude = np.where(whole, amplitude * roughness, amplitude)
    normalize = params["normalize"]
    if normalize:
        out_distance = out_distance / (max_amplitude * params["max_distance"])
        colour = colour / max_amplitude[..., None]
    scale_out = params["scale"][..., None]
    position = np.where(scale_out != 0, position / np.where(scale_out != 0, scale_out, 1), 0)
    return out_distance.astype(FLOAT), colour.astype(FLOAT), position.astype(FLOAT)


def fractal_distance_to_edge(coord, params):
    """The distance to the nearest edge over the octaves (each octave's, in its scale, can only bring it
    nearer), normalized by the largest distance where Normalize is on."""
    detail, roughness, lacunarity, largest = (params[name] for name in ("detail", "roughness", "lacunarity",
                                                                         "max_distance"))
    shape = detail.shape
    amplitude, max_amplitude, scale = np.ones(shape, FLOAT), largest.astype(FLOAT), np.ones(shape, FLOAT)
    out = np.full(shape, FLOAT(8), FLOAT)
    remainder = detail - np.floor(detail)
    for first, whole, part in _octave_masks(detail, roughness):
        octave = distance_to_edge(coord * scale[..., None], params)
        nearer = _mix(out, np.minimum(out, octave / scale), amplitude)
        lerp_amplitude = _mix(max_amplitude, largest / scale, amplitude)
        out = np.where(first, octave, np.where(whole, nearer, np.where(part, _mix(out, np.minimum(out, nearer),
                                                                                   remainder), out)))
        max_amplitude = np.where(whole, lerp_amplitude,
                                 np.where(part, _mix(max_amplitude, lerp_amplitude, remainder), max_amplitude))
        scale = np.where(whole, scale * lacunarity, scale)
        amplitude = np.where(whole, amplitude * roughness, amplitude)
    if params["normalize"]:
        out = out / max_amplitude
    return out.astype(FLOAT)


def tex_voronoi(settings, vector, scale, detail, roughness, lacunarity, smoothness, exponent, randomness):
    """The Voronoi Texture in 3D (settings: feature, metric, normalize, output: Distance, Color, Position or
    Radius; the scalar inputs on all three channels): the output on all three (a colour or position as it
    is)."""
    feature, metric, normalize, output = settings
    shape = np.shape(vector)[:-1]
    arrays = [np.asarray(a, FLOAT).reshape(-1, 3) for a in (vector, scale, detail, roughness, lacunarity,
                                                              smoothness, exponent, randomness)]
    vector = arrays[0]
    scale, detail, roughness, lacunarity, smoothness, exponent, randomness = (a[:, 0] for a in arrays[1:])
    randomness = np.clip(randomness, 0, 1)
    params = {"feature": feature, "metric": metric, "normalize": normalize, "scale": scale,
              "detail": np.clip(detail, 0, 15), "roughness": np.clip(roughness, 0, 1), "lacunarity": lacunarity,
              "smoothness": np.clip(smoothness / FLOAT(2), 0, FLOAT(0.5)), "exponent": exponent,
              "randomness": randomness}
    coord = (vector * scale[:, None]).astype(FLOAT)
    half = (FLOAT(0.5) + FLOAT(0.5) * randomness)
    if feature == "DISTANCE_TO_EDGE":
        params["max_distance"] = half
        value = np.repeat(fractal_distance_to_edge(coord, params)[:, None], 3, axis=-1)
    elif feature == "N_SPHERE_RADIUS":
        value = np.repeat(n_sphere_radius(coord, params)[:, None], 3, axis=-1)
        value = value if output == "Radius" else np.zeros_like(value)
    else:
        corner = np.repeat(half[:, None], 3, axis=-1)
        params["max_distance"] = distance(np.zeros_like(corner), corner, metric, exponent) * \
            FLOAT(2 if feature == "F2" else 1)
        d, colour, position = fractal(coord, params)
        value = {"Distance": np.repeat(d[:, None], 3, axis=-1), "Color": colour, "Position": position}.get(
            output, np.zeros_like(colour))
    if feature == "DISTANCE_TO_EDGE" and output != "Distance":
        value = np.zeros_like(value)
    return value.reshape(shape + (3,)).astype(FLOAT)
