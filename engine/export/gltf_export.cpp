// Based on: the glTF 2.0 specification (Khronos, 2021), sections 3.6 (buffers,
// accessors: 4-byte alignment, POSITION min/max), 3.7 (meshes) and 3.8
// (texture data: PNG and JPEG only, which is why the EXR is a side file).
#include "export/gltf_export.h"

#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "bake/bake_output.h"
#include "io/stb_codec.h"
#include "io/image_io.h"
#include "render/scene_renderer.h"

namespace bb {

namespace {

constexpr int GL_FLOAT_ = 5126;
constexpr int GL_UNSIGNED_INT_ = 5125;
constexpr int GL_ARRAY_BUFFER_ = 34962;
constexpr int GL_ELEMENT_ARRAY_BUFFER_ = 34963;
constexpr int GL_LINEAR_ = 9729;
constexpr int GL_CLAMP_TO_EDGE_ = 33071;

const char* LIGHTMAP_UNITS = "L_lm = E/pi (irradiance over pi), scene radiance units; lit colour = baseColor * L_lm + emission";
const char* RGBM_DECODE =
    "L_lm = rgb * a * range * scale, with rgb and a the PNG's bytes / 255 (linear: no sRGB transfer); "
    "row 0 of the image is v = 0 of TEXCOORD_1 (glTF convention)";

// tinygltf image callback: keep the encoded bytes (they are embedded as they are).
bool keepEncodedBytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
    image->image.assign(bytes, bytes + size);
    image->width = -1;
    image->height = -1;
    image->as_is = true;
    return true;
}

std::string mimeOf(const std::vector<unsigned char>& bytes, const std::string& declared) {
    if (bytes.size() >= 8 && std::memcmp(bytes.data(), "\x89PNG", 4) == 0) return "image/png";
    if (bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF) return "image/jpeg";
    if (bytes.size() >= 12 && std::memcmp(bytes.data(), "\xABKTX 20", 7) == 0) return "image/ktx2";
    if (bytes.size() >= 12 && std::memcmp(bytes.data(), "RIFF", 4) == 0 && std::memcmp(bytes.data() + 8, "WEBP", 4) == 0)
        return "image/webp";
    return declared;
}

// The binary chunk being built: 4-byte aligned views.
struct BinBuilder {
    tinygltf::Model& model;
    std::vector<unsigned char>& data;

