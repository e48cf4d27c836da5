"""Blender node materials (EEVEE, Cycles) matched to each material's SG-PRT settings.

`match_scene(scene)` rewrites the node tree of every material the scene's meshes use from
its ``material.sgprt`` settings, so EEVEE and Cycles render (as closely as Blender's nodes
allow) the BRDF the SG-PRT engine and the Monte Carlo reference render
(sg_prt_addon/reflectance/brdf.py): Lambert ``kd / pi`` plus ``ks x`` the specular model.
`configure_eevee` / `configure_cycles` set the render engines up for direct light only
as far as each allows.  Only the node trees and render settings change; ``material.sgprt``
(what SG-PRT and the reference read) is left alone.

Mapping per model (ours -> nodes) and the mismatches left:

- Diffuse: Diffuse BSDF (roughness 0: Lambert), colour ``diffuse_color`` x the diffuse
  texture.  Exact.
- GGX (ours: alpha = roughness^2, height-correlated Smith, no Fresnel, ks the colour) ->
  Glossy BSDF, GGX distribution, the same roughness (Blender squares it too), colour ks.
  Cycles matches up to its own Smith form; EEVEE uses split-sum prefiltered probes for
  the world and LTC for lights (approximations of its own).
- COOK_TORRANCE (ours: wang2009 eq. 10-12, D = exp(-(theta_h/m)^2) unnormalized, V-cavity
  shadowing, exact dielectric Fresnel F_ior(i.h), 1/(pi (n.i)(n.o))) -> Glossy BSDF,
  Beckmann distribution with alpha = m (node roughness sqrt(m)), colour
  ks x 4 m^2 x Fresnel(ior) (the Fresnel node, at n.o):
  near the lobe's peak exp(-tan^2/m^2)/(pi m^2 cos^4) x G/4 (Beckmann) equals ours / (4 m^2).
  Left: the two NDF shapes part away from the peak (tan vs angle, cos^4: Beckmann is wider
  for rough tiles, m up to 0.5), Smith vs V-cavity shadowing, Fresnel at n.o instead of
  i.h.  EEVEE does not support the Beckmann distribution (Blender manual, EEVEE's supported
  nodes) and shades it as GGX (so its tiles and glaze are GGX of alpha m).
- ASHIKHMIN_SHIRLEY (ours: (n.h)^e lobe, exponents nu along the tangent, nv along the
  bitangent, Schlick Fresnel rf0 = 0.05, 1/(4 (h.k) max(n.i, n.o))) -> Glossy BSDF,
  Ashikhmin-Shirley distribution (Cycles' own A-S lobe: exponent 2/alpha^2 - 2 per axis),
  alpha_t = sqrt(2/(nu + 2)), alpha_b = sqrt(2/(nv + 2)) as the node's roughness and Anisotropy
  (glossy_node_anisotropy, the inverse of the Glossy node's own mapping), colour ks x
  Fresnel(IOR (1 + sqrt(rf0))/(1 - sqrt(rf0)) = 1.58) (dielectric at n.o in place of Schlick at
  h.k).  Tangent: the object axis (tangent_source OBJECT_AXIS) through a Vector Transform to
  world space (the BSDF projects it onto the surface, as we do), or the UV map's tangent;
  tangent_rotation becomes the node's Rotation.  The Glossy node's Anisotropy is not the
  Principled BSDF's: alpha_x = r^2 (1 - a), alpha_y = r^2 / (1 - a) along its tangent for a > 0
  (the lobe widened across the tangent), the other way for a < 0
  (reflectance.principled.glossy_anisotropic_alphas); until session 20 the Principled mapping
  was used here, with a quarter turn found by trial, which made the widths wrong (0.017 and
  0.57 in Cycles for our 0.05 and 0.196) and the torus figures an upper bound.  EEVEE supports
  neither the A-S distribution (Blender manual) nor, as far as we could tell, anisotropy: it
  shades this material as a GGX lobe of the node roughness, a large mismatch reported as it is.
- GGX_ANISO (ours: Cycles' anisotropic GGX, alpha_x along the tangent) -> Glossy BSDF, GGX,
  the roughness and Anisotropy whose alphas the node makes are ours (glossy_node_anisotropy),
  colour ks, the tangent wired as for Ashikhmin-Shirley.  Exact up to Cycles' own Smith form, as GGX.
- BECKMANN (the Glossy BSDF's) -> Glossy BSDF, Beckmann, same roughness, colour ks: exact up to Cycles'
  Smith form.
- Others (not in the example scenes): BLINN_PHONG -> Beckmann alpha = sqrt(2/(n + 2));
  WARD_ISO / WARD_ANISO -> Beckmann of the same alphas (anisotropic as above), colour ks.
- Textures: diffuse and specular colour textures multiply the colours (sRGB images decoded
  to linear, as the engine does); the roughness texture multiplies the roughness as stored
  (a Non-Color copy of the image, as the engine reads data slots); the normal map goes
  through a tangent-space Normal Map node.  Other parameter textures (ior, exponent,
  alpha, nu, nv) are not wired (no example uses them).  Bilinear filtering, repeat.
- Lights and world are left as the scene has them (both engines read the same point light
  radius and HDRI as SG-PRT's export).
"""
import math

