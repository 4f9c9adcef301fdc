"""Screen-space ground-truth ambient occlusion (GTAO; Jimenez, Wu, Pesce and Jarabo 2016,
"Practical Realtime Strategies for Accurate Indirect Occlusion"): the numpy twins of the GLSL in
shaders/common/gtao.glsl, and the pass's settings.

Per pixel, the cosine-weighted visibility is an integral over slices (half-planes about the view
vector v, one per screen direction phi) of an inner integral over the angle theta from v inside
the slice, between the two horizons h1 <= 0 <= h2 found in the depth buffer:

    V = (1/pi) int_0^pi |n_p| a(h1, h2, gamma) dphi,
    a = 1/4 (-cos(2 h1 - gamma) + cos gamma + 2 h1 sin gamma)
      + 1/4 (-cos(2 h2 - gamma) + cos gamma + 2 h2 sin gamma)

with n_p the normal projected into the slice and gamma its angle from v. Each horizon is clamped
to the normal's hemisphere (gamma -/+ pi/2), so an open point gets V = 1 at any orientation.
"""

from __future__ import annotations

import numpy as np

# Quality choices (named defines of shaders/render/gtao.frag; app/core/shader_names.py).
SLICES = 2          # GTAO_SLICES: slice directions per pixel (x 16 rotations over the 4x4 denoise)
STEPS = 8           # GTAO_STEPS: depth samples per side of a slice
RADIUS_FRACTION = 1.0    # the search radius in world units, as a share of the mesh's bounding-box diagonal (the bake reaches the whole mesh; 0.25: corner 15.9%, bowl 22.4% under royal_esplanade, 1.0: 13.8, 17.0%)
MAX_RADIUS_PX = 96.0     # and at most this many pixels on screen, or MAX_RADIUS_HEIGHT of the draw height where more
MAX_RADIUS_HEIGHT = 0.5  # (the editor's 720 rows: 360 px; the samples stay GTAO_STEPS, spaced quadratically:
                         # render/gtao.frag sample_offset_px. 0.2 missed the shader ball's bowl over its base at
                         # 384 px: V 0.6-0.8 there, 2.6x the path tracer's light; benchmarks/results/gtao.md)
# The height field's assumption, limited (benchmarks/results/gtao.md, "Thin occluders"). Screen
# depth takes every occluder as the top of a solid that claims all directions below it; a grid of
# spheres in front of another across an empty gap (Khronos' MetalRoughSpheres) then hides the back
# grid (0.60 of --occlusion off). How thick an occluder is comes from the scene's scale, per part:
# its part's bounding-box diagonal (render/gtao_depth.frag writes it beside the normal). One that is
# more than THICKNESS times that in front of the point, in view depth, fades out of the horizon as
# if the excess were 1 + THIN_OCCLUDER times longer (common/gtao.glsl gtao_falloff_weight; XeGTAO's
# thin occluder compensation, there scaled by the search radius, which here is the whole mesh's
# diagonal: 4x a sphere's depth gap, and so it would need a factor that breaks the bowl, whose
# near rim hides its floor from the same distance; 0.1 of the radius, 4: bowl 8.6 -> 18.9%). A
# one-part mesh (the corner, the bowl) is as before: no point lies farther than its diagonal.
THICKNESS = 1.0
THIN_OCCLUDER = 4.0     # (the back grid 0.93 of --occlusion off; 8: 0.93)
# A facing occluder's own light (render/gtao.frag horizon_cos) takes the band from its front only
# down to this share of its part's size behind it along the view ray; below that the screen does
# not say what the point sees (the corner's wall above the box sees the box's unlit back face and
# the gap's floor, not its sky-lit top: a halo, 19 bins of 349 above 1.2x the path tracer, 5 with
# 0.12; 0.2: 12, 0.05: 5 but the corner's relMAE up 0.2-2 points), lit as the point is.
FACING_THICKNESS = 0.12
# More rotations than the 4x4 pattern's 16, over passes (the paper's temporal accumulation, its
# section 6: 6 rotations x 16 spatial offsets): each pass turns the pattern by a further fraction of
# its step and the estimate is the passes' mean. `alight render` takes STILL_FRAMES passes in one
# frame (2 left faint lines on the corner's walls at 860x720, 4 none there, but faint blotches on
# the shader ball's base under quarry_01's sun, where the occluders' sunlit radiance follows the
# mean occluded direction; 8 none to the eye at 3x contrast); a still view in the editor
# refines over TEMPORAL_FRAMES frames, then costs no search at all, and rests at the same picture
# as `alight render` of its camera. benchmarks/bench_gtao_temporal.py measures both.
STILL_FRAMES = 8
TEMPORAL_FRAMES = STILL_FRAMES


