// The local origin (issue 10): the choice of Scene::origin, the double
// transforms of the loader, and bake-mesh positions that do not depend on
// where the scene is (GL-free; the bakes are in
// tests/golden/far_from_origin_bake_test.cpp).
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "../support/translated_gltf.h"
#include "layout/bake_mesh.h"
#include "layout/layout.h"
#include "render/scene_renderer.h"
#include "scene/scene.h"

namespace bb {
namespace {

std::string asset(const std::string& relative) { return std::string(BUNDLEBAKE_SOURCE_DIR) + "/" + relative; }

TEST(LocalOrigin, ZeroNearTheWorldOriginElseTheCentre) {
    // the world origin inside the bounding sphere: 0
    EXPECT_EQ(chooseLocalOrigin(glm::dvec3(-1, 0, -1), glm::dvec3(1, 2, 1)), glm::dvec3(0.0));
    EXPECT_EQ(chooseLocalOrigin(glm::dvec3(0.0), glm::dvec3(0.556, 0.549, 0.559)), glm::dvec3(0.0));
    // outside: the centre, exactly
    EXPECT_EQ(chooseLocalOrigin(glm::dvec3(4999, 0, -1), glm::dvec3(5001, 2, 1)), glm::dvec3(5000, 1, 0));
    EXPECT_EQ(chooseLocalOrigin(glm::dvec3(10, 10, 10), glm::dvec3(12, 12, 12)), glm::dvec3(11, 11, 11));
    // empty
    EXPECT_EQ(chooseLocalOrigin(glm::dvec3(1), glm::dvec3(-1)), glm::dvec3(0.0));
}

TEST(LocalOrigin, HandBuiltInstancesFallBackToTheFloatTransform) {
    Instance inst;
    inst.setWorldFromObject(glm::translate(glm::dmat4(1.0), glm::dvec3(100000.001, 0, 0)));
    EXPECT_EQ(inst.exactWorldFromObject()[3].x, 100000.001);  // float would round to 100000.0
    EXPECT_EQ(double(inst.worldFromObject[3].x), 100000.0);
    // edited through the float matrix only: the stale double one is not used
    inst.worldFromObject = glm::translate(glm::mat4(1.0f), glm::vec3(2, 0, 0));
    EXPECT_EQ(inst.exactWorldFromObject()[3].x, 2.0);
}

struct Placement {
    Scene scene;
    BakeMesh mesh;
};

Placement load(const glm::dvec3& outer, const std::string& tag) {
    Placement p;
    std::string error;
    const std::string path =
        test::writeTranslatedGltf(asset("assets/two_rooms/two_rooms_doorway.gltf"), outer, glm::dvec3(0, -1, 0), tag, &error);
    EXPECT_FALSE(path.empty()) << error;
    auto scene = loadScene(path);
    EXPECT_TRUE(scene) << scene.error();
    if (!scene) return p;
    p.scene = std::move(scene.value());
    LayoutOptions options;
    options.mode = UvLayout::Pack;
    options.resolution = 256;
    options.texelDensity = 16.0f;
    auto layout = computeLayout(p.scene, options);
    EXPECT_TRUE(layout) << layout.error();
    if (layout) p.mesh = buildBakeMesh(p.scene, *layout);
    return p;
}

TEST(LocalOrigin, TranslatedSceneGivesTheSameBakeMeshBytes) {
    const Placement origin = load(glm::dvec3(0.0), "unit_origin");
    ASSERT_FALSE(origin.mesh.vertices.empty());
    EXPECT_EQ(origin.scene.origin, glm::dvec3(0.0));  // centred on the world origin
    for (const glm::dvec3 t : {glm::dvec3(3000, 0, -4000), glm::dvec3(60000, 48000, -64000), glm::dvec3(-0.1, 5000.3, 7)}) {
        const Placement far = load(t, "unit_far");
        ASSERT_EQ(far.mesh.vertices.size(), origin.mesh.vertices.size());
        // the origin moved by T (exact for dyadic T: the rooms' bounds are symmetric about 0)
        EXPECT_LE(glm::length(far.scene.origin - t), 1e-12 * glm::length(t));
        EXPECT_EQ(far.mesh.origin, far.scene.origin);
        EXPECT_EQ(far.scene.instances[0].exactWorldFromObject()[3], glm::dvec4(t + glm::dvec3(0, -1, 0), 1.0));
        // world bounds stay world (rounded to float)
        EXPECT_NEAR(far.scene.bounds.center().x, t.x, 1e-2);
        // and the bake mesh is the same, byte for byte
        EXPECT_EQ(std::memcmp(far.mesh.vertices.data(), origin.mesh.vertices.data(),
                              origin.mesh.vertices.size() * sizeof(BakeVertex)),
                  0)
            << "translation (" << t.x << ", " << t.y << ", " << t.z << ")";
        EXPECT_EQ(far.mesh.bounds.min, origin.mesh.bounds.min);
        EXPECT_EQ(far.mesh.bounds.max, origin.mesh.bounds.max);
        // the glTF camera, moved into local space, is where it is at the origin
        ASSERT_EQ(far.scene.cameras.size(), 1u);
        const Camera local = cameraInLocalSpace(far.scene.cameras[0], far.mesh.origin);
        const Camera atOrigin = cameraInLocalSpace(origin.scene.cameras[0], origin.mesh.origin);
        EXPECT_LT(glm::length(glm::vec3(local.worldFromCamera[3] - atOrigin.worldFromCamera[3])), 1e-2f);
    }
}

}  // namespace
}  // namespace bb
