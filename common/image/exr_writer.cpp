#include "common/image/exr_writer.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChromaticitiesAttribute.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfEnvmapAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <Imath/half.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <system_error>

#include "common/image/png_writer.h"

namespace skyfarm {

namespace {

// Rows converted and handed to OpenEXR at a time (bounds the staging memory
// of HALF output to 64 × width × 3 halves).
constexpr int kRowsPerBlock = 64;

// Imf::OStream over an AtomicFile.  OpenEXR writes the scan-line offset table
// from OutputFile's destructor and swallows any exception there, so the
// first failure is also remembered here and checked after the file is closed.
class AtomicOStream final : public Imf::OStream {
 public:
  explicit AtomicOStream(AtomicFile& file) : Imf::OStream(file.path().c_str()), file_(file) {}

  void write(const char c[], int n) override {
    guarded([&] { file_.write(c, static_cast<std::size_t>(n)); });
  }
  uint64_t tellp() override { return file_.tell(); }
  void seekp(uint64_t pos) override {
    guarded([&] { file_.seek(pos); });
  }
  const std::string& error() const { return error_; }

 private:
  template <class F>
  void guarded(F&& f) {
    if (!error_.empty()) throw FileWriteError(error_);
    try {
      f();
    } catch (const std::exception& e) {
      error_ = e.what();
      throw;
    }
  }
  AtomicFile& file_;
  std::string error_;
};

std::string shortest(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

Imf::Compression to_imf(ExrCompression c) {
  switch (c) {
    case ExrCompression::kNone: return Imf::NO_COMPRESSION;
    case ExrCompression::kPiz: return Imf::PIZ_COMPRESSION;
    case ExrCompression::kZip: break;
  }
  return Imf::ZIP_COMPRESSION;
}

float clamp_half(float v, std::size_t* clamped) {
  if (v > kHalfMax) {
    ++*clamped;
    return kHalfMax;
  }
  if (v < -kHalfMax) {
    ++*clamped;
    return -kHalfMax;
  }
  return v;
}

}  // namespace

std::string spectral_channel_name(double wavelength_nm) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, wavelength_nm, std::chars_format::fixed, 6);
  if (r.ec != std::errc()) throw std::invalid_argument("spectral_channel_name: wavelength out of range");
  std::string s(buf, r.ptr);
  std::replace(s.begin(), s.end(), '.', ',');
  return "S0." + s + "nm";
}

