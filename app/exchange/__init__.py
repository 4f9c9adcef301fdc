"""Files in and out, one module per kind: ``meshes`` (OBJ/PLY/STL/glTF through trimesh),
``gltf_material`` (glTF material import and export), ``images`` (texture maps),
``environment_files`` (HDR/EXR panoramas), ``presets`` (material JSON) and ``output`` (atomic
writes of images and text). Builds on ``core`` only."""
