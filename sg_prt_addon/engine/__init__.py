"""SG-PRT render engine: RenderEngine (render_engine.py), CPU scene state and update logic
(scene_state.py), GPU upload and drawing (renderer.py), compiled shaders (shader_cache.py); the rendering
methods are ../techniques.

`classes` is what the add-on registers (blender/registration.py)."""
from .render_engine import SGPRT_RenderEngine

classes = (SGPRT_RenderEngine,)