    int addView(const void* bytes, size_t size, int target) {
        while (data.size() % 4 != 0) data.push_back(0);
        tinygltf::BufferView view;
        view.buffer = 0;
        view.byteOffset = data.size();
        view.byteLength = size;
        view.target = target;
        const auto* p = static_cast<const unsigned char*>(bytes);
        data.insert(data.end(), p, p + size);
        model.bufferViews.push_back(view);
        return int(model.bufferViews.size()) - 1;
    }
    template <class V>
    int addFloatAccessor(const std::vector<V>& values, int type, bool withBounds) {
        constexpr int components = sizeof(V) / sizeof(float);
        tinygltf::Accessor a;
        a.bufferView = addView(values.data(), values.size() * sizeof(V), GL_ARRAY_BUFFER_);
        a.componentType = GL_FLOAT_;
        a.type = type;
        a.count = values.size();
        if (withBounds && !values.empty()) {
            a.minValues.assign(components, 0.0);
            a.maxValues.assign(components, 0.0);
            for (int c = 0; c < components; ++c) {
                float lo = values[0][c], hi = values[0][c];
                for (const V& v : values) lo = std::min(lo, v[c]), hi = std::max(hi, v[c]);
                a.minValues[size_t(c)] = double(lo);
                a.maxValues[size_t(c)] = double(hi);
            }
        }
        model.accessors.push_back(a);
        return int(model.accessors.size()) - 1;
    }
    int addIndexAccessor(const std::vector<uint32_t>& indices) {
        tinygltf::Accessor a;
        a.bufferView = addView(indices.data(), indices.size() * 4, GL_ELEMENT_ARRAY_BUFFER_);
        a.componentType = GL_UNSIGNED_INT_;
        a.type = TINYGLTF_TYPE_SCALAR;
        a.count = indices.size();
        model.accessors.push_back(a);
        return int(model.accessors.size()) - 1;
    }
};

bool isTriangleMode(int mode) {
    const int m = mode < 0 ? TINYGLTF_MODE_TRIANGLES : mode;
    return m == TINYGLTF_MODE_TRIANGLES || m == TINYGLTF_MODE_TRIANGLE_STRIP || m == TINYGLTF_MODE_TRIANGLE_FAN;
}

// The texture coordinates the loader reads as uv0 for a material: the base
// colour texture's (set and KHR_texture_transform), else the emissive one's.
struct UvChoice {
    int texCoord = 0;
    std::string transform;  // the KHR_texture_transform object serialised, "" = none
    bool operator==(const UvChoice&) const = default;
};

std::string serialise(const tinygltf::Value& v);

std::string serialise(const tinygltf::Value& v) {
    if (v.IsObject()) {
        std::string s = "{";
        for (const std::string& k : v.Keys()) s += k + ":" + serialise(v.Get(k)) + ",";
        return s + "}";
    }
    if (v.IsArray()) {
        std::string s = "[";
        for (size_t i = 0; i < v.ArrayLen(); ++i) s += serialise(v.Get(int(i))) + ",";
        return s + "]";
    }
    if (v.IsNumber()) return std::to_string(v.GetNumberAsDouble());
    if (v.IsString()) return v.Get<std::string>();
    if (v.IsBool()) return v.Get<bool>() ? "true" : "false";
    return "null";
}

template <class Info>
UvChoice uvOf(const Info& info) {
    UvChoice c;
    c.texCoord = std::max(info.texCoord, 0);
    auto it = info.extensions.find("KHR_texture_transform");
    if (it != info.extensions.end()) c.transform = serialise(it->second);
    return c;
}

// Every texture of the material samples the exported TEXCOORD_0 (the loader's
// uv0, transform applied): texCoord 0, no KHR_texture_transform. Returns
// false when a texture used other coordinates than the chosen ones.
template <class Info>
bool rebaseTexture(Info& info, const UvChoice& chosen) {
    if (info.index < 0) return true;
    const bool same = uvOf(info) == chosen;
    info.texCoord = 0;
    info.extensions.erase("KHR_texture_transform");
    return same;
}

tinygltf::Value numberValue(double v) { return tinygltf::Value(v); }
tinygltf::Value numberValue(int v) { return tinygltf::Value(v); }
tinygltf::Value numberValue(size_t v) { return tinygltf::Value(int(v)); }
tinygltf::Value stringValue(const std::string& s) { return tinygltf::Value(s); }

// The glb's JSON chunk (or a .gltf's text) and its binary chunk.
struct GlbParts {
    nlohmann::json json;
    std::vector<uint8_t> bin;
};

Expected<GlbParts> readGlbParts(const std::string& path) {
    using Fail = Expected<GlbParts>;
    std::ifstream in(path, std::ios::binary);
    if (!in) return Fail::failure(path + ": cannot open file");
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    GlbParts parts;
    try {
        if (bytes.size() >= 20 && std::memcmp(bytes.data(), "glTF", 4) == 0) {
            uint32_t jsonLength = 0, jsonType = 0;
            std::memcpy(&jsonLength, bytes.data() + 12, 4);
            std::memcpy(&jsonType, bytes.data() + 16, 4);
            if (jsonType != 0x4E4F534Au || size_t(jsonLength) + 20 > bytes.size())
                return Fail::failure(path + ": malformed glb JSON chunk");
            parts.json = nlohmann::json::parse(bytes.begin() + 20, bytes.begin() + 20 + jsonLength);
            size_t at = 20 + size_t(jsonLength);
            if (at + 8 <= bytes.size()) {
                uint32_t binLength = 0, binType = 0;
                std::memcpy(&binLength, bytes.data() + at, 4);
                std::memcpy(&binType, bytes.data() + at + 4, 4);
                if (binType == 0x004E4942u && at + 8 + binLength <= bytes.size())
                    parts.bin.assign(bytes.begin() + ptrdiff_t(at + 8), bytes.begin() + ptrdiff_t(at + 8 + binLength));
            }
        } else {
            parts.json = nlohmann::json::parse(bytes.begin(), bytes.end());
        }
    } catch (const nlohmann::json::exception& e) {
        return Fail::failure(path + ": not valid glTF JSON (" + std::string(e.what()) + ")");
    }
    return parts;
}

}  // namespace

