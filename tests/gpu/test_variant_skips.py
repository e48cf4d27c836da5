"""Shader variants leave out what a scene does not need, and the image does not change.

Each case renders a scene whose variant skips a term next to the same scene made to need it, with a
term that is exactly zero in the full variant (no variant is forced): a zero specular colour against
the default one times an all-zero specular texture (diffuse-only), the same for diffuse
(specular-only), no light against a light of zero power (no light loop), an unbaked mesh against a
bake that sees the whole sphere (no SSDF decode), and a world colour against an equirect image of that
colour (no prefiltered fetch).  The skipped variant's preprocessed source is checked to lack the
code.  Also: variants that assemble to the same shader share one compile (content hash), and
Renderer.upload re-creates nothing whose input did not change.
"""
import re
import types

import engine_fixtures as fx
import numpy as np
import pytest

SIZE = 96
ENV_LAYER_SIZE = 16


@pytest.fixture(scope="module")
def engine(blender):
    from sg_prt_addon.engine import render_engine

    fx.ensure_registered()
    render_engine.debug["environment_layer_size"] = ENV_LAYER_SIZE
    yield blender
    render_engine.debug["environment_layer_size"] = None


# --------------------------------------------------------------------------- the preprocessor

def _expand(expression, macros, depth=0):
    expression = re.sub(r"\bdefined\s*\(\s*(\w+)\s*\)|\bdefined\s+(\w+)",
                        lambda m: "1" if (m.group(1) or m.group(2)) in macros else "0", expression)

    def identifier(match):
        name = match.group(0)
        value = macros.get(name)
        if value is None or depth > 8:
            return "0"
        return "(" + _expand(str(value), macros, depth + 1) + ")"

    return re.sub(r"\b[A-Za-z_]\w*\b", identifier, expression)


def _evaluate(expression, macros):
    python = _expand(expression, macros).replace("&&", " and ").replace("||", " or ")
    python = re.sub(r"!(?!=)", " not ", python)
    return bool(eval(python, {"__builtins__": {}}))


def active_source(source, defines):
    """The lines of `source` the GLSL preprocessor keeps with `defines` (and the #defines it meets):
    conditionals (#if, #ifdef, #ifndef, #elif, #else, #endif) resolved, directives and comments removed."""
    macros = {name: value for name, value in defines.items()}
    source = re.sub(r"/\*.*?\*/", " ", source, flags=re.S)
    stack = []          # (parent active, a branch was taken, this branch active)
    active = True
    kept = []
    for line in source.split("\n"):
        line = re.sub(r"//.*$", "", line)
        directive = re.match(r"\s*#\s*(\w+)\s*(.*)$", line)
        if not directive:
            if active and line.strip():
                kept.append(line)
            continue
        word, rest = directive.group(1), directive.group(2).strip()
        if word in ("if", "ifdef", "ifndef"):
            condition = (rest in macros if word == "ifdef" else rest not in macros if word == "ifndef"
                         else _evaluate(rest, macros)) if active else False
            stack.append((active, condition))
            active = active and condition
        elif word == "elif":
            parent, taken = stack[-1]
            condition = parent and not taken and _evaluate(rest, macros)
            stack[-1] = (parent, taken or condition)
            active = condition
        elif word == "else":
            parent, taken = stack[-1]
            active = parent and not taken
            stack[-1] = (parent, True)
        elif word == "endif":
            active = stack.pop()[0]
        elif word == "define" and active:
            match = re.match(r"(\w+)(\([^)]*\))?\s*(.*)$", rest)
            macros[match.group(1)] = match.group(3) if not match.group(2) else "1"
    assert not stack, "unbalanced conditionals"
    return "\n".join(kept)


def variant_code(key):
    return active_source(fx.variant_fragment(key), fx.variant_defines(key))


