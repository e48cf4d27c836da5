"""A bi-scale material's small-scale tile read from Blender (material.sgprt.biscale) and its BVNDF
(biscale.bvndf), computed when the tile or its settings change and kept by content: an edit of the height
image or the tile mesh makes the next export (the viewport's next frame) recompute it; a redraw does not.

Failures (no image, an unreadable file, NaN heights, a tile that faces down) leave the material rendering with
the default technique and a warning that names the reason, as export does for any unusable technique.
"""
import hashlib
import time
from collections import OrderedDict

import numpy as np

from ....biscale import bvndf, microgeometry
from ....blender.images import image_has_pixels, image_pixels

CACHE_SIZE = 8
_cache = OrderedDict()          # content key -> (BVNDF, its tile's triangles), least recently used first
_status = {}                    # material name -> the last computation's one-line report (the panel shows it)


def last_status(material):
    return _status.get(material.name, "")


def _image_heights(image):
    if image is None:
        raise ValueError("no height image")
    if not image_has_pixels(image):
        raise ValueError(f"height image '{image.name}': file '{image.filepath}' missing or unreadable")
    pixels = image_pixels(image)
    # Blender's row 0 is the bottom: the tile's rows start at the top (biscale.microgeometry)
    return np.flipud(pixels[..., :3].mean(axis=-1))


def _tile_mesh(obj):
    if obj is None:
        raise ValueError("no tile object")
    mesh = obj.data
    mesh.calc_loop_triangles()
    vertices = np.empty(len(mesh.vertices) * 3, np.float64)
    mesh.vertices.foreach_get("co", vertices)
    triangles = np.empty(len(mesh.loop_triangles) * 3, np.int64)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    vertices = vertices.reshape(-1, 3)
    if not len(vertices):
        raise ValueError(f"tile object '{obj.name}' has no vertices")
    low = vertices.min(axis=0)
    size = np.ptp(vertices[:, :2], axis=0)
    return vertices - np.array([low[0], low[1], 0.0]), triangles.reshape(-1, 3), (float(size[0]), float(size[1]))


def _geometry_and_key(settings, second=False):
    """(a function building the microgeometry, content key) of the settings' tile (second: the mask's second
    tile, a height image): the pixels or the mesh are read for the key, the tile is built only when needed."""
    digest = hashlib.sha1()
    if second or settings.source == "IMAGE":
        image, scale = ((settings.second_height_image, settings.second_height_scale) if second
                        else (settings.height_image, settings.height_scale))
        heights = _image_heights(image)
        digest.update(np.ascontiguousarray(heights, np.float32).tobytes())
        digest.update(repr(float(scale)).encode())

        def build():
            return microgeometry.from_height_field(heights, height_scale=float(scale))
    else:
        vertices, triangles, size = _tile_mesh(settings.tile_object)
        digest.update(vertices.tobytes() + triangles.tobytes())

        def build():
            return microgeometry.from_mesh(vertices, triangles, size)
    digest.update(repr((second or settings.source, int(settings.lobes), int(settings.resolution),
                        int(settings.samples))).encode())
    return build, digest.hexdigest()


def masked(settings):
    """Whether the settings choose between two tiles (a mask and a second height image)."""
    return settings.mask is not None and settings.second_height_image is not None


def reads(material):
    """The datablocks the tiles come from, as export.MaterialParams.reads holds them."""
    settings = material.sgprt.biscale
    out = ()
    if settings.source == "IMAGE":
        out = () if settings.height_image is None else (("IMAGE", settings.height_image.name),)
    elif settings.tile_object is not None:
        tile = settings.tile_object
        out = (("OBJECT", tile.name),) + ((("MESH", tile.data.name),) if tile.data else ())
    return out + ((("IMAGE", settings.second_height_image.name),) if masked(settings) else ())


def geometry(material, second=False):
    """The material's biscale.microgeometry tile, or its second (ValueError with the reason when it has none)."""
    return _geometry_and_key(material.sgprt.biscale, second)[0]()


def _tile_tables(settings, second):
    """(BVNDF, seconds computing it (0 when cached), its triangles) of one tile; ValueError says why there is
    none."""
    build, key = _geometry_and_key(settings, second)
    cached = _cache.get(key)
    if cached is not None:
        _cache.move_to_end(key)
        return cached[0], 0.0, cached[1]
    start = time.perf_counter()
    geometry = build()
    model = bvndf.compute(geometry, lobes=int(settings.lobes), resolution=int(settings.resolution),
                          samples=int(settings.samples))
    _cache[key] = (model, len(geometry.triangles))
    while len(_cache) > CACHE_SIZE:
        _cache.popitem(last=False)
    return model, time.perf_counter() - start, len(geometry.triangles)


def tables(material):
    """(BVNDF or bvndf.MaskedTiles, None) of the material's tile(s), or (None, the reason it has none)."""
    settings = material.sgprt.biscale
    try:
        model, seconds, triangles = _tile_tables(settings, False)
        if masked(settings):
            second, more, other = _tile_tables(settings, True)
            model, seconds, triangles = bvndf.MaskedTiles(model, second), seconds + more, triangles + other
    except ValueError as error:
        _status[material.name] = str(error)
        return None, str(error)
    if seconds:
        _status[material.name] = f"{model.lobe_count} lobes from {triangles} triangles in {seconds:.2f} s"
    return model, None
