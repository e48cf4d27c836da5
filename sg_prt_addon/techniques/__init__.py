"""Rendering methods, one package each, and the registry the engine and the material panel read.

A technique (base.Technique) plugs in by registering: ``register(MyTechnique())``.  The draw loop,
the shader cache and the scene state look techniques up here by the material's choice
(MaterialParams.technique); none is named in them.  Built in: wang2009's SG lobes, parametric
(sg_parametric) and from a stored lobe fit (sg_fitted); mccool2001's factored BRDF (factored); kautz2002's
spherical harmonics (spherical_harmonics); iwasaki2012's bi-scale materials on the SG lobes (biscale: sg_biscale).
"""
from .base import DrawContext, ObjectInputs, Technique
from .biscale import sg_biscale
from .homomorphic import factored
from .sg import sg_fitted, sg_parametric
from .sh import spherical_harmonics

DEFAULT = sg_parametric.NAME
_registry = {}
# (on_register, on_unregister) callbacks: the Blender glue registers a technique's settings and panels with
# Blender when it is registered here (blender/technique_sides.py)
_watchers = []


def register(technique):
    """Add a technique (a base.Technique instance); its name and enum number must be new."""
    if not technique.name or technique.name in _registry:
        raise ValueError(f"technique name {technique.name!r} is empty or already registered")
    if any(other.number == technique.number for other in _registry.values()):
        raise ValueError(f"technique {technique.name}: enum number {technique.number} is taken")
    _registry[technique.name] = technique
    for on_register, _ in _watchers:
        on_register(technique)
    return technique


def unregister(name):
    if name == DEFAULT:
        raise ValueError("the default technique cannot be unregistered")
    technique = _registry.pop(name, None)
    if technique is not None:
        for _, on_unregister in _watchers:
            on_unregister(technique)


def watch(on_register, on_unregister):
    """Call on_register(technique) for every technique registered from now on and on_unregister(technique) for
    every one unregistered, until unwatch(on_register)."""
    _watchers.append((on_register, on_unregister))


def unwatch(on_register):
    _watchers[:] = [pair for pair in _watchers if pair[0] is not on_register]


def registered():
    """The registered techniques, in registration order."""
    return tuple(_registry.values())


def rendering_stored(kind):
    """The registered technique that renders the stored fit `kind` by itself (Technique.renders_stored), or None."""
    return next((t for t in _registry.values() if t.renders_stored == kind), None)


def get(name):
    """The registered technique called `name`; KeyError names the registered ones."""
    technique = _registry.get(name)
    if technique is None:
        raise KeyError(f"no SG-PRT technique {name!r} (registered: {', '.join(_registry)})")
    return technique


def names():
    return tuple(_registry)


def for_material(params):
    """The technique of an export.MaterialParams (its `technique`, the default without one)."""
    return get(getattr(params, "technique", DEFAULT) or DEFAULT)


def of_settings(settings):
    """The technique name a material's settings (material.sgprt) pick: `technique` once set; before that
    (files older than the setting) the fitted lobes when the old use_fitted_lobes flag is stored, else
    the default.  A stored technique no longer registered reads as "#<its enum number>"."""
    if settings.is_property_set("technique"):
        return settings.technique or f"#{settings.get('technique')}"
    fitted = rendering_stored("lobe_fit")
    return fitted.name if settings.get("use_fitted_lobes") and fitted is not None else DEFAULT


def enum_items():
    """(identifier, label, description, number) of every technique, for an EnumProperty."""
    return [(t.name, t.label, t.description, t.number) for t in _registry.values()]


register(sg_parametric.TECHNIQUE)
register(sg_fitted.TECHNIQUE)
register(factored.TECHNIQUE)
register(spherical_harmonics.TECHNIQUE)
register(sg_biscale.TECHNIQUE)

__all__ = ["DEFAULT", "DrawContext", "ObjectInputs", "Technique", "enum_items", "for_material", "get", "names",
           "of_settings", "register", "registered", "rendering_stored", "unregister", "unwatch", "watch"]