RF0_ASHIKHMIN_SHIRLEY = 0.05          # reflectance.brdf.AshikhminShirley's default rf0 (the engine's too)
DIELECTRIC_IOR_OF_RF0 = (1 + math.sqrt(RF0_ASHIKHMIN_SHIRLEY)) / (1 - math.sqrt(RF0_ASHIKHMIN_SHIRLEY))


def glossy_node_anisotropy(alpha_t, alpha_b):
    """(roughness, Anisotropy) of a Glossy BSDF whose alphas along our tangent and bitangent (its Tangent
    input, Rotation 0) are alpha_t, alpha_b: the inverse of Cycles' Glossy mapping
    (reflectance.principled.glossy_anisotropic_alphas), r^2 = sqrt(alpha_t alpha_b) and
    1 -+ a = sqrt of the alphas' ratio; exact while the ratio is within 0.99^2 (and r <= 1)."""
    roughness = math.sqrt(math.sqrt(alpha_t * alpha_b))
    if alpha_t <= alpha_b:
        anisotropy = 1.0 - math.sqrt(alpha_t / alpha_b)
    else:
        anisotropy = math.sqrt(alpha_b / alpha_t) - 1.0
    return min(roughness, 1.0), min(max(anisotropy, -0.99), 0.99)


def phong_alpha(exponent):
    """Beckmann alpha of a (n.h)^exponent lobe (same small-angle width)."""
    return math.sqrt(2.0 / (float(exponent) + 2.0))


class _Builder:
    def __init__(self, material):
        self.tree = material.node_tree
        self.nodes, self.links = self.tree.nodes, self.tree.links

    def math(self, operation, a, b=None):
        node = self.nodes.new("ShaderNodeMath")
        node.operation = operation
        for index, value in enumerate((a, b)):
            if value is None:
                continue
            if hasattr(value, "is_output"):
                self.links.new(value, node.inputs[index])
            else:
                node.inputs[index].default_value = float(value)
        return node.outputs[0]

    def scale_colour(self, colour, factor):
        """Colour socket or RGB tuple times a float socket or number -> a socket."""
        node = self.nodes.new("ShaderNodeVectorMath")
        node.operation = "SCALE"
        if hasattr(colour, "is_output"):
            self.links.new(colour, node.inputs["Vector"])
        else:
            node.inputs["Vector"].default_value = tuple(colour)
        if hasattr(factor, "is_output"):
            self.links.new(factor, node.inputs["Scale"])
        else:
            node.inputs["Scale"].default_value = float(factor)
        return node.outputs["Vector"]

    def multiply_colours(self, a, b):
        node = self.nodes.new("ShaderNodeVectorMath")
        node.operation = "MULTIPLY"
        for index, value in enumerate((a, b)):
            if hasattr(value, "is_output"):
                self.links.new(value, node.inputs[index])
            else:
                node.inputs[index].default_value = tuple(value)
        return node.outputs["Vector"]

    def image(self, image, data=False):
        """Image Texture node output (Color) for an image; data: sampled as stored (Non-Color)."""
        import bpy

        if data and image.colorspace_settings.name != "Non-Color":
            name = f"{image.name} (non-color, matched)"
            copy = bpy.data.images.get(name)
            if copy is None:
                copy = image.copy()
                copy.name = name
                copy.colorspace_settings.name = "Non-Color"
            image = copy
        node = self.nodes.new("ShaderNodeTexImage")
        node.image = image
        node.interpolation = "Linear"
        node.extension = "REPEAT"
        return node.outputs["Color"]

    def link(self, value, target):
        """A socket or a constant into an input socket."""
        if hasattr(value, "is_output"):
            self.links.new(value, target)
        elif isinstance(value, tuple) and len(target.default_value) == 4:
            target.default_value = (*value, 1.0)
        else:
            target.default_value = value


