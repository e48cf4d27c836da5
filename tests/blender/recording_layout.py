"""Stands in for a panel's UILayout (pip bpy draws no UI): records what a draw() asks for, against the real
settings (a prop that is not a real property raises AttributeError)."""


class RecordingLayout:
    def __init__(self):
        self.calls = []
        self.use_property_split = False
        self.alert = False

    def prop(self, data, name, **kwargs):
        getattr(data, name)                      # a real property of the real settings, or AttributeError
        self.calls.append(("prop", name))

    def operator(self, idname, **kwargs):
        self.calls.append(("operator", idname))

    def label(self, text="", **kwargs):
        self.calls.append(("label", text))

    def template_ID(self, data, name, **kwargs):
        getattr(data, name)
        self.calls.append(("template_ID", name))

    def template_node_view(self, tree, node, socket):
        assert socket.node == node and node.id_data == tree      # the output's own socket, in the material's tree
        self.calls.append(("template_node_view", socket.name))

    def row(self, **kwargs):
        return self

    column = row


def draw(panel, context):
    """The calls `panel`'s draw() makes in `context`."""
    layout = RecordingLayout()
    panel.draw(type("Panel", (), {"layout": layout})(), context)
    return layout.calls
