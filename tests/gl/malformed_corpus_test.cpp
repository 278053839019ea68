// The malformed-input corpus (tests/corpus/, made by tests/corpus/make_corpus.py):
// every file, given to `bundlebake bake` where it belongs (the scene, --env,
// OUTDIR/checkpoint.bin with --resume), must end the program with exactly one
// line on stderr, "bundlebake: error: ...", a non-zero exit (not a signal),
// nothing on stdout and no output file. Runs the built CLI (BUNDLEBAKE_CLI).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "support/cli_helper.h"
#include "support/gl_fixture.h"

namespace bb::test {
namespace {

namespace fs = std::filesystem;

// At least this many inputs in all (issue 13): the corpus may grow, never shrink below.
constexpr size_t MIN_CORPUS_INPUTS = 40;

std::vector<fs::path> corpusFiles(const std::string& kind, const std::vector<std::string>& extensions) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(sourcePath("tests/corpus/" + kind), ec)) {
        if (!entry.is_regular_file()) continue;
        const std::string ext = entry.path().extension().string();
        if (std::find(extensions.begin(), extensions.end(), ext) != extensions.end()) files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

std::vector<std::string> filesUnder(const fs::path& dir) {
    std::vector<std::string> names;
    std::error_code ec;
    if (!fs::exists(dir, ec)) return names;
    for (auto it = fs::recursive_directory_iterator(dir, ec); it != fs::recursive_directory_iterator(); ++it)
        names.push_back(fs::relative(it->path(), dir).string());
    return names;
}

// One error line, non-zero exit (not a signal), nothing on stdout.
void expectRefusedInOneLine(const CliResult& r) {
    EXPECT_NE(r.exitCode, 0) << "accepted; stderr:\n" << r.err;
    EXPECT_NE(r.exitCode, -1) << "killed by a signal; stderr:\n" << r.err;
    const auto lines = r.errLines();
    ASSERT_EQ(lines.size(), 1u) << "expected exactly one line on stderr, got:\n" << r.err;
    EXPECT_EQ(lines[0].rfind("bundlebake: error:", 0), 0u) << lines[0];
    EXPECT_TRUE(r.out.empty()) << "stdout: " << r.out;
}

// A small, fast bake (if an input were accepted, it would finish quickly).
std::vector<std::string> bakeArgs(const std::string& scene, const std::string& out) {
    return {"bake", scene, "-o", out, "--backend", "osmesa", "--directions", "4", "--resolution", "16", "--no-progress"};
}

size_t checkScenes(const std::string& kind) {
    const auto files = corpusFiles(kind, {".gltf", ".glb"});
    for (const fs::path& file : files) {
        SCOPED_TRACE(kind + "/" + file.filename().string());
        TempDir tmp("corpus-" + kind);
        if (!tmp.ok()) {
            ADD_FAILURE() << "cannot make a temp dir";
            break;
        }
        CliResult r = runCli(bakeArgs(file.string(), tmp / "out"), tmp);
        expectRefusedInOneLine(r);
        EXPECT_NE(r.err.find(file.filename().string()), std::string::npos) << "the error should name the file: " << r.err;
        EXPECT_TRUE(filesUnder(tmp.path() / "out").empty()) << "output written for bad input";
        std::printf("[corpus] %s/%s: %s", kind.c_str(), file.filename().c_str(), r.err.c_str());
    }
    return files.size();
}

TEST(MalformedCorpus, GltfAndGlbScenes) {
    const size_t n = checkScenes("gltf");
    EXPECT_GE(n, 30u);
}

TEST(MalformedCorpus, SceneTextures) {
    const size_t n = checkScenes("texture");
    EXPECT_GE(n, 5u);
}

TEST(MalformedCorpus, EnvironmentMaps) {
    const auto files = corpusFiles("env", {".exr", ".hdr"});
    for (const fs::path& file : files) {
        SCOPED_TRACE("env/" + file.filename().string());
        TempDir tmp("corpus-env");
        ASSERT_TRUE(tmp.ok());
        auto args = bakeArgs(sourcePath("assets/furnace/furnace.gltf"), tmp / "out");
        args.insert(args.end(), {"--env", file.string()});
        CliResult r = runCli(args, tmp);
        expectRefusedInOneLine(r);
        EXPECT_NE(r.err.find(file.filename().string()), std::string::npos) << "the error should name the file: " << r.err;
        EXPECT_TRUE(filesUnder(tmp.path() / "out").empty()) << "output written for bad input";
        std::printf("[corpus] env/%s: %s", file.filename().c_str(), r.err.c_str());
    }
    EXPECT_GE(files.size(), 5u);
}

TEST(MalformedCorpus, Checkpoints) {
    const auto files = corpusFiles("checkpoint", {".bin"});
    for (const fs::path& file : files) {
        SCOPED_TRACE("checkpoint/" + file.filename().string());
        TempDir tmp("corpus-checkpoint");
        ASSERT_TRUE(tmp.ok());
        fs::create_directories(tmp.path() / "out");
        const fs::path checkpoint = tmp.path() / "out" / "checkpoint.bin";
        fs::copy_file(file, checkpoint);
        const std::string before = readFileBytes(checkpoint);
        auto args = bakeArgs(sourcePath("assets/furnace/furnace.gltf"), tmp / "out");
        args.insert(args.end(), {"--uv-layout", "asset", "--resume"});
        CliResult r = runCli(args, tmp);
        expectRefusedInOneLine(r);
        EXPECT_NE(r.err.find("checkpoint"), std::string::npos) << r.err;
        EXPECT_EQ(filesUnder(tmp.path() / "out"), std::vector<std::string>{"checkpoint.bin"})
            << "only the checkpoint may be in OUTDIR";
        EXPECT_TRUE(readFileBytes(checkpoint) == before) << "the checkpoint was changed";
        std::printf("[corpus] checkpoint/%s: %s", file.filename().c_str(), r.err.c_str());
    }
    EXPECT_GE(files.size(), 5u);
}

TEST(MalformedCorpus, HoldsAtLeastFortyInputs) {
    const size_t n = corpusFiles("gltf", {".gltf", ".glb"}).size() + corpusFiles("texture", {".gltf", ".glb"}).size() +
                     corpusFiles("env", {".exr", ".hdr"}).size() + corpusFiles("checkpoint", {".bin"}).size();
    std::printf("[corpus] %zu malformed inputs\n", n);
    EXPECT_GE(n, MIN_CORPUS_INPUTS);
}

}  // namespace
}  // namespace bb::test
