// loadScene(): glTF 2.0 (.gltf and .glb) into bb::Scene, with tinygltf (Debian's
// libtinygltf; its implementation lives in the shared library).
//
// Choices where glTF leaves room (what a baker's user would expect):
// - Only what the chosen scene instantiates is converted: meshes, materials and
//   images that no instanced node reaches are not loaded, checked or counted, so
//   Scene::materials and Scene::textures hold what the bake uses (in first-use
//   order; they are not glTF's indices).
// - Albedo is the diffuse part of metallic-roughness, baseColor * (1 - metallic).
//   With a metallicRoughnessTexture, metallic varies per texel (its B channel), so
//   (1 - metallicFactor * B) is multiplied into a derived albedo texture. Without
//   this, the SheenChair wood in mixed_lighting (metallicFactor 1, B about 0)
//   would bake black.
// - Material textures are sampled with Primitive::uv0. When a material's textures
//   read another TEXCOORD set or carry KHR_texture_transform, that set, already
//   transformed, is what the primitive stores in uv0.
// - glTF's default material is fully metallic (black when baked): primitives
//   without a material get a bundlebake default diffuse material instead.
// - extras.texelDensity on a node applies to its whole subtree until a
//   descendant sets its own.
// - Directional lights take the node's world linear transform applied to
//   (0,0,-1), normalized (the rotation when the scale is uniform); point and
//   spot lights the node's world origin (in double) and, for spots, that
//   direction. Cone angles are clamped to the spec's 0 <= inner <= outer <= pi/2;
//   a range of 0 or none is infinite.
// - alphaMode MASK: Material::alphaMask with baseColorFactor.a and alphaCutoff
//   (the albedo texture keeps the base colour texture's alpha); BLEND bakes opaque.
// - Images are kept encoded while tinygltf parses and decoded only when a used
//   material needs them; one that cannot be read or decoded is an error (a bake
//   without it would be silently wrong), an unused one is never looked at.
// - Degenerate triangles: a repeated index, or |cross| <= 1e-12 * (diagonal of
//   the primitive's bounding box)^2, computed in double from the float positions.
// Not converted: alphaMode BLEND (bakes opaque), skins and morph targets (the
// node's rest transform is used), KHR_materials_variants (the default mapping),
// Draco/meshopt compression (an error: the geometry cannot be read).
#include "scene/scene.h"

#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/log.h"

namespace bb {
namespace {

constexpr uint32_t UNUSED_VERTEX = 0xffffffffu;
// Largest element count accepted for an accessor without a bufferView (zeros,
// usually under a sparse override): guards allocations against hostile counts.
constexpr size_t MAX_ZERO_ACCESSOR_COUNT = size_t(1) << 26;
// Triangles whose |cross| is at most this times the squared diagonal of their
// primitive's bounding box are degenerate (zero area in float object space).
constexpr double DEGENERATE_RELATIVE_CROSS = 1e-12;

// One line, no control characters, bounded length: errors travel as one line.
std::string oneLine(const std::string& text, size_t maxLength = 400) {
    std::string out;
    bool pendingSeparator = false;
    for (char c : text) {
        if (c == '\n' || c == '\r') {
            pendingSeparator = !out.empty();
            continue;
        }
        if (pendingSeparator) {
            while (!out.empty() && (out.back() == ' ' || out.back() == '.' || out.back() == ';')) out.pop_back();
            out += "; ";
            pendingSeparator = false;
        }
        out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? ' ' : c;
    }
    while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
    if (out.size() > maxLength) out = out.substr(0, maxLength) + "...";
    return out;
}

std::string quoted(const std::string& name, const char* kind, int index) {
    if (name.empty()) return std::string(kind) + " " + std::to_string(index);
    return std::string(kind) + " '" + name + "'";
}

bool isFinite(const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

// tinygltf image callback: keep the encoded bytes; decoding waits until a used
// material needs the image (and a failure there is only a warning).
bool keepEncodedImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
    image->image.assign(bytes, bytes + size);
    image->width = -1;  // marks "still encoded"
    image->height = -1;
    image->as_is = true;
    return true;
}

// "MAJOR.MINOR" (glTF's asset.version pattern) as two numbers, or nothing.
std::optional<std::pair<long, long>> parseVersion(const std::string& text) {
    const size_t dot = text.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == text.size() || dot > 9 || text.size() - dot > 10) return {};
    for (size_t i = 0; i < text.size(); ++i)
        if (i != dot && (text[i] < '0' || text[i] > '9')) return {};
    return std::make_pair(std::stol(text.substr(0, dot)), std::stol(text.substr(dot + 1)));
}

// The "asset" object of a .gltf text or of a .glb's JSON chunk, parsed without
// tinygltf (null when there is none or the JSON does not parse).
nlohmann::json assetOf(const std::vector<unsigned char>& bytes, bool binary) {
    const unsigned char* json = bytes.data();
    size_t length = bytes.size();
    if (binary) {
        if (bytes.size() < 20) return nullptr;
        uint32_t chunkLength = 0;
        std::memcpy(&chunkLength, bytes.data() + 12, 4);
        if (chunkLength > bytes.size() - 20) return nullptr;
        json = bytes.data() + 20;
        length = chunkLength;
    }
    nlohmann::json doc = nlohmann::json::parse(json, json + length, nullptr, false);
    if (doc.is_discarded() || !doc.is_object() || !doc.contains("asset")) return nullptr;
    return doc["asset"];
}

// glTF 2.0 only: asset.version's major must be 2 and a minVersion, when
// present, at most 2.0 (glTF 2.0 spec, 3.2 "Asset"). Null passes (tinygltf
// reports a missing asset itself).
Status checkAssetVersion(const nlohmann::json& asset) {
    if (!asset.is_object()) return Status::ok();
    const auto text = [](const nlohmann::json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); };
    if (asset.contains("version")) {
        const std::string version = text(asset["version"]);
        const auto v = parseVersion(version);
        if (!v) return Status::error("asset.version '" + version + "' is not MAJOR.MINOR: not a glTF 2.0 file");
        if (v->first != 2)
            return Status::error("glTF " + version + " is not supported: bundlebake reads glTF 2.0 only (asset.version must be 2.x)");
    }
    if (asset.contains("minVersion")) {
        const std::string minVersion = text(asset["minVersion"]);
        const auto v = parseVersion(minVersion);
        if (!v) return Status::error("asset.minVersion '" + minVersion + "' is not MAJOR.MINOR");
        if (v->first != 2 || v->second > 0)
            return Status::error("the file requires glTF " + minVersion +
                                 " (asset.minVersion): bundlebake reads glTF 2.0 only");
    }
    return Status::ok();
}

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// How a material's textures read the primitive's texture coordinates.
struct UvSource {
    int texCoord = 0;
    glm::dmat3 transform{1.0};  // KHR_texture_transform, uv' = (transform * (uv, 1)).xy
    bool hasTransform = false;
    bool operator==(const UvSource& o) const {
        return texCoord == o.texCoord && hasTransform == o.hasTransform && transform == o.transform;
    }
};

struct TextureRef {
    int image = -1;  // glTF image index, -1 if none or unusable
    UvSource uv;
};

