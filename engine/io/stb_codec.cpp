#include "io/stb_codec.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>

// stb in this translation unit only, with static linkage: tinygltf's shared
// library carries its own copy (and Debian's libstb, which it links, another).
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

namespace bb {

namespace {
void appendBytes(void* context, void* data, int size) {
    auto* out = static_cast<std::vector<uint8_t>*>(context);
    const auto* p = static_cast<const uint8_t*>(data);
    out->insert(out->end(), p, p + size);
}
}  // namespace

Expected<std::vector<uint8_t>> encodePng(const uint8_t* pixels, int width, int height, int channels) {
    using Fail = Expected<std::vector<uint8_t>>;
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4)
        return Fail::failure("PNG encoder: a " + std::to_string(width) + "x" + std::to_string(height) + " image of " +
                             std::to_string(channels) + " channels");
    std::vector<uint8_t> out;
    if (!stbi_write_png_to_func(&appendBytes, &out, width, height, channels, pixels, width * channels))
        return Fail::failure("PNG encoder failed on a " + std::to_string(width) + "x" + std::to_string(height) + " image");
    return out;
}

Expected<std::vector<uint8_t>> encodePngRgba(const std::vector<uint8_t>& rgba, int width, int height) {
    if (width <= 0 || height <= 0 || rgba.size() != size_t(width) * size_t(height) * 4)
        return Expected<std::vector<uint8_t>>::failure("PNG encoder: " + std::to_string(rgba.size()) + " bytes for a " +
                                                       std::to_string(width) + "x" + std::to_string(height) + " RGBA image");
    return encodePng(rgba.data(), width, height, 4);
}

Expected<DecodedRgba> decodeImageRgba(const uint8_t* bytes, size_t size) {
    using Fail = Expected<DecodedRgba>;
    if (size > size_t(1) << 31) return Fail::failure("image larger than 2 GiB");
    // glTF's two image formats only (the decoder here reads more)
    const bool png = size >= 8 && std::memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0;
    const bool jpeg = size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
    if (!png && !jpeg) return Fail::failure("cannot decode image: neither PNG nor JPEG");
    int w = 0, h = 0, n = 0;
    if (!stbi_info_from_memory(bytes, int(size), &w, &h, &n))
        return Fail::failure(std::string("cannot decode image: ") + stbi_failure_reason());
    if (int64_t(w) * h > (int64_t(1) << 28)) return Fail::failure("image larger than 2^28 pixels");
    stbi_uc* pixels = stbi_load_from_memory(bytes, int(size), &w, &h, &n, 4);
    if (!pixels) return Fail::failure(std::string("cannot decode image: ") + stbi_failure_reason());
    DecodedRgba out;
    out.width = w;
    out.height = h;
    out.rgba.assign(pixels, pixels + size_t(w) * h * 4);
    stbi_image_free(pixels);
    return out;
}

namespace {

// Whether a Radiance HDR file holds all the pixel data its header claims, read
// as stb_image reads it (stbi__hdr_load): stb takes bytes past the end of the
// file as 0 and returns a black image for a file cut after its header.
bool hdrComplete(const std::vector<uint8_t>& file) {
    size_t at = 0;
    auto line = [&] {
        std::string text;
        while (at < file.size() && file[at] != '\n') text += char(file[at++]);
        ++at;  // the newline
        return text;
    };
    while (at < file.size() && !line().empty()) {}  // the header, to its blank line
    int height = 0, width = 0;
    if (std::sscanf(line().c_str(), "-Y %d +X %d", &height, &width) != 2 || height <= 0 || width <= 0) return false;
    auto flatFrom = [&](size_t pixels) { return at <= file.size() && file.size() - at >= pixels * 4; };
    if (width < 8 || width >= 32768) return flatFrom(size_t(width) * size_t(height));
    for (int y = 0; y < height; ++y) {
        if (file.size() - at < 4) return false;
        if (file[at] != 2 || file[at + 1] != 2 || (file[at + 2] & 0x80))  // not run-length coded: flat from here on
            return flatFrom(size_t(width) * size_t(height - y));
        at += 4;
        for (int channel = 0; channel < 4; ++channel)
            for (int x = 0; x < width;) {
                if (at >= file.size()) return false;
                int count = file[at++];
                const bool run = count > 128;
                if (run) count -= 128;
                if (count == 0 || count > width - x) return false;
                at += run ? 1 : size_t(count);
                if (at > file.size()) return false;
                x += count;
            }
    }
    return true;
}

}  // namespace

