// The scene as bundlebake sees it: glTF 2.0 meshes, materials, instances,
// directional, point and spot lights and cameras, in scene units (whatever the file uses;
// glTF means metres, the shared Cornell box uses millimetres).
//
// World and local coordinates: instance transforms are composed in double
// (Instance::exactWorldFromObject). Everything the GPU and the bakers see
// (BakeMesh positions and bounds) is relative to Scene::origin, so a scene
// 100 km from the world origin keeps the float precision it has at the origin
// (a float at 5 km has 0.5 mm steps, at 100 km 8 mm).
//
// GL-free: plain structs, loaded by loadScene() (gltf_loader.cpp, tinygltf).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/status.h"

namespace bb {

// Linear-RGB float image (8-bit sRGB sources are decoded to linear on load).
struct Texture {
    std::string name;
    int width = 0;
    int height = 0;
    std::vector<glm::vec4> texels;  // row-major, texels[y * width + x], y = 0 is the top row
};

// Diffuse view of a glTF metallic-roughness material.
struct Material {
    std::string name;
    glm::vec3 albedo{0.8f};        // baseColorFactor.rgb * (1 - metallicFactor)
    int albedoTexture = -1;        // index into Scene::textures, multiplies albedo (TEXCOORD_0)
    glm::vec3 emission{0.0f};      // emissiveFactor * KHR_materials_emissive_strength: radiance, scene units
    int emissionTexture = -1;      // index into Scene::textures, multiplies emission (TEXCOORD_0)
    bool doubleSided = false;
    bool isDefault = false;        // made by bundlebake for primitives without a material
    // glTF alphaMode MASK (cut-outs: foliage, fences): where baseColor alpha x
    // the albedo texture's alpha (TEXCOORD_0, bilinear, level 0, 8 bits; see
    // scene/alpha_mask.h) is below alphaCutoff the surface is not there for
    // any pass: light goes through, its texels are not covered. OPAQUE and
    // BLEND bake opaque (alphaMask false).
    bool alphaMask = false;
    float alphaCutoff = 0.5f;      // glTF's default
    float alpha = 1.0f;            // baseColorFactor.a
};

// One triangle list. Indices are always present (non-indexed glTF primitives
// get 0..n-1); degenerate triangles are removed on load and counted.
struct Primitive {
    std::vector<glm::vec3> positions;  // object space
    std::vector<glm::vec3> normals;    // object space, unit; computed flat if the file has none
    std::vector<glm::vec2> uv0;        // TEXCOORD_0, empty if absent
    std::vector<glm::vec2> uv1;        // TEXCOORD_1 (light map UVs), empty if absent
    std::vector<uint32_t> indices;     // 3 per triangle
    int material = -1;                 // index into Scene::materials (always valid after load)
    size_t triangleCount() const { return indices.size() / 3; }
};

struct Mesh {
    std::string name;
    std::vector<Primitive> primitives;
    // TEXCOORD_1 made by bundlebake (engine/layout/uv_generate.h): the texel
    // grid its charts were packed on, uv1 = texel / uv1Grid, so the pack layout
    // gives the mesh exactly this rectangle. 0 = TEXCOORD_1 from the file (or none).
    glm::ivec2 uv1Grid{0};
};

// A node that references a mesh. Several instances may share one mesh; each
// gets its own light map rectangle in the `pack` layout.
struct Instance {
    std::string name;                // node name, or "node <index>"
    int mesh = -1;
    int node = -1;
    // World from object rounded to float: enough for shapes (areas, normals),
    // not for positions far from the world origin. Scenes built by hand may set
    // only this one.
    glm::mat4 worldFromObject{1.0f};
    // The same transform as the loader composed it, in double (see
    // exactWorldFromObject). Set both with setWorldFromObject.
    glm::dmat4 worldFromObjectDouble{1.0};
    float texelDensity = 0.0f;       // per-node override from extras.texelDensity (texels per scene unit); 0 = none

