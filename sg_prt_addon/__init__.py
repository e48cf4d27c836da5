"""SG-PRT: all-frequency SVBRDF rendering with spherical Gaussians and SSDFs."""


def register():
    from .blender import registration
    registration.register()


def unregister():
    from .blender import registration
    registration.unregister()