def test_preprocessor_keeps_the_full_variant_code():
    """The helper itself: the full variant keeps every term, the #if logic picks branches."""
    from sg_prt_addon.techniques.sg.sg_lobes import VariantKey

    assert active_source("#if defined(A) && B > 1\nyes\n#elif !defined(C)\nno\n#else\nelse\n#endif",
                         {"A": 1, "B": 2}) == "yes"
    assert active_source("#if defined(A) && B > 1\nyes\n#elif !defined(C)\nno\n#else\nelse\n#endif",
                         {"A": 1, "B": 1}) == "no"
    key = VariantKey(model="GGX", ndf_lobes=2, has_lights=True, has_environment=True, visibility_layers=3)
    code = variant_code(key)
    for name in ("warp_lobes_", "model_ndf_lobe(", "model_m_factor(", "environment_radiance(", "scene_light_sg(",
                 "ssdf_decode(", "lobe_visibility(", "env_amplitude", "texture(environment_texture"):
        assert name in code, name


# --------------------------------------------------------------------------- what each skip leaves out

SPECULAR_CODE = ("warp_lobes_", "WARP_FUNCTION", "model_ndf_lobe(", "model_m_factor(", "brdf_slice_amplitude(",
                 "ggx_two_lobes(", "environment_radiance(", "texture(environment_texture", "slice_axis",
                 "oct_encode(")
DIFFUSE_CODE = ("irradiance +=", "env_amplitude", "env_axis_sharpness")
LIGHT_CODE = ("scene_light_sg(", "sphere_light_sg(", "spot_light_sg(", "point_position_radius", "sun_axis_sharpness")
ENVIRONMENT_CODE = ("environment_radiance(", "texture(environment_texture", "env_prefilter_blend_parameter(",
                    "oct_encode(", "env_amplitude")
VISIBILITY_CODE = ("ssdf_decode(", "lobe_visibility(", "visibility_rows", "set_visibility_frame(", "ssdf_local_frame(")


def _assert_lacks(key, names, define):
    code = variant_code(key)
    present = [name for name in names if name in code]
    assert not present, f"{key.describe()}: {present} still in the compiled source"
    assert define not in fx.variant_defines(key)


def test_skipped_variants_lack_the_code():
    from sg_prt_addon.blender.export import MaterialParams

    full = dict(has_lights=True, has_environment=True, visibility_layers=3)
    diffuse_only = fx.variant_key(MaterialParams(specular_color=(0.0, 0.0, 0.0)), **full)
    assert (diffuse_only.has_diffuse, diffuse_only.has_specular) == (True, False)
    _assert_lacks(diffuse_only, SPECULAR_CODE, "HAS_SPECULAR")
    assert "env_amplitude" in variant_code(diffuse_only) and "ssdf_decode(" in variant_code(diffuse_only)
    specular_only = fx.variant_key(MaterialParams(diffuse_color=(0.0, 0.0, 0.0)), **full)
    assert (specular_only.has_diffuse, specular_only.has_specular) == (False, True)
    _assert_lacks(specular_only, DIFFUSE_CODE, "HAS_DIFFUSE")
    assert "environment_radiance(" in variant_code(specular_only)
    # the light loop's SSDF decodes go with the term: specular-only decodes light x slice products and the
    # light's own visibility (for the light tail, sg_shading.glsl's LIGHT_TAIL), not the diffuse lobes'
    def decodes(key):       # visibility call sites, macro definitions aside
        code = "\n".join(line for line in variant_code(key).split("\n") if not line.lstrip().startswith("#define"))
        return sum(code.count(name) for name in ("lobe_visibility(", "LOBE_VISIBILITY(", "DIFFUSE_VISIBILITY("))
    assert decodes(specular_only) == decodes(fx.variant_key(MaterialParams(), **full)) - 1
    # with the per-vertex pass the environment's diffuse lobes read the interpolated fractions
    per_vertex_key = fx.variant_key(MaterialParams(), **full, diffuse_rows=2)
    assert fx.variant_defines(per_vertex_key)["DIFFUSE_VISIBILITY_ROWS"] == "2"
    assert "diffuse_fractions[1] = diffuse_fractions_1;" in variant_code(per_vertex_key)
    assert fx.variant_key(MaterialParams(diffuse_color=(0.0, 0.0, 0.0)), **full,
                          diffuse_rows=2).diffuse_visibility_rows == 0
    _assert_lacks(fx.variant_key(MaterialParams(), False, True, False, 3), LIGHT_CODE, "HAS_LIGHTS")
    _assert_lacks(fx.variant_key(MaterialParams(), True, False, False, 3), ENVIRONMENT_CODE,
                  "HAS_ENVIRONMENT")
    _assert_lacks(fx.variant_key(MaterialParams(), True, True, False, 0), VISIBILITY_CODE,
                  "HAS_VISIBILITY")
    # a texture keeps the term; textures only the specular term reads leave the diffuse-only variant
    textured = MaterialParams(specular_color=(0.0, 0.0, 0.0), textures={"specular_color": "s", "roughness": "r"})
    assert fx.variant_key(textured, True, True).has_specular
    rough = MaterialParams(specular_color=(0.0, 0.0, 0.0), textures={"roughness": "r", "normal_map": "n"})
    assert fx.variant_key(rough, True, True).textures == ("normal_map",)
    assert fx.variant_key(MaterialParams(diffuse_color=(0.0, 0.0, 0.0),
                                         textures={"diffuse_color": "d"}), True, True).has_diffuse
    # NaN is not zero: the full variant shows it
    assert fx.variant_key(MaterialParams(specular_color=(float("nan"), 0.0, 0.0)), True, True).has_specular


