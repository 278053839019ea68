// Image and JSON output (and image input): EXR through OpenEXR, PNG and
// Radiance HDR through stb (io/stb_codec.h), JSON through nlohmann-json.
// Every writer goes to "<path>.tmp-<pid>" and renames over `path`; on any
// failure the temp file is removed and the error is one line that names `path`.
// (Until 2026-12-05 through OpenImageIO, whose 261 shared libraries cost every
// bundlebake process half a second to start.)
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

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfTestFile.h>
#include <half.h>
#include <zlib.h>

#include "core/check.h"
#include "io/stb_codec.h"

namespace bb::io {
namespace {

namespace fs = std::filesystem;

// Library messages can span lines; a Status is one line.
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

// PNG chunks stb_image_write does not write: after IHDR (the 8-byte
// signature and IHDR's 25 bytes), an sRGB chunk (rendering intent 0) for
// sRGB-encoded values, or gAMA 1.0 for linear ones, so that a reader (this
// one, readPngTransfer) knows which.
std::string withTransferChunk(const std::vector<uint8_t>& png, bool srgb) {
    std::string out(png.begin(), png.end());
    if (out.size() < 33) return out;
    const std::string type = srgb ? "sRGB" : "gAMA";
    const std::string data = srgb ? std::string(1, '\0') : std::string("\x00\x01\x86\xa0", 4);  // 100000 = 1.0
    std::string chunk;
    const uint32_t length = uint32_t(data.size());
    for (int k = 3; k >= 0; --k) chunk += char((length >> (8 * k)) & 0xff);
    chunk += type + data;
    const uLong crc = crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(chunk.data() + 4), uInt(chunk.size() - 4));
    for (int k = 3; k >= 0; --k) chunk += char((crc >> (8 * k)) & 0xff);
    return out.insert(33, chunk);
}

// The transfer function a PNG's chunks before its pixels name: sRGB, or gAMA
// g (linear = encoded ^ (1 / g); 1.0 linear). None: sRGB, as PNG readers take it.
struct PngTransfer {
    bool srgb = true;
    float exponent = 1.0f;  // linear = encoded ^ exponent where not sRGB
};
PngTransfer readPngTransfer(const std::string& path) {
    PngTransfer t;
    std::ifstream file(path, std::ios::binary);
    char signature[8];
    if (!file.read(signature, 8) || std::string(signature, 8) != "\x89PNG\r\n\x1a\n") return t;
    for (int chunks = 0; chunks < 64; ++chunks) {
        unsigned char head[8];
        if (!file.read(reinterpret_cast<char*>(head), 8)) break;
        const uint32_t length = uint32_t(head[0]) << 24 | uint32_t(head[1]) << 16 | uint32_t(head[2]) << 8 | head[3];
        const std::string type(reinterpret_cast<char*>(head + 4), 4);
        if (type == "IDAT" || type == "IEND" || length > (1u << 24)) break;
        if (type == "sRGB") return PngTransfer{};
        if (type == "gAMA" && length == 4) {
            unsigned char g[4];
            if (!file.read(reinterpret_cast<char*>(g), 4)) break;
            const uint32_t gamma = uint32_t(g[0]) << 24 | uint32_t(g[1]) << 16 | uint32_t(g[2]) << 8 | g[3];
            if (gamma > 0) t = PngTransfer{false, 100000.0f / float(gamma)};
            file.seekg(4, std::ios::cur);  // its CRC
            continue;
        }
        file.seekg(std::streamoff(length) + 4, std::ios::cur);
    }
    return t;
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
                 bool srgb) {
    if (Status s = checkImage(image); !s) return Status::error("cannot write " + path + ": " + s.message());
    std::vector<uint8_t> bytes(image.pixels.size() * 3);
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        for (int c = 0; c < 3; ++c) bytes[3 * i + size_t(c)] = encode(image.pixels[i][c]);
    }
    auto encoded = encodePng(bytes.data(), image.width, image.height, 3);
    if (!encoded) return Status::error("cannot write " + path + ": " + encoded.error());
    return writeFileAtomic(path, withTransferChunk(*encoded, srgb));
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

bool exrWritesFloat(const ImageRgb& image) {
    float largest = 0.0f;
    for (const glm::vec3& p : image.pixels) largest = std::max({largest, p.r, p.g, p.b});
    return largest > 65504.0f;
}

float exrStoredValue(float v, bool asFloat) { return asFloat ? v : float(half(v)); }

Status writeExr(const std::string& path, const ImageRgb& image,
                    const std::vector<std::pair<std::string, std::string>>& attributes) {
    if (Status s = checkImage(image); !s) return Status::error("cannot write " + path + ": " + s.message());
    // half, unless a value is beyond half's range (65504): then float, never a clamp
    const bool asFloat = exrWritesFloat(image);
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "ImageRgb pixels must be packed RGB floats");
    // float -> half rounds to nearest, ties to even (Imath)
    std::vector<half> halves;
    if (!asFloat) {
        halves.resize(image.pixels.size() * 3);
        for (size_t i = 0; i < image.pixels.size(); ++i)
            for (int c = 0; c < 3; ++c) halves[3 * i + size_t(c)] = half(image.pixels[i][c]);  // exrStoredValue
    }
    return writeThroughTemp(path, [&](const std::string& temp) {
        try {
            Imf::Header header(image.width, image.height);
            header.compression() = Imf::ZIP_COMPRESSION;
            for (const auto& [name, value] : attributes) header.insert(name, Imf::StringAttribute(value));
            const Imf::PixelType type = asFloat ? Imf::FLOAT : Imf::HALF;
            const size_t size = asFloat ? sizeof(float) : sizeof(half);
            char* base = asFloat ? reinterpret_cast<char*>(const_cast<glm::vec3*>(image.pixels.data()))
                                 : reinterpret_cast<char*>(halves.data());
            Imf::FrameBuffer frame;
            const char* names[3] = {"R", "G", "B"};
            for (int c = 0; c < 3; ++c) {
                header.channels().insert(names[c], Imf::Channel(type));
                frame.insert(names[c], Imf::Slice(type, base + size_t(c) * size, 3 * size, 3 * size * size_t(image.width)));
            }
            Imf::OutputFile file(temp.c_str(), header);
            file.setFrameBuffer(frame);
            file.writePixels(image.height);
        } catch (const std::exception& e) {
            return Status::error(oneLine(e.what()));
        }
        return Status::ok();
    });
}