const tinygltf::Value* findObjectMember(const tinygltf::Value& v, const char* key) {
    if (!v.IsObject() || !v.Has(key)) return nullptr;
    return &v.Get(key);
}

const tinygltf::Value* findExtension(const tinygltf::ExtensionMap& extensions, const char* name) {
    auto it = extensions.find(name);
    return it == extensions.end() ? nullptr : &it->second;
}

std::optional<double> numberMember(const tinygltf::Value& v, const char* key) {
    const tinygltf::Value* m = findObjectMember(v, key);
    if (!m || !m->IsNumber()) return std::nullopt;
    return m->GetNumberAsDouble();
}

class SceneBuilder {
public:
    // Warnings met while building, for the caller to log once the load has
    // succeeded: a refused file gives one error line and nothing else.
    const std::vector<std::string>& warnings() const { return warnings_; }
    SceneBuilder(const tinygltf::Model& model, const LoadOptions& options, Scene& scene)
        : model_(model), options_(options), scene_(scene) {}

    Status build();

private:
    // --- accessors
    Status elementBytes(const tinygltf::Accessor& a, const std::string& label, size_t elementSize,
                        const unsigned char** base, size_t* stride) const;
    Status readFloats(int accessorIndex, int components, const std::string& what, std::vector<float>& out) const;
    Status readIndices(int accessorIndex, const std::string& what, std::vector<uint32_t>& out) const;

    // --- meshes and materials
    Status sceneMesh(int gltfMesh, int* out);
    Status convertPrimitive(int gltfMesh, int primIndex, Primitive& out, bool* keep);
    Status sceneMaterial(int gltfMaterial, int* out);
    int defaultMaterial();
    TextureRef textureRef(const tinygltf::TextureInfo& info, const std::string& materialLabel, const char* slot);
    const Texture* decodedImage(int image, bool srgb, const std::string& usage);
    int addTexture(const std::string& key, Texture texture);

    // --- nodes
    Status traverse();
    Status visitNode(int node, const glm::dmat4& worldFromNode, float texelDensity);

    const tinygltf::Model& model_;
    const LoadOptions& options_;
    Scene& scene_;

    std::vector<int> meshMap_;      // glTF mesh -> scene mesh; -2 not converted yet, -1 empty
    std::vector<int> materialMap_;  // glTF material -> scene material, -1 not converted yet
    std::vector<UvSource> materialUv_;  // per scene material
    int defaultMaterial_ = -1;
    std::map<std::pair<int, bool>, std::optional<Texture>> decoded_;  // (image, sRGB) -> texels
    std::string imageError_;  // set by decodedImage when a used image cannot be read or decoded
    std::vector<std::string> warnings_;  // logged by loadScene only when the load succeeds
    void deferWarning(std::string message) { warnings_.push_back(std::move(message)); }
    std::map<std::string, int> textureKeys_;                          // dedup of Scene::textures
    size_t skippedLights_ = 0;
    size_t badNormals_ = 0;
};

// ---------------------------------------------------------------------------
// accessors

Status SceneBuilder::elementBytes(const tinygltf::Accessor& a, const std::string& label, size_t elementSize,
                                  const unsigned char** base, size_t* stride) const {
    if (a.bufferView < 0 || size_t(a.bufferView) >= model_.bufferViews.size())
        return Status::error(label + " refers to a missing bufferView");
    const tinygltf::BufferView& view = model_.bufferViews[size_t(a.bufferView)];
    if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
        return Status::error("bufferView " + std::to_string(a.bufferView) + " refers to a missing buffer");
    const tinygltf::Buffer& buffer = model_.buffers[size_t(view.buffer)];
    if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset)
        return Status::error("bufferView " + std::to_string(a.bufferView) + " lies outside its buffer (" +
                             std::to_string(buffer.data.size()) + " bytes)");
    if (view.byteStride != 0 && view.byteStride > 252)
        return Status::error("bufferView " + std::to_string(a.bufferView) + " has an invalid byteStride (" +
                             std::to_string(view.byteStride) + ")");
    size_t s = view.byteStride != 0 ? view.byteStride : elementSize;
    if (s < elementSize)
        return Status::error(label + ": byteStride " + std::to_string(s) + " is smaller than an element (" +
                             std::to_string(elementSize) + " bytes)");
    if (a.count > 0) {
        // count <= byteLength keeps the products below far from overflow
        bool fits = a.count <= view.byteLength && a.byteOffset <= view.byteLength &&
                    (a.count - 1) * s + elementSize <= view.byteLength - a.byteOffset;
        if (!fits)
            return Status::error(label + " (" + std::to_string(a.count) + " elements) reads past the end of bufferView " +
                                 std::to_string(a.bufferView));
    }
    *base = buffer.data.data() + view.byteOffset + a.byteOffset;
    *stride = s;
    return Status::ok();
}

