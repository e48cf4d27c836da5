"""Rendering methods, one module each, and the registry the engine and the material panel read.

A technique (base.Technique) plugs in by registering: ``register(MyTechnique())``.  The draw loop,
the shader cache and the scene state look techniques up here by the material's choice
(MaterialParams.technique); none is named in them.  Built in: wang2009's SG lobes, parametric
(sg_parametric) and from a stored lobe fit (sg_fitted); mccool2001's factored BRDF (factored); kautz2002's
spherical harmonics (spherical_harmonics); iwasaki2012's bi-scale materials on the SG lobes (sg_biscale).
"""
from . import factored, sg_biscale, sg_fitted, sg_parametric, spherical_harmonics
from .base import DrawContext, ObjectInputs, Technique

DEFAULT = sg_parametric.NAME
_registry = {}


def register(technique):
    """Add a technique (a base.Technique instance); its name and enum number must be new."""
    if not technique.name or technique.name in _registry:
        raise ValueError(f"technique name {technique.name!r} is empty or already registered")
    if any(other.number == technique.number for other in _registry.values()):
        raise ValueError(f"technique {technique.name}: enum number {technique.number} is taken")
    _registry[technique.name] = technique
    return technique


def unregister(name):
    if name == DEFAULT:
        raise ValueError("the default technique cannot be unregistered")
    _registry.pop(name, None)


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
    return sg_fitted.NAME if settings.get("use_fitted_lobes") else DEFAULT


def enum_items():
    """(identifier, label, description, number) of every technique, for an EnumProperty."""
    return [(t.name, t.label, t.description, t.number) for t in _registry.values()]


register(sg_parametric.TECHNIQUE)
register(sg_fitted.TECHNIQUE)
register(factored.TECHNIQUE)
register(spherical_harmonics.TECHNIQUE)
register(sg_biscale.TECHNIQUE)

__all__ = ["DEFAULT", "DrawContext", "ObjectInputs", "Technique", "enum_items", "for_material", "get", "names",
           "of_settings", "register", "unregister"]
