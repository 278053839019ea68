// The bake vertices as an SSBO, bound in chunks like triangles[] (vertex 3t + k
// of the mesh is vertices[3 (t - meshChunkFirstTriangle) + k]), and a
// triangle's own side. Needs shared/bundle_layout.h and lib/bake_vertex.glsl.
layout(std430, binding = BINDING_VERTICES) readonly buffer Vertices { BakeVertex vertices[]; };

// Mesh triangle t's plane normal (not normalised), oriented as its shading
// normals are on the whole: the side the bundle pass gives its fragments and
// the update pass its texels (there from TRIANGLE_DERIVATIVE_NORMAL_FLIPPED,
// computed the same way with the mesh). A vertex normal alone can point the
// other way near a smooth mesh's silhouette.
vec3 triangleSide(uint t) {
    uint v0 = 3u * (t - meshChunkFirstTriangle);
    vec3 w0 = vertices[v0].position.xyz, w1 = vertices[v0 + 1u].position.xyz, w2 = vertices[v0 + 2u].position.xyz;
    vec3 face = cross(w1 - w0, w2 - w0);
    vec3 shading = vertices[v0].normal.xyz + vertices[v0 + 1u].normal.xyz + vertices[v0 + 2u].normal.xyz;
    return dot(face, shading) < 0.0 ? -face : face;
}
