// Image and JSON output: EXR round trip and attributes, PNG tone mapping,
// atomic writes (no temp file left behind) and one-line errors naming the path.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <OpenImageIO/imageio.h>

#include "bake/rounding.h"
#include "io/image_io.h"

namespace bb::io {
namespace {

namespace fs = std::filesystem;

// A fresh directory per test under the system temp dir, removed afterwards.
class ImageIo : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("bundlebake_image_io_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    // Files in the directory other than the ones a test meant to write.
    std::vector<std::string> leftovers() const {
        std::vector<std::string> names;
        for (const auto& entry : fs::directory_iterator(dir_)) {
            const std::string name = entry.path().filename().string();
            if (name.find(".tmp-") != std::string::npos) names.push_back(name);
        }
        return names;
    }
    fs::path dir_;
};

ImageRgb gradient(int width, int height) {
    ImageRgb image;
    image.width = width;
    image.height = height;
    image.pixels.resize(size_t(width) * height);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            image.at(x, y) = glm::vec3(0.37f * x + 0.01f, 1000.0f / (1.0f + y), 1e-3f * float(x * y));
        }
    }
    return image;
}

bool isOneLine(const std::string& s) { return !s.empty() && s.find('\n') == std::string::npos; }

TEST_F(ImageIo, ExrRoundTripIsExactToHalf) {
    const ImageRgb image = gradient(13, 7);
    const std::string file = path("page0.exr");
    ASSERT_TRUE(writeExr(file, image).isOk());
    Expected<ImageRgb> back = readImageRgb(file);
    ASSERT_TRUE(back) << back.error();
    ASSERT_EQ(back->width, 13);
    ASSERT_EQ(back->height, 7);
    for (int y = 0; y < 7; ++y) {
        for (int x = 0; x < 13; ++x) {
            for (int c = 0; c < 3; ++c) {
                // what the file holds is the nearest half of each value
                const float expected = halfToFloat(floatToHalf(image.at(x, y)[c], Rounding::Nearest, 0.0f));
                EXPECT_EQ(back->at(x, y)[c], expected) << x << "," << y << " channel " << c;
            }
        }
    }
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(ImageIo, ExrIsZipHalfRgbWithAttributes) {
    const std::string file = path("page1.exr");
    ASSERT_TRUE(writeExr(file, gradient(4, 4),
                             {{"bundlebake:units", "L_lm = E/pi"}, {"bundlebake:page", "1"}})
                    .isOk());
    auto in = OIIO::ImageInput::open(file);
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    EXPECT_EQ(spec.nchannels, 3);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::HALF);
    EXPECT_EQ(spec.get_string_attribute("compression"), "zip");
    EXPECT_EQ(spec.get_string_attribute("bundlebake:units"), "L_lm = E/pi");
    EXPECT_EQ(spec.get_string_attribute("bundlebake:page"), "1");
    EXPECT_EQ(spec.channelnames, (std::vector<std::string>{"R", "G", "B"}));
}

