"""A mesh's colour attributes as renders read them."""


def default_color_attribute(mesh):
    """The mesh's default colour attribute (a Color Attribute node without a name reads it), or None."""
    attributes = getattr(mesh, "color_attributes", None)
    if not attributes:
        return None
    name = getattr(attributes, "default_color_name", "") or getattr(mesh.attributes, "default_color_name", "")
    index = getattr(attributes, "render_color_index", 0)
    return attributes.get(name) if name else attributes[index if 0 <= index < len(attributes) else 0]
