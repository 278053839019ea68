// The scene view: bake mesh + material textures + light map pages, drawn
// through a camera with the bake's display transform. See scene_renderer.h.
#include "layout/bake_mesh_gl.h"
#include "render/scene_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <fstream>
#include <numeric>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "core/check.h"
#include "gl/gl.h"
#include "gl/objects.h"
#include "gl/shader.h"

namespace bb {
namespace {

float srgbOetf(float linear) {
    return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

float srgbEotf(float encoded) {
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

uint8_t toByte(float encoded) { return uint8_t(std::floor(std::clamp(encoded, 0.0f, 1.0f) * 255.0f + 0.5f)); }

// Farthest distance from `eye` to a corner of `bounds`.
float farDistance(const glm::vec3& eye, const Bounds& bounds) {
    if (bounds.empty()) return 1.0f;
    float far = 0.0f;
    for (int k = 0; k < 8; ++k) {
        glm::vec3 corner((k & 1) ? bounds.max.x : bounds.min.x, (k & 2) ? bounds.max.y : bounds.min.y,
                         (k & 4) ? bounds.max.z : bounds.min.z);
        far = std::max(far, glm::length(corner - eye));
    }
    return far;
}

// A sampler object (bilinear, clamped) for the light map array, owned here:
// the live texture belongs to the Baker, whose state we do not touch.
struct Sampler {
    GLuint name = 0;
    Sampler() = default;
    Sampler(const Sampler&) = delete;
    Sampler& operator=(const Sampler&) = delete;
    ~Sampler() {
        if (name) glDeleteSamplers(1, &name);
    }
};

}  // namespace

// --- free functions ---------------------------------------------------------

const char* viewModeName(ViewMode mode) {
    switch (mode) {
    case ViewMode::Lit: return "lit";
    case ViewMode::Lightmap: return "lightmap";
    case ViewMode::Albedo: return "albedo";
    case ViewMode::Importance: return "importance";
    case ViewMode::TexelDensity: return "density";
    }
    return "?";
}

Expected<ViewMode> parseViewMode(const std::string& name) {
    for (int m = 0; m < VIEW_MODE_COUNT; ++m)
        if (name == viewModeName(ViewMode(m))) return ViewMode(m);
    return Expected<ViewMode>::failure("unknown view mode '" + name +
                                       "' (expected lit, lightmap, albedo, importance or density)");
}

RenderView viewFromCamera(const Camera& camera, float aspect, const Bounds& bounds) {
    // the camera frame without scale: eye, -Z forward, +Y up
    const glm::vec3 eye(camera.worldFromCamera[3]);
    glm::vec3 forward = -glm::vec3(camera.worldFromCamera[2]);
    glm::vec3 up = glm::vec3(camera.worldFromCamera[1]);
    forward = glm::length(forward) > 0 ? glm::normalize(forward) : glm::vec3(0, 0, -1);
    up = glm::length(up) > 0 ? glm::normalize(up) : glm::vec3(0, 1, 0);
    RenderView view;
    view.eye = eye;
    view.viewFromWorld = glm::lookAt(eye, eye + forward, up);
    aspect = aspect > 0 && std::isfinite(aspect) ? aspect : 1.0f;
    const float znear = camera.znear > 0 ? camera.znear : 1e-3f;
    float zfar = camera.zfar > znear ? camera.zfar : farDistance(eye, bounds) * 1.05f;
    zfar = std::max(zfar, znear * 2.0f);
    if (camera.perspective) {
        view.clipFromView = glm::perspective(camera.yfov > 0 ? camera.yfov : 0.8f, aspect, znear, zfar);
    } else {
        const float ymag = camera.ymag > 0 ? camera.ymag : 1.0f;
        view.clipFromView = glm::ortho(-ymag * aspect, ymag * aspect, -ymag, ymag, znear, zfar);
    }
    return view;
}

Camera cameraInLocalSpace(const Camera& camera, const glm::dvec3& origin) {
    Camera local = camera;
    const glm::dvec3 eye = glm::dvec3(camera.worldFromCamera[3]) - origin;
    local.worldFromCamera[3] = glm::vec4(glm::vec3(eye), camera.worldFromCamera[3].w);
    return local;
}

Camera framingCamera(const Bounds& bounds, const glm::vec3& forwardIn, float yfov, float aspect) {
    const glm::vec3 center = bounds.empty() ? glm::vec3(0.0f) : bounds.center();
    const float radius = std::max(0.5f * glm::length(bounds.size()), 1e-4f);
    const glm::vec3 forward = glm::length(forwardIn) > 0 ? glm::normalize(forwardIn) : glm::vec3(0, 0, -1);
    aspect = aspect > 0 && std::isfinite(aspect) ? aspect : 1.0f;
    const float xfov = 2.0f * std::atan(std::tan(0.5f * yfov) * aspect);
    const float fov = std::min(yfov, xfov);
    const float distance = radius / std::sin(0.5f * fov);
    const glm::vec3 eye = center - forward * distance;
    const glm::vec3 up = std::abs(forward.y) > 0.999f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
    Camera camera;
    camera.name = "framing";
    camera.worldFromCamera = glm::inverse(glm::lookAt(eye, center, up));
    camera.perspective = true;
    camera.yfov = yfov;
    camera.znear = std::max(distance - radius, distance * 1e-3f) * 0.5f;
    camera.zfar = 0.0f;
    return camera;
}

float autoExposure(const LightmapPages& maps) {
    std::vector<float> lum;
    for (size_t p = 0; p < maps.pages.size(); ++p)
        for (size_t i = 0; i < maps.pages[p].pixels.size(); ++i) {
            const bool covered = p < maps.covered.size() ? maps.covered[p][i] != 0 : true;
            const glm::vec3& c = maps.pages[p].pixels[i];
            const float y = 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
            if (covered && y > 0.0f && std::isfinite(y)) lum.push_back(y);
        }
    if (lum.empty()) return 0.0f;
    auto q = lum.begin() + std::ptrdiff_t(lum.size() * 3 / 4);
    std::nth_element(lum.begin(), q, lum.end());
    return *q > 0.0f ? std::log2(0.6f / *q) : 0.0f;
}

Expected<LightmapPages> readBakedLightmaps(const std::string& dir, const Layout& layout) {
    using Fail = Expected<LightmapPages>;
    const std::string manifestPath = dir + "/manifest.json";
    std::ifstream file(manifestPath);
    if (!file) return Fail::failure("cannot read " + manifestPath + ": not a bundlebake light map directory");
    nlohmann::json manifest;
    try {
        file >> manifest;
    } catch (const nlohmann::json::exception& e) {
        return Fail::failure(manifestPath + ": not valid JSON");
    }
    const char* hint = " (render with the --uv-layout, --resolution and --texel-density of the bake)";
    try {
        const int resolution = manifest.at("resolution").get<int>();
        const auto& pages = manifest.at("pages");
        const auto& instances = manifest.at("instances");
        if (resolution != layout.resolution)
            return Fail::failure(manifestPath + ": pages are " + std::to_string(resolution) + " texels, the layout's " +
                                 std::to_string(layout.resolution) + hint);
        if (int(pages.size()) != layout.pageCount)
            return Fail::failure(manifestPath + ": " + std::to_string(pages.size()) + " pages, the layout has " +
                                 std::to_string(layout.pageCount) + hint);
        if (instances.size() != layout.rects.size())
            return Fail::failure(manifestPath + ": " + std::to_string(instances.size()) + " instances, the scene has " +
                                 std::to_string(layout.rects.size()) + " (another scene?)");
        for (size_t i = 0; i < instances.size(); ++i) {
            const auto& inst = instances[i];
            const InstanceRect& r = layout.rects[i];
            const glm::vec2 scale(inst.at("uv1_scale")[0].get<float>(), inst.at("uv1_scale")[1].get<float>());
            const glm::vec2 offset(inst.at("uv1_offset")[0].get<float>(), inst.at("uv1_offset")[1].get<float>());
            const float tolerance = 0.25f / float(layout.resolution);  // a quarter texel
            if (inst.at("page").get<int>() != r.page || glm::any(glm::greaterThan(glm::abs(scale - r.scale), glm::vec2(tolerance))) ||
                glm::any(glm::greaterThan(glm::abs(offset - r.offset), glm::vec2(tolerance))))
                return Fail::failure(manifestPath + ": instance " + std::to_string(i) + " (" +
                                     inst.value("name", std::string("?")) + ") has another light map rectangle" + hint);
        }
        LightmapPages maps;
        maps.resolution = resolution;
        for (size_t p = 0; p < pages.size(); ++p) {
            auto image = io::readImageRgb(dir + "/" + pages[p].at("exr").get<std::string>());
            if (!image) return image.status();
            if (image->width != resolution || image->height != resolution)
                return Fail::failure(dir + "/" + pages[p].at("exr").get<std::string>() + ": " +
                                     std::to_string(image->width) + "x" + std::to_string(image->height) +
                                     " texels, the manifest says " + std::to_string(resolution));
            std::vector<uint8_t> covered(image->pixels.size(), 0);
            std::string coverage = pages[p].value("coverage_png", std::string());
            auto mask = coverage.empty() ? Expected<io::ImageRgb>::failure("none") : io::readImageRgb(dir + "/" + coverage);
            if (mask && mask->pixels.size() == covered.size()) {
                for (size_t i = 0; i < covered.size(); ++i) covered[i] = mask->pixels[i].r > 0.5f;
            } else {
                for (size_t i = 0; i < covered.size(); ++i) covered[i] = image->pixels[i] != glm::vec3(0.0f);
            }
            maps.pages.push_back(std::move(image.value()));
            maps.covered.push_back(std::move(covered));
        }
        return maps;
    } catch (const nlohmann::json::exception& e) {
        return Fail::failure(manifestPath + ": missing or malformed field (" + std::string(e.what()) + ")");
    }
}

Status writeImagePng(const std::string& path, const Image8& image) {
    // through linear floats: writePng re-encodes with the same OETF and rounds
    // to nearest, which gives every byte back exactly (|error| << 0.5/255)
    io::ImageRgb linear;
    linear.width = image.width;
    linear.height = image.height;
    linear.pixels.resize(size_t(image.width) * image.height);
    for (size_t i = 0; i < linear.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) linear.pixels[i][c] = srgbEotf(image.rgb[3 * i + size_t(c)] / 255.0f);
    return io::writePng(path, linear, true);
}

Expected<Image8> readImage8(const std::string& path) {
    auto linear = io::readImageRgb(path);
    if (!linear) return linear.status();
    Image8 out;
    out.width = linear->width;
    out.height = linear->height;
    out.rgb.resize(linear->pixels.size() * 3);
    for (size_t i = 0; i < linear->pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) out.rgb[3 * i + size_t(c)] = toByte(srgbOetf(linear->pixels[i][c]));
    return out;
}

// --- renderer ---------------------------------------------------------------

struct SceneRenderer::Impl {
    struct MaterialRun {
        uint32_t material = 0;
        uint32_t first = 0;  // index into the index buffer
        uint32_t count = 0;  // indices
        int chunk = 0;       // of `chunks`: a material's triangles are cut into runs at chunk boundaries
    };
    std::vector<Material> materials;
    std::vector<MaterialRun> runs;
    size_t triangleCount = 0;
    int lightmapResolution = 0;

    gl::Buffer vertexBuffer, triangleBuffer, indexBuffer, importanceBuffer, dummyBuffer;
    gl::VertexArray vao;
    MeshChunks chunks;  // triangles (binding 1), importance (binding 2, once set), bound per chunk
    gl::Program program;
    std::vector<gl::Texture> textures;  // Scene::textures, sRGB8 mipmapped
    gl::Texture ownedLightmap, dummyLightmap, dummyTexture;
    GLuint lightmapTexture = 0;         // owned or borrowed
    Sampler lightmapSampler;
    bool importanceReady = false;
    glm::vec2 importanceLogRange{0.0f, 1.0f};
    std::optional<Baker::BundleGrid> grid;

    gl::Framebuffer fbo;
    gl::Texture colorTarget, depthTarget;
};

SceneRenderer::SceneRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SceneRenderer::~SceneRenderer() = default;

Expected<std::unique_ptr<SceneRenderer>> SceneRenderer::create(const Scene& scene, const BakeMesh& mesh,
                                                               int lightmapResolution) {
    if (Status drawable = checkMeshDrawable(int64_t(mesh.triangleCount())); !drawable) return drawable;
    auto m = std::make_unique<Impl>();
    m->materials = scene.materials;
    m->triangleCount = mesh.triangleCount();
    m->lightmapResolution = lightmapResolution;
    auto program = gl::buildProgram({"render/lit.vert", "render/lit.frag"});
    if (!program) return program.status();
    m->program = std::move(program.value());

    // mesh: the bake vertices as they are, indices sorted by material (one draw per material)
    CHECK(!mesh.vertices.empty());
    m->vertexBuffer = gl::Buffer::create("render vertices", int64_t(mesh.vertices.size() * sizeof(BakeVertex)),
                                         mesh.vertices.data(), 0);
    m->triangleBuffer = gl::Buffer::create("render triangles", int64_t(mesh.triangles.size() * sizeof(BakeTriangle)),
                                           mesh.triangles.data(), 0);
    std::vector<uint32_t> order(mesh.triangles.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return mesh.triangles[a].material < mesh.triangles[b].material; });
    std::vector<uint32_t> indices;
    indices.reserve(order.size() * 3);
    // the per-triangle SSBOs in chunks of GL_MAX_SHADER_STORAGE_BLOCK_SIZE; a
    // material's triangles ascend (stable sort), so its run cuts at chunk boundaries
    m->chunks = MeshChunks::create(int64_t(mesh.triangleCount()),
                                   {{MESH_BINDING_TRIANGLES, m->triangleBuffer.id(), int64_t(sizeof(BakeTriangle))},
                                    {2, 0, int64_t(sizeof(float))}});  // importance: setImportance
    for (size_t begin = 0; begin < order.size();) {
        const uint32_t material = mesh.triangles[order[begin]].material;
        size_t end = begin;
        while (end < order.size() && mesh.triangles[order[end]].material == material) ++end;
        m->chunks.forEachPiece(std::span<const uint32_t>(order).subspan(begin, end - begin),
                               [&](int chunk, size_t b, size_t e) {
                                   m->runs.push_back({material, uint32_t(3 * (begin + b)), uint32_t(3 * (e - b)), chunk});
                               });
        begin = end;
    }
    for (uint32_t t : order)
        for (uint32_t k = 0; k < 3; ++k) indices.push_back(t * 3 + k);
    m->indexBuffer = gl::Buffer::create("render indices", int64_t(indices.size() * 4), indices.data(), 0);
    m->vao = createBakeVertexArray("render vertex array", m->vertexBuffer);
    glVertexArrayElementBuffer(m->vao.id(), m->indexBuffer.id());

    // material textures: linear floats back to sRGB bytes (the glTF's own
    // encoding), decoded by GL: half the memory of the baker's RGBA16F copies
    for (const Texture& t : scene.textures) {
        const int levels = 1 + int(std::floor(std::log2(std::max(t.width, t.height))));
        gl::Texture tex = gl::Texture::create2DLevels("render texture " + t.name, GL_SRGB8_ALPHA8, t.width, t.height, levels);
        std::vector<uint8_t> bytes(t.texels.size() * 4);
        for (size_t i = 0; i < t.texels.size(); ++i) {
            for (int c = 0; c < 3; ++c) bytes[4 * i + size_t(c)] = toByte(srgbOetf(std::max(t.texels[i][c], 0.0f)));
            bytes[4 * i + 3] = toByte(t.texels[i].a);
        }
        glTextureSubImage2D(tex.id(), 0, 0, 0, t.width, t.height, GL_RGBA, GL_UNSIGNED_BYTE, bytes.data());
        glGenerateTextureMipmap(tex.id());
        glTextureParameteri(tex.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTextureParameteri(tex.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTextureParameteri(tex.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
        glTextureParameteri(tex.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
        m->textures.push_back(std::move(tex));
    }

    // placeholders bound where nothing is set, so every declared binding is valid
    const float zero4[4] = {0, 0, 0, 0};
    m->dummyBuffer = gl::Buffer::create("render placeholder importance", 16, zero4, 0);
    m->dummyLightmap = gl::Texture::create2DArray("render placeholder light map", GL_RGBA32F, 1, 1, 1);
    glClearTexImage(m->dummyLightmap.id(), 0, GL_RGBA, GL_FLOAT, zero4);
    m->dummyTexture = gl::Texture::create2D("render placeholder texture", GL_RGBA8, 1, 1);
    const uint8_t white[4] = {255, 255, 255, 255};
    glClearTexImage(m->dummyTexture.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, white);

    glCreateSamplers(1, &m->lightmapSampler.name);
    glSamplerParameteri(m->lightmapSampler.name, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glSamplerParameteri(m->lightmapSampler.name, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glSamplerParameteri(m->lightmapSampler.name, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glSamplerParameteri(m->lightmapSampler.name, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glObjectLabel(GL_SAMPLER, m->lightmapSampler.name, -1, "render light map sampler");
    return std::unique_ptr<SceneRenderer>(new SceneRenderer(std::move(m)));
}

void SceneRenderer::useLightmapTexture(uint32_t texture) {
    impl_->ownedLightmap.reset();
    impl_->lightmapTexture = texture;
}

void SceneRenderer::uploadLightmaps(const LightmapPages& maps) {
    Impl& m = *impl_;
    if (maps.pages.empty()) {
        useLightmapTexture(0);
        return;
    }
    const int res = maps.pages[0].width;
    m.ownedLightmap = gl::Texture::create2DArray("render light maps", GL_RGBA32F, res, maps.pages[0].height,
                                                 int(maps.pages.size()));
    for (size_t p = 0; p < maps.pages.size(); ++p) {
        const io::ImageRgb& page = maps.pages[p];
        CHECK_EQ(page.width, m.ownedLightmap.width);
        CHECK_EQ(page.height, m.ownedLightmap.height);
        std::vector<glm::vec4> rgba(page.pixels.size());
        for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = glm::vec4(page.pixels[i], 1.0f);
        glTextureSubImage3D(m.ownedLightmap.id(), 0, 0, 0, GLint(p), page.width, page.height, 1, GL_RGBA, GL_FLOAT,
                            rgba.data());
    }
    m.lightmapTexture = m.ownedLightmap.id();
}

LightmapPages SceneRenderer::readLightmaps() const {
    const Impl& m = *impl_;
    LightmapPages out;
    if (!m.lightmapTexture) return out;
    GLint w = 0, h = 0, layers = 0;
    glGetTextureLevelParameteriv(m.lightmapTexture, 0, GL_TEXTURE_WIDTH, &w);
    glGetTextureLevelParameteriv(m.lightmapTexture, 0, GL_TEXTURE_HEIGHT, &h);
    glGetTextureLevelParameteriv(m.lightmapTexture, 0, GL_TEXTURE_DEPTH, &layers);
    if (w <= 0 || h <= 0 || layers <= 0) return out;
    std::vector<glm::vec4> texels(size_t(w) * h * layers);
    gl::readTexture(m.lightmapTexture, 0, 0, 0, w, h, layers, GL_RGBA, GL_FLOAT, 16, texels.data());
    out.resolution = w;
    for (int p = 0; p < layers; ++p) {
        io::ImageRgb page;
        page.width = w;
        page.height = h;
        page.pixels.resize(size_t(w) * h);
        std::vector<uint8_t> covered(page.pixels.size());
        for (size_t i = 0; i < page.pixels.size(); ++i) {
            const glm::vec4& t = texels[size_t(p) * w * h + i];
            page.pixels[i] = glm::vec3(t);
            covered[i] = t.a > 0.0f && glm::vec3(t) != glm::vec3(0.0f);
        }
        out.pages.push_back(std::move(page));
        out.covered.push_back(std::move(covered));
    }
    return out;
}

Status SceneRenderer::setImportance(std::span<const float> perTriangle) {
    Impl& m = *impl_;
    if (perTriangle.empty()) {
        m.importanceBuffer.reset();
        m.chunks.setBuffer(1, 0);
        m.importanceReady = false;
        return Status::ok();
    }
    if (perTriangle.size() != m.triangleCount)
        return Status::error("importance has " + std::to_string(perTriangle.size()) + " values for " +
                             std::to_string(m.triangleCount) + " triangles");
    float lo = INFINITY, hi = -INFINITY;
    for (float i : perTriangle)
        if (i > 0.0f && std::isfinite(i)) lo = std::min(lo, std::log2(i)), hi = std::max(hi, std::log2(i));
    // at least 4 stops across the ramp, so nearly uniform densities read as uniform
    const float mid = lo <= hi ? 0.5f * (lo + hi) : 0.0f, half = lo <= hi ? std::max(0.5f * (hi - lo), 2.0f) : 2.0f;
    m.importanceLogRange = glm::vec2(mid - half, mid + half);
    m.importanceBuffer = gl::Buffer::create("render importance", int64_t(perTriangle.size() * sizeof(float)),
                                            perTriangle.data(), 0);
    m.chunks.setBuffer(1, m.importanceBuffer.id());
    m.importanceReady = true;
    return Status::ok();
}

bool SceneRenderer::hasImportance() const { return impl_->importanceReady; }

void SceneRenderer::setBundleGrid(const std::optional<Baker::BundleGrid>& grid) { impl_->grid = grid; }

void SceneRenderer::draw(const RenderView& view, const RenderSettings& settings, uint32_t framebuffer, int width,
                         int height) {
    Impl& m = *impl_;
    gl::DebugGroup group("scene view");
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glViewport(0, 0, width, height);
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glFrontFace(GL_CCW);
    glCullFace(GL_BACK);

    const float scale = std::exp2(settings.exposure);
    glClearColor(settings.background.r, settings.background.g, settings.background.b, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

    const GLuint p = m.program.id();
    glUseProgram(p);
    const glm::mat4 clipFromWorld = view.clipFromView * view.viewFromWorld;
    glUniformMatrix4fv(m.program.uniform("clipFromWorld"), 1, GL_FALSE, &clipFromWorld[0][0]);
    ViewMode mode = settings.mode;
    if (mode == ViewMode::Importance && !m.importanceReady) mode = ViewMode::Lit;
    glUniform1i(m.program.uniform("viewMode"), int(mode));
    glUniform1f(m.program.uniform("exposureScale"), scale);
    glUniform1i(m.program.uniform("hasLightmap"), m.lightmapTexture != 0);
    glUniform1i(m.program.uniform("lightmapResolution"), m.lightmapResolution);
    glUniform2fv(m.program.uniform("importanceLogRange"), 1, &m.importanceLogRange.x);
    const bool overlay = settings.tileOverlay && m.grid.has_value();
    glUniform1i(m.program.uniform("tileOverlay"), overlay);
    if (overlay) {
        const Baker::BundleGrid& g = *m.grid;
        glUniform3fv(m.program.uniform("bundleU"), 1, &g.u.x);
        glUniform3fv(m.program.uniform("bundleV"), 1, &g.v.x);
        glUniform2fv(m.program.uniform("bundleOrigin"), 1, &g.origin.x);
        glUniform1f(m.program.uniform("bundlePixelSize"), g.pixelSize);
        glUniform1i(m.program.uniform("bundleGridSize"), g.gridSize);
        glUniform1i(m.program.uniform("bundleTileStep"), g.tileStep);
    }

    glBindVertexArray(m.vao.id());
    // the mesh's SSBOs: per chunk, below (importance: the placeholder until setImportance)
    if (!m.importanceReady) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, m.dummyBuffer.id());
    glBindTextureUnit(0, m.lightmapTexture ? m.lightmapTexture : m.dummyLightmap.id());
    glBindSampler(0, m.lightmapSampler.name);

    const GLint albedoLoc = m.program.uniform("albedo"), emissionLoc = m.program.uniform("emission");
    const GLint hasAlbedoLoc = m.program.uniform("hasAlbedoTexture"), hasEmissionLoc = m.program.uniform("hasEmissionTexture");
    int boundChunk = -1;
    for (const Impl::MaterialRun& run : m.runs) {
        if (run.chunk != boundChunk) m.chunks.bind(boundChunk = run.chunk, p);
        const Material& mat = m.materials[run.material];
        if (mat.doubleSided)
            glDisable(GL_CULL_FACE);
        else
            glEnable(GL_CULL_FACE);
        glUniform3fv(albedoLoc, 1, &mat.albedo.x);
        glUniform3fv(emissionLoc, 1, &mat.emission.x);
        const bool hasAlbedo = mat.albedoTexture >= 0 && size_t(mat.albedoTexture) < m.textures.size();
        const bool hasEmission = mat.emissionTexture >= 0 && size_t(mat.emissionTexture) < m.textures.size();
        glUniform1i(hasAlbedoLoc, hasAlbedo);
        glUniform1i(hasEmissionLoc, hasEmission);
        glBindTextureUnit(1, hasAlbedo ? m.textures[size_t(mat.albedoTexture)].id() : m.dummyTexture.id());
        glBindTextureUnit(2, hasEmission ? m.textures[size_t(mat.emissionTexture)].id() : m.dummyTexture.id());
        glDrawElements(GL_TRIANGLES, GLsizei(run.count), GL_UNSIGNED_INT,
                       reinterpret_cast<const void*>(uintptr_t(int64_t(run.first) * int64_t(sizeof(uint32_t)))));
    }

    // the state the Baker assumes (it sets it once at creation)
    glBindSampler(0, 0);
    glDisable(GL_CULL_FACE);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

Image8 SceneRenderer::renderImage(const RenderView& view, const RenderSettings& settings, int width, int height) {
    Impl& m = *impl_;
    CHECK_GT(width, 0);
    CHECK_GT(height, 0);
    if (!m.fbo || m.colorTarget.width != width || m.colorTarget.height != height) {
        m.fbo = gl::Framebuffer::create("render target");
        m.colorTarget = gl::Texture::create2D("render colour", GL_RGBA8, width, height);
        m.depthTarget = gl::Texture::create2D("render depth", GL_DEPTH_COMPONENT24, width, height);
        glNamedFramebufferTexture(m.fbo.id(), GL_COLOR_ATTACHMENT0, m.colorTarget.id(), 0);
        glNamedFramebufferTexture(m.fbo.id(), GL_DEPTH_ATTACHMENT, m.depthTarget.id(), 0);
        glNamedFramebufferDrawBuffer(m.fbo.id(), GL_COLOR_ATTACHMENT0);
        CHECK_EQ(glCheckNamedFramebufferStatus(m.fbo.id(), GL_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
    }
    draw(view, settings, m.fbo.id(), width, height);
    std::vector<uint8_t> rgba(size_t(width) * height * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(m.colorTarget.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, GLsizei(rgba.size()), rgba.data());
    Image8 image;
    image.width = width;
    image.height = height;
    image.rgb.resize(size_t(width) * height * 3);
    for (int y = 0; y < height; ++y) {
        const uint8_t* src = &rgba[size_t(height - 1 - y) * width * 4];  // GL row 0 is the bottom
        uint8_t* dst = &image.rgb[size_t(y) * width * 3];
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c) dst[3 * x + c] = src[4 * x + c];
    }
    return image;
}

}  // namespace bb
