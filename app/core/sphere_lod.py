"""How finely to tessellate the built-in UV sphere for the size it has on screen.

The built-in ball's shading normal is the sphere's own (``alight.core.mesh.sphere``: the vertex
normals are the unit positions, so the interpolated, renormalised normal points from the centre
through the facet point), so a coarser tessellation moves the picture only where the flat
facets part from the true sphere: at the silhouette, and in where a pixel's ray meets the facet
instead of the sphere. On a software rasteriser (llvmpipe) the ball's cost grows with its
triangle count at editor sizes (small triangles pay for whole 4x4 blocks), so the renderer draws
the coarsest level of SPHERE_LOD_SEGMENTS whose facets stay within MAX_SILHOUETTE_ERROR_PX of the
sphere's outline. A GPU pays nothing for it either way.

The error model: a UV sphere of ``n`` segments and ``n / 2`` rings steps 2 pi / n in longitude
and latitude; its flat triangles part furthest from the sphere at the middle of a quad's
diagonal, half a diagonal (about sqrt(2) pi / n of arc) from its corners, so the outline moves
in by at most ``R (1 - cos(sqrt(2) pi / n))`` (the sagitta of that arc; R the sphere's radius).
"""

from __future__ import annotations

import functools
import math

import numpy as np

# The levels the renderer keeps (segments; rings are half). 128 is the built-in ball's own, and
# the finest: a larger picture is drawn as before, never with more triangles than today.
SPHERE_LOD_SEGMENTS = (16, 20, 24, 28, 32, 40, 48, 56, 64, 80, 96, 112, 128)
# The quality choice: how far (in output pixels) the facets may fall inside the true outline.
MAX_SILHOUETTE_ERROR_PX = 0.5


def silhouette_error(segments: int, radius_px: float) -> float:
    """The farthest the outline of a ``segments`` x ``segments / 2`` UV sphere of ``radius_px``
    pixels lies inside the true sphere's, in pixels (the module docstring's model)."""
    return float(radius_px) * (1.0 - math.cos(math.sqrt(2.0) * math.pi / segments))


def sphere_segments(radius_px: float, max_error_px: float = MAX_SILHOUETTE_ERROR_PX,
                    levels: tuple[int, ...] = SPHERE_LOD_SEGMENTS) -> int:
    """The fewest segments among ``levels`` whose silhouette error is at most ``max_error_px``
    for a sphere ``radius_px`` pixels across (its projected radius); the finest level when none
    is. A radius that is not finite or not positive gets the finest level."""
    if not (math.isfinite(radius_px) and radius_px > 0.0):
        return levels[-1]
    for n in levels:
        if silhouette_error(n, radius_px) <= max_error_px:
            return n
    return levels[-1]


def projected_radius_px(view_projection: np.ndarray, centre, radius: float, image_size: tuple[int, int]) -> float:
    """The radius, in pixels of the whole image, of a sphere's outline on screen (its largest
    semi-axis where it is off the axis).

    ``view_projection``: the camera's (4, 4) matrix in pyrr's row-vector layout (``clip = (p, 1)
    @ VP``, alight.core.scene.Camera.view_projection), perspective or orthographic, not a tile's;
    ``image_size``: (width, height) in pixels. Perspective: a sphere of angular radius a seen
    on the axis is ``f tan(a)`` across, ``tan(a) = r / sqrt(d^2 - r^2)``; off the axis at angle t
    its outline stretches radially by about ``1 / cos^2(t)``. Where the sphere reaches the eye,
    infinity (the caller draws the finest level).
    """
    vp = np.asarray(view_projection, np.float64)
    c = np.append(np.asarray(centre, np.float64), 1.0) @ vp
    r = float(radius)
    # Pixels per unit of tan(angle) (perspective) or per world unit (orthographic), in x and y.
    gx, gy = float(np.linalg.norm(vp[:3, 0])), float(np.linalg.norm(vp[:3, 1]))
    fx, fy = gx * image_size[0] / 2.0, gy * image_size[1] / 2.0
    w_gradient = float(np.linalg.norm(vp[:3, 3]))      # 1 for a perspective camera, 0 orthographic
    if w_gradient == 0.0:
        return r * max(fx, fy) / float(c[3])
    d = float(c[3]) / w_gradient           # the centre's depth along the view axis
    if d <= r * 1.0000001:
        return math.inf
    tan_x, tan_y = float(c[0]) / float(c[3]) / gx * w_gradient, float(c[1]) / float(c[3]) / gy * w_gradient
    off_axis = 1.0 + tan_x * tan_x + tan_y * tan_y
    return r / math.sqrt(d * d - r * r) * max(fx, fy) / w_gradient * off_axis


