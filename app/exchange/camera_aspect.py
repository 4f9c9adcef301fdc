"""The name and aspect ratio of each camera a glTF file places, in the order ``load_mesh`` lists them.

``--camera gltf:N`` numbers cameras as the loader meets them (the default scene's nodes, depth
first, parents before children); this reads the same JSON the same way and gives each camera's
``perspective.aspectRatio`` (glTF 2.0 5.13: optional; the viewport's width over height) or, for
an orthographic camera, ``xmag / ymag``, with the name a warning can call it by. Only the
JSON is read (a .glb's first chunk), never the buffers, so it costs little next to the load.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import NamedTuple


class CameraFrame(NamedTuple):
    """``name``: the camera's glTF name, else its node's (None: neither has one); ``aspect``:
    width over height (None where the file gives none or an unusable value);
    ``orthographic``: the view's height is ``ymag`` rather than a vertical field of view."""

    name: str | None
    aspect: float | None
    orthographic: bool


def _gltf_json(path: str) -> dict:
    data = Path(path).read_bytes()
    if data[:4] == b"glTF" and len(data) >= 20:
        length, kind = struct.unpack_from("<II", data, 12)
        if kind == 0x4E4F534A:   # 'JSON'
            return json.loads(data[20:20 + length])
        return {}
    return json.loads(data)


def gltf_camera_frames(path: str) -> list[CameraFrame]:
    """Each placed camera's name and aspect ratio. Returns [] for a file that is not glTF or
    cannot be read: the loader reports those."""
    try:
        doc = _gltf_json(path)
    except (OSError, ValueError, UnicodeDecodeError, struct.error):
        return []
    if not isinstance(doc, dict):
        return []
    nodes = doc.get("nodes") or []
    scenes = doc.get("scenes") or []
    if scenes:
        index = doc.get("scene", 0) or 0
        roots = list((scenes[index] if 0 <= index < len(scenes) else {}).get("nodes") or [])
    else:
        children = {c for n in nodes for c in (n.get("children") or [])}
        roots = [i for i in range(len(nodes)) if i not in children]
    cameras = doc.get("cameras") or []
    out: list[CameraFrame] = []
    stack, seen = list(reversed(roots)), set()
    while stack:
        i = stack.pop()
        if not isinstance(i, int) or not 0 <= i < len(nodes) or i in seen:
            continue
        seen.add(i)
        node = nodes[i]
        if node.get("camera") is not None:
            c = node["camera"]
            camera = cameras[c] if isinstance(c, int) and 0 <= c < len(cameras) else None
            camera = camera if isinstance(camera, dict) else {}
            name = camera.get("name") or node.get("name")
            out.append(CameraFrame(name if isinstance(name, str) else None, _aspect(camera),
                                   camera.get("type") == "orthographic"))
        stack.extend(reversed(node.get("children") or []))
    return out


def _aspect(camera: dict) -> float | None:
    try:
        if camera.get("type") == "orthographic":
            o = camera.get("orthographic") or {}
            value = abs(float(o["xmag"])) / abs(float(o["ymag"]))
        else:
            value = float((camera.get("perspective") or {})["aspectRatio"])
    except (KeyError, TypeError, ValueError, ZeroDivisionError):
        return None
    return value if 1e-3 < value < 1e3 else None
