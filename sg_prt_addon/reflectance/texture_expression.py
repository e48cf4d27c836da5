"""Values a node tree computes per pixel: sums of products of constants and factors (an affine function of an
image, such as 1 - metallic, or of one of its channels; a colour attribute; the surface's coordinates; a node
function of other Expressions: reflectance/node_functions.py), with the arithmetic of the formulas that use
them (reflectance/principled.py writes kd = base (1 - metallic) once for numbers and for textures).  A value
with no factor is a constant; with one plain image it is the engine's factor x texture; anything else is
computed per pixel (techniques/material_textures.py writes it in GLSL; `values` and `bound` are its numpy
mirrors).

Colours are RGB triples throughout: a scalar constant c is (c, c, c), and a scalar slot reads the red channel.
"""
from dataclasses import dataclass, replace

import numpy as np

# The surface's coordinates a value may read (Texture Coordinate, Geometry and UV Map nodes): UV (the material's
# texture coordinates), SECOND_UV (the mesh's second UV map), OBJECT (object space), GENERATED (object space in
# the mesh's texture space, [0, 1] over its box), NORMAL (object space), POSITION, WORLD_NORMAL and INCOMING
# (toward the viewer; world space)
COORDINATES = ("UV", "SECOND_UV", "OBJECT", "GENERATED", "NORMAL", "POSITION", "WORLD_NORMAL", "INCOMING")


@dataclass(frozen=True)
class Function:
    """A node function (reflectance.node_functions.apply) of Expressions, per pixel: its name, the node's
    fixed settings (hashable) and its inputs."""
    name: str
    settings: tuple
    args: tuple


@dataclass(frozen=True)
class Factor:
    """offset + scale x an image's RGB (linear, as Blender decodes it), or x one of its channels on all three
    (channel 0, 1, 2: a Separate Color's output); with `attribute`, `image` names a mesh's colour attribute
    (its corners' linear RGB, interpolated over the triangle) in place of an image; with `function`, the
    function's value takes the image's place (image ""), with `coordinates` the surface's coordinates of that
    name (COORDINATES)."""
    image: str
    scale: float = 1.0
    offset: float = 0.0
    channel: int = None
    attribute: bool = False
    function: Function = None
    coordinates: str = None

    def sort_key(self):
        return (self.attribute, self.image, str(self.coordinates), repr(self.function), self.scale, self.offset,
                -1 if self.channel is None else self.channel)

    def values(self, rgb):
        """Its image's RGB (..., 3) as this factor reads it."""
        rgb = np.asarray(rgb)
        return rgb if self.channel is None else np.repeat(rgb[..., self.channel:self.channel + 1], 3, axis=-1)


def _rgb(value):
    values = np.broadcast_to(np.asarray(value, np.float64), (3,))
    return tuple(float(v) for v in values)


