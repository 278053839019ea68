// The part of a distance cube map's face an emitter sample needs
// (engine/bake/direct_light.cpp): a single-sided emitter lights only what lies
// in front of it, so the visibility lookups (lib/cube_visibility.glsl) stay in
// front of its plane, give or take the texel they step past it.
#pragma once

#include <glm/glm.hpp>

namespace bb {

// The pixels of a cube face of side `size` whose directions lie in front of
// the plane with normal m, or within 4 texels' angle behind it. m is in the
// face's view space: the face looks along -z, and its direction at NDC (x, y)
// is (x, y, -1). Returns (x, y, w, h) for glScissor; w or h 0: none.
glm::ivec4 faceScissor(const glm::vec3& m, int size);

}  // namespace bb
