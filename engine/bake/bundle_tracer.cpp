#include "bake/bundle_tracer.h"

#include <algorithm>
#include <cmath>

#include "bake/rounding.h"
#include "core/check.h"
#include "core/timer.h"
#include "gl/gl.h"
#include "gl/shader.h"
#include "glsl/shared/bundle_layout.h"
#include "glsl/shared/material_layout.h"

namespace bb {

void setFrameUniforms(GLuint program, const TileFrame& f) {
    glUniform3fv(glGetUniformLocation(program, "bundleDir"), 1, &f.d.x);
    glUniform3fv(glGetUniformLocation(program, "bundleU"), 1, &f.u.x);
    glUniform3fv(glGetUniformLocation(program, "bundleV"), 1, &f.v.x);
    glUniform2fv(glGetUniformLocation(program, "rootOrigin"), 1, &f.rootOrigin.x);
    glUniform1f(glGetUniformLocation(program, "rootSize"), f.rootSize);
    glUniform2f(glGetUniformLocation(program, "leafMin"), float(f.leaf.min.x), float(f.leaf.min.y));
    glUniform1f(glGetUniformLocation(program, "leafExtent"), float(f.leaf.extent));
    glUniform1i(glGetUniformLocation(program, "leafPixels"), f.leaf.pixels);
    glUniform1f(glGetUniformLocation(program, "pixelSize"), f.pixelSize);
    // head image pixel p is the leaf's pixel p + tileOffset
    const glm::ivec2 o = f.headOrigin;
    glUniform2i(glGetUniformLocation(program, "tileOffset"), f.drawn.x - o.x, f.drawn.y - o.y);
    glUniform4i(glGetUniformLocation(program, "drawnPixels"), o.x, o.y, o.x + f.drawn.width, o.y + f.drawn.height);
    glUniform4i(glGetUniformLocation(program, "ownedPixels"), f.window.x - f.drawn.x + o.x, f.window.y - f.drawn.y + o.y,
                f.window.x - f.drawn.x + o.x + f.window.width, f.window.y - f.drawn.y + o.y + f.window.height);
}

Expected<std::unique_ptr<BundleTracer>> BundleTracer::create(const BundleScene& scene, const BundleLimits& limits,
                                                             const std::string& defines, BakeStats* stats) {
    std::unique_ptr<BundleTracer> t(new BundleTracer());
    if (Status drawable = checkMeshDrawable(int64_t(scene.mesh->triangleCount())); !drawable) return drawable;
    auto program = gl::buildProgram({"bundle/append.vert", "bundle/append.frag"}, defines);
    if (!program) return program.status();
    t->append_ = std::move(program.value());
    t->scene_ = scene;
    t->limits_ = limits;
    t->stats_ = stats;
    t->chunks_ = MeshChunks::create(int64_t(scene.mesh->triangleCount()),
                                    {{MESH_BINDING_TRIANGLES, scene.triangleBuffer, int64_t(sizeof(BakeTriangle))},
                                     {BINDING_VERTICES, scene.vertexBuffer, 3 * int64_t(sizeof(BakeVertex))}});
    // nodes appended, and those of the tile's own pixels (not its apron's)
    t->counter_ = gl::Buffer::create("bundle node counters", 8, nullptr, GL_DYNAMIC_STORAGE_BIT);
    t->ensureNodes(limits.predict ? std::min<int64_t>(limits.nodeCapacity, 1 << 16) : limits.nodeCapacity);
    t->ensureHeads(64);
    t->fbo_ = gl::Framebuffer::create("bundle framebuffer (no attachments)");
    glNamedFramebufferParameteri(t->fbo_.id(), GL_FRAMEBUFFER_DEFAULT_WIDTH, limits.maxTileSize);
    glNamedFramebufferParameteri(t->fbo_.id(), GL_FRAMEBUFFER_DEFAULT_HEIGHT, limits.maxTileSize);
    return t;
}

void BundleTracer::ensureNodes(int64_t nodes) {
    nodes = std::min(nodes, limits_.nodeCapacity);
    if (nodes <= nodeAllocated_) return;
    // grow by at least half, so a run of growing tiles reallocates a few times only
    nodes = std::min(std::max(nodes, nodeAllocated_ + nodeAllocated_ / 2), limits_.nodeCapacity);
    nodes_ = gl::Buffer();  // free first: the budget is for one buffer
    nodes_ = gl::Buffer::create("bundle nodes", nodes * int64_t(sizeof(shared::Node)), nullptr, 0);
    nodeAllocated_ = nodes;
    stats_->nodeBufferBytes = std::max<int64_t>(stats_->nodeBufferBytes, nodes_.bytes());
}

void BundleTracer::ensureHeads(int side) {
    if (side <= headSide_) return;
    int s = 64;
    while (s < side) s *= 2;
    s = std::min(s, limits_.maxTileSize);
    heads_ = gl::Texture();
    heads_ = gl::Texture::create2D("bundle head pointers", GL_R32UI, s, s);
    headSide_ = s;
    stats_->headImageBytes = std::max<int64_t>(stats_->headImageBytes, heads_.bytes());
}

void BundleTracer::drawClusters(GLuint program, const std::vector<uint32_t>& ids, bool receiversOnly) {
    // the update pass draws only triangles with texel centres (receivers first in each cluster);
    // int32 vertex ranges hold: create() checked the mesh against GLint firsts
    clusterRanges(*scene_.clusters, ids, drawFirst_, drawCount_, receiversOnly);
    chunks_.multiDrawArrays(program, drawFirst_, drawCount_);
    int64_t triangles = 0;
    for (int32_t c : drawCount_) triangles += c / 3;
    if (recordStats_) (receiversOnly ? stats_->updateTrianglesDrawn : stats_->bundleTrianglesDrawn) += triangles;
}

void BundleTracer::setCurvedTexels(std::vector<uint32_t> clusterFirst, std::function<void(GLuint)> bind) {
    curvedClusterFirst_ = std::move(clusterFirst);
    bindCurvedTexels_ = std::move(bind);
}

void BundleTracer::drawCurvedTexels(GLuint program, const std::vector<uint32_t>& ids) {
    if (curvedClusterFirst_.empty()) return;
    drawFirst_.clear();
    drawCount_.clear();
    for (uint32_t c : ids)
        appendDrawRange(drawFirst_, drawCount_, int32_t(curvedClusterFirst_[c]),
                        int32_t(curvedClusterFirst_[c + 1] - curvedClusterFirst_[c]));
    if (drawFirst_.empty()) return;
    bindCurvedTexels_(program);
    drawCurvedTexelRuns(program, scene_.pageResolution, drawFirst_, drawCount_);
    glBindVertexArray(scene_.vertexArray);
}

void drawCurvedTexelRuns(GLuint program, int res, const std::vector<int32_t>& first, const std::vector<int32_t>& count) {
    const GLint firstUniform = glGetUniformLocation(program, "curvedFirst");
    const GLint countUniform = glGetUniformLocation(program, "curvedCount");
    glUniform1ui(glGetUniformLocation(program, "curvedRowWidth"), uint32_t(res));
    const uint32_t most = uint32_t(res) * uint32_t(res);  // what one viewport holds
    for (size_t k = 0; k < first.size(); ++k)
        for (uint32_t done = 0; done < uint32_t(count[k]); done += most) {
            glUniform1ui(firstUniform, uint32_t(first[k]) + done);
            glUniform1ui(countUniform, std::min(uint32_t(count[k]) - done, most));
            glDrawArrays(GL_TRIANGLES, 0, 6);
        }
}

// At most this many leaves a run: each update fragment looks its leaf up in
// the run's table (update.frag takeLeaf), and each tile added to a run packs
// the run's leaves again.
constexpr size_t kMostLeavesInARun = 64;

void BundleTracer::planGroups() {
    const std::vector<Tile>& tiles = tiling_.tiles;
    const auto nodesFor = [](double predicted) { return int64_t(std::ceil(1.25 * predicted)) + 1024; };
    // the open run: tiles [first, i), their predicted nodes, their leaves' sides and places
    size_t first = 0;
    double predicted = 0;
    std::vector<int> sides;
    std::vector<glm::ivec2> origins;
    int side = 0;
    const auto close = [&](size_t end) {
        if (end - first >= 2) {  // one tile alone is updated as before
            Group g;
            g.nodes = nodesFor(predicted);
            g.side = side;
            for (size_t k = first; k < end; ++k) {
                const int leaf = tiles[k].leaf;
                const BundleLeaf& l = tiling_.leaves[size_t(leaf)];
                const glm::ivec2 o = origins[k - first];
                leafGroup_[size_t(leaf)] = int(groups_.size());
                leafOrigin_[size_t(leaf)] = o;
                g.records.push_back({float(l.min.x), float(l.min.y), float(l.extent), l.pixels,
                                     float(tiling_.pixelSize(leaf)), o.x, o.y, 0});
            }
            groups_.push_back(std::move(g));
        }
        first = end;
        predicted = 0;
        sides.clear();
        origins.clear();
    };
    for (size_t i = 0; i < tiles.size(); ++i) {
        const Tile& t = tiles[i];
        const int pixels = tiling_.leaves[size_t(t.leaf)].pixels;
        if (t.window.x != 0 || t.window.y != 0 || t.window.width != pixels || t.window.height != pixels) {
            close(i);  // a leaf the budget cut: its tiles alone
            first = i + 1;
            continue;
        }
        for (int pass = 0; pass < 2; ++pass) {  // into the open run, or (if it does not fit there) a new one
            sides.push_back(pixels);
            std::vector<glm::ivec2> placed;
            int placedSide = 0;
            if (sides.size() <= kMostLeavesInARun && nodesFor(predicted + t.predictedNodes) <= limits_.nodeCapacity)
                placed = packSquares(sides, limits_.maxTileSize, placedSide);
            if (!placed.empty()) {
                origins = std::move(placed);
                side = placedSide;
                predicted += t.predictedNodes;
                break;
            }
            sides.pop_back();
            close(i);
            if (pass == 1) first = i + 1;  // too large for a run of its own: alone
        }
    }
    close(tiles.size());
}

void BundleTracer::begin(const BundleFrame& frame, const TilerOptions& options, uint32_t seed, bool recordStats,
                         bool leafRuns) {
    auto t0 = Clock::now();
    frame_ = frame;
    options_ = options;
    seed_ = seed;
    recordStats_ = recordStats;
    views_ = projectClusters(*scene_.mesh, *scene_.clusters, frame);
    tiling_ = tileBundle(*scene_.clusters, views_, frame.size, options);
    work_.assign(tiling_.tiles.rbegin(), tiling_.tiles.rend());
    tiles_ = 0;
    clearRun();
    leafGroup_.assign(tiling_.leaves.size(), -1);
    leafOrigin_.assign(tiling_.leaves.size(), glm::ivec2(0));
    groups_.clear();
    if (leafRuns) planGroups();
    if (recordStats) {
        stats_->secondsTiling += secondsSince(t0);
        stats_->leavesPerDirection.push_back(int(tiling_.leaves.size()));
        if (work_.empty()) stats_->tilesPerDirection.push_back(0);
    }
}

void BundleTracer::run(const BundleFrame& frame, const TilerOptions& options, uint32_t seed, bool recordStats,
                       const UpdateFn& update, bool leafRuns) {
    begin(frame, options, seed, recordStats, leafRuns);
    while (!done()) next(update);
}

void BundleTracer::next(const UpdateFn& update) {
    CHECK(!work_.empty());
    Tile tile = std::move(work_.back());
    work_.pop_back();
    TileFrame f;
    f.d = frame_.dir;
    f.u = frame_.u;
    f.v = frame_.v;
    f.rootOrigin = glm::vec2(frame_.origin);
    f.rootSize = float(frame_.size);
    f.leaf = tiling_.leaves[size_t(tile.leaf)];
    f.window = tile.window;
    f.drawn = drawnWindow(tile.window, f.leaf.pixels);
    f.pixelSize = float(tiling_.pixelSize(tile.leaf));
    // whole leaves of a run updated at once (planGroups) share the buffers: the counts are the run's so far
    const int group = leafGroup_[size_t(tile.leaf)];
    const bool firstOfRun = group < 0 || groupTiles_.empty();
    if (group >= 0) {
        f.headOrigin = leafOrigin_[size_t(tile.leaf)];
        if (firstOfRun) {
            const Group& g = groups_[size_t(group)];
            if (limits_.predict) ensureNodes(g.nodes);
            ensureHeads(g.side);
            const int64_t bytes = int64_t(g.records.size() * sizeof(shared::LeafRecord));
            if (leafTable_.bytes() < bytes)
                leafTable_ = gl::Buffer::create("bundle leaf table", std::max<int64_t>(bytes, 4096), nullptr,
                                                GL_DYNAMIC_STORAGE_BIT);
            glNamedBufferSubData(leafTable_.id(), 0, bytes, g.records.data());
        }
    } else {
        // buffers sized from the prediction (a quarter of margin), within the budget
        if (limits_.predict) ensureNodes(int64_t(std::ceil(1.25 * tile.predictedNodes)) + 1024);
        ensureHeads(std::max(f.drawn.width, f.drawn.height));
    }

    // what both passes read (the mesh's SSBOs: per chunk, in drawClusters)
    glBindVertexArray(scene_.vertexArray);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_NODES, nodes_.id());
    if (scene_.materialAlpha) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_MATERIAL_ALPHA, scene_.materialAlpha);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_ALPHA_TEXELS, scene_.alphaTexels);
    }

    auto tb = Clock::now();
    drawBundle(tile, f, firstOfRun);
    uint32_t counts[2] = {0, 0};
    glGetNamedBufferSubData(counter_.id(), 0, 8, counts);
    const uint32_t count = counts[0];
    lastCount_ = count;
    ++tiles_;
    if (recordStats_) {
        stats_->secondsBundle += secondsSince(tb);
        ++stats_->tilesDrawn;
    }
    if (int64_t(count) > nodeAllocated_) {
        // overflow: nothing is used from this draw.
        if (recordStats_) ++stats_->overflows;
        if (group >= 0) {  // nothing of the run updated yet: its tiles again, each alone
            std::replace(leafGroup_.begin(), leafGroup_.end(), group, -1);
            work_.push_back(std::move(tile));
            for (auto it = groupTiles_.rbegin(); it != groupTiles_.rend(); ++it) work_.push_back(std::move(*it));
            clearRun();
            return;
        }
        // Redraw into a buffer of the measured size if the budget holds it, else in four quarters.
        if (int64_t(count) <= limits_.nodeCapacity && limits_.predict) {
            ensureNodes(int64_t(count));
            work_.push_back(std::move(tile));
        } else {
            CHECK(tile.window.width > 1 || tile.window.height > 1);
            auto quarters = splitWindow(tile.window);
            for (auto it = quarters.rbegin(); it != quarters.rend(); ++it)
                work_.push_back(makeTile(tiling_, tile.leaf, *it, *scene_.clusters, views_, tile.clusters, options_.cull));
        }
        return;
    }
    const uint32_t before = firstOfRun ? 0u : drawnNodes_, ownedBefore = firstOfRun ? 0u : drawnOwned_;
    drawnTiles_.push_back({tile.predictedNodes, count - before, counts[1] - ownedBefore, f.pixelSize});
    drawnNodes_ = count;
    drawnOwned_ = counts[1];
    if (group >= 0) {
        groupTiles_.push_back(std::move(tile));
        if (groupTiles_.size() < groups_[size_t(group)].records.size()) return;  // the update follows the run's last tile
        f.leafRun = true;
    }
    if (recordStats_) {
        for (const DrawnTile& t : drawnTiles_) {
            stats_->fragments += t.owned;  // each once, whichever tile owns it
            if (t.nodes > 0) stats_->predictedOverActual.push_back(t.predicted / t.nodes);
            stats_->tilePixelSizes.push_back(t.pixelSize);
        }
        stats_->peakNodesPerTile = std::max<int64_t>(stats_->peakNodesPerTile, count);  // what the buffer held
        stats_->leafRunUpdates += f.leafRun;
    }
    if (count > 0) {
        if (f.leafRun) {  // the run's receivers, each cluster once
            std::vector<uint32_t> clusters;
            for (const Tile& t : groupTiles_) clusters.insert(clusters.end(), t.clusters.begin(), t.clusters.end());
            std::sort(clusters.begin(), clusters.end());
            clusters.erase(std::unique(clusters.begin(), clusters.end()), clusters.end());
            runUpdate(update, f, count, clusters);
        } else {
            runUpdate(update, f, count, tile.clusters);
        }
    }
    clearRun();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (recordStats_ && work_.empty()) stats_->tilesPerDirection.push_back(tiles_);
}