@dataclass(frozen=True)
class Expression:
    """sum over terms of coefficient (RGB) x the product of the term's factors; hashable."""
    terms: tuple = ()
    __array_ufunc__ = None          # numpy arrays defer to its arithmetic (array * Expression is an Expression)

    @staticmethod
    def constant(value):
        return Expression(((_rgb(value), ()),))

    @staticmethod
    def image(name, scale=1.0, offset=0.0):
        return Expression((((1.0, 1.0, 1.0), (Factor(name, float(scale), float(offset)),)),))

    @staticmethod
    def function(name, settings, args):
        """node_functions.apply(name, settings, args) per pixel; computed now where every input is constant."""
        args = tuple(Expression.of(arg) for arg in args)
        constants = [arg.as_constant() for arg in args]
        if all(value is not None for value in constants):
            from .node_functions import apply

            value = apply(name, settings, [np.asarray(c, np.float32) for c in constants])
            return Expression.constant(tuple(float(v) for v in np.asarray(value).reshape(3)))
        return Expression((((1.0, 1.0, 1.0), (Factor("", function=Function(name, tuple(settings), args)),)),))

    @staticmethod
    def image_at(name, extension, vector, output="Color"):
        """Image `name` read at texture coordinates vector's (x, y), past its edges as `extension` says
        (REPEAT, EXTEND, CLIP, MIRROR): its Color, or its Alpha on all three."""
        function = Function("image", (name, extension, output), (Expression.of(vector),))
        return Expression((((1.0, 1.0, 1.0), (Factor("", function=function),)),))

    @staticmethod
    def coordinates(name):
        """The surface's coordinates `name` (one of COORDINATES) as a vector (x, y, z)."""
        return Expression((((1.0, 1.0, 1.0), (Factor("", coordinates=name),)),))

    @staticmethod
    def attribute(name):
        """A mesh's colour attribute ("": the mesh's default one)."""
        return Expression((((1.0, 1.0, 1.0), (Factor(name, attribute=True),)),))

    @staticmethod
    def of(value):
        return value if isinstance(value, Expression) else Expression.constant(value)

    # -- arithmetic
    def __add__(self, other):
        return Expression(self.terms + Expression.of(other).terms).simplified()

    __radd__ = __add__

    def __neg__(self):
        return self * -1.0

    def __sub__(self, other):
        return self + (-Expression.of(other))

    def __rsub__(self, other):
        return Expression.of(other) + (-self)

    def __mul__(self, other):
        other = Expression.of(other)
        terms = tuple((tuple(a * b for a, b in zip(ca, cb)), fa + fb) for ca, fa in self.terms for cb, fb in other.terms)
        return Expression(terms).simplified()

    __rmul__ = __mul__

    def channel(self, k):
        """Its channel k (0, 1, 2) on all three: each coefficient's k-th part, each image read at channel k."""
        terms = tuple(((c[k],) * 3, tuple(f if f.channel is not None else replace(f, channel=k) for f in factors))
                      for c, factors in self.terms)
        return Expression(terms).simplified()

    def simplified(self):
        """Like terms (the same factors) summed, zero terms dropped, a single factor with no offset folded into
        the coefficient."""
        merged = {}
        for coefficient, factors in self.terms:
            key = tuple(sorted(factors, key=Factor.sort_key))
            if len(key) == 1 and key[0].offset == 0.0 and key[0].scale != 1.0:
                coefficient = tuple(c * key[0].scale for c in coefficient)
                key = (replace(key[0], scale=1.0),)
            previous = merged.get(key, (0.0, 0.0, 0.0))
            merged[key] = tuple(a + b for a, b in zip(previous, coefficient))
        terms = tuple((c, f) for f, c in merged.items() if any(v != 0.0 for v in c))
        return Expression(terms or (((0.0, 0.0, 0.0), ()),))

    # -- what it is
    def _sources(self):
        """(kind: "image", "attribute" or "coordinates", name) of everything it reads, inside its functions too."""
        for _, factors in self.terms:
            for factor in factors:
                if factor.function is not None:
                    if factor.function.name == "image":
                        yield "image", factor.function.settings[0]
                    for arg in factor.function.args:
                        yield from arg._sources()
                elif factor.coordinates is not None:
                    yield "coordinates", factor.coordinates
                else:
                    yield "attribute" if factor.attribute else "image", factor.image

    def _names(self, kind):
        return tuple(sorted({name for source, name in self._sources() if source == kind}))

    @property
    def images(self):
        return self._names("image")

    @property
    def attributes(self):
        """The colour attributes it reads."""
        return self._names("attribute")

    @property
    def coordinate_names(self):
        """The surface coordinates it reads (COORDINATES)."""
        return self._names("coordinates")

    def as_constant(self):
        """Its RGB value when it holds no factor (image, attribute, coordinates, function), else None."""
        if any(factors for _, factors in self.terms):
            return None
        return tuple(float(sum(c[k] for c, _ in self.terms)) for k in range(3))

    def as_factor_times_image(self, scalar=False):
        """(RGB factor, image name) when it is a constant times one plain image (with `scalar`, or its red
        channel: what a scalar slot reads of it), else None."""
        if len(self.terms) != 1:
            return None
        coefficient, factors = self.terms[0]
        plain = (Factor(factors[0].image),) + ((Factor(factors[0].image, channel=0),) if scalar else ())
        if len(factors) == 1 and factors[0] in plain:
            return coefficient, factors[0].image
        return None

    def mean_value(self, means, attribute_mean=(0.5, 0.5, 0.5)):
        """Its value with every image replaced by its mean RGB (means: name -> RGB), every attribute by
        attribute_mean."""
        total = np.zeros(3)
        for coefficient, factors in self.terms:
            product = np.asarray(coefficient, np.float64)
            for factor in factors:
                if factor.function is not None and factor.function.name == "image":
                    mean = means[factor.function.settings[0]]
                elif factor.function is not None:
                    from .node_functions import apply

                    mean = apply(factor.function.name, factor.function.settings,
                                 [np.asarray(arg.mean_value(means, attribute_mean), np.float32)
                                  for arg in factor.function.args])
                else:
                    mean = attribute_mean if factor.attribute or factor.coordinates else means[factor.image]
                product = product * (factor.offset + factor.scale * factor.values(np.asarray(mean, np.float64)))
            total += product
        return tuple(float(v) for v in total)

    def values(self, samples, attributes=None, coordinates=None, image_at=None):
        """Its value (..., 3) float32 where each image reads samples[name] (..., 3), each attribute
        attributes[name] and each of the surface's coordinates coordinates[name]: what a pixel gets when every
        image is sampled there (the shader's texture_value_<slot>); an image read at coordinates of its own (an
        "image" Function) reads image_at(name, extension, uv (..., 2)) -> RGBA (..., 4)."""
        from .node_functions import apply

        sources = {**{("image", name): samples[name] for name in self.images},
                   **{("attribute", name): (attributes or {})[name] for name in self.attributes},
                   **{("coordinates", name): (coordinates or {})[name] for name in self.coordinate_names}}
        shape = np.broadcast_shapes(*(np.shape(value)[:-1] for value in sources.values())) if sources else ()

        def source_of(factor):
            if factor.coordinates is not None:
                return np.asarray(sources["coordinates", factor.coordinates], np.float32)[..., :3]
            if factor.function is None:
                kind = "attribute" if factor.attribute else "image"
                return np.asarray(sources[kind, factor.image], np.float32)[..., :3]
            args = [np.broadcast_to(arg.values(samples, attributes, coordinates, image_at), shape + (3,))
                    for arg in factor.function.args]
            if factor.function.name == "image":
                name, extension, output = factor.function.settings
                rgba = np.asarray(image_at(name, extension, args[0][..., :2]), np.float32)
                return np.repeat(rgba[..., 3:4], 3, axis=-1) if output == "Alpha" else rgba[..., :3]
            return np.asarray(apply(factor.function.name, factor.function.settings, args), np.float32)

        out = np.zeros(shape + (3,), np.float32)
        for coefficient, factors in self.terms:
            product = np.broadcast_to(np.asarray(coefficient, np.float32), shape + (3,))
            for factor in factors:
                product = product * (np.float32(factor.offset)
                                     + np.float32(factor.scale) * factor.values(source_of(factor)))
            out += product
        return out

    def bound(self, images):
        """The expression with its images' pixels (name -> (H, W, >=3) linear, Blender's row order): what the
        numpy mirrors sample for a computed slot."""
        return BoundExpression(self, {name: np.asarray(images[name], np.float32) for name in self.images})


