#include "common/image/png_writer.h"

#include <png.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "common/spectrum/color.h"

namespace skyfarm {

namespace {

// --- libpng error handling ---------------------------------------------------
// libpng reports errors through a callback that must not return; we longjmp
// back to the setjmp in encode_png / read_png_header / read_png_rows.  Those
// functions, the callbacks and libpng's own (C) frames hold no object with a
// destructor, so the longjmp skips none (C++ [csetjmp.syn]/4); everything
// that owns memory lives in the callers, which never call setjmp.
struct PngErrorState {
  char message[256];
};

void on_png_error(png_structp png, png_const_charp msg) {
  auto* st = static_cast<PngErrorState*>(png_get_error_ptr(png));
  if (st != nullptr) {
    std::strncpy(st->message, msg != nullptr ? msg : "unknown libpng error", sizeof st->message - 1);
    st->message[sizeof st->message - 1] = '\0';
  }
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

// Appends to a std::vector<png_byte>; a failed allocation becomes a libpng
// error (the try block has ended, so nothing is live when png_error jumps).
void on_png_write(png_structp png, png_bytep data, png_size_t n) {
  auto* out = static_cast<std::vector<png_byte>*>(png_get_io_ptr(png));
  bool ok = true;
  try {
    out->insert(out->end(), data, data + n);
  } catch (...) {
    ok = false;
  }
  if (!ok) png_error(png, "out of memory while encoding");
}

void on_png_flush(png_structp) {}

bool encode_png(png_structp png, png_infop info, png_uint_32 w, png_uint_32 h, int depth, png_bytepp rows,
                png_textp texts, int n_texts) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_IHDR(png, info, w, h, depth, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  if (n_texts > 0) png_set_text(png, info, texts, n_texts);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, info);
  return true;
}

struct PngHeader {
  png_uint_32 width, height;
  int bit_depth;
  int srgb;
};

bool read_png_header(png_structp png, png_infop info, std::FILE* fp, PngHeader* hdr) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, fp);
  png_read_info(png, info);
  int bit_depth = 0, color_type = 0;
  png_get_IHDR(png, info, &hdr->width, &hdr->height, &bit_depth, &color_type, nullptr, nullptr, nullptr);
  int intent = 0;
  hdr->srgb = png_get_sRGB(png, info, &intent) != 0;
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (color_type == PNG_COLOR_TYPE_GRAY && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (color_type == PNG_COLOR_TYPE_GRAY || color_type == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
  if (color_type & PNG_COLOR_MASK_ALPHA) png_set_strip_alpha(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_strip_alpha(png);
  png_read_update_info(png, info);
  hdr->bit_depth = png_get_bit_depth(png, info) == 16 ? 16 : 8;
  return true;
}

bool read_png_rows(png_structp png, png_infop info, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, info);
  return true;
}

// PNG keyword: 1–79 Latin-1 printable characters (PNG spec §11.3.4.2).
std::string png_keyword(const std::string& key) {
  std::string k = key.substr(0, 79);
  for (char& c : k) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u < 32 || u > 126) c = '_';
  }
  if (k.empty()) k.push_back('_');
  if (k.front() == ' ') k.front() = '_';
  if (k.back() == ' ') k.back() = '_';
  return k;
}

std::string shortest(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// Encodes RGB rows (8 or 16 bits, sRGB) with iTXt text chunks (UTF-8; long
// values compressed) and writes the file atomically.
void write_png_rows(const std::filesystem::path& path, int w, int h, int bit_depth, png_bytepp rows,
                    std::vector<std::pair<std::string, std::string>>& entries) {
  std::vector<png_text> texts(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    png_text& t = texts[i];
    std::memset(&t, 0, sizeof t);
    t.compression = entries[i].second.size() > 1024 ? PNG_ITXT_COMPRESSION_zTXt : PNG_ITXT_COMPRESSION_NONE;
    t.key = entries[i].first.data();
    t.text = entries[i].second.data();
    t.itxt_length = entries[i].second.size();
    t.lang = nullptr;
    t.lang_key = nullptr;
  }

  std::vector<png_byte> encoded;
  PngErrorState err{};
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, on_png_error, on_png_warning);
  if (png == nullptr) throw FileWriteError("cannot write '" + path.string() + "': libpng initialisation failed");
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    throw FileWriteError("cannot write '" + path.string() + "': libpng initialisation failed");
  }
  png_set_write_fn(png, &encoded, on_png_write, on_png_flush);
  const bool ok = encode_png(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), bit_depth, rows,
                             texts.data(), static_cast<int>(texts.size()));
  png_destroy_write_struct(&png, &info);
  if (!ok) throw FileWriteError("cannot write '" + path.string() + "': libpng: " + err.message);

  AtomicFile::write_file(path, encoded.data(), encoded.size());
}

}  // namespace

