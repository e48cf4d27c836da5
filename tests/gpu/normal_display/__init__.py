"""A technique written as a test fixture: the shading normal as a colour, (0.5 n + 0.5) times its own setting
Brightness, in Diffuse and Combined (Specular zero).  It is a package of its own: this module (the technique),
blender.py (its Blender side: the setting, its panel row, its reading into MaterialParams); one line,
techniques.register(TECHNIQUE), plugs it in."""
from dataclasses import dataclass

import numpy as np

from sg_prt_addon.techniques import Technique, shader_sources

NAME = "TEST_NORMAL_DISPLAY"
BRIGHTNESS = "normal_display.brightness"       # its value in MaterialParams.options

FRAGMENT = """
void main()
{
  bool front = gl_FrontFacing != (determinant(mat3(model_matrix)) < 0.0);
  vec3 n = normalize(front ? world_normal : -world_normal);
  vec3 colour = (0.5 * n + 0.5) * material.specular_color.a * BRIGHTNESS;    /* a = 1: the block is read */
#ifndef GBUFFER
  out_combined = vec4(colour, 1.0);
#endif
  out_diffuse = vec4(colour, 1.0);
  out_specular = vec4(0.0, 0.0, 0.0, 1.0);
#ifdef GBUFFER
  out_position = vec4(world_position, float(gbuffer_triangle_offset + gl_PrimitiveID) + 1.0);
  out_normal = vec4(n, float(gbuffer_object_index) + 1.0);
  out_tangent = world_tangent;
  out_uv = vec4(texcoord, material.options.y, 1.0);
#endif
}
"""


@dataclass(frozen=True)
class NormalDisplayKey:
    technique: str = NAME
    gbuffer: bool = False
    brightness: float = 1.0

    def describe(self):
        return f"normal display x{self.brightness:g}" + (", G-buffer" if self.gbuffer else "")


def normal_colour(normal, brightness=1.0):
    """The mirror: the colour of unit normals (N, 3)."""
    normal = np.asarray(normal, np.float64)
    return (0.5 * normal / np.linalg.norm(normal, axis=-1, keepdims=True) + 0.5) * brightness


class NormalDisplay(Technique):
    name = NAME
    label = "Normal Display (test)"
    description = "The shading normal as a colour"
    number = 900
    mirror = staticmethod(normal_colour)
    blender_side = ".blender"

    def variant_key(self, params, inputs):
        return NormalDisplayKey(gbuffer=inputs.gbuffer, brightness=float(params.options.get(BRIGHTNESS, 1.0)))

    def create_info_calls(self, key):
        defines = {"BRIGHTNESS": f"{key.brightness:.9g}", **({"GBUFFER": 1} if key.gbuffer else {})}
        return shader_sources.surface_calls(defines, FRAGMENT, [], key.gbuffer)

    def bind(self, shader, key, context):
        shader.uniform_block("scene", context.scene_buffer)
        shader.uniform_block("material", context.material_buffer)


TECHNIQUE = NormalDisplay()
