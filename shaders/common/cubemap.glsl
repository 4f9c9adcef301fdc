// Directions of cubemap texels, for passes that write cube faces as images.

// Direction through the centre of texel (x, y) of face f (OpenGL's face order +X -X +Y -Y +Z -Z;
// row y = 0 is the first row in memory, t = 0 in the spec's face table).
vec3 cube_texel_direction(ivec3 texel, int size) {
    vec2 st = 2.0 * (vec2(texel.xy) + 0.5) / float(size) - 1.0;
    float s = st.x;
    float t = st.y;
    vec3 d;
    switch (texel.z) {
        case 0: d = vec3(1.0, -t, -s); break;
        case 1: d = vec3(-1.0, -t, s); break;
        case 2: d = vec3(s, 1.0, t); break;
        case 3: d = vec3(s, -1.0, -t); break;
        case 4: d = vec3(s, -t, 1.0); break;
        default: d = vec3(-s, -t, -1.0); break;
    }
    return normalize(d);
}

// Solid angle of one texel of a cube face of the given size, averaged over the sphere.
float cube_texel_solid_angle(int size) {
    return 4.0 * PI / (6.0 * float(size * size));
}
