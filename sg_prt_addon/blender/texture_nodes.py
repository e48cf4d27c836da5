"""The procedural texture nodes read as node functions of their inputs (reflectance/node_functions.py, voronoi.py):
Checker, Gradient, Noise, Wave, Magic, White Noise, Voronoi and Brick, as Cycles defines them.  `value(reader, node, out)` is what
node_reader.SocketReader reads for an output of one of NODE_TYPES."""
from ..reflectance import voronoi
from ..reflectance.texture_expression import Expression
from .node_graph import enabled_inputs

NODE_TYPES = ("TEX_CHECKER", "TEX_GRADIENT", "TEX_NOISE", "TEX_WAVE", "TEX_MAGIC", "TEX_WHITE_NOISE", "TEX_VORONOI",
              "TEX_BRICK")
NOISE_DEFAULTS = {"Scale": 5.0, "Detail": 2.0, "Roughness": 0.5, "Lacunarity": 2.0, "Offset": 0.0, "Gain": 1.0,
                  "Distortion": 0.0}


def value(reader, node, out):
    """The Expression of a procedural texture's output `out` (reader: the node_reader.SocketReader)."""
    return {"TEX_CHECKER": checker, "TEX_GRADIENT": gradient, "TEX_NOISE": noise, "TEX_WAVE": wave,
            "TEX_MAGIC": magic, "TEX_WHITE_NOISE": white_noise, "TEX_VORONOI": voronoi_texture,
            "TEX_BRICK": brick}[node.type](
                reader, node, out)


def texture_vector(reader, node, unlinked="GENERATED"):
    """A texture's Vector: its input, or where it is unlinked the coordinates Blender gives it (Generated for
    every texture with a texture mapping; the position for White Noise); 0 where the node hides it (1D)."""
    socket = enabled_inputs(node, "Vector")[0]
    if socket is None:
        return Expression.constant(0.0)
    return reader.value(socket, True) if socket.is_linked else Expression.coordinates(unlinked)


def _output(out, colour_name="Color", other="Fac"):
    return colour_name if out.identifier == colour_name else other


def checker(reader, node, out):
    """The Checker texture's Color or Fac."""
    values = [texture_vector(reader, node)] + [reader.value(node.inputs[name], name != "Scale")
                                               for name in ("Color1", "Color2", "Scale")]
    return Expression.function("tex_checker", (_output(out),), values)


def gradient(reader, node, out):
    """The Gradient texture's Fac (its Color is the same grey)."""
    return Expression.function("tex_gradient", (node.gradient_type,), (texture_vector(reader, node),))


def noise(reader, node, out):
    """The Noise Texture in 3D, of each of its types (another dimension count is read as 3D)."""
    if getattr(node, "noise_dimensions", "3D") != "3D":
        reader.note(node, f"{node.noise_dimensions} noise: read as 3D")
    values = [texture_vector(reader, node)]
    for name, default in NOISE_DEFAULTS.items():
        socket = enabled_inputs(node, name)[0]
        values.append(reader.value(socket, False) if socket is not None else Expression.constant(default))
    settings = (getattr(node, "noise_type", "FBM"), bool(getattr(node, "normalize", True)), _output(out))
    return Expression.function("tex_noise", settings, values)


def wave(reader, node, out):
    """The Wave Texture's Fac (its Color is the same grey)."""
    names = ("Scale", "Distortion", "Detail", "Detail Scale", "Detail Roughness", "Phase Offset")
    values = [texture_vector(reader, node)] + [reader.value(node.inputs[name], False) for name in names]
    settings = (node.wave_type, node.bands_direction, node.rings_direction, node.wave_profile, _output(out))
    return Expression.function("tex_wave", settings, values)


def magic(reader, node, out):
    """The Magic Texture's Color or Fac."""
    values = [texture_vector(reader, node)] + [reader.value(node.inputs[name], False)
                                               for name in ("Scale", "Distortion")]
    return Expression.function("tex_magic", (int(node.turbulence_depth), _output(out)), values)


def white_noise(reader, node, out):
    """The White Noise Texture's Value or Color, in each dimension count (its W where it reads one)."""
    w_socket = enabled_inputs(node, "W")[0]
    w = reader.value(w_socket, False) if w_socket is not None else Expression.constant(0.0)
    settings = (getattr(node, "noise_dimensions", "3D"), _output(out, "Color", "Value"))
    return Expression.function("tex_white_noise", settings, (texture_vector(reader, node, "POSITION"), w))


def voronoi_texture(reader, node, out):
    """The Voronoi Texture in 3D (another dimension count is read as 3D): its Distance, Color, Position or
    Radius for every feature and metric, with its fractal Detail."""
    if getattr(node, "voronoi_dimensions", "3D") != "3D":
        reader.note(node, f"{node.voronoi_dimensions} Voronoi: read as 3D")
    defaults = {"Scale": 5.0, "Detail": 0.0, "Roughness": 0.5, "Lacunarity": 2.0, "Smoothness": 1.0,
                "Exponent": 0.5, "Randomness": 1.0}
    values = [texture_vector(reader, node)]
    for name, default in defaults.items():
        socket = enabled_inputs(node, name)[0]
        values.append(reader.value(socket, False) if socket is not None else Expression.constant(default))
    if out.identifier not in voronoi.OUTPUTS:
        reader.note(node, f"its {out.name} output (1D and 4D): 0 is used")
        return Expression.constant(0.0)
    settings = (node.feature, node.distance, bool(getattr(node, "normalize", False)), out.identifier)
    return Expression.function("tex_voronoi", settings, values)


def brick(reader, node, out):
    """The Brick Texture's Color or Fac (its Offset and Squash and their frequencies are the node's settings)."""
    names = ("Color1", "Color2", "Mortar", "Scale", "Mortar Size", "Mortar Smooth", "Bias", "Brick Width",
             "Row Height")
    values = [texture_vector(reader, node)] + [reader.value(node.inputs[name], name in ("Color1", "Color2", "Mortar"))
                                               for name in names]
    settings = (float(node.offset), int(node.offset_frequency), float(node.squash), int(node.squash_frequency),
                _output(out))
    return Expression.function("tex_brick", settings, values)