namespace {

// An EXR's first part: R, G, B, else its one channel of Y, R or the first name
// that is not A, replicated; the data window's pixels.
Expected<ImageRgb> readExr(const std::string& path, const std::function<Expected<ImageRgb>(const std::string&)>& fail) {
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i window = file.header().dataWindow();
        const int64_t width = int64_t(window.max.x) - window.min.x + 1, height = int64_t(window.max.y) - window.min.y + 1;
        if (width <= 0 || height <= 0) return fail("empty image");
        // bounds before allocation: a header may claim any size
        if (width * height > MAX_IMAGE_PIXELS)
            return fail(std::to_string(width) + " x " + std::to_string(height) + " is larger than bundlebake reads (" +
                        std::to_string(MAX_IMAGE_PIXELS >> 20) + " M pixels)");
        const Imf::ChannelList& channels = file.header().channels();
        std::vector<std::string> names;
        if (channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B")) {
            names = {"R", "G", "B"};
        } else {
            for (const char* one : {"Y", "R"})
                if (names.empty() && channels.findChannel(one)) names = {one};
            for (auto it = channels.begin(); names.empty() && it != channels.end(); ++it)
                if (std::string(it.name()) != "A") names = {it.name()};
            if (names.empty() && channels.begin() != channels.end()) names = {channels.begin().name()};
            if (names.empty()) return fail("no channels");
        }
        ImageRgb image;
        image.width = int(width);
        image.height = int(height);
        image.pixels.assign(size_t(width) * size_t(height), glm::vec3(0.0f));
        const size_t xStride = sizeof(glm::vec3), yStride = xStride * size_t(width);
        // the slices start where pixel (0, 0) of the data window's origin would be
        char* origin = reinterpret_cast<char*>(image.pixels.data()) - ptrdiff_t(window.min.x) * ptrdiff_t(xStride) -
                       ptrdiff_t(window.min.y) * ptrdiff_t(yStride);
        Imf::FrameBuffer frame;
        for (size_t c = 0; c < names.size(); ++c)
            frame.insert(names[c], Imf::Slice(Imf::FLOAT, origin + c * sizeof(float), xStride, yStride));
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        if (names.size() == 1)
            for (glm::vec3& p : image.pixels) p = glm::vec3(p.r);
        return image;
    } catch (const std::exception& e) {
        return fail(oneLine(e.what()));
    }
}

}  // namespace

Expected<ImageRgb> readImageRgb(const std::string& path) {
    auto fail = [&](const std::string& why) {
        return Expected<ImageRgb>::failure("cannot read image " + path + ": " + why);
    };
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return fail(fs::exists(path, ec) ? "not a regular file" : "no such file");

    bool tiled = false, deep = false, multiPart = false;
    if (Imf::isOpenExrFile(path.c_str(), tiled, deep, multiPart)) {
        if (deep) return fail("deep images are not supported");
        return readExr(path, fail);
    }
    // PNG and HDR through stb_image: HDR is linear; a PNG is decoded with the
    // transfer function it names (sRGB, or gAMA), else as sRGB
    auto decoded = decodeImageFile(path, MAX_IMAGE_PIXELS);
    if (!decoded) return fail(oneLine(decoded.error()));
    const int width = decoded->width, height = decoded->height, channels = decoded->channels;
    const std::vector<float>& data = decoded->values;
    const PngTransfer transfer = decoded->isFloat ? PngTransfer{false, 1.0f} : readPngTransfer(path);
    auto toLinear = [&](float v) {
        if (transfer.srgb) return srgbEotf(v);
        return transfer.exponent == 1.0f ? v : std::pow(std::max(v, 0.0f), transfer.exponent);
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
                     true);
}

Status writePng(const std::string& path, const ImageRgb& image, bool srgb) {
    if (srgb) {
        return writePng8(path, image, [](float x) { return toByte(srgbOetf(std::min(sanitize(x), 1.0f))); }, true);
    }
    return writePng8(path, image, [](float x) { return toByte(std::min(sanitize(x), 1.0f)); }, false);
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
