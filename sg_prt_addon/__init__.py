"""SG-PRT: all-frequency SVBRDF rendering with spherical Gaussians and SSDFs.

Importing the package needs no bpy (its maths runs anywhere); register() imports the Blender side."""


def register():
    try:
        import numpy  # noqa: F401
    except ImportError as error:
        # Blender's own builds ship numpy; some Linux distributions' Blender packages leave it out
        raise ImportError("SG-PRT needs numpy, which this Blender's Python lacks: Blender's own builds "
                          "include it; with a distribution's Blender, install its numpy package (Debian and "
                          "Ubuntu: python3-numpy)") from error
    from . import registration
    registration.register()


def unregister():
    from . import registration
    registration.unregister()