float rgbmScale(const std::vector<glm::vec3>& pixels) {
    float peak = 0.0f;
    for (const glm::vec3& p : pixels)
        for (int c = 0; c < 3; ++c)
            if (std::isfinite(p[c])) peak = std::max(peak, p[c]);
    return peak > 0.0f ? peak / RGBM_RANGE : 1.0f;
}

std::vector<uint8_t> encodeRgbm(const std::vector<glm::vec3>& pixels, float scale) {
    std::vector<uint8_t> out(pixels.size() * 4);
    for (size_t i = 0; i < pixels.size(); ++i) {
        glm::vec3 x = pixels[i] / (scale * RGBM_RANGE);  // in [0, 1]
        for (int c = 0; c < 3; ++c) x[c] = std::isfinite(x[c]) ? std::clamp(x[c], 0.0f, 1.0f) : 0.0f;
        const float m = std::max(std::max(x.r, x.g), x.b);
        // the smallest multiplier that holds the largest channel, at least 1/255
        const int a = std::clamp(int(std::ceil(m * 255.0f - 1e-4f)), 1, 255);
        const float inv = 255.0f / float(a);
        for (int c = 0; c < 3; ++c)
            out[4 * i + size_t(c)] = uint8_t(std::clamp(std::lround(x[c] * inv * 255.0f), 0L, 255L));
        out[4 * i + 3] = uint8_t(a);
    }
    return out;
}

glm::vec3 decodeRgbm(const uint8_t* rgba, float scale) {
    const float k = float(rgba[3]) / 255.0f * RGBM_RANGE * scale / 255.0f;
    return glm::vec3(float(rgba[0]), float(rgba[1]), float(rgba[2])) * k;
}