double exposure_scale(double ev100) { return kMiddleGrey * std::exp2(3.0 - ev100); }

double auto_exposure_ev(const Image& image, double percentile) {
  if (!(percentile > 0.0 && percentile < 1.0))
    throw std::invalid_argument("auto_exposure_ev: percentile " + std::to_string(percentile) +
                                " must be in (0, 1)");
  const std::size_t n = image.pixel_count();
  const std::size_t stride = std::max<std::size_t>(1, n >> 20);
  const std::vector<float>& rgb = image.rgb();
  std::vector<float> lit;
  lit.reserve(n / stride + 1);
  for (std::size_t i = 0; i < n; i += stride) {
    const double y = kLinearSrgbToXyz[1][0] * rgb[3 * i] + kLinearSrgbToXyz[1][1] * rgb[3 * i + 1] +
                     kLinearSrgbToXyz[1][2] * rgb[3 * i + 2];
    if (y > 0.0 && std::isfinite(y)) lit.push_back(static_cast<float>(y));
  }
  if (lit.empty()) return 0.0;
  // Nearest rank on the sorted values: k = round(p (m − 1)).
  const std::size_t k = static_cast<std::size_t>(std::llround(percentile * static_cast<double>(lit.size() - 1)));
  std::nth_element(lit.begin(), lit.begin() + static_cast<std::ptrdiff_t>(k), lit.end());
  return std::log2(8.0 * static_cast<double>(lit[k]));
}

PngWriteReport write_png(const Image& image, const std::filesystem::path& path, const PngWriteOptions& options) {
  if (options.bit_depth != 8 && options.bit_depth != 16)
    throw std::invalid_argument("write_png: bit_depth " + std::to_string(options.bit_depth) + " must be 8 or 16");
  if (options.exposure_ev && !std::isfinite(*options.exposure_ev))
    throw std::invalid_argument("write_png: exposure_ev must be finite");
  PngWriteReport report{};
  report.exposure_ev = options.exposure_ev ? *options.exposure_ev : auto_exposure_ev(image, options.auto_percentile);
  report.scale = exposure_scale(report.exposure_ev);

  const int w = image.width(), h = image.height();
  const int bytes_per_sample = options.bit_depth / 8;
  const std::size_t row_bytes = static_cast<std::size_t>(w) * 3 * static_cast<std::size_t>(bytes_per_sample);
  const double max_code = options.bit_depth == 16 ? 65535.0 : 255.0;
  std::vector<png_byte> pixels(row_bytes * static_cast<std::size_t>(h));
  const std::vector<float>& rgb = image.rgb();
  // The ACES view: exposed scene light through OCIO's output transform, to
  // encoded display values (color_management.h); srgb: clip, then encode.
  std::vector<float> display;
  if (options.view == DisplayView::kAces) {
    display.resize(rgb.size());
    for (std::size_t i = 0; i < rgb.size(); ++i) {
      const double v = report.scale * static_cast<double>(rgb[i]);
      display[i] = std::isfinite(v) ? static_cast<float>(v) : (v > 0 ? 65504.0f : 0.0f);
    }
    apply_aces_srgb_view(display.data(), display.size() / 3);
  }
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    double encoded;
    if (options.view == DisplayView::kAces) {
      const double v = static_cast<double>(display[i]);
      encoded = std::isnan(v) ? 0.0 : std::clamp(v, 0.0, 1.0);
    } else {
      double v = report.scale * static_cast<double>(rgb[i]);
      v = std::isnan(v) ? 0.0 : std::clamp(v, 0.0, 1.0);
      encoded = srgb_encode(v);
    }
    const auto code = static_cast<std::uint32_t>(std::lround(encoded * max_code));
    if (bytes_per_sample == 1) {
      pixels[i] = static_cast<png_byte>(code);
    } else {  // PNG stores 16-bit samples big-endian
      pixels[2 * i] = static_cast<png_byte>(code >> 8);
      pixels[2 * i + 1] = static_cast<png_byte>(code & 0xFFu);
    }
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(h));
  for (int y = 0; y < h; ++y) rows[static_cast<std::size_t>(y)] = pixels.data() + row_bytes * static_cast<std::size_t>(y);

  std::vector<std::pair<std::string, std::string>> entries;
  for (const auto& [key, value] : image.metadata()) {
    const auto* s = std::get_if<std::string>(&value);
    entries.emplace_back(png_keyword(kMetadataPrefix + key), s ? *s : shortest(std::get<double>(value)));
  }
  entries.emplace_back(std::string(kMetadataPrefix) + metadata_key::kExposureEv100, shortest(report.exposure_ev));
  entries.emplace_back(std::string(kMetadataPrefix) + metadata_key::kExposureScale, shortest(report.scale));
  // Only a non-default view is named: the default's bytes stay as they were.
  if (options.view != DisplayView::kSrgb) entries.emplace_back(std::string(kMetadataPrefix) + metadata_key::kView, std::string(name_of(options.view)));
  write_png_rows(path, w, h, options.bit_depth, rows.data(), entries);
  return report;
}

