"""SG-PRT render engine: RenderEngine (render_engine.py), CPU scene state and update logic
(scene_state.py), GPU upload and drawing (renderer.py), compiled shaders (shader_cache.py), the frames
of anti-aliasing (anti_aliasing.py); the rendering methods are ../techniques, registration.py registers
the engine class."""
