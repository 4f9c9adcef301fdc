// The equirectangular mapping and environment rotation of docs/conventions.md.
// Numpy twins: app/core/shading.py.

// u = 0.5 + atan2(d.x, -d.z)/(2 pi) left to right; v = acos(d.y)/pi, v = 0 at the top row (+Y).
vec2 direction_to_equirect_uv(vec3 d) {
    float u = 0.5 + atan(d.x, -d.z) / (2.0 * PI);
    // atan(|d.xz|, d.y) = acos(d.y) for unit d, and keeps float32 precision near the poles
    // (llvmpipe's acos is good to only ~1e-4 rad).
    float v = atan(length(d.xz), d.y) / PI;
    return vec2(u, v);
}

vec3 equirect_uv_to_direction(vec2 uv) {
    float phi = (uv.x - 0.5) * 2.0 * PI;
    float theta = uv.y * PI;
    float s = sin(theta);
    return vec3(s * sin(phi), cos(theta), -s * cos(phi));
}

// Radiance from world direction d is the map's radiance in R_y(-deg) d; cos_sin holds
// (cos(-deg), sin(-deg)).
vec3 rotate_world_to_map(vec3 d, vec2 cos_sin) {
    return vec3(cos_sin.x * d.x + cos_sin.y * d.z, d.y, -cos_sin.y * d.x + cos_sin.x * d.z);
}
