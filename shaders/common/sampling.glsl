// Low-discrepancy points and GGX importance sampling (Karis 2013; Hammersley 1964).
// Numpy twins: app/core/shading.py.

// Van der Corput radical inverse, base 2.
float radical_inverse_vdc(uint bits) {
    return float(bitfieldReverse(bits)) * 2.3283064365386963e-10;
}

// The i-th of n Hammersley points in [0,1)^2.
vec2 hammersley(uint i, uint n) {
    return vec2(float(i) / float(n), radical_inverse_vdc(i));
}

// Half vector in tangent space (z = normal) with pdf D(h) n.h (Karis 2013).
vec3 importance_sample_ggx_tangent(vec2 xi, float roughness) {
    float a = roughness * roughness;
    float phi = 2.0 * PI * xi.x;
    float denominator = 1.0 + (a * a - 1.0) * xi.y;
    float cos_theta = sqrt((1.0 - xi.y) / denominator);
    // sin^2 = 1 - cos^2 written without the cancellation that loses float32 precision near n.
    float sin_theta = sqrt(a * a * xi.y / denominator);
    return vec3(cos(phi) * sin_theta, sin(phi) * sin_theta, cos_theta);
}

// An orthonormal frame around n; columns are tangent, bitangent, n.
mat3 tangent_frame(vec3 n) {
    vec3 up = abs(n.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    vec3 t = normalize(cross(up, n));
    vec3 b = cross(n, t);
    return mat3(t, b, n);
}