TEST_F(ImageIo, WriteReplacesAnExistingFileAtomically) {
    const std::string file = path("page.exr");
    ASSERT_TRUE(writeExr(file, gradient(2, 2)).isOk());
    ASSERT_TRUE(writeExr(file, gradient(5, 3)).isOk());
    Expected<ImageRgb> back = readImageRgb(file);
    ASSERT_TRUE(back) << back.error();
    EXPECT_EQ(back->width, 5);
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(ImageIo, WritingIntoAMissingDirectoryFailsWithOneLineNamingThePath) {
    const std::string exr = path("no/such/dir/page0.exr");
    Status s = writeExr(exr, gradient(2, 2));
    ASSERT_FALSE(s.isOk());
    EXPECT_TRUE(isOneLine(s.message())) << s.message();
    EXPECT_NE(s.message().find(exr), std::string::npos) << s.message();

    const std::string png = path("no/such/dir/preview.png");
    s = writePngToneMapped(png, gradient(2, 2));
    ASSERT_FALSE(s.isOk());
    EXPECT_TRUE(isOneLine(s.message())) << s.message();
    EXPECT_NE(s.message().find(png), std::string::npos) << s.message();

    const std::string json = path("no/such/dir/stats.json");
    s = writeJson(json, nlohmann::json{{"a", 1}});
    ASSERT_FALSE(s.isOk());
    EXPECT_TRUE(isOneLine(s.message())) << s.message();
    EXPECT_NE(s.message().find(json), std::string::npos) << s.message();

    EXPECT_FALSE(fs::exists(path("no")));
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(ImageIo, FailedRenameLeavesNoTempFile) {
    // the target is a directory: the temp file is written, the rename fails
    fs::create_directories(path("taken.exr"));
    Status s = writeExr(path("taken.exr"), gradient(2, 2));
    ASSERT_FALSE(s.isOk());
    EXPECT_TRUE(isOneLine(s.message())) << s.message();
    EXPECT_NE(s.message().find(path("taken.exr")), std::string::npos);
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(ImageIo, ToneMappedPngIsEightBitOfTheRightSize) {
    ImageRgb image = gradient(9, 5);
    image.at(0, 0) = glm::vec3(0.0f);
    image.at(1, 0) = glm::vec3(1.0e6f);
    image.at(2, 0) = glm::vec3(-1.0f, std::nanf(""), INFINITY);
    image.at(3, 0) = glm::vec3(0.18f);
    const std::string file = path("preview.png");
    ASSERT_TRUE(writePngToneMapped(file, image, 1.0f).isOk());
    auto in = OIIO::ImageInput::open(file);
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec spec = in->spec();
    EXPECT_EQ(spec.width, 9);
    EXPECT_EQ(spec.height, 5);
    EXPECT_EQ(spec.nchannels, 3);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT8);
    std::vector<uint8_t> bytes(size_t(9) * 5 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, bytes.data()));
    auto px = [&](int x, int y, int c) { return int(bytes[(size_t(y) * 9 + x) * 3 + c]); };
    // black stays black, huge saturates, non-finite and negative are handled
    EXPECT_EQ(px(0, 0, 0), 0);
    EXPECT_EQ(px(1, 0, 1), 255);
    EXPECT_EQ(px(2, 0, 0), 0);
    EXPECT_EQ(px(2, 0, 1), 0);
    EXPECT_EQ(px(2, 0, 2), 255);
    // 0.18 * 2 -> ACES 0.3551... -> sRGB 0.6303... -> 161
    const float x = 0.36f;
    const float aces = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    const float srgb = 1.055f * std::pow(aces, 1.0f / 2.4f) - 0.055f;
    EXPECT_EQ(px(3, 0, 0), int(std::floor(srgb * 255.0f + 0.5f)));
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(ImageIo, PngRoundTripLinearizesSrgb) {
    ImageRgb image;
    image.width = 4;
    image.height = 1;
    image.pixels = {glm::vec3(0.0f), glm::vec3(0.5f), glm::vec3(1.0f), glm::vec3(0.2f, 0.04f, 2.0f)};
    for (bool srgb : {true, false}) {
        const std::string file = path(srgb ? "srgb.png" : "linear.png");
        ASSERT_TRUE(writePng(file, image, srgb).isOk());
        Expected<ImageRgb> back = readImageRgb(file);
        ASSERT_TRUE(back) << back.error();
        ASSERT_EQ(back->pixels.size(), 4u);
        for (size_t i = 0; i < 4; ++i) {
            for (int c = 0; c < 3; ++c) {
                // 8 bits: within one code value of the clamped input, in linear terms
                EXPECT_NEAR(back->pixels[i][c], std::min(image.pixels[i][c], 1.0f), srgb ? 0.01f : 0.5f / 255.0f + 1e-6f)
                    << (srgb ? "srgb " : "linear ") << i << " " << c;
            }
        }
    }
}

TEST_F(ImageIo, ReadsGreyAsReplicatedRgbAndDropsAlpha) {
    // 8-bit grey + alpha, written directly with OIIO
    const std::string file = path("ga.png");
    {
        auto out = OIIO::ImageOutput::create(file);
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(2, 1, 2, OIIO::TypeDesc::UINT8);
        spec.alpha_channel = 1;
        ASSERT_TRUE(out->open(file, spec));
        const uint8_t data[] = {255, 255, 188, 255};
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, data));
        ASSERT_TRUE(out->close());
    }
    Expected<ImageRgb> back = readImageRgb(file);
    ASSERT_TRUE(back) << back.error();
    EXPECT_EQ(back->at(0, 0), glm::vec3(1.0f));
    // sRGB 188/255 = 0.737 -> linear ~0.503
    const float linear = std::pow((188.0f / 255.0f + 0.055f) / 1.055f, 2.4f);
    EXPECT_NEAR(back->at(1, 0).r, linear, 1e-5f);
    EXPECT_EQ(back->at(1, 0).r, back->at(1, 0).g);
    EXPECT_EQ(back->at(1, 0).r, back->at(1, 0).b);
}

