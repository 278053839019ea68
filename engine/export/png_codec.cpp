#include "export/png_codec.h"

#include <cstring>
#include <string>

// stb in this translation unit only, with static linkage: tinygltf's shared
// library carries its own copy.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
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

Expected<std::vector<uint8_t>> encodePngRgba(const std::vector<uint8_t>& rgba, int width, int height) {
    using Fail = Expected<std::vector<uint8_t>>;
    if (width <= 0 || height <= 0 || rgba.size() != size_t(width) * size_t(height) * 4)
        return Fail::failure("PNG encoder: " + std::to_string(rgba.size()) + " bytes for a " + std::to_string(width) + "x" +
                             std::to_string(height) + " RGBA image");
    std::vector<uint8_t> out;
    if (!stbi_write_png_to_func(&appendBytes, &out, width, height, 4, rgba.data(), width * 4))
        return Fail::failure("PNG encoder failed on a " + std::to_string(width) + "x" + std::to_string(height) + " image");
    return out;
}

Expected<DecodedRgba> decodeImageRgba(const uint8_t* bytes, size_t size) {
    using Fail = Expected<DecodedRgba>;
    if (size > size_t(1) << 31) return Fail::failure("image larger than 2 GiB");
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

}  // namespace bb
