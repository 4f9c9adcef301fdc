"""Extensions that hold metadata only (KHR_xmp_json_ld and the others in
alight.exchange.gltf.METADATA): a file using or requiring them renders exactly as the same file
without them, and nothing is said. Through the real command, against a control file the test
writes without the extensions."""

from __future__ import annotations

import numpy as np
import pytest

from tests.files_cases import render_exr
from tests.gltf_builder import FLOAT, UINT, Gltf, grid_plane

VIEW = ("--elevation", "30")
XMP = {"@context": {"dc": "http://purl.org/dc/elements/1.1/", "rdf": "http://www.w3.org/1999/02/22-rdf-syntax-ns#"},
       "@id": "", "dc:creator": {"@list": ["alight tests"]},
       "dc:title": {"@type": "rdf:Alt", "rdf:_1": {"@language": "en-us", "@value": "A plane"}}}


def plane_glb(path, required: bool | None):
    """A plane with a material; ``required`` None: no extension; else every metadata extension
    written where its specification puts it, listed as used (and required when True)."""
    g = Gltf()
    pos, nor, uv, idx = grid_plane(2, 2.0)
    prim = {"attributes": {"POSITION": g.accessor(pos, FLOAT, bounds=True), "NORMAL": g.accessor(nor)},
            "indices": g.accessor(idx.reshape(-1), UINT),
            "material": g.material(pbrMetallicRoughness={"baseColorFactor": [0.7, 0.4, 0.2, 1.0],
                                                         "metallicFactor": 0.0, "roughnessFactor": 0.5})}
    if required is not None:
        prim["attributes"]["_FEATURE_ID_0"] = g.accessor(np.zeros(len(pos), np.float32), FLOAT)
        prim["extensions"] = {"EXT_mesh_features": {"featureIds": [{"featureCount": 1, "attribute": 0}]}}
        g.mesh([prim], extensions={"KHR_xmp_json_ld": {"packet": 0}, "KHR_xmp": {"packet": 0},
                                   "AGI_stk_metadata": {"noObscuration": True}})
        g.doc["asset"]["extensions"] = {"KHR_xmp_json_ld": {"packet": 0}}
        g.doc["scenes"][0]["extensions"] = {"FB_geometry_metadata": {
            "vertexCount": len(pos), "primitiveCount": len(idx),
            "sceneBounds": {"min": [-1.0, -1.0, 0.0], "max": [1.0, 1.0, 0.0]}}}
        g.doc["extensions"] = {
            "KHR_xmp_json_ld": {"packets": [XMP]},
            "KHR_xmp": {"@context": {"dc": "http://purl.org/dc/elements/1.1/"}, "packets": [{"dc:creator": ["x"]}]},
            "AGI_stk_metadata": {"solarPanelGroups": [{"name": "Geo1", "efficiency": 14.0}]},
            "EXT_structural_metadata": {"schema": {"id": "s", "classes": {"part": {"properties": {
                "label": {"type": "STRING"}}}}}},
        }
        g.use("KHR_xmp_json_ld", "KHR_xmp", "FB_geometry_metadata", "AGI_stk_metadata", "EXT_structural_metadata",
              "EXT_mesh_features", required=required)
    else:
        g.mesh([prim])
    return g.save(path)


@pytest.mark.parametrize("required", [False, True])
def test_metadata_extensions_change_no_pixel_and_say_nothing(tmp_path, required):
    from alight.exchange.gltf import METADATA

    a_path = plane_glb(tmp_path / "meta.glb", required)
    import json
    import struct

    data = a_path.read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    assert set(json.loads(data[20:20 + length])["extensionsUsed"]) == METADATA   # each one is in the file
    a, warn = render_exr(tmp_path / "a.exr", "--mesh", a_path, *VIEW)
    b, _ = render_exr(tmp_path / "b.exr", "--mesh", plane_glb(tmp_path / "plain.glb", None), *VIEW)
    assert warn == []
    assert (a[..., 3] > 0).mean() > 0.1
    np.testing.assert_array_equal(a, b)
