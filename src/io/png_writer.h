// Writing frames as PNG files: 8-bit RGBA, no filtering, zlib-compressed in
// bands of rows on every core (a 1080p frame is written at the end of every
// `render`, so its compression is on the time to first image).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace fibscope {

// Writes `rgba` (width * height * 4 bytes, top row first) to `path`
// (temporary file, then renamed). Throws Error naming the path.
void writePngRgba(const std::string& path, uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba);

}  // namespace fibscope
