// Spline tubes by adaptive tessellation (shared/tube_tess.h): no vertex
// input, one vertex per patch, which only names its patch (the draw's
// first vertex included, so draws split into chunks keep their numbering).
#version 460

layout(location = 0) out uint out_patch;

void main() { out_patch = uint(gl_VertexIndex); }