def test_equal_sources_share_one_shader_key():
    """The model only shapes the BRDF slice: diffuse-only Cook-Torrance, Blinn-Phong and GGX variants
    assemble to one shader (one content hash); with specular they do not."""
    from sg_prt_addon.blender.export import MaterialParams

    keys = [fx.variant_key(MaterialParams(model=model, specular_color=(0.0, 0.0, 0.0)), True, True)
            for model in ("COOK_TORRANCE", "BLINN_PHONG", "GGX")]
    assert len(set(keys)) == 3
    assert len({fx.content_hash(key) for key in keys}) == 1
    full = [fx.variant_key(MaterialParams(model=model), True, True) for model in ("COOK_TORRANCE", "GGX")]
    assert fx.content_hash(full[0]) != fx.content_hash(full[1])


# --------------------------------------------------------------------------- images

def _scene(name, material_settings, light_power=500.0, world="environment", bake=False, textures=None):
    """A sphere over a floor, one point light (power None: none), the world: "environment" (a small
    random equirect), a colour tuple (world colour) or ("constant", colour) (an equirect of that colour)."""
    scene = fx.new_scene(name, SIZE, SIZE)
    scene.camera.location = (0.0, -5.0, 2.0)
    scene.camera.rotation_euler = (np.radians(72.0), 0.0, 0.0)
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 1.0), segments=24, rings=12)
    floor = fx.plane(scene, name + "_floor", (0.0, 0.0, 0.0))
    material = fx.material(name + "_material", **material_settings)
    for slot, pixels in (textures or {}).items():
        setattr(material.sgprt, slot + "_texture", fx.image(f"{name}_{slot}", pixels))
    sphere.data.materials.append(material)
    floor.data.materials.append(material)
    if light_power is not None:
        fx.point_light(scene, name + "_light", (2.0, -2.0, 4.0), light_power, radius=0.2)
    if world == "environment":
        rng = np.random.default_rng(3)
        pixels = np.ones((16, 32, 4), np.float32)
        pixels[..., :3] = rng.uniform(0.2, 1.5, (16, 32, 3))
        _world_image(scene, "skips_environment", pixels)
    elif world[0] == "constant":
        pixels = np.ones((16, 32, 4), np.float32)
        pixels[..., :3] = world[1]
        _world_image(scene, f"skips_constant_{name}", pixels)
    else:
        fx.world_colour(scene, world)
    if bake:
        _all_visible_bakes([sphere, floor])
    return scene


def _world_image(scene, image_name, pixels):
    import bpy

    world = fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    image = bpy.data.images.get(image_name) or fx.image(image_name, pixels)
    world.node_tree.nodes["Environment Texture"].image = image


def _all_visible_bakes(objects):
    """A bake per object whose SSDF is above every horizon (mean 2 pi, zero basis; 19 random PCA
    coefficients still decoded): each visibility ratio is exactly 1, the image the unshadowed one."""
    from sg_prt_addon.engine import scene_state

    rng = np.random.default_rng(7)
    terms, resolution = 19, 16
    bakes = {}
    for obj in objects:
        count = len(obj.data.vertices)
        bakes[obj.name] = types.SimpleNamespace(
            coefficients=rng.normal(size=(count, terms)).astype(np.float32),
            mean=np.full((resolution, resolution), 2 * np.pi, np.float32),
            basis=np.zeros((terms, resolution, resolution), np.float32), terms=terms)
    scene_state.visibility_provider = lambda object_eval: bakes.get(object_eval.name)


