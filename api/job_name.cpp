#include "api/job_name.h"

#include <cstdint>

namespace skyfarm::api {
namespace {

// Counts the code points of well-formed UTF-8 (RFC 3629: no overlong forms,
// no surrogates, at most U+10FFFF) that are not control characters (Unicode
// category Cc: U+0000-U+001F, U+007F-U+009F); nullopt for anything else.
std::optional<std::size_t> printable_code_points(const std::string& text) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < text.size();) {
    const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
    const unsigned char lead = byte(i);
    std::uint32_t cp = 0;
    std::size_t len = 0;
    if (lead < 0x80) {
      cp = lead, len = 1;
    } else if ((lead & 0xE0) == 0xC0) {
      cp = lead & 0x1Fu, len = 2;
    } else if ((lead & 0xF0) == 0xE0) {
      cp = lead & 0x0Fu, len = 3;
    } else if ((lead & 0xF8) == 0xF0) {
      cp = lead & 0x07u, len = 4;
    } else {
      return std::nullopt;
    }
    if (i + len > text.size()) return std::nullopt;
    for (std::size_t k = 1; k < len; ++k) {
      if ((byte(i + k) & 0xC0) != 0x80) return std::nullopt;
      cp = (cp << 6) | (byte(i + k) & 0x3Fu);
    }
    constexpr std::uint32_t kMinForLength[] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < kMinForLength[len] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return std::nullopt;
    if (cp < 0x20 || (cp >= 0x7F && cp <= 0x9F)) return std::nullopt;
    ++count;
    i += len;
  }
  return count;
}

}  // namespace

bool valid_job_name(const std::string& text) {
  const std::optional<std::size_t> n = printable_code_points(text);
  return n && *n >= 1 && *n <= kMaxJobNameChars;
}

void read_job_name(const Fields& top, std::optional<std::string>& out) {
  const Json* v = top.find_value("name");
  if (!v) return;
  static const std::string kRule = "must be a string of 1 to " + std::to_string(kMaxJobNameChars) +
                                   " printable characters (no control characters)";
  if (!v->is_string()) {
    top.errors().add(top.path_of("name"), kRule, value_text(*v));
    return;
  }
  const auto& s = v->get_ref<const std::string&>();
  if (s.empty()) return;
  if (!valid_job_name(s)) {
    const std::optional<std::size_t> n = printable_code_points(s);
    top.errors().add(top.path_of("name"), kRule,
                     n ? std::to_string(*n) + " characters" : std::string("a string with control characters or invalid UTF-8"));
    return;
  }
  out = s;
}

}  // namespace skyfarm::api
