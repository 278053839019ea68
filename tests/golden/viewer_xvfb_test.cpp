// The viewer, scripted under a virtual X server: it opens its GLFW window,
// bakes while drawing 60 frames, writes the scene view and exits 0; the
// picture's centre shows the lit Cornell box. Skips (with the reason) only
// when xvfb-run is missing, or when the viewer was not built (no GLFW/ImGui).
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "render/scene_renderer.h"
#include "support/gl_fixture.h"
#include "support/scratch_dirs.h"

namespace bb::test {
namespace {

TEST(ViewerXvfb, ScriptedScreenshotShowsTheLitScene) {
#ifndef BUNDLEBAKE_VIEWER
    GTEST_SKIP() << "bundlebake-viewer was not built (needs libglfw3-dev and libimgui-dev)";
#else
    if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
        GTEST_SKIP() << "xvfb-run is not installed (Debian: apt-get install xvfb)";
    const std::string dir = removeAtExit(testing::TempDir() + "/bundlebake_viewer_xvfb_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::string shot = dir + "/shot.png", log = dir + "/viewer.log";
    const std::string command = "xvfb-run -a -s '-screen 0 1280x720x24' '" + std::string(BUNDLEBAKE_VIEWER) + "' '" +
                                sourcePath("assets/cornell_box/cornell_box.gltf") + "' --screenshot '" + shot +
                                "' --frames 60 --save-lightmaps --output '" + dir + "/maps' > '" + log + "' 2>&1";
    const int status = std::system(command.c_str());
    std::stringstream output;
    output << std::ifstream(log).rdbuf();
    std::printf("%s", output.str().c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command << "\n" << output.str();

    auto image = readImage8(shot);
    ASSERT_TRUE(image) << image.error();
    EXPECT_EQ(image->width, 1280);
    EXPECT_EQ(image->height, 720);
    // the centre fifth of the picture: the box's back wall and blocks, lit
    double mean = 0, count = 0;
    int brightest = 0;
    for (int y = image->height * 2 / 5; y < image->height * 3 / 5; ++y)
        for (int x = image->width * 2 / 5; x < image->width * 3 / 5; ++x) {
            const int luma = (2 * image->at(x, y, 0) + 5 * image->at(x, y, 1) + image->at(x, y, 2)) / 8;
            mean += luma, ++count, brightest = std::max(brightest, luma);
        }
    mean /= count;
    std::printf("centre region: mean luma %.1f, max %d (of 255)\n", mean, brightest);
    EXPECT_GT(mean, 60.0) << "the centre of the screenshot is not lit";
    EXPECT_GT(brightest, 120);
    // the saved light maps are written as `bundlebake bake` writes them: their seams stitched
    const nlohmann::json stats = nlohmann::json::parse(std::ifstream(dir + "/maps/stats.json"), nullptr, false);
    ASSERT_TRUE(stats.is_object()) << "no stats.json beside the saved light maps";
    EXPECT_EQ(stats["settings"].value("seams", ""), "stitch");
    EXPECT_TRUE(stats.contains("seams") && stats["seams"].contains("seam_edges")) << "the seams were not stitched";
    std::filesystem::remove_all(dir);
#endif
}

}  // namespace
}  // namespace bb::test
