"""SG-PRT: all-frequency SVBRDF rendering with spherical Gaussians and SSDFs.

Importing the package needs no bpy (its maths runs anywhere); register() imports the Blender side."""


def register():
    from . import registration
    registration.register()


def unregister():
    from . import registration
    registration.unregister()