void BundleTracer::drawBundle(const Tile& tile, const TileFrame& f, bool resetCounter) {
    gl::DebugGroup group("bundle pass");
    // per direction and leaf, never per tile: tiles change with the budget, the bits must not
    const uint32_t leafSeed = pcgHash(seed_ ^ pcgHash(uint32_t(tile.leaf) * 7919u + 17u));
    const uint32_t endOfList = END_OF_LIST, zero[2] = {0, 0};
    glClearTexSubImage(heads_.id(), 0, f.headOrigin.x, f.headOrigin.y, 0, f.drawn.width, f.drawn.height, 1,
                       GL_RED_INTEGER, GL_UNSIGNED_INT, &endOfList);
    if (resetCounter) glNamedBufferSubData(counter_.id(), 0, 8, zero);
    glUseProgram(append_.id());
    setFrameUniforms(append_.id(), f);
    glUniform1ui(append_.uniform("nodeCapacity"), uint32_t(nodeAllocated_));
    glUniform1ui(append_.uniform("randomSeed"), leafSeed);
    glUniform1i(append_.uniform("backLayerOffset"), scene_.backLayerOffset);
    // the leaf's grid in a power-of-two viewport (glsl/bundle/append.vert) shifted so the
    // drawn window (the tile and its apron) lands at its place in the head image; the scissor keeps the rest out
    int viewportPixels = 1;
    while (viewportPixels < f.leaf.pixels) viewportPixels *= 2;
    glUniform1i(append_.uniform("viewportPixels"), viewportPixels);
    glUniform1f(append_.uniform("subpixelSteps"), float(1 << limits_.subpixelBits));
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
    glViewport(f.headOrigin.x - f.drawn.x, f.headOrigin.y - f.drawn.y, viewportPixels, viewportPixels);
    glEnable(GL_SCISSOR_TEST);
    glScissor(f.headOrigin.x, f.headOrigin.y, f.drawn.width, f.drawn.height);
    glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, BINDING_NODE_COUNTER, counter_.id());
    glBindImageTexture(BINDING_HEADS, heads_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glBindTextureUnit(BINDING_RADIANCE, scene_.radiance);
    glBindTextureUnit(BINDING_READ_MODES, scene_.readModes);
    glBindTextureUnit(BINDING_TEXEL_CHARTS, scene_.texelCharts);
    glBindTextureUnit(BINDING_SLOPES, scene_.slopes);
    glUniform1i(append_.uniform("slopesInside"), scene_.slopes != 0);
    drawClusters(append_.id(), tile.clusters, false);
    glDisable(GL_SCISSOR_TEST);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_ATOMIC_COUNTER_BARRIER_BIT |
                    GL_BUFFER_UPDATE_BARRIER_BIT);
}

