"""The UV maps a mesh's export carries: the one renders use (its camera icon, else the active one) as its UVs,
and the first other one as its second UVs, which a node tree's UV Map node naming it reads
(texture_expression's SECOND_UV coordinates)."""


def render_layer(mesh):
    """The UV map renders use, or None."""
    return next((layer for layer in mesh.uv_layers if layer.active_render), mesh.uv_layers.active)


def second_layer(mesh):
    """The first UV map other than render_layer's, or None."""
    render = render_layer(mesh)
    return next((layer for layer in mesh.uv_layers if render is None or layer.name != render.name), None)


def coordinates_of(meshes, name):
    """The coordinates a UV Map node naming `name` reads on every mesh of `meshes`: "UV" (each mesh's render
    UV map, also where it names none or no mesh uses the material), "SECOND_UV" (each mesh's second), or None
    where the meshes disagree or one has no such map."""
    if not name or all(render_layer(mesh) is None or render_layer(mesh).name == name for mesh in meshes):
        return "UV"
    if all(second_layer(mesh) is not None and second_layer(mesh).name == name for mesh in meshes):
        return "SECOND_UV"
    return None
