// Everything a surface point sends toward the eye: emission, environment light, punctual lights.
#include "common/brdf.glsl"
#include "common/equirect.glsl"
#include "common/surface.glsl"
#include "common/ibl.glsl"
#include "common/punctual.glsl"

uniform bool u_ibl_enabled;

vec3 shade(Surface s, vec3 n, vec3 v, vec3 position) {
    vec3 radiance = s.emissive;
    if (u_ibl_enabled) {
        // IBL_MODEL is chosen in app/renderer.py; the lecture's model is the reference point.
        radiance += ibl_lecture(s, n, v);
    }
    radiance += punctual_lights(s, n, v, position);
    return radiance;
}
