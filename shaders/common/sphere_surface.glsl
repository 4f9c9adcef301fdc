// The built-in sphere shaded on the true sphere (common/mesh_material.glsl SPHERE_SURFACE): its
// numpy twin is alight.core.sphere_lod.sphere_surface_point.

// The view ray's first hit on the sphere |x| = r centred at the origin (ray-sphere intersection).
// The flat facets lie inside the sphere, so the hit is a step s back along the ray from the facet
// point p: |p - s d|^2 = r^2. Solved about p, not the eye, so that nothing cancels at grazing angles.
vec3 sphere_surface_point(vec3 eye, vec3 facet_point, float r) {
    vec3 d = normalize(facet_point - eye);
    float pd = dot(facet_point, d);
    float s = pd + sqrt(max(pd * pd + (r * r - dot(facet_point, facet_point)), 0.0));
    return facet_point - s * d;
}