@dataclass(frozen=True, eq=False)
class BoundExpression:
    """An Expression and its images' pixels, sampled per pixel as the shader samples it."""
    expression: Expression
    images: dict

    def sample(self, uv, footprint=None):
        """(N, 4) float32 at texture coordinates uv (N, 2): each image read as a material texture
        (spherical.texture_mips.sample, at the footprint when given), the UV coordinates uv, alpha 1.  An
        expression of colour attributes or other coordinates has no value at a texture coordinate: ValueError."""
        from ..spherical import texture_mips

        others = tuple(name for name in self.expression.coordinate_names if name != "UV")
        if self.expression.attributes or others:
            raise ValueError(f"colour attributes {self.expression.attributes} or the surface's coordinates "
                             f"{others} have no value at a texture coordinate")
        samples = {name: texture_mips.sample(pixels, uv, footprint)[..., :3] for name, pixels in self.images.items()}

        def image_at(name, extension, at):
            return texture_mips.sample(self.images[name], at, footprint, extension)

        uv = np.asarray(uv, np.float32)
        coordinates = {"UV": np.concatenate([uv, np.zeros((len(uv), 1), np.float32)], axis=1)}
        out = np.ones((len(uv), 4), np.float32)
        out[:, :3] = self.expression.values(samples, coordinates=coordinates, image_at=image_at)
        return out
