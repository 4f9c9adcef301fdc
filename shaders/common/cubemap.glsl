// Directions of cubemap texels, for passes that write cube faces as images.

// Direction (not normalised) through face coordinates st in [-1, 1]^2 of face f, in OpenGL's
// face order +X -X +Y -Y +Z -Z (t = -1 is the first row in memory; the spec's face table).
vec3 cube_face_direction(int face, vec2 st) {
    switch (face) {
        case 0: return vec3(1.0, -st.y, -st.x);
        case 1: return vec3(-1.0, -st.y, st.x);
        case 2: return vec3(st.x, 1.0, st.y);
        case 3: return vec3(st.x, -1.0, -st.y);
        case 4: return vec3(st.x, -st.y, 1.0);
        default: return vec3(-st.x, -st.y, -1.0);
    }
}

// Unit direction through the centre of texel (x, y) of face z.
vec3 cube_texel_direction(ivec3 texel, int size) {
    return normalize(cube_face_direction(texel.z, 2.0 * (vec2(texel.xy) + 0.5) / float(size) - 1.0));
}

// Solid angle of one texel of a cube face of the given size, averaged over the sphere.
float cube_texel_solid_angle(int size) {
    return 4.0 * PI / (6.0 * float(size * size));
}

// Exact solid angle of texel (x, y) of a cube face of the given size: the area of the face
// rectangle projected onto the unit sphere, from A(s, t) = atan(s t / sqrt(s^2 + t^2 + 1)).
float cube_area_element(float s, float t) {
    return atan(s * t, sqrt(s * s + t * t + 1.0));
}

float cube_texel_solid_angle_exact(ivec2 texel, int size) {
    float inv = 1.0 / float(size);
    vec2 lo = 2.0 * vec2(texel) * inv - 1.0;
    vec2 hi = lo + 2.0 * inv;
    return cube_area_element(lo.x, lo.y) - cube_area_element(lo.x, hi.y)
         - cube_area_element(hi.x, lo.y) + cube_area_element(hi.x, hi.y);
}
