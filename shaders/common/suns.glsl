// Compact bright sources taken out of the environment the bake samples (app/ibl/sun.py), to be
// added back in closed form: each is a delta of power P (radiance integrated over its disk).
const int MAX_SUNS = 4;
uniform int u_sun_count;
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
