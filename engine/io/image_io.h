// Image and JSON output through OpenEXR, stb and nlohmann-json. Every writer
// goes to "<path>.tmp-<pid>" first and renames over `path`, so OUTDIR never
// holds a partial or corrupt file.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "core/status.h"

namespace bb::io {

// A linear RGB float image, row-major, row 0 = top of the file (as EXR/PNG store
// it). Every light-map-space image bundlebake writes (light maps, importance)
// keeps texel row 0 (v = 0, GL's first row) as file row 0: glTF puts v = 0 at
// the top of an image, so the files read as the scene's UVs do.
struct ImageRgb {
    int width = 0, height = 0;
    std::vector<glm::vec3> pixels;
    glm::vec3& at(int x, int y) { return pixels[size_t(y) * width + x]; }
    const glm::vec3& at(int x, int y) const { return pixels[size_t(y) * width + x]; }
};

void flipRows(ImageRgb& image);

// RGB EXR (OpenEXR), ZIP compression, plus string attributes (e.g.
// "bundlebake:units" = "L_lm = E/pi"): half floats, or 32-bit floats when a
// value is beyond half's range (65504), so nothing is clamped.
Status writeExr(const std::string& path, const ImageRgb& image,
                    const std::vector<std::pair<std::string, std::string>>& attributes = {});
// Whether writeExr writes `image` as 32-bit floats (a value beyond half's range).
bool exrWritesFloat(const ImageRgb& image);
// The value writeExr stores for v: v rounded to half (nearest, ties to even),
// or v itself in an image written as float.
float exrStoredValue(float v, bool asFloat);

// Largest image readImageRgb accepts (width x height): 256 M pixels, e.g. a
// 16384 x 8192 environment map is 128 M. Checked before any allocation.
constexpr int64_t MAX_IMAGE_PIXELS = int64_t(1) << 28;

// Reads an image as linear RGB float: EXR (its first part: R, G, B, else one
// channel replicated) through OpenEXR; Radiance HDR and PNG (8 or 16 bits)
// through stb_image (io/stb_codec.h). EXR and HDR are linear; a PNG is decoded
// as sRGB unless its gAMA chunk says otherwise (gAMA 1.0: linear, as writePng
// writes a linear PNG). Error names the file; images larger than
// MAX_IMAGE_PIXELS are refused before allocation.
Expected<ImageRgb> readImageRgb(const std::string& path);

// 8-bit sRGB PNG of a linear image: scaled by 2^exposure, then ACES-fitted
// filmic tone map (Narkowicz 2015), then sRGB encoding.
Status writePngToneMapped(const std::string& path, const ImageRgb& image, float exposure = 0.0f);

// 8-bit PNG written as is (values clamped to [0,1]), sRGB-encoded with an sRGB
// chunk if `srgb`, else linear with gAMA 1.0.
Status writePng(const std::string& path, const ImageRgb& image, bool srgb = true);

// Pretty-printed JSON (2-space indent), atomically.
Status writeJson(const std::string& path, const nlohmann::json& value);

// Writes bytes atomically (temp + rename).
Status writeFileAtomic(const std::string& path, const std::string& bytes);

// Creates a directory (and parents); error if it exists as a file or cannot be made.
Status ensureDirectory(const std::string& path);

}  // namespace bb::io
