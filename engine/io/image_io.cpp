// Image and JSON output (and image input) through OpenImageIO and
// nlohmann-json. Every writer goes to "<path>.tmp-<pid>" and renames over
// `path`; on any failure the temp file is removed and the error is one line
// that names `path`.
//
// Based on: IEC 61966-2-1 (sRGB transfer functions); Narkowicz, "ACES Filmic
// Tone Mapping Curve", 2015 (the fitted curve).
#include "io/image_io.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <system_error>

#include <OpenImageIO/imageio.h>

#include "core/check.h"

namespace bb::io {
namespace {

namespace fs = std::filesystem;

// OIIO messages can span lines; a Status is one line.
std::string oneLine(std::string text) {
    for (char& c : text) {
        if (c == '\n' || c == '\r') c = ' ';
    }
    while (!text.empty() && text.back() == ' ') text.pop_back();
    while (!text.empty() && text.front() == ' ') text.erase(text.begin());
    return text.empty() ? std::string("unknown error") : text;
}

std::string tempPathFor(const std::string& path) { return path + ".tmp-" + std::to_string(::getpid()); }

void removeQuietly(const std::string& path) {
    std::error_code ec;
    fs::remove(path, ec);
}

// Runs `writeTemp(tempPath)`, then renames the temp file over `path`. On any
// failure the temp file is gone afterwards and the error names `path`.
Status writeThroughTemp(const std::string& path, const std::function<Status(const std::string&)>& writeTemp) {
    const std::string temp = tempPathFor(path);
    Status written = writeTemp(temp);
    if (!written) {
        removeQuietly(temp);
        return Status::error("cannot write " + path + ": " + written.message());
    }
    std::error_code ec;
    fs::rename(temp, path, ec);
    if (ec) {
        removeQuietly(temp);
        return Status::error("cannot write " + path + ": rename failed: " + oneLine(ec.message()));
    }
    return Status::ok();
}

Status checkImage(const ImageRgb& image) {
    if (image.width <= 0 || image.height <= 0)
        return Status::error("empty image (" + std::to_string(image.width) + "x" + std::to_string(image.height) + ")");
    CHECK_EQ(image.pixels.size(), size_t(image.width) * size_t(image.height));
    return Status::ok();
}

// Writes `data` (interleaved channels of `dataType`) to `file` in `format`
// ("openexr", "png") with the pixel type and attributes of `spec`.
Status writeOiio(const std::string& file, const char* format, OIIO::ImageSpec spec, OIIO::TypeDesc dataType,
                 const void* data) {
    // the format comes from its name: the temp file's extension says nothing
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(format);
    if (!out) return Status::error(oneLine(OIIO::geterror()));
    if (!out->open(file, spec)) return Status::error(oneLine(out->geterror()));
    if (!out->write_image(dataType, data)) {
        std::string error = oneLine(out->geterror());
        out->close();
        return Status::error(error);
    }
    if (!out->close()) return Status::error(oneLine(out->geterror()));
    return Status::ok();
}

// Non-finite and negative values -> 0 (NaN fails every comparison); +Inf stays.
float sanitize(float x) { return x > 0.0f ? x : 0.0f; }

float srgbOetf(float linear) {  // linear [0,1] -> sRGB-encoded [0,1]
    return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

float srgbEotf(float encoded) {  // sRGB-encoded [0,1] -> linear
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

// Narkowicz 2015: a fit of the ACES RRT+ODT, input pre-exposed, output [0,1].
float acesFitted(float x) {
    if (std::isinf(x)) return 1.0f;
    const float y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    return std::clamp(y, 0.0f, 1.0f);
}

uint8_t toByte(float encoded) {  // [0,1] -> 0..255, rounded to nearest
    return uint8_t(std::floor(std::clamp(encoded, 0.0f, 1.0f) * 255.0f + 0.5f));
}

Status writePng8(const std::string& path, const ImageRgb& image, const std::function<uint8_t(float)>& encode,
                 const char* colorSpace) {
    if (Status s = checkImage(image); !s) return Status::error("cannot write " + path + ": " + s.message());
    std::vector<uint8_t> bytes(image.pixels.size() * 3);
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        for (int c = 0; c < 3; ++c) bytes[3 * i + size_t(c)] = encode(image.pixels[i][c]);
    }
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", colorSpace);
    return writeThroughTemp(path, [&](const std::string& temp) {
        return writeOiio(temp, "png", spec, OIIO::TypeDesc::UINT8, bytes.data());
    });
}

}  // namespace

void flipRows(ImageRgb& image) {
    const size_t width = size_t(std::max(image.width, 0));
    for (int top = 0, bottom = image.height - 1; top < bottom; ++top, --bottom) {
        std::swap_ranges(image.pixels.begin() + ptrdiff_t(size_t(top) * width),
                         image.pixels.begin() + ptrdiff_t(size_t(top + 1) * width),
                         image.pixels.begin() + ptrdiff_t(size_t(bottom) * width));
    }
}

Status writeExr(const std::string& path, const ImageRgb& image,
                    const std::vector<std::pair<std::string, std::string>>& attributes) {
    if (Status s = checkImage(image); !s) return Status::error("cannot write " + path + ": " + s.message());
    // half, unless a value is beyond half's range (65504): then float, never a clamp
    float largest = 0.0f;
    for (const glm::vec3& p : image.pixels) largest = std::max({largest, p.r, p.g, p.b});
    OIIO::ImageSpec spec(image.width, image.height, 3, largest > 65504.0f ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::HALF);
    spec.attribute("compression", "zip");
    // OIIO's EXR writer stamps the current time unless DateTime is set; an
    // empty one keeps the file a function of its pixels (determinism).
    spec.attribute("DateTime", "");
    for (const auto& [name, value] : attributes) spec.attribute(name, value);
    // OIIO converts float -> half with round to nearest (ties to even)
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "ImageRgb pixels must be packed RGB floats");
    return writeThroughTemp(path, [&](const std::string& temp) {
        return writeOiio(temp, "openexr", spec, OIIO::TypeDesc::FLOAT, image.pixels.data());
    });
}

Expected<ImageRgb> readImageRgb(const std::string& path) {
    auto fail = [&](const std::string& why) {
        return Expected<ImageRgb>::failure("cannot read image " + path + ": " + why);
    };
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return fail(fs::exists(path, ec) ? "not a regular file" : "no such file");

    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path);
    if (!in) return fail(oneLine(OIIO::geterror()));
    const OIIO::ImageSpec& spec = in->spec();
    const int width = spec.width, height = spec.height, channels = spec.nchannels;
    if (width <= 0 || height <= 0 || channels <= 0) return fail("empty image");
    if (spec.deep) return fail("deep images are not supported");
    // bounds before allocation: a header may claim any size
    if (int64_t(width) * height > MAX_IMAGE_PIXELS || int64_t(width) * height * channels > 4 * MAX_IMAGE_PIXELS)
        return fail(std::to_string(width) + " x " + std::to_string(height) + " x " + std::to_string(channels) +
                    " channels is larger than bundlebake reads (" + std::to_string(MAX_IMAGE_PIXELS >> 20) + " M pixels)");

