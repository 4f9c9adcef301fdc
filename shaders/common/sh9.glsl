// Real spherical harmonics up to order 2 and the irradiance they give
// (Ramamoorthi and Hanrahan 2001, "An Efficient Representation for Irradiance Environment Maps").

void sh9_basis(vec3 d, out float y[9]) {
    y[0] = 0.282095;
    y[1] = 0.488603 * d.y;
    y[2] = 0.488603 * d.z;
    y[3] = 0.488603 * d.x;
    y[4] = 1.092548 * d.x * d.y;
    y[5] = 1.092548 * d.y * d.z;
    y[6] = 0.315392 * (3.0 * d.z * d.z - 1.0);
    y[7] = 1.092548 * d.x * d.z;
    y[8] = 0.546274 * (d.x * d.x - d.y * d.y);
}

// E(n)/pi from the radiance's coefficients: the clamped-cosine kernel's bands are
// A0 = pi, A1 = 2 pi / 3, A2 = pi / 4; dividing by pi gives the cosine-weighted mean radiance.
vec3 sh9_irradiance_over_pi(vec3 coeffs[9], vec3 n) {
    float y[9];
    sh9_basis(n, y);
    const float a[3] = float[3](1.0, 2.0 / 3.0, 1.0 / 4.0);
    vec3 e = a[0] * coeffs[0] * y[0];
    for (int i = 1; i < 4; ++i) e += a[1] * coeffs[i] * y[i];
    for (int i = 4; i < 9; ++i) e += a[2] * coeffs[i] * y[i];
    return max(e, vec3(0.0));
}