def inner_integral(h, gamma):
    """The cosine-weighted visibility one horizon angle ``h`` (from v, in the slice) passes, for
    the projected normal at angle ``gamma``: 1/4 (-cos(2h - gamma) + cos gamma + 2 h sin gamma),
    which is int_0^h cos(theta - gamma) |sin theta| dtheta (signed: h < 0 counts the other side)."""
    h = np.asarray(h, np.float64)
    gamma = np.asarray(gamma, np.float64)
    return 0.25 * (-np.cos(2.0 * h - gamma) + np.cos(gamma) + 2.0 * h * np.sin(gamma))


def clamped_horizons(cos_h1, cos_h2, gamma):
    """The two horizon angles from their cosines (h1 on the -phi side, negative), each clamped to
    the hemisphere of the projected normal (gamma -/+ pi/2), as the paper's Algorithm 1."""
    gamma = np.asarray(gamma, np.float64)
    h1 = -np.arccos(np.clip(cos_h1, -1.0, 1.0))
    h2 = np.arccos(np.clip(cos_h2, -1.0, 1.0))
    h1 = gamma + np.maximum(h1 - gamma, -0.5 * np.pi)
    h2 = gamma + np.minimum(h2 - gamma, 0.5 * np.pi)
    return h1, h2


def slice_visibility(cos_h1, cos_h2, gamma, projected_length=1.0):
    """One slice's share: |n_p| (a(h1) + a(h2)), the horizons given by their cosines to v."""
    h1, h2 = clamped_horizons(cos_h1, cos_h2, gamma)
    return np.asarray(projected_length) * (inner_integral(h1, gamma) + inner_integral(h2, gamma))


def slice_frame(n, v, phi):
    """For unit normal ``n`` and view vector ``v`` = (0, 0, 1) (view space), the slice at screen
    angle ``phi``: (gamma, |n_p|) as the shader computes them."""
    n = np.asarray(n, np.float64)
    direction = np.array([np.cos(phi), np.sin(phi), 0.0])
    axis = np.cross(direction, v)
    projected = n - axis * np.dot(n, axis)
    length = np.linalg.norm(projected)
    cos_n = np.clip(np.dot(projected, v) / max(length, 1e-12), -1.0, 1.0)
    gamma = np.sign(np.dot(projected, direction)) * np.arccos(cos_n)
    return gamma, length


def open_visibility(n, slices: int = 64) -> float:
    """V of an unoccluded point with normal ``n`` (view space, v = +Z), over ``slices`` slices:
    every horizon at the normal's hemisphere. 1 up to the slice quadrature."""
    v = np.array([0.0, 0.0, 1.0])
    total = 0.0
    for phi in (np.arange(slices) + 0.5) * np.pi / slices:
        gamma, length = slice_frame(n, v, phi)
        total += float(slice_visibility(-1.0, -1.0, gamma, length))
    return total / slices


def multi_bounce(visibility, albedo):
    """The paper's fit of the occluders' interreflections (its section 5): the visibility seen by
    light that bounces between surfaces of ``albedo``, max(V, ((V a + b) V + c) V)."""
    v = np.asarray(visibility, np.float64)[..., None]
    albedo = np.asarray(albedo, np.float64)
    a = 2.0404 * albedo - 0.3324
    b = -4.7951 * albedo + 0.6417
    c = 2.7552 * albedo + 0.6903
    return np.maximum(v, ((v * a + b) * v + c) * v)


def _direction_antiderivative(theta, gamma):
    """H(theta) = int_0^theta (sin t, cos t) cos(t - gamma) |sin t| dt: the (slice direction, v)
    components of the cosine-weighted directions from v up to angle theta (signed side)."""
    theta = np.asarray(theta, np.float64)
    gamma = np.asarray(gamma, np.float64)

    def f(t):
        s, c = np.sin(t), np.cos(t)
        return (np.cos(gamma) * s ** 3 / 3.0 + np.sin(gamma) * (c ** 3 / 3.0 - c),
                -np.cos(gamma) * c ** 3 / 3.0 + np.sin(gamma) * s ** 3 / 3.0)

    f0 = f(np.zeros_like(theta))
    ft = f(theta)
    sign = np.sign(theta)
    return sign * (ft[0] - f0[0]), sign * (ft[1] - f0[1])


def slice_occluded_direction(cos_h1, cos_h2, gamma, projected_length=1.0):
    """The cosine-weighted sum of the occluded directions of one slice, as (along the slice
    direction, along v) times |n_p|: the parts of the normal's half-disc beyond the horizons,
    [gamma - pi/2, h1] and [h2, gamma + pi/2]. Its mean over slices points at the occluders, whose
    surfaces face back along it (the forward pass reads E there: common/gtao.glsl)."""
    h1, h2 = clamped_horizons(cos_h1, cos_h2, gamma)
    lo = _direction_antiderivative(np.asarray(gamma) - 0.5 * np.pi, gamma)
    hi = _direction_antiderivative(np.asarray(gamma) + 0.5 * np.pi, gamma)
    a = _direction_antiderivative(h1, gamma)
    b = _direction_antiderivative(h2, gamma)
    return tuple(np.asarray(projected_length) * ((a[k] - lo[k]) + (hi[k] - b[k])) for k in range(2))


