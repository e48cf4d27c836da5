"""The world: an Environment Texture's equirect pixels, else the world colour."""
from dataclasses import dataclass

import numpy as np

from ..images import image_has_pixels, image_pixels
from .lights import finite_setting
from .messages import finite_texels, warn
from .textures import no_pixels_reason


@dataclass
class WorldExport:
    """A constant colour, or an equirect image (H, W, 3) float32 in numpy orientation (row 0 at the top)."""
    colour: tuple = (0.05, 0.05, 0.05)
    image_name: str = ""
    equirect: np.ndarray = None
    strength: float = 1.0


# --------------------------------------------------------------------------- world

def export_world(world):
    """WorldExport of a bpy World from its node tree (blender/world_reader.py: a Background's colour or
    Environment Texture, turned by a Mapping node, and its strength), else its colour."""
    if world is None:
        return WorldExport(colour=(0.0, 0.0, 0.0))
    import bpy

    from .. import world_reader

    colour = tuple(world.color)
    # Blender 5 always renders worlds with nodes (use_nodes is deprecated there)
    uses_nodes = world.node_tree is not None and (bpy.app.version >= (5, 0, 0) or world.use_nodes)
    reading = world_reader.read_world(world) if uses_nodes else world_reader.WorldReading()
    if reading.notes:
        warn(f"world '{world.name}' (node tree): " + "; ".join(reading.notes))
    strength = finite_setting(reading.strength, 0.0, f"world '{world.name}': strength")
    if reading.colour is not None:
        colour = tuple(reading.colour)[:3]
    if not np.all(np.isfinite(colour[:3])):
        warn(f"world '{world.name}': colour {tuple(colour[:3])} not finite, 0 used there")
        colour = tuple(float(c) if np.isfinite(c) else 0.0 for c in colour[:3])
    image = reading.image
    if image is not None and not image_has_pixels(image):
        warn(f"world '{world.name}': image '{image.name}': {no_pixels_reason(image)}: the "
             f"world colour {tuple(round(float(c), 4) for c in colour[:3])} used")
    elif image is not None:
        pixels = image_pixels(image)[::-1, :, :3]      # numpy orientation, row 0 at the top
        with np.errstate(over="ignore", invalid="ignore"):      # huge x strength: Inf, repaired below
            pixels = pixels * np.float32(strength)
        pixels = finite_texels(pixels, f"world '{world.name}': image '{image.name}'")
        if reading.matrix is not None and not np.allclose(reading.matrix, np.eye(3)):
            from ...lighting import equirect
            pixels = equirect.rotated(pixels, reading.matrix)
        return WorldExport(colour=colour, image_name=image.name, equirect=np.ascontiguousarray(pixels, np.float32),
                           strength=strength)
    return WorldExport(colour=tuple(float(c) * strength for c in colour[:3]), strength=strength)