def sphere_surface_point(eye, facet_point, radius: float) -> np.ndarray:
    """The view ray's first hit on the sphere ``|x| = radius`` centred at the origin, for rays
    from ``eye`` (3,) through ``facet_point`` (N, 3) or (3,), a point of the drawn mesh (a facet
    inside the sphere, or the impostor's proxy outside it): the shaded point of the built-in ball
    (GLSL twin: common/sphere_surface.glsl). Solved about the facet point p, ``|p - s d|^2 = r^2``
    for the step s back toward the eye (the larger root), so that nothing cancels at grazing
    angles. A ray that misses gets its point closest to the centre. float64."""
    p = np.asarray(facet_point, np.float64)
    d = p - np.asarray(eye, np.float64)
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    pd = np.sum(p * d, axis=-1, keepdims=True)
    s = pd + np.sqrt(np.maximum(pd * pd + (radius * radius - np.sum(p * p, axis=-1, keepdims=True)), 0.0))
    return p - s * d


# The impostor's proxy (alight.render.sphere_impostor): a polygon of
# this many sides facing the eye, in the plane of the sphere's outline circle, around that circle
# with this many output pixels to spare. A pixel whose samples (at most 0.53 px from its centre
# in the standard 4x pattern) meet the sphere then has its centre inside the proxy. Few, large
# triangles: llvmpipe shades whole 4x4 blocks along every triangle edge.
IMPOSTOR_PROXY_SIDES = 16
IMPOSTOR_MARGIN_PX = 2.0


@functools.lru_cache(maxsize=4)
def impostor_proxy_polygon(sides: int = IMPOSTOR_PROXY_SIDES) -> tuple[np.ndarray, np.ndarray]:
    """The proxy in its own frame: the unit circle's centre and ``sides`` vertices at radius 1 in
    the plane z = 0, counter-clockwise seen from +z, as a triangle fan. Returns positions
    (sides + 1, 3) float32 and indices (sides, 3) uint32 (shared: read-only)."""
    angles = 2.0 * np.pi * np.arange(sides) / sides
    ring = np.stack([np.cos(angles), np.sin(angles), np.zeros(sides)], axis=1)
    positions = np.vstack([[0.0, 0.0, 0.0], ring]).astype(np.float32)
    k = np.arange(sides)
    indices = np.stack([np.zeros(sides, int), 1 + k, 1 + (k + 1) % sides], axis=1).astype(np.uint32)
    positions.flags.writeable = indices.flags.writeable = False
    return positions, indices


def _outline_frame(eye, radius: float):
    """The sphere's outline seen from ``eye``: (x, y, axis, centre, circle): the unit vectors
    spanning the plane of the circle where the view rays touch the sphere, its normal toward the
    eye, the circle's centre and radius. None where the eye is not outside the sphere."""
    ex, ey, ez = (float(c) for c in eye)
    d = math.sqrt(ex * ex + ey * ey + ez * ez)
    if d <= radius * 1.0000001:
        return None
    # (Per frame, in Python: scalar arithmetic, not numpy's small-array calls.)
    ax, ay, az = ex / d, ey / d, ez / d
    if abs(ay) < 0.9:      # x = normalize(cross((0, 1, 0), axis))
        x = (az, 0.0, -ax)
    else:                  # x = normalize(cross((1, 0, 0), axis))
        x = (0.0, -az, ay)
    n = math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
    x = np.array(x) / n
    axis = np.array([ax, ay, az])
    y = np.array([ay * x[2] - az * x[1], az * x[0] - ax * x[2], ax * x[1] - ay * x[0]])    # cross(axis, x)
    return x, y, axis, axis * radius * radius / d, radius * math.sqrt(1.0 - (radius / d) ** 2)


def _polygon_model(frame, scale: float) -> np.ndarray:
    x, y, axis, centre, _ = frame
    model = np.eye(4)
    model[:3, 0], model[:3, 1], model[:3, 2] = x * scale, y * scale, axis
    model[:3, 3] = centre
    return model