float readComponent(const unsigned char* p, int componentType, bool normalized) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        int8_t v;
        std::memcpy(&v, p, 1);
        return normalized ? std::max(float(v) / 127.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        uint8_t v;
        std::memcpy(&v, p, 1);
        return normalized ? float(v) / 255.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(float(v) / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? float(v) / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_INT: {
        int32_t v;
        std::memcpy(&v, p, 4);
        return normalized ? std::max(float(double(v) / 2147483647.0), -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return normalized ? float(double(v) / 4294967295.0) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v;
        std::memcpy(&v, p, 4);
        return v;
    }
    default:
        return 0.0f;
    }
}

bool isIndexType(int componentType) {
    return componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
           componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
           componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
}

uint32_t readIndex(const unsigned char* p, int componentType) {
    if (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return *p;
    if (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
    }
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

// Reads a float vector accessor (any component type; normalized integers map to
// [0,1] or [-1,1]), applying a sparse override if present.
Status SceneBuilder::readFloats(int accessorIndex, int components, const std::string& what,
                                std::vector<float>& out) const {
    const std::string label = "accessor " + std::to_string(accessorIndex) + " (" + what + ")";
    if (accessorIndex < 0 || size_t(accessorIndex) >= model_.accessors.size())
        return Status::error(what + " refers to missing accessor " + std::to_string(accessorIndex));
    const tinygltf::Accessor& a = model_.accessors[size_t(accessorIndex)];
    if (tinygltf::GetNumComponentsInType(uint32_t(a.type)) != components)
        return Status::error(label + " must have " + std::to_string(components) + " components per element");
    int componentSize = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    if (componentSize <= 0 || a.componentType == TINYGLTF_COMPONENT_TYPE_DOUBLE)
        return Status::error(label + " has invalid componentType " + std::to_string(a.componentType));
    const size_t elementSize = size_t(componentSize) * size_t(components);
    const size_t n = size_t(components);

    if (a.bufferView < 0) {
        // no bufferView: zeros, normally with a sparse override (glTF 2.0 §3.6.2.3)
        if (a.count > MAX_ZERO_ACCESSOR_COUNT)
            return Status::error(label + " has no bufferView and too many elements (" + std::to_string(a.count) + ")");
        out.assign(a.count * n, 0.0f);
    } else {
        const unsigned char* base = nullptr;
        size_t stride = 0;
        if (Status s = elementBytes(a, label, elementSize, &base, &stride); !s) return s;
        out.resize(a.count * n);
        for (size_t i = 0; i < a.count; ++i)
            for (size_t c = 0; c < n; ++c)
                out[i * n + c] = readComponent(base + i * stride + c * size_t(componentSize), a.componentType, a.normalized);
    }

    if (a.sparse.isSparse && a.sparse.count > 0) {
        const auto& sp = a.sparse;
        if (!isIndexType(sp.indices.componentType))
            return Status::error(label + ": sparse indices have invalid componentType");
        // The sparse index and value arrays are tightly packed: read them through
        // temporary accessors so the bounds checks are shared.
        tinygltf::Accessor idx;
        idx.bufferView = sp.indices.bufferView;
        idx.byteOffset = size_t(std::max(sp.indices.byteOffset, 0));
        idx.componentType = sp.indices.componentType;
        idx.count = size_t(sp.count);
        tinygltf::Accessor val;
        val.bufferView = sp.values.bufferView;
        val.byteOffset = size_t(std::max(sp.values.byteOffset, 0));
        val.componentType = a.componentType;
        val.count = size_t(sp.count);
        if (size_t(sp.count) > a.count) return Status::error(label + ": more sparse values than elements");
        size_t indexSize = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(sp.indices.componentType)));
        const unsigned char* idxBase = nullptr;
        const unsigned char* valBase = nullptr;
        size_t idxStride = 0, valStride = 0;
        if (Status s = elementBytes(idx, label + " sparse indices", indexSize, &idxBase, &idxStride); !s) return s;
        if (Status s = elementBytes(val, label + " sparse values", elementSize, &valBase, &valStride); !s) return s;
        for (size_t k = 0; k < size_t(sp.count); ++k) {
            uint32_t target = readIndex(idxBase + k * idxStride, sp.indices.componentType);
            if (target >= a.count)
                return Status::error(label + ": sparse index " + std::to_string(target) + " is out of range");
            for (size_t c = 0; c < n; ++c)
                out[target * n + c] =
                    readComponent(valBase + k * valStride + c * size_t(componentSize), a.componentType, a.normalized);
        }
    }
    return Status::ok();
}

Status SceneBuilder::readIndices(int accessorIndex, const std::string& what, std::vector<uint32_t>& out) const {
    const std::string label = "accessor " + std::to_string(accessorIndex) + " (" + what + ")";
    if (accessorIndex < 0 || size_t(accessorIndex) >= model_.accessors.size())
        return Status::error(what + " refers to missing accessor " + std::to_string(accessorIndex));
    const tinygltf::Accessor& a = model_.accessors[size_t(accessorIndex)];
    if (a.type != TINYGLTF_TYPE_SCALAR || !isIndexType(a.componentType))
        return Status::error(label + " must be SCALAR unsigned byte, short or int");
    if (a.sparse.isSparse) return Status::error(label + ": sparse index accessors are not supported");
    const size_t size = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)));
    const unsigned char* base = nullptr;
    size_t stride = 0;
    if (Status s = elementBytes(a, label, size, &base, &stride); !s) return s;
    out.resize(a.count);
    for (size_t i = 0; i < a.count; ++i) out[i] = readIndex(base + i * stride, a.componentType);
    return Status::ok();
}

// ---------------------------------------------------------------------------
// textures and materials

UvSource uvSource(const tinygltf::TextureInfo& info) {
    UvSource uv;
    uv.texCoord = std::max(info.texCoord, 0);
    const tinygltf::Value* ext = findExtension(info.extensions, "KHR_texture_transform");
    if (!ext || !ext->IsObject()) return uv;
    glm::dvec2 offset(0.0), scale(1.0);
    double rotation = numberMember(*ext, "rotation").value_or(0.0);
    if (const tinygltf::Value* o = findObjectMember(*ext, "offset"); o && o->ArrayLen() == 2)
        offset = {o->Get(0).GetNumberAsDouble(), o->Get(1).GetNumberAsDouble()};
    if (const tinygltf::Value* s = findObjectMember(*ext, "scale"); s && s->ArrayLen() == 2)
        scale = {s->Get(0).GetNumberAsDouble(), s->Get(1).GetNumberAsDouble()};
    if (std::optional<double> t = numberMember(*ext, "texCoord")) uv.texCoord = std::max(int(*t), 0);
    // translation * rotation * scale, rotation as in the extension's example
    // (u' = cos u + sin v, v' = -sin u + cos v, counter-clockwise in UV space)
    const double c = std::cos(rotation), s = std::sin(rotation);
    glm::dmat3 t(1.0);
    t[2] = glm::dvec3(offset, 1.0);
    glm::dmat3 r(glm::dvec3(c, -s, 0.0), glm::dvec3(s, c, 0.0), glm::dvec3(0.0, 0.0, 1.0));
    glm::dmat3 sc(glm::dvec3(scale.x, 0.0, 0.0), glm::dvec3(0.0, scale.y, 0.0), glm::dvec3(0.0, 0.0, 1.0));
    uv.transform = t * r * sc;
    uv.hasTransform = uv.transform != glm::dmat3(1.0);
    return uv;
}

TextureRef SceneBuilder::textureRef(const tinygltf::TextureInfo& info, const std::string& materialLabel,
                                    const char* slot) {
    TextureRef ref;
    if (info.index < 0) return ref;
    if (size_t(info.index) >= model_.textures.size()) {
        deferWarning(scene_.path + ": " + materialLabel + ": " + slot + " refers to missing texture " +
                   std::to_string(info.index) + "; ignored");
        return ref;
    }
    const tinygltf::Texture& texture = model_.textures[size_t(info.index)];
    if (texture.source < 0 || size_t(texture.source) >= model_.images.size()) {
        deferWarning(scene_.path + ": " + materialLabel + ": " + slot + " (texture " + std::to_string(info.index) +
                   ") has no image bundlebake can decode (only PNG, JPEG and the like); ignored");
        return ref;
    }
    ref.image = texture.source;
    ref.uv = uvSource(info);
    return ref;
}

