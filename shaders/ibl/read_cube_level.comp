#version 450 core
// Copies one mip level of a cube into a buffer (OpenGL has no direct read of a cube's mip).
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba32f, binding = 0) readonly uniform imageCube u_cube;
layout(std430, binding = 0) writeonly buffer Texels { vec4 u_texels[]; };
uniform int u_size;

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    if (p.x >= u_size || p.y >= u_size) return;
    u_texels[(p.z * u_size + p.y) * u_size + p.x] = imageLoad(u_cube, p);
}
