// The transmission LUT's ior axis (ibl/transmission_lut.comp bakes it, the forward pass reads
// it; app/ibl/transmission_lut.py holds the same constant): z = (1 - 1/ior) / IOR_AXIS_MAX.
// 1 - 1/ior is what the refracted lobe's width scales with (a facet tilted by theta bends the
// ray by theta (1 - 1/ior)); IOR_AXIS_MAX = 0.75 puts ior 1..4 on the axis (diamond: 2.42).
const float IOR_AXIS_MAX = 0.75;

float lut_axis_of_ior(float ior) {
    return clamp((1.0 - 1.0 / max(ior, 1.0)) / IOR_AXIS_MAX, 0.0, 1.0);
}

float ior_of_lut_axis(float z) {
    return 1.0 / (1.0 - IOR_AXIS_MAX * z);
}
