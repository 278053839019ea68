// Images through stb (stb_image_write / stb_image, compiled into
// stb_codec.cpp only): PNG to memory, and decoding from memory (a .glb's
// PNG/JPEG images) or from a file (io/image_io.h's readImageRgb). GL-free.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/status.h"

namespace bb {

// `pixels`: width * height * channels (1-4) bytes, row 0 first (the top of the
// image). Bytes are stored as given: no gamma or sRGB chunk is written.
Expected<std::vector<uint8_t>> encodePng(const uint8_t* pixels, int width, int height, int channels);
Expected<std::vector<uint8_t>> encodePngRgba(const std::vector<uint8_t>& rgba, int width, int height);

struct DecodedRgba {
    int width = 0, height = 0;
    std::vector<uint8_t> rgba;  // 4 bytes a pixel, row 0 first, bytes as stored (no transfer function applied)
};
// Errors: not a PNG or JPEG stb can decode, or larger than 2^28 pixels.
Expected<DecodedRgba> decodeImageRgba(const uint8_t* bytes, size_t size);

// A PNG or Radiance HDR file, its channels as stored: floats for HDR
// (linear), else integers over their maximum (0..1, no transfer function
// applied). Other formats are refused (stb reads more, but most of them take
// a cut file's missing bytes as 0), as is an HDR whose pixel data is cut
// short; images of more than `maxPixels` from the header, before any allocation.
struct DecodedImage {
    int width = 0, height = 0, channels = 0;
    bool isFloat = false;
    std::vector<float> values;  // width * height * channels, row 0 first
};
Expected<DecodedImage> decodeImageFile(const std::string& path, int64_t maxPixels);

}  // namespace bb
