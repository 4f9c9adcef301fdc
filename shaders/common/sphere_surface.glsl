// The built-in sphere shaded on the true sphere (common/mesh_material.glsl SPHERE_SURFACE): its
// numpy twins are alight.core.sphere_lod.sphere_surface_point and ray_meets_sphere.

// The view ray's first hit on the sphere |x| = r centred at the origin (ray-sphere intersection).
// The hit is a step s back along the ray from the point p where the ray crossed the drawn mesh
// (a facet inside the sphere, or the impostor's proxy outside it): |p - s d|^2 = r^2, the larger
// root. Solved about p, not the eye, so that nothing cancels at grazing angles. A ray that misses
// gets its point closest to the centre (the outline's edge pixels).
vec3 sphere_surface_point(vec3 eye, vec3 facet_point, float r) {
    vec3 d = normalize(facet_point - eye);
    float pd = dot(facet_point, d);
    float s = pd + sqrt(max(pd * pd + (r * r - dot(facet_point, facet_point)), 0.0));
    return facet_point - s * d;
}

// Whether the ray from the eye (outside the sphere) along d (any length) meets the sphere
// |x| = r in front of the eye: |eye + t d|^2 = r^2 has a root t > 0.
bool ray_meets_sphere(vec3 eye, vec3 d, float r) {
    float b = dot(eye, d);
    return b < 0.0 && b * b >= dot(d, d) * (dot(eye, eye) - r * r);
}

// alight.core.mesh.sphere's uv at the point x on the sphere (any radius): u = phi / 2 pi about +Y
// from -Z (the seam), v = 1 at the north pole (+Y). atan(|x.xz|, x.y) rather than acos: llvmpipe's
// acos is good to only ~1e-4 rad.
vec2 sphere_uv(vec3 x) {
    // (1/pi spelled out: this file is also included without brdf.glsl's PI, by the reference's G-buffer)
    const float INV_PI = 0.31830988618379067;
    float u = 0.5 * INV_PI * atan(-x.x, -x.z);
    return vec2(u < 0.0 ? u + 1.0 : u, 1.0 - INV_PI * atan(length(x.xz), x.y));
}

// alight.core.mesh.sphere's tangent (+u direction, handedness +1) at the point x: zero at the poles.
vec4 sphere_tangent(vec3 x) {
    vec3 t = vec3(x.z, 0.0, -x.x);
    float len2 = dot(t, t);
    return vec4(len2 > 0.0 ? t * inversesqrt(len2) : vec3(0.0), 1.0);
}
