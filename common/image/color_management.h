// Colour management of the written images, with OpenColorIO: the colour space
// of an EXR's RGB, the units of its values, and the display view of a PNG.
// Every conversion goes through the one OCIO config built in code here
// (color_management.cpp); nothing reads $OCIO or a config file.
//
// Parameters
//   ColorSpace (request output.color_space, envmap query color_space=): the
//   primaries of a written EXR's R, G, B, all linear, scene-referred:
//     lin_rec709   ITU-R BT.709 primaries, D65 white: the renderer's own RGB
//                  (Image::rgb), written as it is (default; unchanged bytes)
//     acescg       ACES AP1 primaries, ACES white (≈ D60) (S-2014-004, ACEScg)
//     aces2065-1   ACES AP0 primaries, ACES white (SMPTE ST 2065-1); AP0
//                  encloses the spectral locus, so no physical colour (the
//                  red sun at the horizon included) has a negative channel
//     cie_xyz      CIE 1931 X, Y, Z as computed from the spectrum: D65 is the
//                  adopted white (no chromatic adaptation; a D65 spectrum has
//                  X:Y:Z = 0.9505:1:1.089); the EXR's chromaticities are
//                  OpenEXR's convention for XYZ data, R (1, 0), G (0, 1),
//                  B (0, 0), white (1/3, 1/3) = the chromaticity of (1, 1, 1)
//   Rec.709 → ACES uses OCIO's BuiltinTransforms "UTILITY - ACES-AP0_to_CIE-
//   XYZ-D65_BFD" / "UTILITY - ACES-AP1_to_CIE-XYZ-D65_BFD" (inverted): a
//   Bradford adaptation D65 → ACES white, as the ACES configs do, so that a
//   D65-white pixel is neutral (R = G = B) in ACES.
//
//   RadiometricUnits (output.units, envmap query units=): what the values mean
//     cd_m2        absolute: Y in cd/m² (default)
//     relative     the values times the exposure scale of the image's PNG
//                  (png_writer.h): 0.18 · 2^(3 − EV100), EV100 = the
//                  request's exposure_ev or the automatic one (median lit
//                  luminance).  The metered luminance lands on 0.18, middle
//                  grey, so a Blender / Houdini / Nuke user loads the map with
//                  a strength (or gain) of 1 and sees the exposure of the PNG
//     w_m2_sr      radiometric equivalent: cd/m² / 683 lm/W (K_m), i.e. the
//                  radiance a 555 nm source of that luminance would have
//   Whatever the units, the EXR's standard whiteLuminance attribute says the
//   luminance, cd/m², of RGB (1, 1, 1) (1 / scale), and skyfarm:units_scale the
//   factor applied (divide by it to get cd/m² back).
//
//   DisplayView (output.view): how a PNG turns scene light into pixels
//     srgb         exposure, hard clip to [0, 1], sRGB encoding (default;
//                  unchanged bytes; png_writer.h)
//     aces         exposure, then the ACES 1.0 SDR video output transform
//                  (RRT + ODT, OCIO BuiltinTransform "ACES-OUTPUT -
//                  ACES2065-1_to_CIE-XYZ-D65 - SDR-VIDEO_1.0") and "DISPLAY -
//                  CIE-XYZ-D65_to_sRGB": a filmic tone scale that rolls bright
//                  light (the sun's glow) off to white instead of clipping, and
//                  desaturates only near white.  Scene middle grey 0.18 shows
//                  as ≈ 0.1 display-linear (the ACES reference), darker than
//                  the srgb view's 0.18.
//   No AgX view: OCIO 2.1 has no built-in AgX, and it needs its LUTs.
#pragma once
#include <array>
#include <cstddef>
#include <optional>
#include <string_view>
#include <utility>

#include "common/spectrum/color.h"

namespace skyfarm {

enum class ColorSpace { kLinRec709, kAcesCg, kAces2065_1, kCieXyz };
enum class RadiometricUnits { kCdM2, kRelative, kWM2Sr };
enum class DisplayView { kSrgb, kAces };

// Request / query names, in this order (the first is the default).
inline constexpr std::array<std::pair<std::string_view, ColorSpace>, 4> kColorSpaceNames{
    {{"lin_rec709", ColorSpace::kLinRec709},
     {"acescg", ColorSpace::kAcesCg},
     {"aces2065-1", ColorSpace::kAces2065_1},
     {"cie_xyz", ColorSpace::kCieXyz}}};
inline constexpr std::array<std::pair<std::string_view, RadiometricUnits>, 3> kRadiometricUnitsNames{
    {{"cd_m2", RadiometricUnits::kCdM2}, {"relative", RadiometricUnits::kRelative}, {"w_m2_sr", RadiometricUnits::kWM2Sr}}};
inline constexpr std::array<std::pair<std::string_view, DisplayView>, 2> kDisplayViewNames{
    {{"srgb", DisplayView::kSrgb}, {"aces", DisplayView::kAces}}};

std::string_view name_of(ColorSpace c);
std::string_view name_of(RadiometricUnits u);
std::string_view name_of(DisplayView v);
std::optional<ColorSpace> color_space_named(std::string_view name);
std::optional<RadiometricUnits> units_named(std::string_view name);
std::optional<DisplayView> view_named(std::string_view name);

// Published primaries and white, (x, y) each: red, green, blue, white.
//   AP0: SMPTE ST 2065-1:2012 §4.1.1; AP1: Academy S-2014-004 §4.1;
//   ACES white (0.32168, 0.33767) for both.
inline constexpr std::array<Chromaticity, 4> kAp0Chromaticities{
    {{0.7347, 0.2653}, {0.0, 1.0}, {0.0001, -0.0770}, {0.32168, 0.33767}}};
inline constexpr std::array<Chromaticity, 4> kAp1Chromaticities{
    {{0.713, 0.293}, {0.165, 0.830}, {0.128, 0.044}, {0.32168, 0.33767}}};
// The chromaticities attribute of each space (cie_xyz: OpenEXR's XYZ convention above).
std::array<Chromaticity, 4> chromaticities_of(ColorSpace c);

// Converts n interleaved RGB triples in place from one space to another
// (OCIO CPU processor, 32-bit float).  Thread-safe.
void convert_color_space(ColorSpace from, ColorSpace to, float* rgb, std::size_t n);

// 1 cd/m² in the units: 1, the relative scale given, 1/683.
double units_scale(RadiometricUnits u, double relative_scale);

// The ACES view: n interleaved linear Rec.709 triples (already exposed, scene
// middle grey at 0.18) to sRGB-encoded display values, in place, in [0, 1]
// up to rounding (the caller clamps).  Thread-safe.
void apply_aces_srgb_view(float* rgb, std::size_t n);

}  // namespace skyfarm
