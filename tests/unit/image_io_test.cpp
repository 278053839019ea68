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

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfStringAttribute.h>

#include "bake/bake_output.h"
#include "bake/rounding.h"
#include "io/image_io.h"
#include "io/stb_codec.h"

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

// The written maps' half rounding (bake_output.h exrRoundingError), against
// the values written and read back: a page just under 2 (the rho 0.5
// furnace's) loses 1.9991 - 1.99902 on every texel; a page beyond half's range
// is written as float and loses nothing; padding is left out.
TEST_F(ImageIo, ExrRoundingErrorIsWhatTheFileLoses) {
    LightmapPages maps;
    maps.resolution = 4;
    maps.pages.resize(1);
    maps.pages[0].width = maps.pages[0].height = 4;
    maps.pages[0].pixels.assign(16, glm::vec3(1.9991f));
    maps.pages[0].pixels[15] = glm::vec3(7.0f);  // padding
    maps.covered = {std::vector<uint8_t>(16, 1)};
    maps.covered[0][15] = 0;
    const std::string file = path("rounding.exr");
    ASSERT_TRUE(writeExr(file, maps.pages[0]).isOk());
    Expected<ImageRgb> back = readImageRgb(file);
    ASSERT_TRUE(back) << back.error();
    const double lost = std::fabs(double(back->pixels[0].r) - double(1.9991f));
    EXPECT_GT(lost, 0.0);
    EXPECT_NEAR(exrRoundingError(maps), lost / double(1.9991f), 1e-9);
    maps.pages[0].pixels[15] = glm::vec3(1e5f);  // the page is written as float now
    EXPECT_EQ(exrRoundingError(maps), 0.0);
}

TEST_F(ImageIo, ExrIsZipHalfRgbWithAttributes) {
    const std::string file = path("page1.exr");
    ASSERT_TRUE(writeExr(file, gradient(4, 4),
                             {{"bundlebake:units", "L_lm = E/pi"}, {"bundlebake:page", "1"}})
                    .isOk());
    Imf::InputFile in(file.c_str());
    const Imf::Header& header = in.header();
    std::vector<std::string> names;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
        names.push_back(it.name());
        EXPECT_EQ(it.channel().type, Imf::HALF) << it.name();
    }
    EXPECT_EQ(names, (std::vector<std::string>{"B", "G", "R"}));  // OpenEXR lists channels by name
    EXPECT_EQ(header.compression(), Imf::ZIP_COMPRESSION);
    const auto* units = header.findTypedAttribute<Imf::StringAttribute>("bundlebake:units");
    const auto* page = header.findTypedAttribute<Imf::StringAttribute>("bundlebake:page");
    ASSERT_TRUE(units && page);
    EXPECT_EQ(units->value(), "L_lm = E/pi");
    EXPECT_EQ(page->value(), "1");
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
    auto decoded = decodeImageFile(file, int64_t(1) << 20);
    ASSERT_TRUE(decoded) << decoded.error();
    EXPECT_FALSE(decoded->isFloat);
    EXPECT_EQ(decoded->width, 9);
    EXPECT_EQ(decoded->height, 5);
    ASSERT_EQ(decoded->channels, 3);
    // the bytes as stored (8 bits: exact multiples of 1/255)
    auto px = [&](int x, int y, int c) { return int(std::lround(decoded->values[(size_t(y) * 9 + x) * 3 + c] * 255.0f)); };
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

TEST_F(ImageIo, ReadsRadianceHdrAsLinear) {
    // two RGBE pixels, flat (a scanline under 8 pixels is never run-length coded):
    // 128 x 2^(129 - 136) = 1; 64 -> 0.5; 32 -> 0.25; exponent 131: x 4
    const std::string file = path("env.hdr");
    const unsigned char pixels[] = {128, 64, 32, 129, 128, 128, 128, 131};
    {
        std::ofstream out(file, std::ios::binary);
        out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
        out.write(reinterpret_cast<const char*>(pixels), sizeof(pixels));
    }
    Expected<ImageRgb> back = readImageRgb(file);
    ASSERT_TRUE(back) << back.error();
    ASSERT_EQ(back->width, 2);
    ASSERT_EQ(back->height, 1);
    EXPECT_EQ(back->at(0, 0), glm::vec3(1.0f, 0.5f, 0.25f));
    EXPECT_EQ(back->at(1, 0), glm::vec3(4.0f));

    // a run-length coded scanline of 8 (each channel one run of 8: 128 + 8, value),
    // and the same cut short by a byte: refused, not read as black
    const unsigned char rle[] = {2, 2, 0, 8, 136, 128, 136, 64, 136, 32, 136, 129};
    for (size_t cut : {size_t(0), size_t(1)}) {
        const std::string name = path(cut ? "cut.hdr" : "rle.hdr");
        {
            std::ofstream out(name, std::ios::binary);
            out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n";
            out.write(reinterpret_cast<const char*>(rle), std::streamsize(sizeof(rle) - cut));
        }
        Expected<ImageRgb> image = readImageRgb(name);
        if (cut) {
            ASSERT_FALSE(image);
            EXPECT_TRUE(isOneLine(image.error())) << image.error();
            EXPECT_NE(image.error().find(name), std::string::npos) << image.error();
        } else {
            ASSERT_TRUE(image) << image.error();
            ASSERT_EQ(image->width, 8);
            for (int x = 0; x < 8; ++x) EXPECT_EQ(image->at(x, 0), glm::vec3(1.0f, 0.5f, 0.25f)) << x;
        }
    }
}

TEST_F(ImageIo, ReadsGreyAsReplicatedRgbAndDropsAlpha) {
    // 8-bit grey + alpha, written without a colour chunk (so sRGB)
    const std::string file = path("ga.png");
    const uint8_t data[] = {255, 255, 188, 255};
    auto png = encodePng(data, 2, 1, 2);
    ASSERT_TRUE(png) << png.error();
    std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(png->data()), std::streamsize(png->size()));
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
