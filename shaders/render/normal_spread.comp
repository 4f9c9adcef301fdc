#version 450 core
// One mip level of a normal map's spread (Toksvig 2005), written into that level's A; its RGB
// (GL's generate_mipmap, or the CPU's bit-for-bit twin) is kept. The numpy twin is
// alight.render.normal_spread (unit_normals, _halve_mean, spread_to_alpha_channel), run by
// alight.render.normal_spread_pass.
//
// Level 1 reads the level-0 texels, decodes each as unit_normals does and averages each 2x2;
// every coarser level averages the 2x2 means of the level above (u_finer_mean). The means are kept
// in an RGBA32F texture, a level per level of the map from 1 on. The 2x2 box is done here, not by
// generate_mipmap on the float texture: GL leaves generate_mipmap's filter to the implementation,
// a box is what the numpy twin computes, and a side of 1 pairs a texel with itself, as it does.
// Every step is the twin's float32 operation in the twin's order, under `precise` (no fused
// multiply-add, no reordering), so the means match numpy's to the last bit wherever the driver
// rounds division and sqrt correctly (llvmpipe does) and to an ulp or so elsewhere.

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba8, binding = 0) readonly uniform image2D u_level0;          // the map's level 0 (level 1's source)
layout(rgba32f, binding = 1) readonly uniform image2D u_finer_mean;    // the level above's means (levels >= 2)
layout(rgba32f, binding = 2) writeonly uniform image2D u_mean;         // this level's means
layout(rgba8, binding = 3) uniform image2D u_level;                    // this level of the map: A written
uniform ivec2 u_size;         // this level's size
uniform ivec2 u_finer_size;   // the source's size (level 0's, or the level above's)
uniform int u_from_level0;    // 1: level 1, from the map's texels
uniform float u_scale;        // normalTexture.scale: x and y times it before normalising
uniform float u_decode;       // float32(2 / 255): the twin's constant, passed so both round it alike
uniform ivec2 u_origin;       // the first texel of this dispatch (a band of a big level)

// A texel's normal as unit_normals decodes it: 2c - 1 as float32(c) * float32(2/255) - 1, x and y
// times the scale, divided by its length; a zero vector (length <= NORMAL_FLAT_LENGTH) is (0, 0, 1).
vec3 unit_normal(ivec2 at) {
    // the stored byte back as an integer (the load gives c / 255 rounded: x 255 rounds back to c)
    vec3 c = round(imageLoad(u_level0, at).rgb * 255.0);
    precise vec3 m = c * u_decode - 1.0;
    m.xy = m.xy * u_scale;
    precise float length_squared = m.x * m.x + m.y * m.y + m.z * m.z;
    precise float len = sqrt(length_squared);
    return len <= NORMAL_FLAT_LENGTH ? vec3(0.0, 0.0, 1.0) : m / len;
}

vec3 finer(ivec2 at) {
    at = min(at, u_finer_size - 1);   // a side of 1 pairs its texel with itself
    return u_from_level0 != 0 ? unit_normal(at) : imageLoad(u_finer_mean, at).xyz;
}

void main() {
    ivec2 texel = u_origin + ivec2(gl_GlobalInvocationID.xy);
    if (texel.x >= u_size.x || texel.y >= u_size.y) return;
    ivec2 at = texel * 2;
    // _halve_mean's order: ((m[y][x] + m[y][x+1]) + m[y+1][x]) + m[y+1][x+1], then x 0.25
    precise vec3 sum = finer(at) + finer(at + ivec2(1, 0));
    sum = sum + finer(at + ivec2(0, 1));
    sum = sum + finer(at + ivec2(1, 1));
    precise vec3 mean = 0.25 * sum;
    imageStore(u_mean, texel, vec4(mean, 0.0));
    // spread_to_alpha_channel: |Na| clipped to [NORMAL_FLAT_LENGTH, 1], sigma^2 = (1 - |Na|) / |Na|
    // up to NORMAL_SPREAD_MAX, 0 below NORMAL_SPREAD_FLOOR, A = round(255 sigma^(1/2))
    precise float length_squared = mean.x * mean.x + mean.y * mean.y + mean.z * mean.z;
    precise float len = clamp(sqrt(length_squared), NORMAL_FLAT_LENGTH, 1.0);
    precise float spread = min((1.0 - len) / len, NORMAL_SPREAD_MAX);
    if (spread < NORMAL_SPREAD_FLOOR) spread = 0.0;
    precise float code = roundEven(255.0 * sqrt(sqrt(spread)));
    vec4 texel_value = imageLoad(u_level, texel);
    imageStore(u_level, texel, vec4(texel_value.rgb, code / 255.0));
}
