// KHR_materials_diffuse_transmission's term (docs/layer_diffuse_transmission.md): a Lambertian
// BTDF on the back side of the surface. Numpy twin: app/core/layers/diffuse_transmission.py
// (same name). Needs common/brdf.glsl (PI).

// The Lambertian BTDF c / pi times |n.l| for l behind the surface (n.l < 0), 0 in front.
vec3 diffuse_btdf_cos(vec3 color, float n_dot_l) {
    return color * (max(-n_dot_l, 0.0) / PI);
}