void write_png_rgb8(const std::filesystem::path& path, int width, int height, const std::vector<std::uint8_t>& rgb,
                    const std::map<std::string, std::string>& text) {
  if (width < 1 || height < 1 || rgb.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3)
    throw std::invalid_argument("write_png_rgb8: " + std::to_string(rgb.size()) + " bytes for " +
                                std::to_string(width) + " x " + std::to_string(height) + " RGB pixels");
  std::vector<png_bytep> rows(static_cast<std::size_t>(height));
  auto* data = const_cast<png_byte*>(rgb.data());  // libpng's row pointers are not const; it only reads them
  for (int y = 0; y < height; ++y) rows[static_cast<std::size_t>(y)] = data + static_cast<std::size_t>(y) * width * 3;
  std::vector<std::pair<std::string, std::string>> entries;
  for (const auto& [key, value] : text) entries.emplace_back(png_keyword(key), value);
  write_png_rows(path, width, height, 8, rows.data(), entries);
}

PngFile read_png(const std::filesystem::path& path) {
  std::FILE* fp = std::fopen(path.c_str(), "rb");
  if (fp == nullptr) {
    const int e = errno;
    throw std::runtime_error("cannot read '" + path.string() + "': " + std::strerror(e));
  }
  PngErrorState err{};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, on_png_error, on_png_warning);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr) {
    png_destroy_read_struct(png != nullptr ? &png : nullptr, nullptr, nullptr);
    std::fclose(fp);
    throw std::runtime_error("cannot read '" + path.string() + "': libpng initialisation failed");
  }
  PngHeader hdr{};
  PngFile f;
  bool ok = read_png_header(png, info, fp, &hdr);
  std::vector<png_byte> pixels;
  std::vector<png_bytep> rows;
  if (ok) {
    f.width = static_cast<int>(hdr.width);
    f.height = static_cast<int>(hdr.height);
    f.bit_depth = hdr.bit_depth;
    f.has_srgb_chunk = hdr.srgb != 0;
    const std::size_t row_bytes = png_get_rowbytes(png, info);
    try {
      pixels.resize(row_bytes * hdr.height);
      rows.resize(hdr.height);
    } catch (...) {
      png_destroy_read_struct(&png, &info, nullptr);
      std::fclose(fp);
      throw;
    }
    for (png_uint_32 y = 0; y < hdr.height; ++y) rows[y] = pixels.data() + row_bytes * y;
    ok = read_png_rows(png, info, rows.data());
  }
  if (ok) {
    png_textp texts = nullptr;
    int n = 0;
    png_get_text(png, info, &texts, &n);
    for (int i = 0; i < n; ++i)
      f.text[texts[i].key] = std::string(texts[i].text, texts[i].compression >= PNG_ITXT_COMPRESSION_NONE
                                                            ? texts[i].itxt_length
                                                            : texts[i].text_length);
  }
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(fp);
  if (!ok) throw std::runtime_error("cannot read '" + path.string() + "': libpng: " + err.message);

  const std::size_t n = static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height) * 3;
  f.rgb.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    f.rgb[i] = f.bit_depth == 16 ? static_cast<std::uint16_t>((pixels[2 * i] << 8) | pixels[2 * i + 1]) : pixels[i];
  return f;
}

}  // namespace skyfarm