def band_weight(cos_from, cos_to, gamma, side, projected_length=1.0):
    """common/gtao.glsl gtao_band_weight: the cosine-weighted share (times |n_p|) of one side's
    band between two horizon cosines (the lower first; ``side`` +1: h = acos, -1: h = -acos),
    both clamped to the projected normal's hemisphere: what the sample that raised the horizon
    from the first to the second occludes (render/gtao.frag horizon_cos weights that occluder's
    normal by it). From -1 up to a side's horizon the bands sum to that side's occluded share."""
    side = float(side)
    gamma = np.asarray(gamma, np.float64)
    a = side * np.arccos(np.clip(cos_from, -1.0, 1.0))
    b = side * np.arccos(np.clip(cos_to, -1.0, 1.0))
    limit = gamma + side * 0.5 * np.pi
    clamp = np.minimum if side > 0 else np.maximum
    a, b = clamp(a, limit), clamp(b, limit)
    return np.asarray(projected_length) * (inner_integral(a, gamma) - inner_integral(b, gamma))


# The facing occluders' own light is held to the point's where their V is below the point's: ramped
# in over this range of (their V - the point's) (common/occlusion.glsl screen_facing_light).
FACING_RAMP = (-0.1, 0.05)


def smoothstep(edge0, edge1, x):
    t = np.clip((np.asarray(x, np.float64) - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def facing_light(by_occluders, as_point, occluder_visibility, visibility):
    """The light / pi on the occluders that face the point on screen (common/gtao.glsl
    gtao_facing_light, through common/occlusion.glsl screen_facing_light): their own (``by_occluders``, the sky their normals see) where their V
    is above the point's, no more than the point's own (``as_point``) where it is below."""
    by_occluders = np.asarray(by_occluders, np.float64)
    t = smoothstep(*FACING_RAMP, np.asarray(occluder_visibility, np.float64) - visibility)
    return np.minimum(by_occluders, as_point) * (1.0 - t) + by_occluders * t


def occluders_reflectance(albedo, visibility):
    """a V / (1 - a (1 - V)): what occluders of albedo ``albedo`` and visibility V reflect of the
    light on them / pi, their own occluders' bounces as a series (common/occlusion.glsl)."""
    albedo = np.asarray(albedo, np.float64)
    return albedo * visibility / np.maximum(1.0 - albedo * (1.0 - visibility), 1e-3)


def occluder_radiance(albedo, facing_share, occluder_visibility, visibility, by_occluders, as_point):
    """What the occluded share sees / pi (common/occlusion.glsl screen_occluder_radiance): the
    facing share lit by facing_light through their V, the rest lit as the point is through its V."""
    lit = facing_light(by_occluders, as_point, occluder_visibility, visibility)
    rest = occluders_reflectance(albedo, visibility) * np.asarray(as_point, np.float64)
    facing = occluders_reflectance(albedo, occluder_visibility) * lit
    return rest * (1.0 - facing_share) + facing * facing_share


def bent_normal(n, occluded_sum):
    """The mean unoccluded direction from the occluded directions' sum (mean over slices of
    ``slice_occluded_direction``, in the world): the whole hemisphere sums to 2/3 n in this
    measure, so the visible directions sum to 2/3 n - occluded; n where that leaves n's side."""
    n = np.asarray(n, np.float64)
    b = 2.0 / 3.0 * n - np.asarray(occluded_sum, np.float64)
    d = float(np.dot(b, n))
    return b / np.linalg.norm(b) if d > 1e-6 else n


def rotation_offset(k: int, passes: int) -> tuple[float, float]:
    """Pass ``k`` of ``passes``' turn of the 4x4 pattern: (added to the slice angle, in units of
    pi / SLICES; added to the step jitter), render/gtao.frag's ``u_rotation_offset``. The angles
    fill the pattern's step of 1/16 evenly in bit-reversed order, so that any first few passes
    are spread over it; the jitter follows the golden ratio's sequence."""
    if passes <= 1:
        return 0.0, 0.0
    bits = max(int(passes - 1).bit_length(), 1)
    reversed_k = int(format(k % (1 << bits), f"0{bits}b")[::-1], 2)
    return reversed_k / float(1 << bits) / 16.0, (k * 0.6180339887) % 1.0



def falloff_weight(delta, v, radius, thickness, thin):
    """common/gtao.glsl gtao_falloff_weight: how much an occluder at ``delta`` from the point
    counts (1 within 0.75 ``radius``, 0 beyond it), the part of its distance along ``v`` (toward
    the eye) beyond ``thickness`` stretched by 1 + ``thin``."""
    delta = np.asarray(delta, np.float64)
    v = np.asarray(v, np.float64)
    along = np.sum(delta * v, axis=-1)
    across = np.linalg.norm(delta - along[..., None] * v, axis=-1)
    along = along + thin * np.maximum(along - thickness, 0.0)
    return np.clip((radius - np.hypot(across, along)) / (0.25 * radius), 0.0, 1.0)
