"""What everything else stands on: the numpy twins of the shaders' maths (``shading``), the
headless GL context and shader library (``gpu``), and the scene's plain state: ``material``,
``scene`` (camera, lights, display), ``mesh`` (arrays and the built-in meshes),
``texture_maps`` and ``ibl_models`` (the names of the forward pass's IBL models). Imports nothing
of alight's but ``errors`` and ``paths``."""
