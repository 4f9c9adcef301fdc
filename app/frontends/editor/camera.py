"""Orbit camera: yaw/pitch/distance about a target, turned into alight.core.scene's Camera each frame."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from alight.core.scene import Camera


# The farthest the wheel zooms out, in framed distances: the framed mesh is a tenth of its
# framed size there, still seen and picked up again in a few clicks.
ZOOM_OUT_LIMIT = 10.0


@dataclass
class OrbitCamera:
    target: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw_deg: float = 0.0       # 0: on +Z looking toward -Z (docs/conventions.md's default camera)
    pitch_deg: float = 0.0
    distance: float = 4.0
    fov_y_deg: float = 35.0
    radius: float = 1.0        # the framed object's size: sets near/far and pan speed
    framed_distance: float = 0.0   # the last frame()'s distance (0: none yet): the zoom's outer limit

    def _offset(self) -> np.ndarray:
        y, p = math.radians(self.yaw_deg), math.radians(self.pitch_deg)
        return np.array([math.sin(y) * math.cos(p), math.sin(p), math.cos(y) * math.cos(p)]) * self.distance

    def camera(self) -> Camera:
        t = np.asarray(self.target, dtype=np.float64)
        pos = t + self._offset()
        near = max(self.distance - 2.0 * self.radius, self.distance * 1e-3)
        return Camera(tuple(pos), tuple(t), (0.0, 1.0, 0.0), self.fov_y_deg, near=near,
                      far=self.distance + 8.0 * self.radius)

    def render_flags(self, size: tuple[int, int]) -> list[str]:
        """This camera and a view of ``size`` (width, height) as ``alight render``'s flags, which
        draw the same picture of the same scene (9 significant digits: a rounded distance moved
        the silhouette by a fraction of a pixel)."""
        def g(x: float) -> str:
            return f"{float(x):.9g}"

        return ["--orbit", g(self.yaw_deg), "--elevation", g(self.pitch_deg), "--distance", g(self.distance),
                "--fov", g(self.fov_y_deg), "--target", ",".join(g(x) for x in self.target),
                "--size", f"{int(size[0])}x{int(size[1])}"]

    def orbit(self, dx_px: float, dy_px: float) -> None:
        self.yaw_deg -= dx_px * 0.3
        # Stop short of the poles, where the look-at 'up' would be parallel to the view.
        self.pitch_deg = max(-89.0, min(89.0, self.pitch_deg + dy_px * 0.3))

    def pan(self, dx_px: float, dy_px: float, height_px: int) -> None:
        # One pixel moves the target by one pixel's worth of the view at the target's distance.
        scale = 2.0 * self.distance * math.tan(math.radians(self.fov_y_deg) / 2) / max(height_px, 1)
        forward = -self._offset() / self.distance
        right = np.cross(forward, [0.0, 1.0, 0.0])
        right /= max(np.linalg.norm(right), 1e-9)
        up = np.cross(right, forward)
        self.target = tuple(np.asarray(self.target) + (-dx_px * right + dy_px * up) * scale)

    def zoom(self, wheel: float) -> None:
        # Out to ZOOM_OUT_LIMIT times the framed distance (60 wheel clicks out left a dot, and
        # the way back as many); a camera never framed (a restored session's) by the radius.
        far = ZOOM_OUT_LIMIT * (self.framed_distance or 4.0 * self.radius)
        self.distance = min(max(self.radius * 0.05, self.distance * 0.9 ** wheel), max(far, self.distance))

    def look_from(self, direction) -> None:
        """Yaw and pitch so the eye sits along ``direction`` from the target (the distance kept;
        the pitch stops short of the poles, as ``orbit``)."""
        d = np.asarray(direction, dtype=np.float64)
        d = d / max(float(np.linalg.norm(d)), 1e-12)
        self.yaw_deg = math.degrees(math.atan2(d[0], d[2])) if abs(d[1]) < 1.0 - 1e-9 else self.yaw_deg
        self.pitch_deg = max(-89.0, min(89.0, math.degrees(math.asin(max(-1.0, min(1.0, float(d[1])))))))

    def direction(self) -> np.ndarray:
        """The unit vector from the target toward the eye (3,)."""
        offset = self._offset()
        return offset / max(float(np.linalg.norm(offset)), 1e-12)

    def frame(self, center, radius: float, aspect: float, margin: float = 1.3, corners=None) -> None:
        """Fit a sphere in the narrower field of view, or the bounding box's ``corners`` where
        they need less distance, from the current direction (alight.core.scene.fit_distance, as
        frame_camera does)."""
        from alight.core.scene import fit_distance

        self.radius = max(float(radius), 1e-6)
        direction = self.direction()
        self.distance = fit_distance(center, self.radius, self.fov_y_deg, aspect, direction, corners, margin)
        self.framed_distance = self.distance
        self.target = tuple(float(x) for x in center)