// Decodes a glTF image to linear float RGBA (sRGB transfer removed when `srgb`).
// nullptr (after one warning) when the image cannot be read or decoded.
const Texture* SceneBuilder::decodedImage(int imageIndex, bool srgb, const std::string& usage) {
    auto key = std::make_pair(imageIndex, srgb);
    auto it = decoded_.find(key);
    if (it != decoded_.end()) return it->second ? &*it->second : nullptr;

    const tinygltf::Image& image = model_.images[size_t(imageIndex)];
    std::string label = quoted(image.name.empty() ? image.uri : image.name, "image", imageIndex);
    std::optional<Texture> result;
    tinygltf::Image pixels;  // stb through tinygltf: 8 or 16 bits, always expanded to RGBA
    std::string err, warn;
    if (image.image.empty()) {
        imageError_ = usage + ": " + label + " could not be read (missing or empty file, or a bad URI)";
    } else if (image.image.size() > size_t(std::numeric_limits<int>::max()) ||
               !tinygltf::LoadImageData(&pixels, imageIndex, &err, &warn, 0, 0, image.image.data(),
                                        int(image.image.size()), nullptr) ||
               pixels.component != 4 || (pixels.bits != 8 && pixels.bits != 16)) {
        imageError_ = usage + ": " + label + " could not be decoded (" +
                      oneLine(err.empty() ? "unsupported format" : err, 160) + ")";
    } else {
        Texture t;
        t.name = image.name.empty() ? (image.uri.empty() ? "image " + std::to_string(imageIndex) : image.uri)
                                    : image.name;
        t.width = pixels.width;
        t.height = pixels.height;
        t.texels.resize(size_t(t.width) * size_t(t.height));
        float lut[256];
        for (int i = 0; i < 256; ++i) lut[i] = srgb ? srgbToLinear(float(i) / 255.0f) : float(i) / 255.0f;
        const unsigned char* src = pixels.image.data();
        for (size_t p = 0; p < t.texels.size(); ++p) {
            float v[4];
            for (size_t c = 0; c < 4; ++c) {
                if (pixels.bits == 16) {
                    uint16_t raw;
                    std::memcpy(&raw, src + (p * 4 + c) * 2, 2);
                    const float x = float(raw) / 65535.0f;
                    v[c] = (srgb && c < 3) ? srgbToLinear(x) : x;  // alpha is always linear
                } else {
                    const uint8_t raw = src[p * 4 + c];
                    v[c] = c < 3 ? lut[raw] : float(raw) / 255.0f;
                }
            }
            t.texels[p] = glm::vec4(v[0], v[1], v[2], v[3]);
        }
        result = std::move(t);
    }
    auto [pos, inserted] = decoded_.emplace(key, std::move(result));
    (void)inserted;
    return pos->second ? &*pos->second : nullptr;
}

int SceneBuilder::addTexture(const std::string& key, Texture texture) {
    auto it = textureKeys_.find(key);
    if (it != textureKeys_.end()) return it->second;
    int index = int(scene_.textures.size());
    scene_.textures.push_back(std::move(texture));
    textureKeys_.emplace(key, index);
    return index;
}

int SceneBuilder::defaultMaterial() {
    if (defaultMaterial_ < 0) {
        Material m;
        m.name = "bundlebake default";
        m.albedo = options_.defaultAlbedo;
        m.isDefault = true;
        m.doubleSided = false;
        defaultMaterial_ = int(scene_.materials.size());
        scene_.materials.push_back(m);
        materialUv_.push_back(UvSource{});
    }
    return defaultMaterial_;
}

glm::vec3 vec3Of(const std::vector<double>& v, glm::vec3 fallback) {
    if (v.size() < 3) return fallback;
    return glm::vec3(float(v[0]), float(v[1]), float(v[2]));
}

Status SceneBuilder::sceneMaterial(int gltfMaterial, int* out) {
    if (gltfMaterial < 0) {
        *out = defaultMaterial();
        return Status::ok();
    }
    if (size_t(gltfMaterial) >= model_.materials.size())
        return Status::error("primitive refers to missing material " + std::to_string(gltfMaterial));
    if (materialMap_[size_t(gltfMaterial)] >= 0) {
        *out = materialMap_[size_t(gltfMaterial)];
        return Status::ok();
    }
    const tinygltf::Material& src = model_.materials[size_t(gltfMaterial)];
    const std::string label = quoted(src.name, "material", gltfMaterial);
    const tinygltf::PbrMetallicRoughness& pbr = src.pbrMetallicRoughness;

    Material m;
    m.name = src.name.empty() ? "material " + std::to_string(gltfMaterial) : src.name;
    m.doubleSided = src.doubleSided;
    // cut-outs: alphaMode MASK (scene/alpha_mask.h); BLEND bakes opaque
    m.alphaMask = src.alphaMode == "MASK";
    m.alphaCutoff = std::isfinite(src.alphaCutoff) ? std::max(float(src.alphaCutoff), 0.0f) : 0.5f;
    m.alpha = pbr.baseColorFactor.size() >= 4 && std::isfinite(pbr.baseColorFactor[3])
                  ? std::clamp(float(pbr.baseColorFactor[3]), 0.0f, 1.0f) : 1.0f;
    const glm::vec3 baseColor = glm::max(vec3Of(pbr.baseColorFactor, glm::vec3(1.0f)), glm::vec3(0.0f));
    const float metallic = std::clamp(float(pbr.metallicFactor), 0.0f, 1.0f);
    UvSource uv;
    bool haveUv = false;

    // albedo: baseColor * (1 - metallic), per texel when metallic comes from a texture
    TextureRef base = textureRef(pbr.baseColorTexture, label, "baseColorTexture");
    TextureRef mr = metallic > 0.0f ? textureRef(pbr.metallicRoughnessTexture, label, "metallicRoughnessTexture")
                                    : TextureRef{};
    const Texture* baseTexels = base.image >= 0 ? decodedImage(base.image, true, label + " baseColorTexture") : nullptr;
    const Texture* mrTexels =
        mr.image >= 0 ? decodedImage(mr.image, false, label + " metallicRoughnessTexture") : nullptr;
    if (!imageError_.empty()) return Status::error(imageError_);
    m.albedo = baseColor * (1.0f - metallic);
    if (mrTexels && (!baseTexels || base.uv == mr.uv)) {
        // (1 - metallic * B) multiplied into a derived albedo texture
        char key[96];
        std::snprintf(key, sizeof key, "albedo:%d:%d:%.9g", baseTexels ? base.image : -1, mr.image, double(metallic));
        auto it = textureKeys_.find(key);
        if (it != textureKeys_.end()) {
            m.albedoTexture = it->second;
        } else {
            Texture t;
            const Texture& size = baseTexels ? *baseTexels : *mrTexels;
            t.name = (baseTexels ? baseTexels->name + " x " : std::string()) + "(1 - metallic) of " + mrTexels->name;
            t.width = size.width;
            t.height = size.height;
            t.texels.resize(size_t(t.width) * size_t(t.height));
            for (int y = 0; y < t.height; ++y) {
                int my = std::min(int((double(y) + 0.5) / t.height * mrTexels->height), mrTexels->height - 1);
                for (int x = 0; x < t.width; ++x) {
                    int mx = std::min(int((double(x) + 0.5) / t.width * mrTexels->width), mrTexels->width - 1);
                    float b = mrTexels->texels[size_t(my) * size_t(mrTexels->width) + size_t(mx)].b;
                    float diffuse = 1.0f - metallic * b;
                    glm::vec4 c = baseTexels ? baseTexels->texels[size_t(y) * size_t(t.width) + size_t(x)]
                                             : glm::vec4(1.0f);
                    t.texels[size_t(y) * size_t(t.width) + size_t(x)] = glm::vec4(glm::vec3(c) * diffuse, c.a);
                }
            }
            m.albedoTexture = addTexture(key, std::move(t));
        }
        m.albedo = baseColor;
        uv = baseTexels ? base.uv : mr.uv;
        haveUv = true;
    } else {
        if (mrTexels) {
            // the two textures are sampled differently: use the mean metallic
            double sum = 0.0;
            for (const glm::vec4& t : mrTexels->texels) sum += t.b;
            float meanB = mrTexels->texels.empty() ? 0.0f : float(sum / double(mrTexels->texels.size()));
            m.albedo = baseColor * (1.0f - metallic * meanB);
            deferWarning(scene_.path + ": " + label +
                       ": metallicRoughnessTexture and baseColorTexture use different texture coordinates; "
                       "albedo uses the texture's mean metallic");
        }
        if (baseTexels) {
            m.albedoTexture = addTexture("srgb:" + std::to_string(base.image), *baseTexels);
            uv = base.uv;
            haveUv = true;
        }
    }

    // emission: emissiveFactor * KHR_materials_emissive_strength (x texture)
    float strength = 1.0f;
    if (const tinygltf::Value* ext = findExtension(src.extensions, "KHR_materials_emissive_strength"))
        strength = float(numberMember(*ext, "emissiveStrength").value_or(1.0));
    m.emission = glm::max(vec3Of(src.emissiveFactor, glm::vec3(0.0f)) * strength, glm::vec3(0.0f));
    if (glm::any(glm::greaterThan(m.emission, glm::vec3(0.0f)))) {
        TextureRef emissive = textureRef(src.emissiveTexture, label, "emissiveTexture");
        if (emissive.image >= 0) {
            const Texture* t = decodedImage(emissive.image, true, label + " emissiveTexture");
            if (!imageError_.empty()) return Status::error(imageError_);
            if (t) {
                m.emissionTexture = addTexture("srgb:" + std::to_string(emissive.image), *t);
                if (!haveUv) {
                    uv = emissive.uv;
                    haveUv = true;
                } else if (!(uv == emissive.uv)) {
                    deferWarning(scene_.path + ": " + label +
                               ": emissiveTexture uses other texture coordinates than the albedo texture; "
                               "it is sampled with the albedo texture's");
                }
            }
        }
    }
    if (!std::isfinite(m.albedo.x + m.albedo.y + m.albedo.z + m.emission.x + m.emission.y + m.emission.z))
        return Status::error(label + " has a NaN or infinite factor");

    int index = int(scene_.materials.size());
    scene_.materials.push_back(std::move(m));
    materialUv_.push_back(uv);
    materialMap_[size_t(gltfMaterial)] = index;
    *out = index;
    return Status::ok();
}

