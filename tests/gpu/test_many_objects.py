"""Many objects (issue 20's scaling): linked duplicates of a plain mesh share one export and one GPU copy,
and the draw loop binds a run of objects with one variant and material once; neither changes the image."""
import engine_fixtures as fx
import numpy as np
import pytest

SIZE = 64


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _spheres(name):
    """Six small spheres, linked duplicates of one mesh, in two alternating materials of different variants
    (per-object slots), lit; and a sphere of its own mesh with a visibility bake (_render)."""
    import bpy

    scene = fx.new_scene(name, SIZE, SIZE)
    fx.world_colour(scene, (0.1, 0.1, 0.12))
    fx.point_light(scene, name + "_light", (1.0, -3.0, 3.0), 500.0)
    materials = [fx.material(name + "_ggx", model="GGX", roughness=0.3),
                 fx.material(name + "_phong", model="BLINN_PHONG", exponent=40.0)]
    first = fx.uv_sphere(scene, name + "_0", (-2.5, 0.0, 1.0), radius=0.45, segments=16, rings=8)
    objects = [first]
    for index in range(1, 6):
        obj = fx.add_object(scene, bpy.data.objects.new(f"{name}_{index}", first.data))
        obj.location = (-2.5 + index, 0.0, 1.0 + 0.1 * index)
        objects.append(obj)
    first.data.materials.append(None)
    for index, obj in enumerate(objects):      # per-object slots: linked duplicates may differ in material
        obj.material_slots[0].link = "OBJECT"
        obj.material_slots[0].material = materials[(index // 2) % 2]
    baked = fx.uv_sphere(scene, name + "_baked", (0.0, 0.0, -0.2), radius=0.6, segments=16, rings=8)
    baked.data.materials.append(materials[0])
    return scene, objects, baked


def _render(scene, baked, bake=None):
    """(G-buffer render, plain render) of a _spheres scene, and the baked object's bake (`bake`: that one
    instead of a new one, so renders to compare draw the same bake)."""
    from sg_prt_addon.engine import scene_state

    if bake is None:
        bake = fx.bake_objects(scene, [baked], resolution=8)[baked.name]
    scene_state.visibility_provider = lambda object_eval: bake if object_eval.name == baked.name else None
    try:
        # copies: fx.render returns render_engine.last_render, which the next render refills
        return (dict(fx.render(scene, gbuffer=True)), dict(fx.render(scene))), bake
    finally:
        fx.clear_bakes()


def test_linked_duplicates_share_one_export(engine, monkeypatch):
    """Linked duplicates draw one export (and one GPU copy) of their mesh; the image equals the one drawn
    with an export for each object (as before they were shared)."""
    from sg_prt_addon.engine import scene_state

    scene, objects, baked = _spheres("linked")
    shared, bake = _render(scene, baked)
    monkeypatch.setattr(scene_state, "_is_plain_mesh", lambda obj: False)      # a key per object
    separate, _ = _render(scene, baked, bake)
    state = shared[0]["state"]
    assert len({state.objects[obj.name].mesh_key for obj in objects}) == 1
    assert len(state.meshes) == 2 and len(separate[0]["state"].meshes) == 7
    for shared_result, separate_result in zip(shared, separate):
        assert "error" not in shared_result and "error" not in separate_result
        for name, image in shared_result["passes"].items():
            if isinstance(image, np.ndarray):
                assert np.array_equal(image, separate_result["passes"][name]), name
    assert (shared[0]["passes"]["gbuffer_normal"][..., 3] > 0).sum() > 100


def test_objects_of_one_mesh_and_material_share_key_and_bindings(engine, monkeypatch):
    """The draw loop makes a variant key once for the objects drawing one mesh and material (unless making it
    read the object's transform) and binds a run of objects with one variant and material once (unless the
    technique's bind reads the object's own): the image (passes and G-buffer, whose object ids are set per
    object) equals the one made with a key and a bind for each object."""
    from sg_prt_addon.techniques.sg import sg_parametric

    technique = sg_parametric.TECHNIQUE
    scene, objects, baked = _spheres("runs")
    keys, binds = [], []
    variant_key, bind = technique.variant_key, technique.bind

    def counted_key(params, inputs):
        keys.append(params.name)
        return variant_key(params, inputs)

    def counted_bind(shader, key, context):
        binds.append(key.visibility_layers)
        return bind(shader, key, context)

    monkeypatch.setattr(technique, "variant_key", counted_key)
    monkeypatch.setattr(technique, "bind", counted_bind)
    shared, bake = _render(scene, baked)
    # each of the two renders: a key for each material of the linked spheres and one for the baked sphere
    # (whose key reads its transform: shared light visibility); three runs of two unbaked spheres (the
    # materials alternate in pairs) and the baked one, whose bind reads its rows
    assert len(keys) == 2 * 3
    assert binds.count(0) == 2 * 3 and len(binds) == 2 * 4

    def key_reading_the_transform(params, inputs):
        assert inputs.matrix_world.shape == (4, 4)
        return counted_key(params, inputs)

    monkeypatch.setattr(technique, "variant_key", key_reading_the_transform)
    monkeypatch.setattr(technique, "bind_reads_object", lambda key: True)
    keys.clear()
    binds.clear()
    every, _ = _render(scene, baked, bake)
    assert len(keys) == len(binds) == 2 * (len(objects) + 1)
    for shared_result, every_result in zip(shared, every):
        for name, image in shared_result["passes"].items():
            if isinstance(image, np.ndarray):
                assert np.array_equal(image, every_result["passes"][name]), name
