// Compact bright sources taken out of the environment the bake samples (app/ibl/sun.py), to be
// added back in closed form: each is a delta of power P (radiance integrated over its disk).
const int MAX_SUNS = 4;
// IBL_SUNS 0: the environment drawn has no compact source (app/render/variants.py sun_defines),
// so the count is a constant 0 and every loop over them folds away: llvmpipe otherwise generates
// the exact suns' shading (suns_exact, a seventh of a pbr.frag variant's code) at each first draw
// (benchmarks/results/compile.md).
#ifndef IBL_SUNS
#define IBL_SUNS 1
#endif
#if IBL_SUNS
uniform int u_sun_count;
#else
const int u_sun_count = 0;
#endif
uniform vec3 u_sun_direction[MAX_SUNS];
uniform vec3 u_sun_power[MAX_SUNS];
uniform float u_sun_spread[MAX_SUNS];   // RMS angular radius (radians) of each source

// Their E/pi at normal n: P max(n.l, 0) / pi each.
vec3 suns_irradiance_over_pi(vec3 n) {
    vec3 e = vec3(0.0);
    for (int i = 0; i < u_sun_count; ++i) {
        e += u_sun_power[i] * max(dot(n, u_sun_direction[i]), 0.0);
    }
    return e / PI;
}