// ---------------------------------------------------------------------------
// meshes

const char* modeName(int mode) {
    switch (mode) {
    case TINYGLTF_MODE_POINTS: return "POINTS";
    case TINYGLTF_MODE_LINE: return "LINES";
    case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
    default: return "unknown mode";
    }
}

std::vector<glm::vec2> toVec2(const std::vector<float>& f) {
    std::vector<glm::vec2> v(f.size() / 2);
    for (size_t i = 0; i < v.size(); ++i) v[i] = glm::vec2(f[2 * i], f[2 * i + 1]);
    return v;
}

std::vector<glm::vec3> toVec3(const std::vector<float>& f) {
    std::vector<glm::vec3> v(f.size() / 3);
    for (size_t i = 0; i < v.size(); ++i) v[i] = glm::vec3(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
    return v;
}

Status SceneBuilder::convertPrimitive(int gltfMesh, int primIndex, Primitive& out, bool* keep) {
    const tinygltf::Mesh& mesh = model_.meshes[size_t(gltfMesh)];
    const tinygltf::Primitive& src = mesh.primitives[size_t(primIndex)];
    const std::string where = quoted(mesh.name, "mesh", gltfMesh) + " (primitive " + std::to_string(primIndex) + ")";
    *keep = false;

    // points and lines are not surfaces
    const int mode = src.mode < 0 ? TINYGLTF_MODE_TRIANGLES : src.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        ++scene_.report.skippedNonTrianglePrimitives;
        logDebug(scene_.path + ": " + where + ": " + modeName(mode) + " primitive skipped");
        return Status::ok();
    }

    // positions
    auto attribute = [&](const std::string& name) {
        auto it = src.attributes.find(name);
        return it == src.attributes.end() ? -1 : it->second;
    };
    const int positionAccessor = attribute("POSITION");
    if (positionAccessor < 0) return Status::error(where + " has no POSITION attribute");
    std::vector<float> raw;
    if (Status s = readFloats(positionAccessor, 3, where + " POSITION", raw); !s) return s;
    for (size_t i = 0; i < raw.size(); ++i)
        if (!std::isfinite(raw[i]))
            return Status::error(where + " has a NaN or infinite position (vertex " + std::to_string(i / 3) + ")");
    std::vector<glm::vec3> positions = toVec3(raw);
    const size_t vertexCount = positions.size();

    // triangle list (strips and fans converted, glTF 2.0 §3.7.2.1)
    std::vector<uint32_t> ids;
    if (src.indices >= 0) {
        if (Status s = readIndices(src.indices, where + " indices", ids); !s) return s;
        for (uint32_t id : ids)
            if (id >= vertexCount)
                return Status::error(where + ": index " + std::to_string(id) + " is out of range (" +
                                     std::to_string(vertexCount) + " vertices)");
    } else {
        ids.resize(vertexCount);
        for (size_t i = 0; i < vertexCount; ++i) ids[i] = uint32_t(i);
    }
    std::vector<uint32_t> tris;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        tris.assign(ids.begin(), ids.begin() + ptrdiff_t(ids.size() / 3 * 3));
    } else if (ids.size() >= 3) {
        tris.reserve((ids.size() - 2) * 3);
        for (size_t i = 0; i + 2 < ids.size(); ++i) {
            if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                bool odd = i % 2 != 0;
                tris.insert(tris.end(), {ids[i], ids[odd ? i + 2 : i + 1], ids[odd ? i + 1 : i + 2]});
            } else {
                tris.insert(tris.end(), {ids[i + 1], ids[i + 2], ids[0]});
            }
        }
    }

    // degenerate triangles: repeated index or zero area relative to the primitive's size
    Bounds box;
    for (const glm::vec3& p : positions) box.extend(p);
    const double diagonal2 = box.empty() ? 0.0 : double(glm::dot(box.size(), box.size()));
    const double minCross = DEGENERATE_RELATIVE_CROSS * diagonal2;
    std::vector<uint32_t> kept;
    kept.reserve(tris.size());
    for (size_t t = 0; t < tris.size(); t += 3) {
        uint32_t a = tris[t], b = tris[t + 1], c = tris[t + 2];
        bool degenerate = a == b || b == c || a == c;
        if (!degenerate) {
            glm::dvec3 p0(positions[a]), p1(positions[b]), p2(positions[c]);
            degenerate = glm::length(glm::cross(p1 - p0, p2 - p0)) <= minCross;
        }
        if (degenerate) {
            ++scene_.report.skippedDegenerateTriangles;
        } else {
            kept.insert(kept.end(), {a, b, c});
        }
    }
    if (kept.empty()) return Status::ok();

    // material decides which TEXCOORD set becomes uv0
    int material = -1;
    if (Status s = sceneMaterial(src.material, &material); !s) return Status::error(where + ": " + s.message());
    if (src.material < 0) ++scene_.report.primitivesWithoutMaterial;
    const UvSource& uvSrc = materialUv_[size_t(material)];

    auto readUv = [&](int set, std::vector<glm::vec2>& uv) -> Status {
        int accessor = attribute("TEXCOORD_" + std::to_string(set));
        if (accessor < 0) return Status::ok();
        std::vector<float> f;
        const std::string what = where + " TEXCOORD_" + std::to_string(set);
        if (Status s = readFloats(accessor, 2, what, f); !s) return s;
        if (f.size() != vertexCount * 2) return Status::error(what + " has a different count than POSITION");
        for (float x : f)
            if (!std::isfinite(x)) return Status::error(what + " has a NaN or infinite coordinate");
        uv = toVec2(f);
        return Status::ok();
    };
    std::vector<glm::vec2> uv0, uv1;
    if (Status s = readUv(uvSrc.texCoord, uv0); !s) return s;
    if (Status s = readUv(1, uv1); !s) return s;
    if (uvSrc.hasTransform)
        for (glm::vec2& t : uv0) t = glm::vec2(uvSrc.transform * glm::dvec3(glm::dvec2(t), 1.0));
    if (uv1.empty()) {
        ++scene_.report.primitivesWithoutUv1;
        if (options_.requireUv1)
            return Status::error(where + " has no TEXCOORD_1 (light map UVs); bundlebake cannot generate them yet, "
                                         "so add a TEXCOORD_1 set (a lightmap UV unwrap) in your DCC tool and re-export");
    }

    std::vector<glm::vec3> normals;
    if (int normalAccessor = attribute("NORMAL"); normalAccessor >= 0) {
        std::vector<float> f;
        if (Status s = readFloats(normalAccessor, 3, where + " NORMAL", f); !s) return s;
        if (f.size() != vertexCount * 3) return Status::error(where + " NORMAL has a different count than POSITION");
        normals = toVec3(f);
    }

    if (normals.empty()) {
        // flat normals: every triangle gets its own three vertices
        const size_t n = kept.size();
        out.positions.resize(n);
        out.normals.resize(n);
        if (!uv0.empty()) out.uv0.resize(n);
        if (!uv1.empty()) out.uv1.resize(n);
        out.indices.resize(n);
        for (size_t t = 0; t < n; t += 3) {
            glm::dvec3 p0(positions[kept[t]]), p1(positions[kept[t + 1]]), p2(positions[kept[t + 2]]);
            glm::vec3 normal(glm::normalize(glm::cross(p1 - p0, p2 - p0)));
            for (size_t k = 0; k < 3; ++k) {
                uint32_t v = kept[t + k];
                out.positions[t + k] = positions[v];
                out.normals[t + k] = normal;
                if (!uv0.empty()) out.uv0[t + k] = uv0[v];
                if (!uv1.empty()) out.uv1[t + k] = uv1[v];
                out.indices[t + k] = uint32_t(t + k);
            }
        }
    } else {
        // keep only the vertices that kept triangles use, in their original order
        std::vector<uint32_t> remap(vertexCount, UNUSED_VERTEX);
        for (uint32_t v : kept) remap[v] = 0;
        uint32_t next = 0;
        for (size_t v = 0; v < vertexCount; ++v)
            if (remap[v] != UNUSED_VERTEX) {
                remap[v] = next++;
                out.positions.push_back(positions[v]);
                out.normals.push_back(normals[v]);
                if (!uv0.empty()) out.uv0.push_back(uv0[v]);
                if (!uv1.empty()) out.uv1.push_back(uv1[v]);
            }
        out.indices.resize(kept.size());
        for (size_t i = 0; i < kept.size(); ++i) out.indices[i] = remap[kept[i]];

        // normalize; zero or non-finite normals get the area-weighted face normal
        std::vector<size_t> bad;
        for (size_t v = 0; v < out.normals.size(); ++v) {
            glm::vec3& nv = out.normals[v];
            float len = glm::length(nv);
            if (std::isfinite(len) && len > 1e-20f) {
                nv /= len;
            } else {
                bad.push_back(v);
            }
        }
        if (!bad.empty()) {
            badNormals_ += bad.size();
            std::vector<glm::dvec3> sum(out.positions.size(), glm::dvec3(0.0));
            for (size_t t = 0; t < out.indices.size(); t += 3) {
                glm::dvec3 p0(out.positions[out.indices[t]]), p1(out.positions[out.indices[t + 1]]),
                    p2(out.positions[out.indices[t + 2]]);
                glm::dvec3 area2 = glm::cross(p1 - p0, p2 - p0);
                for (size_t k = 0; k < 3; ++k) sum[out.indices[t + k]] += area2;
            }
            for (size_t v : bad) {
                double len = glm::length(sum[v]);
                out.normals[v] = len > 0.0 ? glm::vec3(sum[v] / len) : glm::vec3(0.0f, 0.0f, 1.0f);
            }
        }
    }
    out.material = material;
    *keep = true;
    return Status::ok();
}