TEST_F(ImageIo, ReadingAMissingFileFailsWithOneLine) {
    const std::string file = path("missing.exr");
    Expected<ImageRgb> image = readImageRgb(file);
    ASSERT_FALSE(image);
    EXPECT_TRUE(isOneLine(image.error())) << image.error();
    EXPECT_NE(image.error().find(file), std::string::npos) << image.error();

    // not an image at all
    {
        std::ofstream(path("junk.exr")) << "definitely not an EXR\nsecond line\n";
    }
    image = readImageRgb(path("junk.exr"));
    ASSERT_FALSE(image);
    EXPECT_TRUE(isOneLine(image.error())) << image.error();
    EXPECT_NE(image.error().find(path("junk.exr")), std::string::npos) << image.error();
}

TEST_F(ImageIo, JsonAndBytesAreWrittenWhole) {
    const nlohmann::json value = {{"pages", 2}, {"units", "L_lm = E/pi"}};
    ASSERT_TRUE(writeJson(path("manifest.json"), value).isOk());
    std::ifstream in(path("manifest.json"));
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), value.dump(2) + "\n");

    ASSERT_TRUE(writeFileAtomic(path("raw.bin"), std::string("a\0b", 3)).isOk());
    EXPECT_EQ(fs::file_size(path("raw.bin")), 3u);
    EXPECT_TRUE(leftovers().empty());
}

TEST_F(ImageIo, EnsureDirectoryCreatesParentsAndRejectsFiles) {
    EXPECT_TRUE(ensureDirectory(path("a/b/c")).isOk());
    EXPECT_TRUE(fs::is_directory(path("a/b/c")));
    EXPECT_TRUE(ensureDirectory(path("a/b/c")).isOk());  // already there
    ASSERT_TRUE(writeFileAtomic(path("file"), "x").isOk());
    Status s = ensureDirectory(path("file"));
    ASSERT_FALSE(s.isOk());
    EXPECT_TRUE(isOneLine(s.message()));
    EXPECT_NE(s.message().find(path("file")), std::string::npos);
    s = ensureDirectory(path("file/sub"));
    ASSERT_FALSE(s.isOk());
    EXPECT_TRUE(isOneLine(s.message()));
}

TEST(ImageIoFlip, FlipRowsReversesRowOrder) {
    ImageRgb image;
    image.width = 2;
    image.height = 3;
    for (int i = 0; i < 6; ++i) image.pixels.push_back(glm::vec3(float(i)));
    flipRows(image);
    EXPECT_EQ(image.at(0, 0), glm::vec3(4.0f));
    EXPECT_EQ(image.at(1, 0), glm::vec3(5.0f));
    EXPECT_EQ(image.at(0, 1), glm::vec3(2.0f));
    EXPECT_EQ(image.at(1, 2), glm::vec3(1.0f));
    flipRows(image);
    EXPECT_EQ(image.at(1, 2), glm::vec3(5.0f));
}

}  // namespace
}  // namespace bb::io

namespace bb {
namespace {

// Beyond half's range the EXR is written in 32-bit floats: 2e5 reads back 2e5, not Inf or 65504.
TEST(ExrRange, ValuesBeyondTheHalfRangeAreKept) {
    io::ImageRgb img;
    img.width = 2;
    img.height = 1;
    img.pixels = {glm::vec3(2e5f, 1.0f, 0.5f), glm::vec3(0.25f)};
    const std::string path = testing::TempDir() + "/bundlebake_exr_range_" + std::to_string(::getpid()) + ".exr";
    ASSERT_TRUE(io::writeExr(path, img));
    auto back = io::readImageRgb(path);
    ASSERT_TRUE(back) << back.error();
    EXPECT_EQ(back->pixels[0], img.pixels[0]);
    EXPECT_EQ(back->pixels[1], img.pixels[1]);
    std::remove(path.c_str());
}

}  // namespace
}  // namespace bb