def impostor_proxy_model(eye, radius: float, radius_px: float, sides: int = IMPOSTOR_PROXY_SIDES,
                         margin_px: float = IMPOSTOR_MARGIN_PX) -> np.ndarray | None:
    """The (4, 4) float64 matrix (column vectors: ``world = M @ (p, 1)``) that places
    ``impostor_proxy_polygon`` around the outline of the sphere ``|x| = radius`` seen from
    ``eye`` (3,): in the plane of the circle where the view rays touch the sphere (its centre
    ``a r^2 / d`` along the unit axis a toward the eye, its radius ``r sqrt(1 - r^2 / d^2)``),
    facing the eye, scaled so the polygon's edges clear the circle by ``margin_px`` of the
    outline's ``radius_px`` (``projected_radius_px``). The rays through the polygon are then a
    cone around the sphere's outline. None where the eye is not outside the sphere or
    ``radius_px`` is not finite and positive."""
    if not (math.isfinite(radius_px) and radius_px > 0.0):
        return None
    frame = _outline_frame(eye, radius)
    if frame is None:
        return None
    return _polygon_model(frame, frame[4] * (1.0 + margin_px / radius_px) / math.cos(math.pi / sides))


def impostor_hole_model(eye, radius: float, radius_px: float, inset_px: float = 1.0) -> np.ndarray | None:
    """As ``impostor_proxy_model``, but for the polygon inscribed in the outline circle, its
    vertices ``inset_px`` of ``radius_px`` inside it: every ray through it meets the sphere, so
    where the impostor is drawn over the background no background pixel lies inside it
    (``impostor_background_ring``). None as ``impostor_proxy_model``, or where the outline is
    within ``inset_px`` of a point."""
    if not (math.isfinite(radius_px) and radius_px > inset_px):
        return None
    frame = _outline_frame(eye, radius)
    if frame is None:
        return None
    return _polygon_model(frame, frame[4] * (1.0 - inset_px / radius_px))


def impostor_background_ring(hole_model: np.ndarray, view_projection: np.ndarray,
                             sides: int = IMPOSTOR_PROXY_SIDES) -> np.ndarray | None:
    """Triangles covering the whole viewport but the polygon ``hole_model`` places
    (``impostor_hole_model``): (6 sides, 2) float32 NDC points, three per triangle,
    counter-clockwise. Each of the polygon's edges is joined to a far polygon along the rays from
    the polygon's projected centroid through its vertices, far enough out to enclose the NDC
    square, so neighbouring triangles share their edges exactly (no pixel twice, none missed:
    OpenGL 4.5 section 14.6.1). ``view_projection``: (4, 4) row-vector matrix (``clip = p @ vp``).
    None where a vertex is not in front of the eye."""
    points = impostor_proxy_polygon(sides)[0][1:]
    clip = np.hstack([points, np.ones((sides, 1))]) @ hole_model.T @ np.asarray(view_projection, np.float64)
    if not (clip[:, 3] > 1e-9).all():
        return None
    inner = clip[:, :2] / clip[:, 3:]
    centre = inner.mean(axis=0)
    spoke = inner - centre
    length = np.sqrt(np.sum(spoke * spoke, axis=1, keepdims=True))
    if not (length > 0.0).all():
        return None
    # The far polygon's edges lie at least R cos(gap / 2) from the centre; a projected regular
    # polygon's angular gaps stay well under 90 degrees, so R = 4 (|c| + 2) encloses the square.
    outer = centre + spoke / length * (4.0 * (float(np.hypot(*centre)) + 2.0))
    nxt = np.roll(np.arange(sides), -1)
    triangles = np.stack([inner, outer[nxt], inner[nxt], inner, outer, outer[nxt]], axis=1)
    return triangles.reshape(-1, 2).astype(np.float32)


def ray_meets_sphere(eye, directions, radius: float) -> np.ndarray:
    """Whether rays from ``eye`` (3,), outside the sphere ``|x| = radius`` centred at the origin,
    along ``directions`` (N, 3) of any length meet it in front of the eye: the impostor's coverage
    test (GLSL twin: common/sphere_surface.glsl ray_meets_sphere). Returns (N,) bool."""
    e = np.asarray(eye, np.float64)
    d = np.asarray(directions, np.float64)
    b = d @ e
    return (b < 0.0) & (b * b >= np.sum(d * d, axis=-1) * (e @ e - radius * radius))