def _render(scene):
    result = dict(fx.render(scene))         # a copy: the next render clears render_engine.last_render
    assert "error" not in result, result.get("error")
    return result


def _keys(result):
    """The VariantKeys the render drew with (its SceneState through variant_key)."""
    state = result["state"]
    has_lights = state.light_data().count > 0
    has_environment = state.environment.prefiltered is not None
    keys = set()
    for entry in state.objects.values():
        layers = state.visibility[entry.mesh_key].layers if entry.mesh_key in state.visibility else 0
        for name in entry.material_names:
            keys.add(fx.variant_key(state.materials.get(name) or state.materials[""], has_lights,
                                    has_environment, False, layers))
    return keys


def _compare(skipped, full, record_error, label, rtol=2e-5, passes=("Combined", "Diffuse", "Specular")):
    covered = full["passes"]["Diffuse"][..., 3] > 0.5
    assert covered.mean() > 0.3
    errors = {}
    for name in passes:
        a, b = skipped["passes"][name][..., :3], full["passes"][name][..., :3]
        assert np.all(np.isfinite(a))
        scale = max(float(np.abs(b).max()), 1e-30)
        errors[name] = float(np.max(np.abs(a - b))) / scale
        record_error(f"variant skip {label}: {name} max |skip - full| / max", errors[name])
        assert errors[name] <= rtol, (name, errors[name])
    return errors


def test_diffuse_only_skips_the_specular_path(engine, record_error):
    zero = np.zeros((4, 4, 4), np.float32)
    skipped = _render(_scene("skip_diffuse_only", dict(specular_color=(0.0, 0.0, 0.0))))
    full = _render(_scene("full_diffuse_only", {}, textures={"specular_color": zero}))
    assert {key.has_specular for key in _keys(skipped)} == {False}
    assert {key.has_specular for key in _keys(full)} == {True}
    assert np.all(skipped["passes"]["Specular"][..., :3] == 0)
    assert skipped["passes"]["Diffuse"][..., :3].max() > 0.05
    _compare(skipped, full, record_error, "diffuse-only")


def test_specular_only_skips_the_diffuse_path(engine, record_error):
    zero = np.zeros((4, 4, 4), np.float32)
    skipped = _render(_scene("skip_specular_only", dict(diffuse_color=(0.0, 0.0, 0.0))))
    full = _render(_scene("full_specular_only", {}, textures={"diffuse_color": zero}))
    assert {key.has_diffuse for key in _keys(skipped)} == {False}
    assert {key.has_diffuse for key in _keys(full)} == {True}
    assert np.all(skipped["passes"]["Diffuse"][..., :3] == 0)
    assert skipped["passes"]["Specular"][..., :3].max() > 0.01
    _compare(skipped, full, record_error, "specular-only")


def test_no_lights_skips_the_light_loop(engine, record_error):
    skipped = _render(_scene("skip_no_lights", {}, light_power=None))
    full = _render(_scene("full_no_lights", {}, light_power=0.0))
    assert {key.has_lights for key in _keys(skipped)} == {False}
    assert {key.has_lights for key in _keys(full)} == {True}
    # float rounding only, at one or two pixels: the light loop (with its light tail since) changes how the
    # compiler contracts the slice code both variants share; measured 1.2e-5 to 3.7e-5 of the maximum
    # depending on what compiled before in the process
    _compare(skipped, full, record_error, "no lights", rtol=5e-5)


def test_no_bake_skips_the_ssdf_decode(engine, record_error):
    try:
        full = _render(_scene("full_no_bake", {}, bake=True))
    finally:
        fx.clear_bakes()
    skipped = _render(_scene("skip_no_bake", {}))
    assert {key.visibility_layers for key in _keys(skipped)} == {0}
    assert {key.visibility_layers for key in _keys(full)} == {5}
    _compare(skipped, full, record_error, "no bake")


