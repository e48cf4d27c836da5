"""Properties-editor panels of the SG-PRT engine."""
import bpy

from ..reflectance import models
from . import technique_sides

ENGINE_ID = "SG_PRT"


class MaterialPanel:
    """Placement and poll shared by the material panels: shown while SG-PRT renders."""
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"
    COMPAT_ENGINES = {ENGINE_ID}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES and context.material is not None


class SGPRT_PT_material(MaterialPanel, bpy.types.Panel):
    """The material's one Surface panel: its Source and Technique, then what SG-PRT renders of it, the node
    tree's surface as Blender draws it (its own Surface panel is not shown) or SG-PRT's settings."""
    bl_label = "Surface"

    def draw(self, context):
        material = context.material
        settings = material.sgprt
        layout = self.layout
        layout.use_property_split = True
        layout.prop(settings, "source")
        layout.prop(settings, "technique")
        if settings.source == "NODE_TREE":
            _draw_node_surface(layout, material)
            layout.operator("sgprt.copy_from_node_tree")
            technique_sides.draw(layout, material)
            return
        layout.prop(settings, "model")
        textured = settings.show_textures
        for name in ("diffuse_color", "specular_color") + models.BY_NAME[settings.model].panel_parameters:
            row = layout.row(align=True)
            row.prop(settings, name)
            if name == "lobe_count" and settings.lobe_count == 0:
                row.label(text=f"Auto: {models.lobes_of(settings.model, 0)}")
            if textured and hasattr(settings, f"{name}_texture"):
                row.template_ID(settings, f"{name}_texture", open="image.open")
        for name in ("fresnel", "multiscatter", "layered_diffuse", "emission_color", "emission_strength"):
            layout.prop(settings, name)
        technique_sides.draw(layout, context.material)
        layout.prop(settings, "show_textures")



def _draw_node_surface(layout, material):
    """The material output's Surface input and the nodes behind it, as EEVEE's and Cycles' Surface panels draw
    them; a material without nodes (Blender 4.x's Use Nodes off) offers Use Nodes."""
    from bl_ui.properties_material import panel_node_draw

    if material.node_tree is None or not getattr(material, "use_nodes", True):
        layout.prop(material, "use_nodes", icon="NODETREE")
        return
    panel_node_draw(layout, material.node_tree, "OUTPUT_MATERIAL", "Surface")


class SGPRT_PT_material_geometry(MaterialPanel, bpy.types.Panel):
    bl_label = "Normal and Tangent"
    bl_parent_id = "SGPRT_PT_material"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        settings = context.material.sgprt
        layout = self.layout
        layout.use_property_split = True
        layout.template_ID(settings, "normal_map", open="image.open")
        layout.prop(settings, "normal_strength")
        if settings.model in models.ANISOTROPIC:
            layout.prop(settings, "tangent_source")
            if settings.tangent_source == "OBJECT_AXIS":
                layout.prop(settings, "tangent_axis")
            layout.prop(settings, "tangent_rotation")


class RenderPanel:
    """Placement and poll shared by the render-properties panels: shown while SG-PRT renders."""
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {ENGINE_ID}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES


class SGPRT_PT_sampling(RenderPanel, bpy.types.Panel):
    bl_label = "Sampling"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        settings = context.scene.sgprt
        layout.prop(settings, "render_samples")
        column = layout.column()
        column.active = settings.render_samples > 1
        column.prop(settings, "sample_edges_only")
        row = column.row()
        row.active = settings.sample_edges_only
        row.prop(settings, "edge_threshold")
        layout.prop(settings, "specular_anti_aliasing")
        layout.prop(settings, "area_light_patches")


class SGPRT_PT_film(RenderPanel, bpy.types.Panel):
    bl_label = "Film"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        column = layout.column()
        column.prop(context.scene.sgprt, "pixel_filter_type")
        column.prop(context.scene.render, "filter_size")
        layout.prop(context.scene.render, "film_transparent")


class SGPRT_PT_shadows(RenderPanel, bpy.types.Panel):
    bl_label = "Light Shadows"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        settings = context.scene.sgprt
        layout.prop(settings, "light_shadows")
        row = layout.row()
        row.active = settings.light_shadows == "SHADOW_MAPS"
        row.prop(settings, "shadow_map_size")


classes = (SGPRT_PT_material, SGPRT_PT_material_geometry, SGPRT_PT_sampling, SGPRT_PT_film, SGPRT_PT_shadows)

# Built-in panels that work unchanged with this engine.
COMPATIBLE_BUILTIN_PANELS = (
    "RENDER_PT_format", "RENDER_PT_frame_range", "RENDER_PT_output", "RENDER_PT_color_management",
    "DATA_PT_context_light", "DATA_PT_light", "DATA_PT_lens", "DATA_PT_camera", "DATA_PT_camera_display",
    "WORLD_PT_context_world", "EEVEE_WORLD_PT_surface", "MATERIAL_PT_preview", "EEVEE_MATERIAL_PT_context_material",
)


def _builtin_panels():
    for name in COMPATIBLE_BUILTIN_PANELS:
        panel = getattr(bpy.types, name, None)
        if panel is not None and hasattr(panel, "COMPAT_ENGINES"):
            yield panel


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    for panel in _builtin_panels():
        panel.COMPAT_ENGINES.add(ENGINE_ID)


def unregister():
    for panel in _builtin_panels():
        panel.COMPAT_ENGINES.discard(ENGINE_ID)
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