    void setWorldFromObject(const glm::dmat4& m) {
        worldFromObjectDouble = m;
        worldFromObject = glm::mat4(m);
    }
    // worldFromObjectDouble while it still rounds to worldFromObject, else
    // worldFromObject (a scene built or edited by hand through the float one).
    glm::dmat4 exactWorldFromObject() const {
        return glm::mat4(worldFromObjectDouble) == worldFromObject ? worldFromObjectDouble : glm::dmat4(worldFromObject);
    }
};

// KHR_lights_punctual "directional": a sun. `direction` is the unit world-space
// direction the light travels (from the sun towards the scene). `irradiance`
// is colour * intensity: the irradiance on a surface facing the sun, scene units.
struct DirectionalLight {
    std::string name;
    glm::vec3 direction{0.0f, -1.0f, 0.0f};
    glm::vec3 irradiance{1.0f};
};

// KHR_lights_punctual "point" and "spot", in glTF's units: `intensity` is
// colour * intensity in candela (lm/sr), so the irradiance at distance d on a
// surface facing the light is E = intensity / d^2 (d in scene units; glTF means
// metres, E is then lux), times the range window and the spot's cone falloff
// (scene/punctual_light.h, the spec's recommended formulas).
struct PunctualLight {
    std::string name;
    enum class Type { Point, Spot } type = Type::Point;
    glm::dvec3 position{0.0};          // world space, exact (the node's translation, composed in double)
    glm::vec3 direction{0.0f, 0.0f, -1.0f};  // spot: unit world direction the cone points (the node's -Z)
    glm::vec3 intensity{1.0f};         // colour * intensity, candela
    float range = 0.0f;                // > 0: smooth window clamp(1 - (d/range)^4, 0, 1); 0 = infinite (undefined)
    float innerConeAngle = 0.0f;       // spot, radians: full intensity inside
    float outerConeAngle = 0.7853982f; // spot, radians: nothing outside (glTF default pi/4)
};

struct Camera {
    std::string name;
    glm::mat4 worldFromCamera{1.0f};  // camera looks down its -Z, +Y up (glTF)
    bool perspective = true;
    float yfov = 0.8f;                // radians (perspective)
    float aspect = 0.0f;              // 0 = use the image's
    float znear = 0.01f;
    float zfar = 0.0f;                // 0 = infinite
    float xmag = 1.0f, ymag = 1.0f;   // orthographic half extents
};

struct Bounds {
    glm::vec3 min{1e30f};
    glm::vec3 max{-1e30f};
    bool empty() const { return min.x > max.x; }
    void extend(const glm::vec3& p) { min = glm::min(min, p); max = glm::max(max, p); }
    glm::vec3 size() const { return empty() ? glm::vec3(0.0f) : max - min; }
    glm::vec3 center() const { return (min + max) * 0.5f; }
};

// What the loader saw and skipped.
struct LoadReport {
    size_t skippedNonTrianglePrimitives = 0;   // points, lines, strips of lines
    size_t skippedDegenerateTriangles = 0;     // zero world-independent area or repeated index
    size_t primitivesWithoutMaterial = 0;
    size_t primitivesWithoutUv1 = 0;
};

struct Scene {
    std::string path;
    std::vector<Mesh> meshes;
    std::vector<Material> materials;
    std::vector<Texture> textures;
    std::vector<Instance> instances;
    std::vector<DirectionalLight> lights;
    std::vector<PunctualLight> punctualLights;  // point and spot lights
    std::vector<Camera> cameras;
    Bounds bounds;            // world space, over all instances (float: rounded far from the origin)
    // The local origin (world space, exact): BakeMesh positions are world - origin.
    // loadScene sets it with chooseLocalOrigin; scenes built by hand keep 0
    // (their bake mesh is then in world space, as before).
    glm::dvec3 origin{0.0};
    LoadReport report;

    size_t triangleCount() const;           // over instances (an instanced mesh counts each time)
    size_t emitterTriangleCount() const;    // instanced triangles whose material emits
    bool allHaveUv1() const;                // every instanced primitive has TEXCOORD_1
    double instanceArea(size_t instance) const;  // world-space surface area of one instance
};

// The local origin for a scene whose world bounds (in double) are [lo, hi]:
// 0 while the world origin lies within the bounding sphere (|centre| <=
// radius: world coordinates are then at most twice the local ones, and scenes
// near the origin bake exactly as they always did), else the centre (lo + hi)/2.
// The centre is exact for a translated scene: a node translation T moves it
// by exactly T, so world - origin gives the same floats wherever the scene is.
// An empty box (lo > hi) gives 0.
glm::dvec3 chooseLocalOrigin(const glm::dvec3& lo, const glm::dvec3& hi);

struct LoadOptions {
    glm::vec3 defaultAlbedo{0.8f};  // for primitives without a material (glTF's default is metallic, i.e. black)
    bool requireUv1 = false;        // fail with a hint if any primitive lacks TEXCOORD_1
    bool externalFiles = true;      // false: buffer and image URIs other than data: are not read (fuzzing)
};

// Loads a .gltf or .glb file. Errors (one line each, naming the file and what
// is wrong): missing/unreadable file, parse error, a glTF version other than
// 2.x, NaN/Inf positions (names the mesh), a texture of a used material that
// cannot be read or decoded, missing TEXCOORD_1 when requireUv1 is set,
// nothing to bake (no triangles).
// Non-triangle primitives and degenerate triangles are skipped and counted in
// Scene::report; a warning is logged for each kind.
Expected<Scene> loadScene(const std::string& path, const LoadOptions& options = {});

// The same from a file's bytes (fuzzing, tests): `path` names the file in
// errors and chooses .glb by its extension (else the "glTF" magic decides);
// external URIs resolve against `baseDir`. Files other than glTF 2.0 (asset
// version major 2, minVersion at most 2.0, .glb container version 2) are
// refused in one line.
Expected<Scene> loadSceneFromMemory(std::vector<unsigned char> bytes, const std::string& path, const std::string& baseDir,
                                    const LoadOptions& options = {});

}  // namespace bb