def _textured_colour(builder, settings, name):
    colour = tuple(getattr(settings, name))
    texture = getattr(settings, f"{name}_texture", None)
    return colour if texture is None else builder.multiply_colours(colour, builder.image(texture))


def _textured_scalar(builder, settings, name):
    value = float(getattr(settings, name))
    texture = getattr(settings, f"{name}_texture", None)
    if texture is None:
        return value
    separate = builder.nodes.new("ShaderNodeSeparateColor")
    builder.links.new(builder.image(texture, data=True), separate.inputs[0])
    return builder.math("MULTIPLY", separate.outputs[0], value)       # the engine reads the red channel


def _sqrt(builder, value):
    """sqrt of a socket or a number."""
    return builder.math("SQRT", value) if hasattr(value, "is_output") else math.sqrt(max(value, 0.0))


def match_material(material):
    """Rebuild ``material``'s node tree from ``material.sgprt``; returns a one-line description."""
    import bpy

    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    settings = material.sgprt
    builder = _Builder(material)
    builder.nodes.clear()
    output = builder.nodes.new("ShaderNodeOutputMaterial")
    output.location = (400, 0)

    normal = None
    if getattr(settings, "normal_map", None) is not None:
        normal_map = builder.nodes.new("ShaderNodeNormalMap")
        normal_map.space = "TANGENT"
        normal_map.inputs["Strength"].default_value = float(settings.normal_strength)
        builder.links.new(builder.image(settings.normal_map, data=True), normal_map.inputs["Color"])
        normal = normal_map.outputs["Normal"]

    diffuse = builder.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.0
    builder.link(_textured_colour(builder, settings, "diffuse_color"), diffuse.inputs["Color"])
    glossy = builder.nodes.new("ShaderNodeBsdfGlossy")
    specular = _textured_colour(builder, settings, "specular_color")
    model = settings.model
    description = model
    if model in ("GGX", "BECKMANN"):
        glossy.distribution = model
        builder.link(_textured_scalar(builder, settings, "roughness"), glossy.inputs["Roughness"])
        builder.link(specular, glossy.inputs["Color"])
        description = f"Glossy {'GGX' if model == 'GGX' else 'Beckmann'}, same roughness, colour ks"
    elif model == "COOK_TORRANCE":
        glossy.distribution = "BECKMANN"
        m = _textured_scalar(builder, settings, "roughness")
        builder.link(_sqrt(builder, m), glossy.inputs["Roughness"])
        fresnel = builder.nodes.new("ShaderNodeFresnel")
        fresnel.inputs["IOR"].default_value = float(settings.ior)
        peak = builder.math("MULTIPLY", builder.math("MULTIPLY", m, m), 4.0) if hasattr(m, "is_output") \
            else 4.0 * m * m
        factor = builder.math("MULTIPLY", fresnel.outputs["Fac"], peak)
        builder.link(builder.scale_colour(specular, factor), glossy.inputs["Color"])
        description = "Glossy Beckmann alpha m, colour ks x 4 m^2 x Fresnel(ior)"
    elif model in ("ASHIKHMIN_SHIRLEY", "WARD_ANISO", "WARD_ISO", "BLINN_PHONG", "GGX_ANISO"):
        if model == "GGX_ANISO":
            alpha_t, alpha_b = float(settings.alpha_x), float(settings.alpha_y)
            glossy.distribution = "GGX"
            builder.link(specular, glossy.inputs["Color"])
        elif model == "ASHIKHMIN_SHIRLEY":
            alpha_t, alpha_b = phong_alpha(settings.nu), phong_alpha(settings.nv)
            glossy.distribution = "ASHIKHMIN_SHIRLEY"
            fresnel = builder.nodes.new("ShaderNodeFresnel")
            fresnel.inputs["IOR"].default_value = DIELECTRIC_IOR_OF_RF0
            builder.link(builder.scale_colour(specular, fresnel.outputs["Fac"]), glossy.inputs["Color"])
        else:
            glossy.distribution = "BECKMANN"
            if model == "BLINN_PHONG":
                alpha_t = alpha_b = phong_alpha(settings.exponent)
            else:
                alpha_t = float(settings.alpha_x)
                alpha_b = float(settings.alpha_y) if model == "WARD_ANISO" else alpha_t
            builder.link(specular, glossy.inputs["Color"])
        roughness, anisotropy = glossy_node_anisotropy(alpha_t, alpha_b)
        glossy.inputs["Roughness"].default_value = roughness
        glossy.inputs["Anisotropy"].default_value = anisotropy
        glossy.inputs["Rotation"].default_value = float(settings.tangent_rotation) / (2 * math.pi)
        if anisotropy != 0:
            if settings.tangent_source == "OBJECT_AXIS":
                transform = builder.nodes.new("ShaderNodeVectorTransform")
                transform.vector_type, transform.convert_from, transform.convert_to = "VECTOR", "OBJECT", "WORLD"
                transform.inputs["Vector"].default_value = tuple(settings.tangent_axis)
                builder.links.new(transform.outputs["Vector"], glossy.inputs["Tangent"])
            else:
                tangent = builder.nodes.new("ShaderNodeTangent")
                tangent.direction_type = "UV_MAP"
                builder.links.new(tangent.outputs["Tangent"], glossy.inputs["Tangent"])
        description = (f"Glossy {glossy.distribution} roughness {roughness:.3f} anisotropy {anisotropy:.3f} "
                       f"rotation {glossy.inputs['Rotation'].default_value:.3f}")
    else:
        raise ValueError(f"no node match for SG-PRT model {model!r}")
    if normal is not None:
        builder.links.new(normal, diffuse.inputs["Normal"])
        builder.links.new(normal, glossy.inputs["Normal"])
    add = builder.nodes.new("ShaderNodeAddShader")
    builder.links.new(diffuse.outputs[0], add.inputs[0])
    builder.links.new(glossy.outputs[0], add.inputs[1])
    builder.links.new(add.outputs[0], output.inputs["Surface"])
    return f"{material.name}: Diffuse + {description}"


