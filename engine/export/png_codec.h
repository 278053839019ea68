// 8-bit RGBA PNG to and from memory (stb_image_write / stb_image, compiled
// into this file only), for images embedded in a .glb. GL-free.
#pragma once

#include <cstdint>
#include <vector>

#include "core/status.h"

namespace bb {

// `rgba`: width * height * 4 bytes, row 0 first (the top of the image). Bytes
// are stored as given: no gamma or sRGB chunk is written.
Expected<std::vector<uint8_t>> encodePngRgba(const std::vector<uint8_t>& rgba, int width, int height);

struct DecodedRgba {
    int width = 0, height = 0;
    std::vector<uint8_t> rgba;  // 4 bytes a pixel, row 0 first, bytes as stored (no transfer function applied)
};
// Errors: not a PNG/JPEG stb can decode, or larger than 2^28 pixels.
Expected<DecodedRgba> decodeImageRgba(const uint8_t* bytes, size_t size);

}  // namespace bb