def test_world_colour_skips_the_environment_fetch(engine, record_error):
    """A world colour against an equirect of that colour: the prefiltered fetch returns the colour
    (float tolerance); the diffuse term goes through the environment's SG fit, good to its fit error."""
    colour = (0.3, 0.45, 0.6)
    skipped = _render(_scene("skip_world_colour", {}, world=colour))
    full = _render(_scene("full_world_colour", {}, world=("constant", colour)))
    assert {key.has_environment for key in _keys(skipped)} == {False}
    assert {key.has_environment for key in _keys(full)} == {True}
    _compare(skipped, full, record_error, "world colour", rtol=2e-5, passes=("Specular",))
    _compare(skipped, full, record_error, "world colour (environment SG fit)", rtol=2e-3, passes=("Diffuse",))


def test_equal_sources_compile_once(engine):
    """Two materials whose variants assemble to the same shader: one surface compile in the render."""
    from sg_prt_addon.engine import shader_cache

    scene = _scene("shared_shader", dict(model="COOK_TORRANCE", specular_color=(0.0, 0.0, 0.0)), world=(0.2,) * 3)
    other = fx.material("shared_shader_other", model="BLINN_PHONG", specular_color=(0.0, 0.0, 0.0))
    floor = next(obj for obj in scene.objects if obj.name.endswith("_floor"))
    floor.data.materials[0] = other
    shader_cache.clear_cache()
    before = shader_cache.compile_count["surface"]
    result = _render(scene)
    keys = _keys(result)
    assert len(keys) == 2 and len({fx.content_hash(key) for key in keys}) == 1
    assert shader_cache.compile_count["surface"] == before + 1


# --------------------------------------------------------------------------- uploads

def test_upload_skips_unchanged_inputs(engine, monkeypatch):
    """Renderer.upload after the first: nothing changed -> no mesh, material or environment upload (same
    GPU objects); a material edit -> that material only; an environment change -> the environment
    texture re-created once, not again while it stays the same (prefilter from the content cache)."""
    from sg_prt_addon.blender import export
    from sg_prt_addon.engine import render_engine, scene_state

    probes = {}

    def after_frame(depsgraph, state, renderer, camera):
        def snapshot():
            return (dict(renderer.uploads), dict(renderer.mesh_buffers), dict(renderer.material_buffers),
                    renderer.environment_texture, renderer.equirect_texture)

        probes["first"] = snapshot()
        renderer.upload(state, state.consume_dirty(), camera)
        probes["unchanged"] = snapshot()
        state.dirty.materials.add(next(name for name in state.materials if name))
        renderer.upload(state, state.consume_dirty(), camera)
        probes["material"] = snapshot()
        world = export.WorldExport(colour=(0.5, 0.5, 0.5), equirect=np.full((8, 16, 3), 0.7, np.float32),
                                   image_name="skips_upload_other")
        cached = scene_state.environment_data(world, ENV_LAYER_SIZE)
        probes["cache_hit"] = scene_state.environment_data(world, ENV_LAYER_SIZE) is cached
        state.world, state.environment = world, cached
        renderer.upload(state, state.consume_dirty(), camera)
        probes["environment"] = snapshot()
        state.environment = scene_state.environment_data(world, ENV_LAYER_SIZE)
        renderer.upload(state, state.consume_dirty(), camera)
        probes["same_environment"] = snapshot()

    monkeypatch.setitem(render_engine.debug, "after_frame", after_frame)
    _render(_scene("uploads", {}))
    uploads, meshes, materials, environment, equirect = probes["first"]
    assert uploads == {"meshes": 2, "materials": 2} and environment is not None     # "" and the material
    unchanged = probes["unchanged"]
    assert unchanged[0] == uploads and unchanged[3] is environment and unchanged[4] is equirect
    assert all(unchanged[1][key] is meshes[key] for key in meshes)
    assert all(unchanged[2][key] is materials[key] for key in materials)
    edited = probes["material"]
    assert edited[0] == {"meshes": 2, "materials": 3} and edited[3] is environment
    assert sum(edited[2][key] is not materials[key] for key in materials) == 1
    assert probes["cache_hit"]
    changed = probes["environment"]
    assert changed[0] == edited[0] and changed[3] is not environment and changed[4] is not equirect
    same = probes["same_environment"]
    assert same[3] is changed[3] and same[4] is changed[4]
