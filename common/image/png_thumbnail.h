// A smaller copy of a PNG, for lists of images (the web console's render list
// asks GET /v1/renders/{id}/image.png?width=N).
//
// Parameters
//   source   an 8- or 16-bit RGB PNG in sRGB (write_png's files)
//   target   the thumbnail, written atomically (AtomicFile) as 8-bit sRGB
//   width    the thumbnail's width in pixels, >= 1; its height keeps the
//            source's aspect (rounded, at least 1).  A width at or above the
//            source's copies the pixels at the source's size.
//
// Each thumbnail pixel is the mean of the source pixels whose centres fall in
// its footprint (a box filter), averaged in linear light: averaging the
// encoded values would darken every edge between bright and dark (sRGB is
// about a 2.2 power, so the mean of codes is below the code of the mean).
#pragma once
#include <filesystem>

namespace skyfarm {

// Throws std::runtime_error for an unreadable source, std::invalid_argument
// for width < 1, FileWriteError when the target cannot be written.
void write_png_thumbnail(const std::filesystem::path& source, const std::filesystem::path& target, int width);

}  // namespace skyfarm
