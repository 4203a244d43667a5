#include "common/image/color_management.h"

#include <OpenColorIO/OpenColorIO.h>

#include "common/core/constants.h"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>

namespace skyfarm {
namespace OCIO = OCIO_NAMESPACE;
namespace {

template <class E, std::size_t N>
std::string_view name_in(const std::array<std::pair<std::string_view, E>, N>& names, E value) {
  for (const auto& [name, v] : names)
    if (v == value) return name;
  return names[0].first;
}
template <class E, std::size_t N>
std::optional<E> value_in(const std::array<std::pair<std::string_view, E>, N>& names, std::string_view name) {
  for (const auto& [n, v] : names)
    if (n == name) return v;
  return std::nullopt;
}

// The OCIO colour space names of the config below: the request names.
std::string ocio_name(ColorSpace c) { return std::string(name_of(c)); }

OCIO::TransformRcPtr builtin(const char* style) {
  OCIO::BuiltinTransformRcPtr t = OCIO::BuiltinTransform::Create();
  t->setStyle(style);
  return t;
}

// The config, made in code once.  Reference space: CIE XYZ with D65 as the
// adopted white (OCIO's builtins' "CIE-XYZ-D65"), i.e. the renderer's XYZ;
// each space says how to get there.
//   lin_rec709: the renderer's own matrix kLinearSrgbToXyz (color.h), so the
//               XYZ round trip is the one Image::set_xyz inverts
//   acescg, aces2065-1: OCIO's builtin AP1 / AP0 → XYZ-D65, Bradford
//   cie_xyz:    the reference itself
OCIO::ConstConfigRcPtr make_config() {
  OCIO::ConfigRcPtr config = OCIO::Config::CreateRaw()->createEditableCopy();
  auto add = [&](ColorSpace c, OCIO::ConstTransformRcPtr to_reference) {
    OCIO::ColorSpaceRcPtr cs = OCIO::ColorSpace::Create(OCIO::REFERENCE_SPACE_SCENE);
    cs->setName(ocio_name(c).c_str());
    if (to_reference) cs->setTransform(to_reference, OCIO::COLORSPACE_DIR_TO_REFERENCE);
    config->addColorSpace(cs);
  };
  OCIO::MatrixTransformRcPtr rec709 = OCIO::MatrixTransform::Create();
  double m44[16] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m44[4 * i + j] = kLinearSrgbToXyz[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
  m44[15] = 1.0;
  rec709->setMatrix(m44);
  add(ColorSpace::kLinRec709, rec709);
  add(ColorSpace::kAcesCg, builtin("UTILITY - ACES-AP1_to_CIE-XYZ-D65_BFD"));
  add(ColorSpace::kAces2065_1, builtin("UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD"));
  add(ColorSpace::kCieXyz, nullptr);
  config->setRole(OCIO::ROLE_SCENE_LINEAR, ocio_name(ColorSpace::kLinRec709).c_str());
  return config;
}

// Every processor, built once (OCIO processors are immutable and their CPU
// apply is thread-safe).  Lossless optimisation: the colour-space chains are
// matrices, composed exactly.
struct Processors {
  OCIO::ConstConfigRcPtr config = make_config();
  std::map<std::pair<ColorSpace, ColorSpace>, OCIO::ConstCPUProcessorRcPtr> convert;
  OCIO::ConstCPUProcessorRcPtr aces_view;

  Processors() {
    for (const auto& [from_name, from] : kColorSpaceNames)
      for (const auto& [to_name, to] : kColorSpaceNames)
        convert[{from, to}] = config->getProcessor(ocio_name(from).c_str(), ocio_name(to).c_str())
                                  ->getOptimizedCPUProcessor(OCIO::OPTIMIZATION_LOSSLESS);
    // ACES 1.0 SDR video for an sRGB display: scene Rec.709 → ACES2065-1 →
    // RRT + ODT (display XYZ, D65) → sRGB primaries and piecewise EOTF⁻¹.
    OCIO::GroupTransformRcPtr view = OCIO::GroupTransform::Create();
    OCIO::ColorSpaceTransformRcPtr to_ap0 = OCIO::ColorSpaceTransform::Create();
    to_ap0->setSrc(ocio_name(ColorSpace::kLinRec709).c_str());
    to_ap0->setDst(ocio_name(ColorSpace::kAces2065_1).c_str());
    view->appendTransform(to_ap0);
    view->appendTransform(builtin("ACES-OUTPUT - ACES2065-1_to_CIE-XYZ-D65 - SDR-VIDEO_1.0"));
    view->appendTransform(builtin("DISPLAY - CIE-XYZ-D65_to_sRGB"));
    aces_view = config->getProcessor(view)->getDefaultCPUProcessor();
  }
};

const Processors& processors() {
  static const Processors p;
  return p;
}

// OCIO takes an image row as `long` wide: large buffers go in pieces.
void apply(const OCIO::ConstCPUProcessorRcPtr& cpu, float* rgb, std::size_t n) {
  constexpr std::size_t kChunk = std::size_t{1} << 20;
  for (std::size_t i = 0; i < n; i += kChunk) {
    const std::size_t m = std::min(kChunk, n - i);
    OCIO::PackedImageDesc desc(rgb + 3 * i, static_cast<long>(m), 1, 3);
    cpu->apply(desc);
  }
}

}  // namespace

std::string_view name_of(ColorSpace c) { return name_in(kColorSpaceNames, c); }
std::string_view name_of(RadiometricUnits u) { return name_in(kRadiometricUnitsNames, u); }
std::string_view name_of(DisplayView v) { return name_in(kDisplayViewNames, v); }
std::optional<ColorSpace> color_space_named(std::string_view name) { return value_in(kColorSpaceNames, name); }
std::optional<RadiometricUnits> units_named(std::string_view name) { return value_in(kRadiometricUnitsNames, name); }
std::optional<DisplayView> view_named(std::string_view name) { return value_in(kDisplayViewNames, name); }

std::array<Chromaticity, 4> chromaticities_of(ColorSpace c) {
  switch (c) {
    case ColorSpace::kAcesCg: return kAp1Chromaticities;
    case ColorSpace::kAces2065_1: return kAp0Chromaticities;
    case ColorSpace::kCieXyz: return {{{1.0, 0.0}, {0.0, 1.0}, {0.0, 0.0}, {1.0 / 3.0, 1.0 / 3.0}}};
    case ColorSpace::kLinRec709: break;
  }
  return {kRec709Red, kRec709Green, kRec709Blue, kD65White};
}

void convert_color_space(ColorSpace from, ColorSpace to, float* rgb, std::size_t n) {
  if (from == to || n == 0) return;
  apply(processors().convert.at({from, to}), rgb, n);
}

double units_scale(RadiometricUnits u, double relative_scale) {
  switch (u) {
    case RadiometricUnits::kRelative: return relative_scale;
    case RadiometricUnits::kWM2Sr: return 1.0 / kMaxLuminousEfficacy;
    case RadiometricUnits::kCdM2: break;
  }
  return 1.0;
}

void apply_aces_srgb_view(float* rgb, std::size_t n) {
  if (n == 0) return;
  apply(processors().aces_view, rgb, n);
}

}  // namespace skyfarm
