#version 450 core
// Supersampling: the mean of each factor x factor block of linear radiance (a box filter).
uniform sampler2D u_radiance_source;
uniform int u_factor;

layout(location = 0) out vec4 out_radiance;

void main() {
    ivec2 base = ivec2(gl_FragCoord.xy) * u_factor;
    vec4 sum = vec4(0.0);
    for (int j = 0; j < u_factor; ++j)
        for (int i = 0; i < u_factor; ++i)
            sum += texelFetch(u_radiance_source, base + ivec2(i, j), 0);
    out_radiance = sum / float(u_factor * u_factor);
}