ExrWriteReport write_exr(const Image& image, const std::filesystem::path& path, const ExrWriteOptions& options) {
  const int w = image.width(), h = image.height();
  const bool spectral = options.spectral_channels && image.has_spectral();
  const bool error_layer = options.error_layer && image.has_error_layer();
  const Imf::PixelType rgb_type = options.half ? Imf::HALF : Imf::FLOAT;
  ExrWriteReport report;

  // Another colour space or other units: a converted copy of the RGB.  The
  // defaults write the image's buffer as it is (the bytes of before).
  const bool converted = options.color_space != ColorSpace::kLinRec709 || options.units != RadiometricUnits::kCdM2;
  double units_factor = 1.0;
  std::vector<float> converted_rgb;
  if (converted) {
    double relative = 1.0;
    if (options.units == RadiometricUnits::kRelative) {
      if (options.exposure_ev && !std::isfinite(*options.exposure_ev))
        throw std::invalid_argument("write_exr: exposure_ev must be finite");
      relative = exposure_scale(options.exposure_ev ? *options.exposure_ev : auto_exposure_ev(image));
    }
    units_factor = units_scale(options.units, relative);
    converted_rgb = image.rgb();
    convert_color_space(ColorSpace::kLinRec709, options.color_space, converted_rgb.data(), converted_rgb.size() / 3);
    if (units_factor != 1.0)
      for (float& v : converted_rgb) v = static_cast<float>(units_factor * static_cast<double>(v));
  }
  const std::vector<float>& rgb = converted ? converted_rgb : image.rgb();

  // HALF: count the values that will be clamped (the count goes into the header).
  if (options.half) {
    for (float v : rgb) (void)clamp_half(v, &report.clamped_half_values);
  }

  Imf::Header header(w, h);
  header.compression() = to_imf(options.compression);
  const std::array<Chromaticity, 4> prim = chromaticities_of(options.color_space);
  auto v2f = [](Chromaticity c) { return Imath::V2f(float(c.x), float(c.y)); };
  Imf::addChromaticities(header, Imf::Chromaticities(v2f(prim[0]), v2f(prim[1]), v2f(prim[2]), v2f(prim[3])));
  Imf::addWhiteLuminance(header, static_cast<float>(1.0 / units_factor));
  if (options.latlong_envmap) Imf::addEnvmap(header, Imf::ENVMAP_LATLONG);
  for (const auto& [key, value] : image.metadata()) {
    const std::string name = kExrMetadataPrefix + key;
    if (const auto* s = std::get_if<std::string>(&value))
      header.insert(name, Imf::StringAttribute(*s));
    else
      header.insert(name, Imf::DoubleAttribute(std::get<double>(value)));
  }
  if (options.color_space != ColorSpace::kLinRec709)
    header.insert(std::string(kExrMetadataPrefix) + metadata_key::kColorSpace,
                  Imf::StringAttribute(std::string(name_of(options.color_space))));
  if (options.units != RadiometricUnits::kCdM2) {
    header.insert(std::string(kExrMetadataPrefix) + metadata_key::kUnits,
                  Imf::StringAttribute(std::string(name_of(options.units))));
    header.insert(std::string(kExrMetadataPrefix) + metadata_key::kUnitsScale, Imf::DoubleAttribute(units_factor));
  }
  if (options.half)
    header.insert(std::string(kExrMetadataPrefix) + metadata_key::kHalfClampedValues,
                  Imf::DoubleAttribute(static_cast<double>(report.clamped_half_values)));

  Imf::ChannelList& channels = header.channels();
  for (const char* c : {"R", "G", "B"}) channels.insert(c, Imf::Channel(rgb_type));
  std::vector<std::string> spectral_names;
  if (spectral) {
    std::string edges;
    for (int b = 0; b < image.spectral_batches(); ++b) {
      spectral_names.push_back(spectral_channel_name(image.band_center_nm(b)));
      channels.insert(spectral_names.back(), Imf::Channel(Imf::FLOAT));
      edges += shortest(image.band_range(b).min_nm) + ",";
    }
    edges += shortest(image.band_range(image.spectral_batches() - 1).max_nm);
    header.insert("spectralLayoutVersion", Imf::StringAttribute(kSpectralLayoutVersion));
    header.insert("emissiveUnits", Imf::StringAttribute(kSpectralEmissiveUnits));
    header.insert(std::string(kExrMetadataPrefix) + metadata_key::kSpectralBandEdgesNm, Imf::StringAttribute(edges));
  }
  if (error_layer) {
    channels.insert(kExrErrorChannel, Imf::Channel(Imf::FLOAT));
    header.insert(std::string(kExrMetadataPrefix) + metadata_key::kErrorChannel,
                  Imf::StringAttribute("relative standard error of the pixel luminance, sqrt(Var[Y])/Y; "
                                       "+inf where the pixel has no estimate yet"));
  }

  AtomicFile file(path);
  AtomicOStream stream(file);
  try {
    Imf::OutputFile out(stream, header, /*numThreads=*/0);
    std::vector<half> staging;
    if (options.half) staging.resize(static_cast<std::size_t>(kRowsPerBlock) * static_cast<std::size_t>(w) * 3);
    const Imath::V2i origin(0, 0);
    for (int y0 = 0; y0 < h; y0 += kRowsPerBlock) {
      const int rows = std::min(kRowsPerBlock, h - y0);
      Imf::FrameBuffer fb;
      if (options.half) {
        const float* src = rgb.data() + static_cast<std::size_t>(y0) * static_cast<std::size_t>(w) * 3;
        const std::size_t n = static_cast<std::size_t>(rows) * static_cast<std::size_t>(w) * 3;
        std::size_t ignored = 0;
        for (std::size_t i = 0; i < n; ++i) staging[i] = half(clamp_half(src[i], &ignored));
        const char* names[3] = {"R", "G", "B"};
        for (int c = 0; c < 3; ++c)
          fb.insert(names[c], Imf::Slice::Make(Imf::HALF, staging.data() + c, Imath::V2i(0, y0), w, rows,
                                               3 * sizeof(half), 3 * sizeof(half) * static_cast<std::size_t>(w)));
      } else {
        const char* names[3] = {"R", "G", "B"};
        for (int c = 0; c < 3; ++c)
          fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, rgb.data() + c, origin, w, h, 3 * sizeof(float),
                                               3 * sizeof(float) * static_cast<std::size_t>(w)));
      }
      for (int b = 0; b < static_cast<int>(spectral_names.size()); ++b)
        fb.insert(spectral_names[static_cast<std::size_t>(b)],
                  Imf::Slice::Make(Imf::FLOAT, image.spectral_channel(b), origin, w, h, sizeof(float),
                                   sizeof(float) * static_cast<std::size_t>(w)));
      if (error_layer)
        fb.insert(kExrErrorChannel, Imf::Slice::Make(Imf::FLOAT, image.relative_error().data(), origin, w, h,
                                                     sizeof(float), sizeof(float) * static_cast<std::size_t>(w)));
      out.setFrameBuffer(fb);
      out.writePixels(rows);
    }
  } catch (const FileWriteError&) {
    throw;
  } catch (const std::exception& e) {
    if (!stream.error().empty()) throw FileWriteError(stream.error());
    throw FileWriteError("cannot write '" + path.string() + "': OpenEXR: " + e.what());
  }
  // The offset table was written (or not) by ~OutputFile.
  if (!stream.error().empty()) throw FileWriteError(stream.error());
  file.commit();
  return report;
}

