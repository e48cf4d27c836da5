"""The fixture technique's Blender side: its setting (material.sgprt.normal_display.brightness), the row the
material panel draws for it, and its reading into the exported MaterialParams."""
import bpy

from . import BRIGHTNESS


class SGPRT_PG_normal_display(bpy.types.PropertyGroup):
    brightness: bpy.props.FloatProperty(name="Brightness", default=1.0, min=0.0, max=4.0,
                                        description="Scales the normal's colour")


SETTINGS = {"normal_display": SGPRT_PG_normal_display}


def draw(layout, material, name):
    layout.prop(material.sgprt.normal_display, "brightness")


def read(material, params):
    params.options[BRIGHTNESS] = float(material.sgprt.normal_display.brightness)
