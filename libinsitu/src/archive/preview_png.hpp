#pragma once
// The archive's PNG previews, read back (write_png in insitu/core/image.hpp writes them).
#include <string>
#include <vector>

#include "insitu/core/image.hpp"

namespace insitu::archive_format {

/// Decodes a preview the way write_png encoded it: 8-bit sRGB, straight alpha -> linear,
/// premultiplied; 1, 3 or 4 channels as stored (grey + alpha becomes RGBA). IoError names `path`.
Image decode_preview_png(const std::vector<char>& bytes, const std::string& path);

}  // namespace insitu::archive_format