Status SceneBuilder::sceneMesh(int gltfMesh, int* out) {
    if (meshMap_[size_t(gltfMesh)] != -2) {
        *out = meshMap_[size_t(gltfMesh)];
        return Status::ok();
    }
    const tinygltf::Mesh& src = model_.meshes[size_t(gltfMesh)];
    Mesh mesh;
    mesh.name = src.name.empty() ? "mesh " + std::to_string(gltfMesh) : src.name;
    for (size_t p = 0; p < src.primitives.size(); ++p) {
        Primitive prim;
        bool keep = false;
        if (Status s = convertPrimitive(gltfMesh, int(p), prim, &keep); !s) return s;
        if (keep) mesh.primitives.push_back(std::move(prim));
    }
    int index = -1;
    if (!mesh.primitives.empty()) {
        index = int(scene_.meshes.size());
        scene_.meshes.push_back(std::move(mesh));
    }
    meshMap_[size_t(gltfMesh)] = index;
    *out = index;
    return Status::ok();
}

// ---------------------------------------------------------------------------
// nodes

glm::dmat4 localTransform(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major, as glTF
    glm::dmat4 m(1.0);
    if (node.translation.size() == 3)
        m = glm::translate(m, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
    if (node.rotation.size() == 4) {
        glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);  // (w, x, y, z)
        double len = glm::length(q);
        if (len > 0.0) m *= glm::mat4_cast(q / len);
    }
    if (node.scale.size() == 3) m = glm::scale(m, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
    return m;
}

Status SceneBuilder::visitNode(int nodeIndex, const glm::dmat4& worldFromNode, float texelDensity) {
    const tinygltf::Node& node = model_.nodes[size_t(nodeIndex)];
    const std::string label = quoted(node.name, "node", nodeIndex);
    if (!isFinite(worldFromNode)) return Status::error(label + " has a NaN or infinite transform");

    if (node.mesh >= 0) {
        if (size_t(node.mesh) >= model_.meshes.size())
            return Status::error(label + " refers to missing mesh " + std::to_string(node.mesh));
        int mesh = -1;
        if (Status s = sceneMesh(node.mesh, &mesh); !s) return s;
        if (mesh >= 0) {
            Instance inst;
            inst.name = node.name.empty() ? "node " + std::to_string(nodeIndex) : node.name;
            inst.mesh = mesh;
            inst.node = nodeIndex;
            inst.setWorldFromObject(worldFromNode);
            inst.texelDensity = texelDensity;
            scene_.instances.push_back(std::move(inst));
        }
    }

    if (node.camera >= 0) {
        if (size_t(node.camera) >= model_.cameras.size())
            return Status::error(label + " refers to missing camera " + std::to_string(node.camera));
        const tinygltf::Camera& src = model_.cameras[size_t(node.camera)];
        Camera cam;
        cam.name = !src.name.empty() ? src.name : (!node.name.empty() ? node.name : "camera " + std::to_string(node.camera));
        cam.worldFromCamera = glm::mat4(worldFromNode);
        if (src.type == "orthographic") {
            cam.perspective = false;
            cam.xmag = float(src.orthographic.xmag);
            cam.ymag = float(src.orthographic.ymag);
            cam.znear = float(src.orthographic.znear);
            cam.zfar = float(src.orthographic.zfar);
        } else {
            cam.perspective = true;
            if (src.perspective.yfov > 0.0) cam.yfov = float(src.perspective.yfov);
            cam.aspect = float(std::max(src.perspective.aspectRatio, 0.0));
            if (src.perspective.znear > 0.0) cam.znear = float(src.perspective.znear);
            cam.zfar = float(std::max(src.perspective.zfar, 0.0));
        }
        scene_.cameras.push_back(std::move(cam));
    }

    if (const tinygltf::Value* ext = findExtension(node.extensions, "KHR_lights_punctual")) {
        std::optional<double> li = numberMember(*ext, "light");
        if (!li || *li < 0.0 || size_t(*li) >= model_.lights.size())
            return Status::error(label + " refers to a missing KHR_lights_punctual light");
        const tinygltf::Light& src = model_.lights[size_t(*li)];
        if (src.type == "directional") {
            glm::dvec3 d = glm::dmat3(worldFromNode) * glm::dvec3(0.0, 0.0, -1.0);
            double len = glm::length(d);
            DirectionalLight light;
            light.name = !src.name.empty() ? src.name : (!node.name.empty() ? node.name : "light " + std::to_string(int(*li)));
            light.irradiance = vec3Of(src.color, glm::vec3(1.0f)) * float(src.intensity);
            if (len > 0.0 && std::isfinite(light.irradiance.x + light.irradiance.y + light.irradiance.z)) {
                light.direction = glm::vec3(d / len);
                scene_.lights.push_back(std::move(light));
            } else {
                deferWarning(scene_.path + ": " + label + ": directional light with a degenerate transform or "
                                                        "intensity skipped");
            }
        } else if (src.type == "point" || src.type == "spot") {
            PunctualLight light;
            light.name = !src.name.empty() ? src.name : (!node.name.empty() ? node.name : "light " + std::to_string(int(*li)));
            light.type = src.type == "spot" ? PunctualLight::Type::Spot : PunctualLight::Type::Point;
            light.position = glm::dvec3(worldFromNode * glm::dvec4(0.0, 0.0, 0.0, 1.0));
            light.intensity = glm::max(vec3Of(src.color, glm::vec3(1.0f)), glm::vec3(0.0f)) * float(src.intensity);
            light.range = src.range > 0.0 && std::isfinite(src.range) ? float(src.range) : 0.0f;  // undefined: infinite
            glm::dvec3 d = glm::dmat3(worldFromNode) * glm::dvec3(0.0, 0.0, -1.0);
            const double len = glm::length(d);
            // the spec: 0 <= inner < outer <= pi/2
            const double outer = std::clamp(src.spot.outerConeAngle, 0.0, 0.5 * 3.14159265358979);
            const double inner = std::clamp(src.spot.innerConeAngle, 0.0, outer);
            light.outerConeAngle = float(outer);
            light.innerConeAngle = float(inner);
            const bool finite = std::isfinite(light.intensity.x + light.intensity.y + light.intensity.z) &&
                                std::isfinite(light.position.x + light.position.y + light.position.z);
            if (finite && src.intensity >= 0.0 && (light.type == PunctualLight::Type::Point || (len > 0.0 && std::isfinite(len)))) {
                if (len > 0.0 && std::isfinite(len)) light.direction = glm::vec3(d / len);
                scene_.punctualLights.push_back(std::move(light));
            } else {
                deferWarning(scene_.path + ": " + label + ": " + src.type +
                             " light with a degenerate transform or intensity skipped");
            }
        } else {
            ++skippedLights_;
        }
    }
    return Status::ok();
}

Status SceneBuilder::traverse() {
    const size_t nodeCount = model_.nodes.size();
    // roots: the default scene, else every scene, else every node without a parent
    std::vector<int> roots;
    if (model_.defaultScene >= 0 && size_t(model_.defaultScene) >= model_.scenes.size())
        return Status::error("the default scene " + std::to_string(model_.defaultScene) + " does not exist (the file has " +
                             std::to_string(model_.scenes.size()) + " scene(s))");
    if (model_.defaultScene >= 0) {
        roots = model_.scenes[size_t(model_.defaultScene)].nodes;
    } else if (!model_.scenes.empty()) {
        for (const tinygltf::Scene& s : model_.scenes) roots.insert(roots.end(), s.nodes.begin(), s.nodes.end());
    } else {
        std::vector<char> isChild(nodeCount, 0);
        for (const tinygltf::Node& n : model_.nodes)
            for (int c : n.children)
                if (c >= 0 && size_t(c) < nodeCount) isChild[size_t(c)] = 1;
        for (size_t i = 0; i < nodeCount; ++i)
            if (!isChild[i]) roots.push_back(int(i));
    }
    std::vector<char> isRoot(nodeCount, 0), visited(nodeCount, 0);
    struct Item {
        int node;
        glm::dmat4 parentWorld;
        float texelDensity;
    };
    std::vector<Item> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) {
        if (*it < 0 || size_t(*it) >= nodeCount)
            return Status::error("scene refers to missing node " + std::to_string(*it));
        if (isRoot[size_t(*it)]) continue;  // shared by several scenes
        isRoot[size_t(*it)] = 1;
        stack.push_back({*it, glm::dmat4(1.0), 0.0f});
    }
    // depth first, in file order; an explicit stack so deep hierarchies cannot
    // overflow the call stack
    while (!stack.empty()) {
        Item item = stack.back();
        stack.pop_back();
        if (visited[size_t(item.node)])
            return Status::error("the node hierarchy is not a tree: " +
                                 quoted(model_.nodes[size_t(item.node)].name, "node", item.node) + " is reached twice");
        visited[size_t(item.node)] = 1;
        const tinygltf::Node& node = model_.nodes[size_t(item.node)];
        glm::dmat4 world = item.parentWorld * localTransform(node);
        // extras.texelDensity holds for the whole subtree
        float density = item.texelDensity;
        if (std::optional<double> d = numberMember(node.extras, "texelDensity")) {
            if (std::isfinite(*d) && *d > 0.0) {
                density = float(*d);
            } else {
                deferWarning(scene_.path + ": " + quoted(node.name, "node", item.node) +
                           ": extras.texelDensity must be a positive number; ignored");
            }
        }
        if (Status s = visitNode(item.node, world, density); !s) return s;
        for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) {
            if (*c < 0 || size_t(*c) >= nodeCount)
                return Status::error(quoted(node.name, "node", item.node) + " has missing child node " + std::to_string(*c));
            stack.push_back({*c, world, density});
        }
    }
    return Status::ok();
}