Expected<ExportReport> exportBakedGltf(const std::string& sourcePath, const Scene& scene, const Layout& layout,
                                       const LightmapPages& maps, const std::string& outPath) {
    using Fail = Expected<ExportReport>;
    ExportReport report;
    if (layout.rects.size() != scene.instances.size())
        return Fail::failure("export: the layout has " + std::to_string(layout.rects.size()) + " rectangles for " +
                             std::to_string(scene.instances.size()) + " instances");
    if (int(maps.pages.size()) != layout.pageCount)
        return Fail::failure("export: " + std::to_string(maps.pages.size()) + " light map pages for a layout of " +
                             std::to_string(layout.pageCount));

    // the source, images kept encoded
    tinygltf::TinyGLTF gltf;
    gltf.SetImageLoader(&keepEncodedBytes, nullptr);
    tinygltf::Model src;
    std::string err, warn;
    std::string ext = std::filesystem::path(sourcePath).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    const bool ok = ext == ".glb" ? gltf.LoadBinaryFromFile(&src, &err, &warn, sourcePath)
                                  : gltf.LoadASCIIFromFile(&src, &err, &warn, sourcePath);
    if (!ok) return Fail::failure(sourcePath + ": " + (err.empty() ? std::string("cannot read") : err));

    tinygltf::Model out;
    std::vector<unsigned char> bin;
    BinBuilder builder{out, bin};
    out.asset.version = "2.0";
    out.asset.generator = "bundlebake export";
    out.asset.copyright = src.asset.copyright;
    out.asset.extras = src.asset.extras;

    // images: every source image embedded as it was encoded
    for (const tinygltf::Image& image : src.images) {
        tinygltf::Image copy;
        copy.name = image.name;
        copy.extras = image.extras;
        if (image.image.empty())
            return Fail::failure(sourcePath + ": image " + std::to_string(out.images.size()) + " (" + image.uri +
                                 ") could not be read, so it cannot be embedded");
        copy.mimeType = mimeOf(image.image, image.mimeType);
        if (copy.mimeType.empty())
            return Fail::failure(sourcePath + ": image " + std::to_string(out.images.size()) + " (" + image.uri +
                                 ") is of an unknown type");
        copy.bufferView = builder.addView(image.image.data(), image.image.size(), 0);
        out.images.push_back(std::move(copy));
    }
    out.samplers = src.samplers;
    out.textures = src.textures;
    out.cameras = src.cameras;
    out.lights = src.lights;
    out.scenes = src.scenes;
    out.defaultScene = src.defaultScene;
    out.extras = src.extras;

    // materials: the source's, every texture on the exported TEXCOORD_0
    std::set<std::string> otherUvMaterials;
    for (const tinygltf::Material& m : src.materials) {
        tinygltf::Material copy = m;
        UvChoice chosen;
        const tinygltf::TextureInfo& base = m.pbrMetallicRoughness.baseColorTexture;
        if (base.index >= 0) {
            chosen = uvOf(base);
        } else if (m.emissiveTexture.index >= 0) {
            chosen = uvOf(m.emissiveTexture);
        }
        bool same = rebaseTexture(copy.pbrMetallicRoughness.baseColorTexture, chosen);
        same &= rebaseTexture(copy.pbrMetallicRoughness.metallicRoughnessTexture, chosen);
        same &= rebaseTexture(copy.normalTexture, chosen);
        same &= rebaseTexture(copy.occlusionTexture, chosen);
        same &= rebaseTexture(copy.emissiveTexture, chosen);
        if (!same) otherUvMaterials.insert(m.name.empty() ? "material " + std::to_string(out.materials.size()) : m.name);
        out.materials.push_back(std::move(copy));
    }
    if (!otherUvMaterials.empty())
        report.warnings.push_back(std::to_string(otherUvMaterials.size()) + " material(s) (e.g. " +
                                  *otherUvMaterials.begin() +
                                  ") have textures on other texture coordinates than the base colour's: they sample "
                                  "the base colour's (bundlebake keeps one set)");
    // bundlebake's default material, for primitives without one (glTF's default is metallic: black)
    int defaultMaterial = -1;
    for (const Material& m : scene.materials)
        if (m.isDefault) {
            tinygltf::Material d;
            d.name = m.name;
            d.pbrMetallicRoughness.baseColorFactor = {m.albedo.r, m.albedo.g, m.albedo.b, 1.0};
            d.pbrMetallicRoughness.metallicFactor = 0.0;
            d.pbrMetallicRoughness.roughnessFactor = 1.0;
            d.doubleSided = m.doubleSided;
            defaultMaterial = int(out.materials.size());
            out.materials.push_back(d);
        }

    // light map pages: an RGBM PNG embedded with its texture, the EXR beside
    const std::filesystem::path outFs(outPath);
    const std::string stem = outFs.stem().string();
    const std::filesystem::path outDir = outFs.parent_path();
    int lightmapSampler = int(out.samplers.size());
    {
        tinygltf::Sampler s;
        s.name = "bundlebake light map";
        s.magFilter = GL_LINEAR_;
        s.minFilter = GL_LINEAR_;
        s.wrapS = GL_CLAMP_TO_EDGE_;
        s.wrapT = GL_CLAMP_TO_EDGE_;
        out.samplers.push_back(s);
    }
    std::vector<int> pageTexture, pageImage;
    std::vector<std::string> pageExr;
    tinygltf::Value::Array pagesJson;
    for (size_t p = 0; p < maps.pages.size(); ++p) {
        const io::ImageRgb& page = maps.pages[p];
        const float scale = rgbmScale(page.pixels);
        auto png = encodePngRgba(encodeRgbm(page.pixels, scale), page.width, page.height);
        if (!png) return png.status();
        tinygltf::Image image;
        image.name = "bundlebake light map " + std::to_string(p);
        image.mimeType = "image/png";
        image.bufferView = builder.addView(png->data(), png->size(), 0);
        out.images.push_back(std::move(image));
        tinygltf::Texture texture;
        texture.name = "bundlebake light map " + std::to_string(p);
        texture.source = int(out.images.size()) - 1;
        texture.sampler = lightmapSampler;
        out.textures.push_back(texture);
        const std::string exrName = stem + "." + lightmapFileName(int(p));
        const std::string exrPath = (outDir / exrName).string();
        if (Status s = io::writeExr(exrPath, page, {{"bundlebake:units", LIGHTMAP_UNITS}}); !s) return s;
        report.exrFiles.push_back(exrPath);
        report.pageScale.push_back(scale);
        pageTexture.push_back(int(out.textures.size()) - 1);
        pageImage.push_back(int(out.images.size()) - 1);
        pageExr.push_back(exrName);
        tinygltf::Value::Object pageJson;
        pageJson["page"] = numberValue(p);
        pageJson["texture"] = numberValue(pageTexture.back());
        pageJson["image"] = numberValue(pageImage.back());
        pageJson["scale"] = numberValue(double(scale));
        pageJson["exr"] = stringValue(exrName);
        pagesJson.emplace_back(pageJson);
    }

    // scene materials -> source materials, by pairing each instance's
    // primitives with its node's glTF primitives (the loader keeps the
    // triangle primitives that have a triangle left, in file order)
    std::map<int, int> materialOf;  // Scene material -> exported glTF material
    auto pairPrimitives = [&](const Instance& inst) -> Status {
        const tinygltf::Node& node = src.nodes[size_t(inst.node)];
        if (node.mesh < 0 || size_t(node.mesh) >= src.meshes.size())
            return Status::error("export: node " + std::to_string(inst.node) + " of " + sourcePath + " has no mesh");
        std::vector<int> candidates;
        for (size_t k = 0; k < src.meshes[size_t(node.mesh)].primitives.size(); ++k)
            if (isTriangleMode(src.meshes[size_t(node.mesh)].primitives[k].mode)) candidates.push_back(int(k));
        const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
        size_t c = 0;
        for (const Primitive& prim : mesh.primitives) {
            // a candidate whose material agrees with what is known (primitives
            // whose triangles were all degenerate were dropped by the loader)
            for (; c < candidates.size(); ++c) {
                const int gm = src.meshes[size_t(node.mesh)].primitives[size_t(candidates[c])].material;
                const int want = gm < 0 ? defaultMaterial : gm;
                auto known = materialOf.find(prim.material);
                const bool defaultAgrees = (gm < 0) == scene.materials[size_t(prim.material)].isDefault;
                if (defaultAgrees && (known == materialOf.end() || known->second == want)) break;
            }
            if (c == candidates.size())
                return Status::error("export: the primitives of " + inst.name + " do not match " + sourcePath +
                                     " (is the scene the one the bake was made of?)");
            const int gm = src.meshes[size_t(node.mesh)].primitives[size_t(candidates[c])].material;
            materialOf[prim.material] = gm < 0 ? defaultMaterial : gm;
            ++c;
        }
        return Status::ok();
    };

    // geometry per Scene mesh (once), TEXCOORD_1 per rectangle
    struct Geometry {
        std::vector<int> position, normal, uv0, indices;
    };
    std::map<int, Geometry> geometry;
    std::map<std::tuple<int, int, float, float, float, float>, int> meshFor;  // (mesh, page, scale, offset) -> glTF mesh
    std::vector<int> nodeMesh(src.nodes.size(), -1), nodePage(src.nodes.size(), -1);
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        const InstanceRect& rect = layout.rects[i];
        if (inst.node < 0 || size_t(inst.node) >= src.nodes.size())
            return Fail::failure("export: instance " + inst.name + " has no node in " + sourcePath);
        if (Status s = pairPrimitives(inst); !s) return s;
        const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
        if (!geometry.count(inst.mesh)) {
            Geometry g;
            for (const Primitive& prim : mesh.primitives) {
                g.position.push_back(builder.addFloatAccessor(prim.positions, TINYGLTF_TYPE_VEC3, true));
                g.normal.push_back(prim.normals.size() == prim.positions.size()
                                       ? builder.addFloatAccessor(prim.normals, TINYGLTF_TYPE_VEC3, false)
                                       : -1);
                // a textured material needs TEXCOORD_0: zeros where the file had none (as the renderer samples)
                const tinygltf::Material& m = out.materials[size_t(materialOf.at(prim.material))];
                const bool textured = m.pbrMetallicRoughness.baseColorTexture.index >= 0 ||
                                      m.pbrMetallicRoughness.metallicRoughnessTexture.index >= 0 ||
                                      m.normalTexture.index >= 0 || m.occlusionTexture.index >= 0 ||
                                      m.emissiveTexture.index >= 0;
                if (prim.uv0.size() == prim.positions.size())
                    g.uv0.push_back(builder.addFloatAccessor(prim.uv0, TINYGLTF_TYPE_VEC2, false));
                else if (textured)
                    g.uv0.push_back(builder.addFloatAccessor(std::vector<glm::vec2>(prim.positions.size(), glm::vec2(0.0f)),
                                                             TINYGLTF_TYPE_VEC2, false));
                else
                    g.uv0.push_back(-1);
                g.indices.push_back(builder.addIndexAccessor(prim.indices));
            }
            geometry[inst.mesh] = std::move(g);
            ++report.sharedGeometry;
        }
        const auto key = std::make_tuple(inst.mesh, rect.page, rect.scale.x, rect.scale.y, rect.offset.x, rect.offset.y);
        auto found = meshFor.find(key);
        if (found == meshFor.end()) {
            const Geometry& g = geometry.at(inst.mesh);
            tinygltf::Mesh gm;
            gm.name = mesh.name;
            for (size_t k = 0; k < mesh.primitives.size(); ++k) {
                const Primitive& prim = mesh.primitives[k];
                if (prim.uv1.size() != prim.positions.size())
                    return Fail::failure("export: " + mesh.name + " has no light map UVs (TEXCOORD_1) in the layout");
                std::vector<glm::vec2> uv1(prim.uv1.size());
                // as buildBakeMesh maps them: the same floats the bake used
                for (size_t v = 0; v < uv1.size(); ++v) uv1[v] = prim.uv1[v] * rect.scale + rect.offset;
                tinygltf::Primitive p;
                p.mode = TINYGLTF_MODE_TRIANGLES;
                p.material = materialOf.at(prim.material);
                p.indices = g.indices[k];
                p.attributes["POSITION"] = g.position[k];
                if (g.normal[k] >= 0) p.attributes["NORMAL"] = g.normal[k];
                const int uv1Accessor = builder.addFloatAccessor(uv1, TINYGLTF_TYPE_VEC2, false);
                // TEXCOORD_n must count up from 0: without TEXCOORD_0, the light map UVs stand in
                p.attributes["TEXCOORD_0"] = g.uv0[k] >= 0 ? g.uv0[k] : uv1Accessor;
                p.attributes["TEXCOORD_1"] = uv1Accessor;
                gm.primitives.push_back(std::move(p));
            }
            out.meshes.push_back(std::move(gm));
            found = meshFor.emplace(key, int(out.meshes.size()) - 1).first;
        }
        nodeMesh[size_t(inst.node)] = found->second;
        nodePage[size_t(inst.node)] = rect.page;
    }
    report.meshes = out.meshes.size();

    // nodes: the hierarchy as it was, meshes replaced, skins and weights dropped
    bool droppedSkins = false;
    for (size_t n = 0; n < src.nodes.size(); ++n) {
        tinygltf::Node node = src.nodes[n];
        node.mesh = nodeMesh[n];
        if (node.skin >= 0) droppedSkins = true;
        node.skin = -1;
        node.weights.clear();
        if (nodePage[n] >= 0) {
            const int p = nodePage[n];
            tinygltf::Value::Object extras = node.extras.IsObject() ? node.extras.Get<tinygltf::Value::Object>()
                                                                     : tinygltf::Value::Object{};
            tinygltf::Value::Object lm;
            lm["page"] = numberValue(p);
            lm["texture"] = numberValue(pageTexture[size_t(p)]);
            lm["texCoord"] = numberValue(1);
            lm["encoding"] = stringValue("RGBM");
            lm["rgbm_range"] = numberValue(double(RGBM_RANGE));
            lm["scale"] = numberValue(double(report.pageScale[size_t(p)]));
            lm["exr"] = stringValue(pageExr[size_t(p)]);
            extras["bundlebake_lightmap"] = tinygltf::Value(lm);
            node.extras = tinygltf::Value(extras);
        }
        out.nodes.push_back(std::move(node));
    }
    report.nodes = out.nodes.size();
    if (droppedSkins || !src.skins.empty()) report.warnings.push_back("skins are not exported (the rest pose was baked)");
    if (!src.animations.empty())
        report.warnings.push_back(std::to_string(src.animations.size()) + " animation(s) not exported");

    // the root's record of the light maps
    {
        tinygltf::Value::Object root = out.extras.IsObject() ? out.extras.Get<tinygltf::Value::Object>()
                                                             : tinygltf::Value::Object{};
        tinygltf::Value::Object lm;
        lm["units"] = stringValue(LIGHTMAP_UNITS);
        lm["layout"] = stringValue(layoutModeName(layout.mode));
        lm["resolution"] = numberValue(layout.resolution);
        lm["texCoord"] = numberValue(1);
        lm["encoding"] = stringValue("RGBM");
        lm["rgbm_range"] = numberValue(double(RGBM_RANGE));
        lm["decode"] = stringValue(RGBM_DECODE);
        lm["pages"] = tinygltf::Value(pagesJson);
        lm["auto_exposure_stops"] = numberValue(double(autoExposure(maps)));
        root["bundlebake_lightmaps"] = tinygltf::Value(lm);
        out.extras = tinygltf::Value(root);
    }

    // extensions: those still used (KHR_texture_transform no longer is;
    // tinygltf declares KHR_lights_punctual itself when there are lights)
    std::set<std::string> used;
    auto note = [&](const tinygltf::ExtensionMap& e) {
        for (const auto& [name, value] : e) used.insert(name);
    };
    for (const auto& m : out.materials) {
        note(m.extensions);
        note(m.pbrMetallicRoughness.baseColorTexture.extensions);
        note(m.pbrMetallicRoughness.metallicRoughnessTexture.extensions);
        note(m.normalTexture.extensions);
        note(m.occlusionTexture.extensions);
        note(m.emissiveTexture.extensions);
    }
    for (const auto& t : out.textures) note(t.extensions);
    for (const auto& n : out.nodes) note(n.extensions);
    for (const auto& s : out.samplers) note(s.extensions);
    for (const auto& c : out.cameras) note(c.extensions);
    for (const auto& s : out.scenes) note(s.extensions);
    used.erase("KHR_lights_punctual");
    for (const std::string& e : src.extensionsUsed)
        if (used.count(e)) out.extensionsUsed.push_back(e);
    for (const std::string& e : used)
        if (std::find(out.extensionsUsed.begin(), out.extensionsUsed.end(), e) == out.extensionsUsed.end())
            out.extensionsUsed.push_back(e);
    for (const std::string& e : src.extensionsRequired)
        if (used.count(e)) out.extensionsRequired.push_back(e);

    while (bin.size() % 4 != 0) bin.push_back(0);
    tinygltf::Buffer buffer;
    buffer.data = std::move(bin);
    out.buffers.push_back(std::move(buffer));

    std::ostringstream stream;
    if (!gltf.WriteGltfSceneToStream(&out, stream, false, true))
        return Fail::failure(outPath + ": tinygltf could not write the file");
    const std::string bytes = stream.str();
    report.bytes = bytes.size();
    report.images = out.images.size();
    if (Status s = io::writeFileAtomic(outPath, bytes); !s) return s;
    return report;
}

