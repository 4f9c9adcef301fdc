// Everything a surface point sends toward the eye: emission, environment light, punctual lights.
#include "common/brdf.glsl"
#include "common/equirect.glsl"
#include "common/surface.glsl"
#include "common/layers.glsl"
#include "common/base_lobes.glsl"
#include "common/shadows.glsl"
#include "common/ibl.glsl"
#include "common/punctual.glsl"
// The layers' definitions (each under its HAS_* define), after the lookups they use.
#include "common/clearcoat.glsl"
#include "common/sheen.glsl"
#include "common/anisotropy.glsl"
#include "common/transmission.glsl"
#include "common/iridescence.glsl"
#include "common/diffuse_transmission.glsl"

uniform bool u_ibl_enabled;

vec3 shade(Surface s, vec3 n, vec3 v, vec3 position) {
#ifdef HAS_IRIDESCENCE
    iridescence_at_view(s, n, v);
#endif
    vec3 radiance = layered_emission(s, v);
    if (u_ibl_enabled) {
        radiance += ibl_model(s, n, v);
    }
#ifdef TRANSMISSION_SCENE
    else {
        radiance += transmission_scene_only(s, n, v);
    }
#endif
    radiance += punctual_lights(s, n, v, position);
    return radiance;
}
