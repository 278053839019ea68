// `bundlebake bake --checkpoint-every N`, killed (SIGKILL, no cleanup) right
// after its second checkpoint, then `--resume`: the same EXR bytes and the
// same statistics as an uninterrupted bake; a resume with other flags is
// refused in one line. The kill comes from the CLI's test hook
// BUNDLEBAKE_TEST_KILL_AFTER_CHECKPOINTS, at a known point (no timing).
#include <gtest/gtest.h>

#include <cstdlib>

#include <nlohmann/json.hpp>

#include "support/cli_helper.h"
#include "support/gl_fixture.h"

namespace bb::test {
namespace {

std::vector<std::string> bakeArgs(const std::string& out) {
    return {"bake", sourcePath("assets/cornell_box/cornell_box.gltf"), "-o", out, "--uv-layout", "asset",
            "--resolution", "64", "--directions", "12", "--sky", "0.2,0.3,0.4", "--checkpoint-every", "2",
            "--no-progress", "--no-preview"};
}

CliResult runKilledAfterTwoCheckpoints(const std::vector<std::string>& args, const TempDir& tmp) {
    ::setenv("BUNDLEBAKE_TEST_KILL_AFTER_CHECKPOINTS", "2", 1);
    CliResult r = runCli(args, tmp);
    ::unsetenv("BUNDLEBAKE_TEST_KILL_AFTER_CHECKPOINTS");
    return r;
}

double fragments(const std::string& statsPath) {
    auto j = nlohmann::json::parse(readFileBytes(statsPath), nullptr, false);
    return j.is_discarded() ? -1.0 : j["throughput"]["fragments"].get<double>();
}

TEST(CliResume, KilledBakeResumesToTheSameBytes) {
    TempDir tmp("resume");
    ASSERT_TRUE(tmp.ok());
    CliResult whole = runCli(bakeArgs(tmp / "whole"), tmp);
    ASSERT_EQ(whole.exitCode, 0) << whole.err;

    CliResult killed = runKilledAfterTwoCheckpoints(bakeArgs(tmp / "cut"), tmp);
    EXPECT_EQ(killed.exitCode, -1) << "the hook should have killed the bake: " << killed.err;
    ASSERT_TRUE(std::filesystem::exists(tmp / "cut/checkpoint.bin"));
    EXPECT_FALSE(std::filesystem::exists(tmp / "cut/lightmap_0.exr")) << "a killed bake left an output";

    std::vector<std::string> resume = bakeArgs(tmp / "cut");
    resume.push_back("--resume");
    CliResult resumed = runCli(resume, tmp);
    ASSERT_EQ(resumed.exitCode, 0) << resumed.err;
    EXPECT_NE(resumed.err.find("resuming from"), std::string::npos) << resumed.err;
    EXPECT_EQ(readFileBytes(tmp / "cut/lightmap_0.exr"), readFileBytes(tmp / "whole/lightmap_0.exr"))
        << "the resumed bake's light map differs from the uninterrupted one";
    EXPECT_EQ(fragments(tmp / "cut/stats.json"), fragments(tmp / "whole/stats.json"))
        << "statistics did not carry over the resume";
    EXPECT_FALSE(std::filesystem::exists(tmp / "cut/checkpoint.bin")) << "the outputs supersede the checkpoint";
}

TEST(CliResume, ResumeWithOtherFlagsIsRefused) {
    TempDir tmp("resume-refused");
    ASSERT_TRUE(tmp.ok());
    CliResult killed = runKilledAfterTwoCheckpoints(bakeArgs(tmp / "cut"), tmp);
    ASSERT_TRUE(std::filesystem::exists(tmp / "cut/checkpoint.bin")) << killed.err;
    for (const std::vector<std::string>& change :
         {std::vector<std::string>{"--direct", "bundles"}, {"--emitter-samples", "32"}, {"--sun-jitter", "5"}, {"--seed", "9"}}) {
        SCOPED_TRACE(change[0]);
        std::vector<std::string> args = bakeArgs(tmp / "cut");
        args.insert(args.end(), change.begin(), change.end());
        args.push_back("--resume");
        CliResult r = runCli(args, tmp);
        EXPECT_NE(r.exitCode, 0);
        EXPECT_NE(r.err.find("another scene or other bake options"), std::string::npos) << r.err;
        EXPECT_FALSE(std::filesystem::exists(tmp / "cut/lightmap_0.exr"));
    }
}

}  // namespace
}  // namespace bb::test