Expected<DecodedImage> decodeImageFile(const std::string& path, int64_t maxPixels) {
    using Fail = Expected<DecodedImage>;
    auto reason = [] { return std::string(stbi_failure_reason() ? stbi_failure_reason() : "unknown format"); };
    // the whole file, read once: the HDR check and the decoder both take it
    std::ifstream stream(path, std::ios::binary | std::ios::ate);
    const std::streamoff size = stream ? std::streamoff(stream.tellg()) : -1;
    if (size < 0) return Fail::failure("cannot open it");
    if (size > std::numeric_limits<int>::max()) return Fail::failure("larger than 2 GiB");
    std::vector<uint8_t> bytes(static_cast<size_t>(size));
    stream.seekg(0);
    if (!stream.read(reinterpret_cast<char*>(bytes.data()), size)) return Fail::failure("cannot read it");
    // PNG and Radiance HDR only: stb reads more formats, but takes a cut file's
    // missing bytes as 0 in most of them (the HDR is checked for that below)
    auto startsWith = [&](const char* magic, size_t n) { return bytes.size() >= n && std::memcmp(bytes.data(), magic, n) == 0; };
    const bool png = startsWith("\x89PNG\r\n\x1a\n", 8);
    const bool hdr = startsWith("#?RADIANCE", 10) || startsWith("#?RGBE", 6);
    if (!png && !hdr) return Fail::failure("not an EXR, Radiance HDR or PNG file");
    const stbi_uc* data = bytes.data();
    const int length = int(bytes.size());
    DecodedImage out;
    if (!stbi_info_from_memory(data, length, &out.width, &out.height, &out.channels)) return Fail::failure(reason());
    if (out.width <= 0 || out.height <= 0 || out.channels <= 0) return Fail::failure("empty image");
    // bounds before allocation: a header may claim any size
    if (int64_t(out.width) * out.height > maxPixels)
        return Fail::failure(std::to_string(out.width) + " x " + std::to_string(out.height) +
                             " is larger than bundlebake reads (" + std::to_string(maxPixels >> 20) + " M pixels)");
    if (hdr && !hdrComplete(bytes)) return Fail::failure("truncated or malformed Radiance HDR pixel data");
    out.isFloat = hdr;
    const bool is16Bit = png && stbi_is_16_bit_from_memory(data, length);
    int w = 0, h = 0, n = 0;
    void* raw = hdr       ? static_cast<void*>(stbi_loadf_from_memory(data, length, &w, &h, &n, 0))
                : is16Bit ? static_cast<void*>(stbi_load_16_from_memory(data, length, &w, &h, &n, 0))
                          : static_cast<void*>(stbi_load_from_memory(data, length, &w, &h, &n, 0));
    if (!raw) return Fail::failure(reason());
    out.width = w, out.height = h, out.channels = n;
    out.values.resize(size_t(w) * size_t(h) * size_t(n));
    for (size_t i = 0; i < out.values.size(); ++i)
        out.values[i] = hdr       ? static_cast<const float*>(raw)[i]
                        : is16Bit ? float(static_cast<const uint16_t*>(raw)[i]) / 65535.0f
                                  : float(static_cast<const stbi_uc*>(raw)[i]) / 255.0f;
    stbi_image_free(raw);
    return out;
}

}  // namespace bb