Status SceneBuilder::build() {
    for (const std::string& ext : model_.extensionsRequired) {
        if (ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression")
            return Status::error("requires " + ext + ", which bundlebake does not support (re-export without mesh compression)");
    }
    meshMap_.assign(model_.meshes.size(), -2);
    materialMap_.assign(model_.materials.size(), -1);

    if (Status s = traverse(); !s) return s;

    // one warning per kind of thing skipped or substituted
    const LoadReport& r = scene_.report;
    if (r.skippedNonTrianglePrimitives > 0)
        deferWarning(scene_.path + ": skipped " + std::to_string(r.skippedNonTrianglePrimitives) +
                   " point/line primitive(s): only triangles are baked");
    if (r.skippedDegenerateTriangles > 0)
        deferWarning(scene_.path + ": skipped " + std::to_string(r.skippedDegenerateTriangles) +
                   " degenerate triangle(s) (repeated index or zero area)");
    if (r.primitivesWithoutMaterial > 0) {
        const glm::vec3 a = options_.defaultAlbedo;
        char albedo[64];
        std::snprintf(albedo, sizeof albedo, "(%g, %g, %g)", double(a.x), double(a.y), double(a.z));
        deferWarning(scene_.path + ": " + std::to_string(r.primitivesWithoutMaterial) +
                   " primitive(s) have no material: using bundlebake's default diffuse albedo " + albedo +
                   " instead of glTF's default material, which is fully metallic and would bake black");
    }
    if (skippedLights_ > 0)
        deferWarning(scene_.path + ": skipped " + std::to_string(skippedLights_) +
                   " KHR_lights_punctual light(s) of an unknown type (directional, point and spot are baked)");
    if (badNormals_ > 0)
        deferWarning(scene_.path + ": " + std::to_string(badNormals_) +
                   " zero or non-finite normal(s) replaced by face normals");

    // world bounds over every instanced vertex, in double; the local origin from them
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (const Instance& inst : scene_.instances) {
        const glm::dmat4& worldFromObject = inst.worldFromObjectDouble;
        for (const Primitive& p : scene_.meshes[size_t(inst.mesh)].primitives)
            for (const glm::vec3& v : p.positions) {
                const glm::dvec3 w(worldFromObject * glm::dvec4(glm::dvec3(v), 1.0));
                lo = glm::min(lo, w);
                hi = glm::max(hi, w);
            }
    }
    if (lo.x <= hi.x) {
        scene_.bounds.extend(glm::vec3(lo));
        scene_.bounds.extend(glm::vec3(hi));
    }
    scene_.origin = chooseLocalOrigin(lo, hi);

    if (scene_.triangleCount() == 0)
        return Status::error("nothing to bake: the scene has no triangles (" + std::to_string(r.skippedNonTrianglePrimitives) +
                             " point/line primitive(s) and " + std::to_string(r.skippedDegenerateTriangles) +
                             " degenerate triangle(s) skipped)");
    return Status::ok();
}

}  // namespace

