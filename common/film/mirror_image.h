// Fills the right half of an image with the mirror image of its left half
// (column x <- column width - 1 - x), every layer, bit for bit: the second
// half of a mirror-symmetric render (render_plan.h "mirrored").
#pragma once
#include "common/film/image.h"

namespace skyfarm {

void mirror_left_half(Image* image);

}  // namespace skyfarm