void BundleTracer::runUpdate(const UpdateFn& update, const TileFrame& f, uint32_t nodeCount,
                             const std::vector<uint32_t>& clusters) {
    auto tu = Clock::now();
    gl::DebugGroup group("update pass");
    glBindFramebuffer(GL_FRAMEBUFFER, scene_.pageFramebuffer);
    glViewport(0, 0, scene_.pageResolution, scene_.pageResolution);
    const UpdatePrograms programs = update(f, nodeCount);
    glBindImageTexture(BINDING_HEADS, heads_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
    if (f.leafRun) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_LEAF_TABLE, leafTable_.id());
    // the two draws update disjoint texels (update.frag leaves curved ones to the second)
    for (GLuint program : {programs.triangles, programs.curved}) {
        if (!program) continue;
        glUseProgram(program);
        setFrameUniforms(program, f);
        glUniform1ui(glGetUniformLocation(program, "nodeCount"), nodeCount);
        if (f.leafRun)
            glUniform1i(glGetUniformLocation(program, "leafCount"), int(groupTiles_.size()));  // the run's leaves
        if (program == programs.triangles)
            drawClusters(program, clusters, true);
        else
            drawCurvedTexels(program, clusters);
    }
    if (programs.triangles || programs.curved)
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    if (recordStats_) {
        glFinish();
        stats_->secondsUpdate += secondsSince(tu);
    }
}

}  // namespace bb