Expected<Scene> loadScene(const std::string& path, const LoadOptions& options) {
    auto fail = [&](const std::string& what) { return Expected<Scene>::failure(oneLine(path + ": " + what, 600)); };

    // read the file ourselves: clearer errors than tinygltf's for missing files
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (!std::filesystem::exists(status)) return fail("file not found");
    if (std::filesystem::is_directory(status)) return fail("is a directory, not a glTF file");
    std::ifstream in(path, std::ios::binary);
    if (!in) return fail(std::string("cannot open file (") + std::strerror(errno) + ")");
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) return fail("cannot read file");
    return loadSceneFromMemory(std::move(bytes), path, std::filesystem::path(path).parent_path().string(), options);
}

Expected<Scene> loadSceneFromMemory(std::vector<unsigned char> bytes, const std::string& path, const std::string& baseDir,
                                    const LoadOptions& options) {
    auto fail = [&](const std::string& what) { return Expected<Scene>::failure(oneLine(path + ": " + what, 600)); };
    if (bytes.size() > std::numeric_limits<unsigned int>::max()) return fail("file is larger than 4 GiB");

    const std::filesystem::path fsPath(path);
    std::string extension = fsPath.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    const bool binary = extension == ".glb" || (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0);

    if (binary && bytes.size() >= 12 && std::memcmp(bytes.data(), "glTF", 4) == 0) {
        uint32_t container = 0, declared = 0;
        std::memcpy(&container, bytes.data() + 4, 4);  // little-endian, as the host
        std::memcpy(&declared, bytes.data() + 8, 4);
        if (container != 2)
            return fail("glTF binary container version " + std::to_string(container) + " (" +
                        (container == 1 ? std::string("glTF 1.0, KHR_binary_glTF") : std::string("unknown")) +
                        ") is not supported: bundlebake reads glTF 2.0 only");
        if (declared > bytes.size())
            return fail("not a valid glTF binary (.glb): truncated, the header says " + std::to_string(declared) +
                        " bytes but the file has " + std::to_string(bytes.size()));
    }

    tinygltf::TinyGLTF gltf;
    gltf.SetImageLoader(&keepEncodedImage, nullptr);
    if (!options.externalFiles) {
        tinygltf::FsCallbacks noFiles = {};
        noFiles.FileExists = [](const std::string&, void*) { return false; };
        noFiles.ExpandFilePath = [](const std::string& path, void*) { return path; };
        noFiles.ReadWholeFile = [](std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
            if (err) *err += "external file '" + path + "' not read (external files are off)\n";
            return false;
        };
        noFiles.WriteWholeFile = [](std::string*, const std::string&, const std::vector<unsigned char>&, void*) { return false; };
        gltf.SetFsCallbacks(noFiles);
    }
    tinygltf::Model model;
    std::string err, warn;
    bool ok = false;
    try {
        if (binary) {
            ok = gltf.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), static_cast<unsigned int>(bytes.size()), baseDir);
        } else {
            ok = gltf.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                          static_cast<unsigned int>(bytes.size()), baseDir);
        }
    } catch (const std::exception& e) {
        ok = false;
        err = e.what();
    }
    if (!ok) {
        // a glTF 1.0 file usually fails tinygltf's 2.0 schema first: say why instead
        if (Status v = checkAssetVersion(assetOf(bytes, binary)); !v) return fail(v.message());
        return fail(std::string(binary ? "not a valid glTF binary (.glb): " : "not a valid glTF file: ") +
                    (err.empty() ? "unknown error" : err));
    }
    {
        nlohmann::json asset = {{"version", model.asset.version}};
        if (!model.asset.minVersion.empty()) asset["minVersion"] = model.asset.minVersion;
        if (Status v = checkAssetVersion(asset); !v) return fail(v.message());
    }
    bytes.clear();
    bytes.shrink_to_fit();

    Scene scene;
    scene.path = path;
    SceneBuilder builder(model, options, scene);
    Status built = Status::ok();
    try {
        built = builder.build();
    } catch (const std::bad_alloc&) {
        built = Status::error("out of memory while converting the scene");
    }
    if (!built) return fail(built.message());
    // warnings only for a file that loads: a refused one gives its one error line alone
    if (!warn.empty()) logWarning(oneLine(path + ": tinygltf: " + warn));
    for (const std::string& w : builder.warnings()) logWarning(w);
    return Expected<Scene>(std::move(scene));
}

}  // namespace bb
