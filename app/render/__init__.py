"""The forward renderer (``renderer.ForwardRenderer``): draws a scene with the baked IBL maps
and punctual lights through ``shaders/render/``. Knows nothing of any front end."""
