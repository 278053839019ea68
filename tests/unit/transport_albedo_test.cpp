// The scene's transport albedo (bake/transport_albedo.h), the share of the
// light kept per bounce, against what it must be: the albedo in a closed room
// of one albedo (every ray meets a surface), 0 where no ray meets one, and for
// an open-top box of albedo rho at least 0.8 rho and below rho: by reciprocity
// the area-weighted share of cosine rays that leave through the opening is
// its area over the surfaces', 1/5, and the transport is symmetric in the
// area-weighted product, so that uniform light's Rayleigh quotient 0.8 rho is
// a lower bound of its largest eigenvalue.
#include <gtest/gtest.h>

#include <cstdio>

#include "bake/transport_albedo.h"
#include "support/hand_scenes.h"

namespace bb::test {
namespace {

TransportAlbedo transportOf(const Scene& scene) {
    auto layout = packLayout(scene, 64, 8.0f);
    EXPECT_TRUE(layout) << layout.error();
    if (!layout) return {-1.0, -1.0};
    const BakeMesh mesh = buildBakeMesh(scene, *layout);
    std::vector<glm::vec3> albedo;
    std::vector<bool> doubleSided;
    for (const Material& m : scene.materials) {
        albedo.push_back(m.albedo);
        doubleSided.push_back(m.doubleSided);
    }
    return transportAlbedo(mesh, albedo, doubleSided);
}

double lambdaOf(const Scene& scene) { return transportOf(scene).lambda; }

TEST(TransportAlbedo, AClosedRoomOfOneAlbedoKeepsThatAlbedo) {
    Scene scene;
    addBox(scene, glm::vec3(0.0f), glm::vec3(1.0f, 0.5f, 2.0f), addMaterial(scene, glm::vec3(0.7f)), false, "room");
    EXPECT_NEAR(lambdaOf(scene), 0.7, 1e-3);
}

TEST(TransportAlbedo, TheLargestChannelCounts) {
    Scene scene;
    addBox(scene, glm::vec3(0.0f), glm::vec3(1.0f), addMaterial(scene, glm::vec3(0.2f, 0.9f, 0.4f)), false, "room");
    EXPECT_NEAR(lambdaOf(scene), 0.9, 1e-3);
}

TEST(TransportAlbedo, NothingToMeetKeepsNothing) {
    Scene plane;
    addQuad(plane, glm::vec3(0.0f), glm::vec3(1, 0, 0), glm::vec3(0, 0, -1), addMaterial(plane, glm::vec3(0.9f)), "plane");
    EXPECT_EQ(lambdaOf(plane), 0.0);
    // a box's outside: every ray leaves
    Scene inside;
    addBox(inside, glm::vec3(0.0f), glm::vec3(1.0f), addMaterial(inside, glm::vec3(0.9f)), true, "box");
    EXPECT_EQ(lambdaOf(inside), 0.0);
}

TEST(TransportAlbedo, AnOpenTopBoxKeepsBetweenFourFifthsOfItsAlbedoAndItsAlbedo) {
    Scene scene;
    const int grey = addMaterial(scene, glm::vec3(0.6f));
    addBox(scene, glm::vec3(0.0f), glm::vec3(0.5f), grey, false, "box");
    // drop the top (+y, the third face): its instance and mesh are the last but three
    scene.instances.erase(scene.instances.begin() + 2);
    for (size_t i = 2; i < scene.instances.size(); ++i) scene.instances[i].node = int(i);
    const double lambda = lambdaOf(scene);
    std::printf("[transport albedo] open-top box of albedo 0.6: %.4f\n", lambda);
    EXPECT_GE(lambda, 0.8 * 0.6 - 0.01);
    EXPECT_LT(lambda, 0.6 - 0.01);
}

// The slowest: an open-top box of albedo 0.6 (its light settles at ~0.48 a
// bounce, "AnOpenTopBox..." below) beside a closed room of albedo 0.9 with
// 1/80 of its area: five bounces in, the box's light still outweighs the
// room's (lambda near 0.5), while the paths still bouncing after 24 are the
// room's (0.9). In a closed room of one albedo both are that albedo.
TEST(TransportAlbedo, APocketThatKeepsItsLightSetsTheSlowest) {
    Scene scene;
    addBox(scene, glm::vec3(0.0f), glm::vec3(1.0f), addMaterial(scene, glm::vec3(0.6f)), false, "box");
    scene.instances.erase(scene.instances.begin() + 2);  // its top (+y), as below
    for (size_t i = 2; i < scene.instances.size(); ++i) scene.instances[i].node = int(i);
    addBox(scene, glm::vec3(4.0f, 0.0f, 0.0f), glm::vec3(0.1f), addMaterial(scene, glm::vec3(0.9f)), false, "room");
    const TransportAlbedo t = transportOf(scene);
    std::printf("[transport albedo] open box 0.6 beside a small room 0.9: lambda %.4f, slowest %.4f\n", t.lambda,
                t.slowest);
    EXPECT_LT(t.lambda, 0.7);
    EXPECT_NEAR(t.slowest, 0.9, 0.01);
    Scene room;
    addBox(room, glm::vec3(0.0f), glm::vec3(1.0f), addMaterial(room, glm::vec3(0.7f)), false, "room");
    const TransportAlbedo r = transportOf(room);
    EXPECT_NEAR(r.lambda, 0.7, 1e-3);
    EXPECT_NEAR(r.slowest, 0.7, 1e-3);
}

TEST(TransportAlbedo, ADoubleSidedPanelReflectsOnBothSides) {
    for (bool twoSides : {false, true}) {
        Scene scene;
        const int grey = addMaterial(scene, glm::vec3(0.5f));
        addBox(scene, glm::vec3(0.0f), glm::vec3(1.0f), grey, false, "room");
        const int panel = addMaterial(scene, glm::vec3(0.5f));
        scene.materials[size_t(panel)].doubleSided = twoSides;
        addQuad(scene, glm::vec3(0.0f), glm::vec3(0.5f, 0, 0), glm::vec3(0, 0, -0.5f), panel, "panel");
        const double lambda = lambdaOf(scene);
        if (twoSides)
            EXPECT_NEAR(lambda, 0.5, 1e-3) << "both sides reflect: the room is closed";
        else
            EXPECT_LT(lambda, 0.5 - 0.005) << "the panel's back absorbs";
    }
}

}  // namespace
}  // namespace bb::test