def match_scene(scene):
    """Match every material used by the scene's mesh objects; returns {material name: description}."""
    matched = {}
    for obj in scene.objects:
        if obj.type != "MESH":
            continue
        for slot in obj.material_slots:
            if slot.material is not None and slot.material.name not in matched:
                matched[slot.material.name] = match_material(slot.material)
    return matched


def eevee_engine_id():
    import bpy
    return "BLENDER_EEVEE_NEXT" if bpy.app.version < (5, 0, 0) else "BLENDER_EEVEE"


def configure_eevee(scene, samples):
    """EEVEE, as close to direct light only as its settings go; returns the settings made.

    Ray tracing (screen-space reflections and global illumination) and fast GI (horizon scan,
    which also darkens like AO) are off, so surfaces see the world probe and the lights only,
    with EEVEE's shadow maps (the world's sun extraction stays at Blender's default: the HDRI's
    brightest part casts shadows, the rest of the world is unshadowed).  No clamping; the film's
    Filter Size as the scene has it (Blender's default 1.5 px, which Cycles and SG-PRT read too)."""
    scene.render.engine = eevee_engine_id()
    eevee = scene.eevee
    eevee.taa_render_samples = int(samples)
    made = {"taa_render_samples": int(samples)}
    for name, value in (("use_raytracing", False), ("use_fast_gi", False), ("use_shadows", True),
                        ("clamp_surface_direct", 0.0), ("clamp_surface_indirect", 0.0)):
        if hasattr(eevee, name):
            setattr(eevee, name, value)
            made[name] = value
    made["filter_size"] = float(scene.render.filter_size)
    if scene.world is not None:
        for name in ("sun_threshold", "use_sun_shadow"):
            if hasattr(scene.world, name):
                made[f"world.{name}"] = getattr(scene.world, name)
    return made


def configure_cycles(scene, samples, seed=3):
    """Cycles on the CPU with direct light only (max_bounces 0), no adaptive sampling or denoising, the
    pixel filter as the scene has it (Blender's default: Blackman-Harris 1.5 px, which SG-PRT reads too)."""
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = int(samples)
    cycles.seed = seed
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.max_bounces = 0
    return {"device": "CPU", "samples": int(samples), "max_bounces": 0,
            "pixel_filter_type": cycles.pixel_filter_type, "filter_width": float(cycles.filter_width),
            "use_adaptive_sampling": False, "use_denoising": False}