    std::vector<float> data(size_t(width) * size_t(height) * size_t(channels));
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, data.data())) return fail(oneLine(in->geterror()));

    // transfer function: float formats (EXR, HDR) are linear already. An
    // integer file is decoded with the sRGB EOTF when it says sRGB, or says
    // nothing and is 8-bit; with a plain gamma when it says "GammaN"/oiio:Gamma.
    const std::string colorSpace = spec.get_string_attribute("oiio:ColorSpace");
    const bool isInteger = !spec.format.is_floating_point();
    const bool is8Bit = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::INT8;
    const bool isSrgb = isInteger && (colorSpace == "sRGB" || (colorSpace.empty() && is8Bit));
    const float gamma = spec.get_float_attribute("oiio:Gamma", 1.0f);
    const bool isGamma = isInteger && !isSrgb && colorSpace.rfind("Gamma", 0) == 0 && gamma > 0.0f && gamma != 1.0f;
    auto toLinear = [&](float v) {
        if (isSrgb) return srgbEotf(v);
        if (isGamma) return std::pow(std::max(v, 0.0f), gamma);
        return v;
    };

    ImageRgb image;
    image.width = width;
    image.height = height;
    image.pixels.resize(size_t(width) * size_t(height));
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        const float* p = &data[i * size_t(channels)];
        // grey (+ alpha) replicates channel 0; alpha and extra channels are dropped
        const glm::vec3 rgb = channels >= 3 ? glm::vec3(p[0], p[1], p[2]) : glm::vec3(p[0]);
        image.pixels[i] = glm::vec3(toLinear(rgb.r), toLinear(rgb.g), toLinear(rgb.b));
    }
    return image;
}

Status writePngToneMapped(const std::string& path, const ImageRgb& image, float exposure) {
    const float scale = std::exp2(exposure);
    return writePng8(path, image, [scale](float x) { return toByte(srgbOetf(acesFitted(sanitize(x) * scale))); },
                     "sRGB");
}

Status writePng(const std::string& path, const ImageRgb& image, bool srgb) {
    if (srgb) {
        return writePng8(path, image, [](float x) { return toByte(srgbOetf(std::min(sanitize(x), 1.0f))); }, "sRGB");
    }
    return writePng8(path, image, [](float x) { return toByte(std::min(sanitize(x), 1.0f)); }, "Linear");
}

Status writeJson(const std::string& path, const nlohmann::json& value) {
    std::string text;
    try {
        text = value.dump(2) + "\n";
    } catch (const nlohmann::json::exception& e) {  // e.g. invalid UTF-8 in a string
        return Status::error("cannot write " + path + ": " + oneLine(e.what()));
    }
    return writeFileAtomic(path, text);
}

Status writeFileAtomic(const std::string& path, const std::string& bytes) {
    return writeThroughTemp(path, [&](const std::string& temp) {
        std::ofstream file(temp, std::ios::binary | std::ios::trunc);
        if (!file) return Status::error("cannot create " + temp);
        file.write(bytes.data(), std::streamsize(bytes.size()));
        file.close();
        if (!file) return Status::error("write to " + temp + " failed");
        return Status::ok();
    });
}

Status ensureDirectory(const std::string& path) {
    if (path.empty()) return Status::error("cannot create directory: empty path");
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (fs::is_directory(status)) return Status::ok();
    if (fs::exists(status)) return Status::error("cannot create directory " + path + ": it exists and is not a directory");
    fs::create_directories(path, ec);
    if (ec) return Status::error("cannot create directory " + path + ": " + oneLine(ec.message()));
    return Status::ok();
}

}  // namespace bb::io
