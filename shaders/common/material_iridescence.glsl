// KHR_materials_iridescence's material inputs: the factors as uniforms (app/render/bindings.py:
// set_material, from alight.core.layers.iridescence.iridescence_uniforms) and
// apply_material_iridescence, which writes them into a Surface; the maps multiply them
// afterwards (common/mesh_material.glsl). Shared by the forward pass and the reference.
#ifdef HAS_IRIDESCENCE
uniform float u_iridescence;
uniform float u_iridescence_ior;
uniform float u_iridescence_thickness_minimum;   // nm, where the thickness map is 0
uniform float u_iridescence_thickness_maximum;   // nm, where it is 1, and without a map

void apply_material_iridescence(inout Surface s) {
    s.iridescence = u_iridescence;
    s.iridescence_ior = u_iridescence_ior;
    s.iridescence_thickness = u_iridescence_thickness_maximum;
}
#endif
