// `bundlebake bake --seams stitch|off` (bake/seam_stitch.h) on living_room
// (no TEXCOORD_1: light map UVs generated; 17 smooth seams at 256 texels):
// stitch (the default) reports the seams in stats.json with the seam RMS
// lower after than before, and writes the same bytes twice; off reports
// nothing, records the choice in stats.json's settings, and writes other light maps.
// `bundlebake reference --seams` stitches the same seams.
#include <gtest/gtest.h>

#include <cstdio>

#include <nlohmann/json.hpp>

#include "support/cli_helper.h"
#include "support/gl_fixture.h"

namespace bb::test {
namespace {

std::vector<std::string> bakeArgs(const std::string& out) {
    return {"bake", sourcePath("assets/shared/living_room/living_room.glb"), "-o", out, "--backend", "osmesa",
            "--sky", "1,1,1", "--resolution", "256", "--directions", "16", "--no-preview", "--no-progress"};
}

nlohmann::json readJson(const std::string& path) { return nlohmann::json::parse(readFileBytes(path)); }

TEST(CliSeams, StitchReportsSeamsAndIsDeterministicOffLeavesThem) {
    TempDir tmp("seams");
    ASSERT_TRUE(tmp.ok());
    const CliResult a = runCli(bakeArgs(tmp / "a"), tmp);
    ASSERT_EQ(a.exitCode, 0) << a.err;
    const CliResult b = runCli(bakeArgs(tmp / "b"), tmp);
    ASSERT_EQ(b.exitCode, 0) << b.err;
    std::vector<std::string> offArgs = bakeArgs(tmp / "off");
    offArgs.insert(offArgs.end(), {"--seams", "off"});
    const CliResult off = runCli(offArgs, tmp);
    ASSERT_EQ(off.exitCode, 0) << off.err;

    const nlohmann::json stats = readJson(tmp / "a/stats.json");
    ASSERT_TRUE(stats.contains("seams")) << stats.dump();
    const nlohmann::json& s = stats["seams"];
    std::printf("[cli seams] %s\n", s.dump().c_str());
    EXPECT_TRUE(s["solved"].get<bool>());
    EXPECT_GT(s["seam_edges"].get<int>(), 0);
    EXPECT_GT(s["hard_edges"].get<int>(), 0);  // the room's corners and the furniture's edges
    EXPECT_GT(s["sample_pairs"].get<int>(), 0);
    EXPECT_GT(s["texels_adjusted"].get<int>(), 0);
    EXPECT_LT(s["rms_after"].get<double>(), 0.25 * s["rms_before"].get<double>());
    EXPECT_EQ(stats["settings"]["seams"], "stitch");

    EXPECT_EQ(readFileBytes(tmp / "a/lightmap_0.exr"), readFileBytes(tmp / "b/lightmap_0.exr"))
        << "the same scene, flags and seed must give the same bytes";
    const nlohmann::json offStats = readJson(tmp / "off/stats.json");
    EXPECT_FALSE(offStats.contains("seams"));
    EXPECT_EQ(offStats["settings"]["seams"], "off");
    EXPECT_NE(readFileBytes(tmp / "a/lightmap_0.exr"), readFileBytes(tmp / "off/lightmap_0.exr"));
}

// The reference stitches its light maps as the bake does (the same seams,
// the same least squares), so the two are compared as the same product.
TEST(CliSeams, ReferenceStitchesTheSameSeams) {
    TempDir tmp("seams-reference");
    ASSERT_TRUE(tmp.ok());
    auto referenceArgs = [&](const std::string& out, const char* seams) {
        return std::vector<std::string>{"reference", sourcePath("assets/shared/living_room/living_room.glb"), "-o",
                                        tmp / out, "--sky", "1,1,1", "--resolution", "256", "--spp", "2",
                                        "--seams", seams, "--no-preview", "--no-progress"};
    };
    const CliResult stitched = runCli(referenceArgs("stitched", "stitch"), tmp);
    ASSERT_EQ(stitched.exitCode, 0) << stitched.err;
    const CliResult off = runCli(referenceArgs("off", "off"), tmp);
    ASSERT_EQ(off.exitCode, 0) << off.err;
    // whole texels, as the reference's: a supersampled bake leaves the 36 texels
    // of the lamps' rims whose chart holds no half-size texel as padding
    // (bake/supersample.h), and the seams' pairs that tap them are skipped
    std::vector<std::string> args = bakeArgs(tmp / "bake");
    args.insert(args.end(), {"--supersample", "1"});
    const CliResult bake = runCli(args, tmp);
    ASSERT_EQ(bake.exitCode, 0) << bake.err;

    const nlohmann::json s = readJson(tmp / "stitched/stats.json");
    ASSERT_TRUE(s.contains("seams")) << s.dump();
    const nlohmann::json b = readJson(tmp / "bake/stats.json")["seams"];
    for (const char* key : {"seam_edges", "hard_edges", "narrow_pairs", "sample_pairs"})
        EXPECT_EQ(s["seams"][key], b[key]) << key;
    EXPECT_LT(s["seams"]["rms_after"].get<double>(), 0.25 * s["seams"]["rms_before"].get<double>());
    EXPECT_FALSE(readJson(tmp / "off/stats.json").contains("seams"));
    EXPECT_NE(readFileBytes(tmp / "stitched/lightmap_0.exr"), readFileBytes(tmp / "off/lightmap_0.exr"));
}

TEST(CliSeams, RejectsUnknownMode) {
    TempDir tmp("seams-bad");
    ASSERT_TRUE(tmp.ok());
    std::vector<std::string> args = bakeArgs(tmp / "out");
    args.insert(args.end(), {"--seams", "blur"});
    const CliResult r = runCli(args, tmp);
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("--seams"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace bb::test