ExrFile read_exr(const std::filesystem::path& path) {
  try {
    Imf::InputFile in(path.c_str(), /*numThreads=*/0);
    const Imf::Header& header = in.header();
    const Imath::Box2i dw = header.dataWindow();
    ExrFile f;
    f.width = dw.max.x - dw.min.x + 1;
    f.height = dw.max.y - dw.min.y + 1;
    const std::size_t n = static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height);
    Imf::FrameBuffer fb;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      ExrChannel& c = f.channels[it.name()];
      c.type = it.channel().type == Imf::HALF    ? ExrPixelType::kHalf
               : it.channel().type == Imf::FLOAT ? ExrPixelType::kFloat
                                                 : ExrPixelType::kUint;
      c.values.assign(n, 0.0f);
      fb.insert(it.name(), Imf::Slice::Make(Imf::FLOAT, c.values.data(), dw, sizeof(float),
                                            sizeof(float) * static_cast<std::size_t>(f.width)));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    for (auto it = header.begin(); it != header.end(); ++it) {
      const Imf::Attribute& a = it.attribute();
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&a))
        f.string_attributes[it.name()] = s->value();
      else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&a))
        f.number_attributes[it.name()] = d->value();
      else if (const auto* fl = dynamic_cast<const Imf::FloatAttribute*>(&a))
        f.number_attributes[it.name()] = fl->value();
      else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&a))
        f.number_attributes[it.name()] = i->value();
      else if (const auto* c = dynamic_cast<const Imf::ChromaticitiesAttribute*>(&a)) {
        const Imf::Chromaticities& v = c->value();
        f.chromaticities = std::array<Chromaticity, 4>{Chromaticity{v.red.x, v.red.y}, Chromaticity{v.green.x, v.green.y},
                                                       Chromaticity{v.blue.x, v.blue.y},
                                                       Chromaticity{v.white.x, v.white.y}};
      }
    }
    return f;
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read '" + path.string() + "': " + e.what());
  }
}

}  // namespace skyfarm