Expected<ExportedLightmaps> readExportedLightmaps(const std::string& path, const Scene& scene) {
    using Fail = Expected<ExportedLightmaps>;
    auto parts = readGlbParts(path);
    if (!parts) return parts.status();
    const nlohmann::json& j = parts->json;
    const char* hint = " (not written by `bundlebake export`: give the bake directory as well)";
    if (!j.contains("extras") || !j["extras"].contains("bundlebake_lightmaps"))
        return Fail::failure(path + ": no extras.bundlebake_lightmaps" + hint);
    try {
        const auto& lm = j["extras"]["bundlebake_lightmaps"];
        ExportedLightmaps out;
        out.autoExposureStops = lm.value("auto_exposure_stops", 0.0f);
        const int resolution = lm.at("resolution").get<int>();
        const auto& pages = lm.at("pages");
        if (resolution < 1 || pages.empty()) return Fail::failure(path + ": extras.bundlebake_lightmaps has no pages");
        Layout& layout = out.layout;
        layout.mode = UvLayout::Asset;  // TEXCOORD_1 is already in page space
        layout.resolution = resolution;
        layout.pageCount = int(pages.size());
        layout.padding = 0;
        for (const Instance& inst : scene.instances) {
            const auto& nodes = j.at("nodes");
            if (inst.node < 0 || size_t(inst.node) >= nodes.size() || !nodes[size_t(inst.node)].contains("extras") ||
                !nodes[size_t(inst.node)]["extras"].contains("bundlebake_lightmap"))
                return Fail::failure(path + ": node " + std::to_string(inst.node) + " (" + inst.name +
                                     ") has no extras.bundlebake_lightmap" + hint);
            InstanceRect r;
            r.page = nodes[size_t(inst.node)]["extras"]["bundlebake_lightmap"].at("page").get<int>();
            if (r.page < 0 || r.page >= layout.pageCount)
                return Fail::failure(path + ": node " + std::to_string(inst.node) + " is on page " +
                                     std::to_string(r.page) + " of " + std::to_string(layout.pageCount));
            r.width = r.height = resolution;
            layout.rects.push_back(r);
        }
        // the EXR side files when all are there, else the embedded RGBM PNGs
        const std::filesystem::path dir = std::filesystem::path(path).parent_path();
        bool allExr = true;
        for (const auto& p : pages)
            allExr = allExr && std::filesystem::exists(dir / p.at("exr").get<std::string>());
        out.source = allExr ? "exr" : "rgbm png";
        out.maps.resolution = resolution;
        for (const auto& p : pages) {
            io::ImageRgb image;
            if (allExr) {
                auto exr = io::readImageRgb((dir / p.at("exr").get<std::string>()).string());
                if (!exr) return exr.status();
                image = std::move(exr.value());
            } else {
                const int imageIndex = p.at("image").get<int>();
                const auto& img = j.at("images").at(size_t(imageIndex));
                const auto& view = j.at("bufferViews").at(img.at("bufferView").get<size_t>());
                const size_t offset = view.value("byteOffset", size_t(0)), length = view.at("byteLength").get<size_t>();
                if (offset + length > parts->bin.size())
                    return Fail::failure(path + ": light map image " + std::to_string(imageIndex) + " lies outside the binary chunk");
                auto decoded = decodeImageRgba(parts->bin.data() + offset, length);
                if (!decoded) return Fail::failure(path + ": light map image " + std::to_string(imageIndex) + ": " + decoded.error());
                const float scale = p.at("scale").get<float>();
                image.width = decoded->width;
                image.height = decoded->height;
                image.pixels.resize(size_t(image.width) * image.height);
                for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = decodeRgbm(&decoded->rgba[4 * i], scale);
            }
            if (image.width != resolution || image.height != resolution)
                return Fail::failure(path + ": a light map page is " + std::to_string(image.width) + "x" +
                                     std::to_string(image.height) + ", extras say " + std::to_string(resolution));
            std::vector<uint8_t> covered(image.pixels.size());
            for (size_t i = 0; i < covered.size(); ++i) covered[i] = image.pixels[i] != glm::vec3(0.0f);
            out.maps.pages.push_back(std::move(image));
            out.maps.covered.push_back(std::move(covered));
        }
        return out;
    } catch (const nlohmann::json::exception& e) {
        return Fail::failure(path + ": malformed extras.bundlebake_lightmaps (" + std::string(e.what()) + ")");
    }
}

}  // namespace bb
