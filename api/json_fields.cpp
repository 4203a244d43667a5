#include "api/json_fields.h"

#include <charconv>
#include <cmath>
#include <set>
#include <utility>

#include "api/surface_fields.h"

namespace skyfarm::api {
namespace {

constexpr std::size_t kPreviewChars = 80;  // value text in messages
constexpr std::size_t kMaxKeyChars = 64;   // unknown keys quoted in paths
constexpr double kInf = std::numeric_limits<double>::infinity();

// --- Value previews: short, bounded, never recursing far or throwing.

// A JSON string literal of at most ~60 bytes of `s` (ASCII, escaped).
std::string quoted(const std::string& s) {
  constexpr std::size_t kMax = 60;
  const bool cut = s.size() > kMax;
  std::string head = cut ? s.substr(0, kMax) : s;
  std::string out = Json(head).dump(-1, ' ', true, Json::error_handler_t::replace);
  if (cut) out.insert(out.size() - 1, "...");
  return out;
}

std::string non_finite_text(double x) {
  return std::isnan(x) ? "NaN" : (x > 0 ? "Infinity" : "-Infinity");
}

void append_preview(const Json& v, std::string& out, int depth) {
  if (v.is_object() || v.is_array()) {
    const bool object = v.is_object();
    if (v.empty()) {
      out += object ? "{}" : "[]";
      return;
    }
    if (depth >= 3) {
      out += object ? "{...}" : "[...]";
      return;
    }
    out += object ? '{' : '[';
    bool first = true;
    for (auto it = v.begin(); it != v.end(); ++it) {
      if (!first) out += ',';
      if (out.size() > kPreviewChars) {
        out += "...";
        break;
      }
      first = false;
      if (object) out += quoted(it.key()) + ':';
      append_preview(it.value(), out, depth + 1);
    }
    out += object ? '}' : ']';
  } else if (v.is_string()) {
    out += quoted(v.get_ref<const std::string&>());
  } else if (v.is_number_float() && !std::isfinite(v.get<double>())) {
    out += non_finite_text(v.get<double>());
  } else {
    out += v.dump();
  }
}

// Text from the client as it may appear in a path or a rule: at most `max`
// bytes, control characters escaped, invalid UTF-8 replaced.
std::string printable(std::string_view text, std::size_t max) {
  const bool cut = text.size() > max;
  if (cut) {
    while (max > 0 && (static_cast<unsigned char>(text[max]) & 0xC0) == 0x80) --max;
    text = text.substr(0, max);
  }
  std::string s = Json(std::string(text)).dump(-1, ' ', false, Json::error_handler_t::replace);
  s = s.substr(1, s.size() - 2);  // without the quotes
  return cut ? s + "..." : s;
}

// A key as it may appear in a path.
std::string safe_key(const std::string& key) { return printable(key, kMaxKeyChars); }

std::string join(const std::vector<std::string_view>& names) {
  std::string s;
  for (auto n : names) {
    if (!s.empty()) s += ", ";
    s += n;
  }
  return s;
}

// --- Body scanner: a SAX pass before the DOM is built.  It rejects malformed
// JSON, deep nesting (without recursion) and numbers that overflow a double
// (by path), and reports duplicate keys.
class BodyScanner final : public nlohmann::json_sax<Json> {
 public:
  explicit BodyScanner(Errors& errors) : errors_(errors) {}
  std::optional<FieldError> fatal;

  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override { return open(false); }
  bool key(string_t& k) override {
    Frame& f = frames_.back();
    f.key = safe_key(k);
    if (!f.keys.insert(k).second) errors_.add(current_path(), "duplicate field");
    return true;
  }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(true); }
  bool end_array() override { return close(); }
  bool parse_error(std::size_t, const std::string& token, const nlohmann::detail::exception& ex) override {
    if (ex.id == 406) {  // out_of_range.406: a number that overflows a double ("1e999")
      fatal = FieldError{current_path(), "must be a finite number", token.substr(0, kPreviewChars)};
      return false;
    }
    std::string what = ex.what();
    if (auto p = what.find("] "); what.starts_with("[json.exception") && p != std::string::npos)
      what = what.substr(p + 2);
    fatal = FieldError{"", "malformed JSON: " + printable(what, 4 * kPreviewChars), ""};  // may quote the input
    return false;
  }

 private:
  struct Frame {
    bool array = false;
    std::size_t index = 0;
    std::string key;
    std::set<std::string> keys;
  };

  bool open(bool array) {
    if (frames_.size() >= static_cast<std::size_t>(kMaxJsonDepth)) {
      fatal = FieldError{"", "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels", ""};
      return false;
    }
    frames_.push_back(Frame{array, 0, {}, {}});
    return true;
  }
  bool close() {
    frames_.pop_back();
    return value();
  }
  bool value() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
    return true;
  }
  std::string current_path() const {
    std::string p;
    for (const auto& f : frames_) p = f.array ? index_path(p, f.index) : child_path(p, f.key);
    return p;
  }

  Errors& errors_;
  std::vector<Frame> frames_;
};

// --- Atmosphere names.
constexpr Choice<AtmospherePreset> kPresets[] = {{"earth", AtmospherePreset::kEarth},
                                                 {"earth_clear", AtmospherePreset::kEarthClear},
                                                 {"custom", AtmospherePreset::kCustom}};
constexpr Choice<AerosolPhase> kAerosolPhases[] = {
    {"henyey_greenstein", AerosolPhase::kHenyeyGreenstein},
    {"cornette_shanks", AerosolPhase::kCornetteShanks}};
enum class DensityType { kExponential, kTable, kLayers };
constexpr Choice<DensityType> kDensityTypes[] = {{"exponential", DensityType::kExponential},
                                                 {"table", DensityType::kTable},
                                                 {"layers", DensityType::kLayers}};
enum class PhaseType { kRayleigh, kHenyeyGreenstein, kCornetteShanks, kTable };
constexpr Choice<PhaseType> kPhaseTypes[] = {{"rayleigh", PhaseType::kRayleigh},
                                             {"henyey_greenstein", PhaseType::kHenyeyGreenstein},
                                             {"cornette_shanks", PhaseType::kCornetteShanks},
                                             {"table", PhaseType::kTable}};
constexpr std::size_t kMaxConstituents = 16;
constexpr std::size_t kMaxDensityLayers = 8;
constexpr std::size_t kMaxNameChars = 64;

// --- Tables of two parallel arrays (x, y) in one object.
bool read_xy(const Fields& f, std::string_view x_name, const ArrayRule& x_rule,
             std::string_view y_name, const ArrayRule& y_rule, std::vector<double>& x,
             std::vector<double>& y) {
  Errors& e = f.errors();
  std::optional<std::vector<double>> xs, ys;
  if (const Json* v = f.find(x_name)) xs = read_number_array(*v, f.path_of(x_name), x_rule, e);
  else e.add(f.path_of(x_name), "required");
  if (const Json* v = f.find(y_name)) ys = read_number_array(*v, f.path_of(y_name), y_rule, e);
  else e.add(f.path_of(y_name), "required");
  if (!xs || !ys) return false;
  if (xs->size() != ys->size()) {
    e.add(f.path_of(y_name),
          "must have as many entries as " + std::string(x_name) + " (" + std::to_string(xs->size()) + ")",
          entries_text(ys->size()));
    return false;
  }
  x = std::move(*xs);
  y = std::move(*ys);
  return true;
}

// Reads a required number field.
void required_number(const Fields& f, std::string_view name, const Range& range, double& out) {
  if (!f.find(name)) f.errors().add(f.path_of(name), "required");
  else f.number(name, range, out);
}

// --- "atmosphere.aerosol"
AerosolSpec read_aerosol(const Fields& f) {
  f.allow_only({"optical_depth_550", "angstrom_exponent", "asymmetry", "single_scattering_albedo", "phase"});
  AerosolSpec a;
  f.number("optical_depth_550", Range::closed(0, 10), a.optical_depth_550);
  f.number("angstrom_exponent", Range::closed(-1, 4), a.angstrom_exponent);
  f.number("asymmetry", Range::closed(-0.999, 0.999), a.asymmetry);
  f.number("single_scattering_albedo", Range::closed(0, 1), a.single_scattering_albedo);
  f.choice("phase", kAerosolPhases, a.phase);
  return a;
}

// --- "atmosphere.ground_albedo": a number or a spectral table, both in [0, 1].
void read_ground_albedo(const Fields& f, AlbedoSpec& out) {
  const Json* v = f.find("ground_albedo");
  if (!v) return;
  const std::string path = f.path_of("ground_albedo");
  Errors& e = f.errors();
  if (v->is_object()) {
    if (auto t = read_spectral_table(*v, path, 1.0, e)) out = std::move(*t);
  } else if (v->is_number()) {
    if (auto x = read_number(*v, path, Range::closed(0, 1), e)) out = *x;
  } else {
    e.add(path, "must be a number or an object {wavelengths_nm, values}", value_text(*v));
  }
}

// --- A constituent's "density"
DensitySpec read_density(const Fields& f) {
  Errors& e = f.errors();
  const Json* t = f.find("type");
  if (!t) {
    e.add(f.path_of("type"), "required");
    return {};
  }
  auto type = read_choice(*t, f.path_of("type"), kDensityTypes, e);
  if (!type) return {};
  switch (*type) {
    case DensityType::kExponential: {
      f.allow_only({"type", "scale_height_m"});
      ExponentialDensity d;
      required_number(f, "scale_height_m", Range::open_closed(0, 1e7), d.scale_height_m);
      return d;
    }
    case DensityType::kTable: {
      f.allow_only({"type", "altitude_m", "values"});
      TableDensity d;
      read_xy(f, "altitude_m", {2, kMaxTableEntries, Range::at_least(0), true}, "values",
              {1, kMaxTableEntries, Range::at_least(0), false}, d.altitude_m, d.values);
      return d;
    }
    case DensityType::kLayers: {
      f.allow_only({"type", "layers"});
      LayersDensity d;
      const Json* layers = f.find("layers");
      const std::string path = f.path_of("layers");
      if (!layers) e.add(path, "required");
      else if (expect_array(*layers, path, 1, kMaxDensityLayers, e))
        for (std::size_t i = 0; i < layers->size(); ++i) {
          const std::string lp = index_path(path, i);
          if (!expect_object((*layers)[i], lp, e)) continue;
          Fields lf((*layers)[i], lp, e);
          lf.allow_only({"width_m", "exp_term", "exp_scale_per_m", "linear_term_per_m", "constant_term"});
          DensityLayer l;
          lf.number("width_m", Range::at_least(0), l.width_m);
          lf.number("exp_term", Range::any(), l.exp_term);
          lf.number("exp_scale_per_m", Range::any(), l.exp_scale_per_m);
          lf.number("linear_term_per_m", Range::any(), l.linear_term_per_m);
          lf.number("constant_term", Range::any(), l.constant_term);
          d.layers.push_back(l);
        }
      return d;
    }
  }
  return {};
}

// --- A constituent's "phase"
std::optional<PhaseSpec> read_phase(const Fields& f) {
  Errors& e = f.errors();
  const Json* t = f.find("type");
  if (!t) {
    e.add(f.path_of("type"), "required");
    return std::nullopt;
  }
  auto type = read_choice(*t, f.path_of("type"), kPhaseTypes, e);
  if (!type) return std::nullopt;
  const Range g_range = Range::closed(-0.999, 0.999);
  switch (*type) {
    case PhaseType::kRayleigh: {
      f.allow_only({"type", "depolarization"});
      RayleighPhaseSpec p;
      f.number("depolarization", Range::closed(0, 0.5), p.depolarization);
      return p;
    }
    case PhaseType::kHenyeyGreenstein: {
      f.allow_only({"type", "g"});
      HenyeyGreensteinPhaseSpec p;
      required_number(f, "g", g_range, p.g);
      return p;
    }
    case PhaseType::kCornetteShanks: {
      f.allow_only({"type", "g"});
      CornetteShanksPhaseSpec p;
      required_number(f, "g", g_range, p.g);
      return p;
    }
    case PhaseType::kTable: {
      f.allow_only({"type", "angles_deg", "values"});
      TablePhaseSpec p;
      if (!read_xy(f, "angles_deg", {2, kMaxTableEntries, Range::closed(0, 180), true}, "values",
                   {1, kMaxTableEntries, Range::at_least(0), false}, p.angles_deg, p.values))
        return p;
      const std::string ap = f.path_of("angles_deg");
      const Json& angles = *f.find("angles_deg");
      if (p.angles_deg.front() != 0.0)
        e.add(index_path(ap, 0), "must be 0 (the table spans 0 to 180 degrees)", value_text(angles[0]));
      else if (p.angles_deg.back() != 180.0)
        e.add(index_path(ap, angles.size() - 1), "must be 180 (the table spans 0 to 180 degrees)",
              value_text(angles.back()));
      bool all_zero = true;
      for (double v : p.values) all_zero = all_zero && v == 0.0;
      if (all_zero) e.add(f.path_of("values"), "must not be all 0");
      return p;
    }
  }
  return std::nullopt;
}

// --- A constituent's "name": 1-64 characters of [A-Za-z0-9_-].
std::optional<std::string> read_constituent_name(const Fields& f) {
  Errors& e = f.errors();
  const Json* v = f.find("name");
  const std::string path = f.path_of("name");
  if (!v) {
    e.add(path, "required");
    return std::nullopt;
  }
  bool ok = v->is_string();
  if (ok) {
    const auto& s = v->get_ref<const std::string&>();
    ok = !s.empty() && s.size() <= kMaxNameChars;
    for (char c : s)
      ok = ok && ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-');
  }
  if (!ok) {
    e.add(path, "must be 1 to 64 characters of A-Z, a-z, 0-9, _ and -", value_text(*v));
    return std::nullopt;
  }
  return v->get<std::string>();
}

// --- One entry of "atmosphere.constituents"
ConstituentSpec read_constituent(const Fields& f) {
  Errors& e = f.errors();
  f.allow_only({"name", "density", "scattering_per_m", "absorption_per_m", "phase"});
  ConstituentSpec c;
  if (auto name = read_constituent_name(f)) c.name = *name;
  if (const Json* d = f.find("density")) {
    if (expect_object(*d, f.path_of("density"), e)) c.density = read_density(Fields(*d, f.path_of("density"), e));
  } else {
    e.add(f.path_of("density"), "required");
  }
  const Json* scattering = f.find_value("scattering_per_m");
  const Json* absorption = f.find_value("absorption_per_m");
  if (scattering)
    if (auto t = read_spectral_table(*scattering, f.path_of("scattering_per_m"), kInf, e)) c.scattering_per_m = *t;
  if (absorption)
    if (auto t = read_spectral_table(*absorption, f.path_of("absorption_per_m"), kInf, e)) c.absorption_per_m = *t;
  if (!scattering && !absorption) e.add(f.path(), "must have scattering_per_m or absorption_per_m");
  if (const Json* p = f.find_value("phase")) {
    if (expect_object(*p, f.path_of("phase"), e))
      if (auto phase = read_phase(Fields(*p, f.path_of("phase"), e))) c.phase = *phase;
  } else if (scattering) {
    e.add(f.path_of("phase"), "required when scattering_per_m is given");
  }
  return c;
}

// --- "atmosphere.constituents": 1..16 entries with unique names.
std::vector<ConstituentSpec> read_constituents(const Json& v, const std::string& path, Errors& e) {
  std::vector<ConstituentSpec> out;
  if (!expect_array(v, path, 1, kMaxConstituents, e)) return out;
  std::set<std::string> names;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = index_path(path, i);
    if (!expect_object(v[i], p, e)) continue;
    ConstituentSpec c = read_constituent(Fields(v[i], p, e));
    if (!c.name.empty() && !names.insert(c.name).second)
      e.add(child_path(p, "name"), "must be unique", value_text(v[i]["name"]));
    out.push_back(std::move(c));
  }
  return out;
}

// --- Canonical writers of the atmosphere parts.
Json numbers_json(const std::vector<double>& xs) {
  Json a = Json::array();
  for (double x : xs) a.push_back(canonical_number(x));
  return a;
}

Json density_json(const DensitySpec& d) {
  if (const auto* e = std::get_if<ExponentialDensity>(&d))
    return {{"type", "exponential"}, {"scale_height_m", canonical_number(e->scale_height_m)}};
  if (const auto* t = std::get_if<TableDensity>(&d))
    return {{"type", "table"}, {"altitude_m", numbers_json(t->altitude_m)}, {"values", numbers_json(t->values)}};
  Json layers = Json::array();
  for (const auto& l : std::get<LayersDensity>(d).layers)
    layers.push_back({{"width_m", canonical_number(l.width_m)},
                      {"exp_term", canonical_number(l.exp_term)},
                      {"exp_scale_per_m", canonical_number(l.exp_scale_per_m)},
                      {"linear_term_per_m", canonical_number(l.linear_term_per_m)},
                      {"constant_term", canonical_number(l.constant_term)}});
  return {{"type", "layers"}, {"layers", layers}};
}

Json phase_json(const PhaseSpec& p) {
  if (const auto* r = std::get_if<RayleighPhaseSpec>(&p))
    return {{"type", "rayleigh"}, {"depolarization", canonical_number(r->depolarization)}};
  if (const auto* hg = std::get_if<HenyeyGreensteinPhaseSpec>(&p))
    return {{"type", "henyey_greenstein"}, {"g", canonical_number(hg->g)}};
  if (const auto* cs = std::get_if<CornetteShanksPhaseSpec>(&p))
    return {{"type", "cornette_shanks"}, {"g", canonical_number(cs->g)}};
  const auto& t = std::get<TablePhaseSpec>(p);
  return {{"type", "table"}, {"angles_deg", numbers_json(t.angles_deg)}, {"values", numbers_json(t.values)}};
}

// An empty table means "absent" (0 for a constituent's coefficients).
Json optional_table_json(const SpectralTable& t) {
  return t.wavelengths_nm.empty() ? Json(nullptr) : spectral_table_json(t);
}

Json constituent_json(const ConstituentSpec& c) {
  const bool scatters = !c.scattering_per_m.wavelengths_nm.empty();
  return {{"name", c.name},
          {"density", density_json(c.density)},
          {"scattering_per_m", optional_table_json(c.scattering_per_m)},
          {"absorption_per_m", optional_table_json(c.absorption_per_m)},
          {"phase", scatters ? phase_json(c.phase) : Json(nullptr)}};
}

Json aerosol_json(const AerosolSpec& a) {
  return {{"optical_depth_550", canonical_number(a.optical_depth_550)},
          {"angstrom_exponent", canonical_number(a.angstrom_exponent)},
          {"asymmetry", canonical_number(a.asymmetry)},
          {"single_scattering_albedo", canonical_number(a.single_scattering_albedo)},
          {"phase", std::string(name_of(kAerosolPhases, a.phase))}};
}

// A one-entry albedo table is a constant: written as the number.
Json albedo_json(const AlbedoSpec& albedo) {
  if (const auto* x = std::get_if<double>(&albedo)) return canonical_number(*x);
  const auto& t = std::get<SpectralTable>(albedo);
  if (t.values.size() == 1) return canonical_number(t.values[0]);
  return spectral_table_json(t);
}

}  // namespace

// === Errors ================================================================

void Errors::add(std::string path, std::string rule, std::string value) {
  if (full_) return;
  if (list_.size() == kMaxErrors) {
    list_.push_back(FieldError{"", "too many errors; only the first " + std::to_string(kMaxErrors) + " are listed", ""});
    full_ = true;
    return;
  }
  list_.push_back(FieldError{std::move(path), std::move(rule), std::move(value)});
}

void Errors::throw_if_any() const {
  if (!list_.empty()) throw ValidationError(list_);
}

std::string value_text(const Json& value) {
  std::string out;
  append_preview(value, out, 0);
  return out;
}

// === Numbers and ranges ====================================================

bool Range::contains(double x) const {
  const bool above = lo_open ? x > lo : x >= lo;
  const bool below = hi_open ? x < hi : x <= hi;
  return above && below;
}

std::string Range::text() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi)
    return std::string(" in ") + (lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) +
           (hi_open ? ")" : "]");
  if (has_lo) return (lo_open ? " > " : " >= ") + format_number(lo);
  if (has_hi) return (hi_open ? " < " : " <= ") + format_number(hi);
  return "";
}

std::string format_number(double x) {
  if (std::isfinite(x) && x == std::trunc(x) && std::fabs(x) < 1e16)
    return std::to_string(static_cast<long long>(x));
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, res.ptr);
}

std::string child_path(const std::string& path, std::string_view name) {
  return path.empty() ? std::string(name) : path + "." + std::string(name);
}

std::string index_path(const std::string& path, std::size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

std::string entries_text(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " entry" : " entries");
}

std::string one_of_rule(std::initializer_list<std::string_view> names) {
  return one_of_rule(std::vector<std::string_view>(names));
}

std::string one_of_rule(const std::vector<std::string_view>& names) {
  return "must be one of " + join(names);
}

// === Scalar readers ========================================================

std::optional<double> read_number(const Json& v, const std::string& path, const Range& range,
                                  Errors& errors, std::string_view context) {
  if (!v.is_number()) {
    errors.add(path, "must be a number", value_text(v));
    return std::nullopt;
  }
  const double x = v.get<double>();
  if (!std::isfinite(x)) {
    errors.add(path, "must be a finite number", value_text(v));
    return std::nullopt;
  }
  if (!range.contains(x)) {
    errors.add(path, "must be a number" + range.text() + std::string(context), value_text(v));
    return std::nullopt;
  }
  return x;
}

std::optional<std::int64_t> read_integer(const Json& v, const std::string& path, std::int64_t lo,
                                         std::int64_t hi, Errors& errors) {
  const std::string range_rule =
      "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!v.is_number()) {
    errors.add(path, "must be an integer", value_text(v));
    return std::nullopt;
  }
  if (v.is_number_unsigned()) {
    const auto u = v.get<std::uint64_t>();
    if (hi < 0 || u > static_cast<std::uint64_t>(hi) || static_cast<std::int64_t>(u) < lo) {
      errors.add(path, range_rule, value_text(v));
      return std::nullopt;
    }
    return static_cast<std::int64_t>(u);
  }
  if (v.is_number_integer()) {
    const auto i = v.get<std::int64_t>();
    if (i < lo || i > hi) {
      errors.add(path, range_rule, value_text(v));
      return std::nullopt;
    }
    return i;
  }
  const double d = v.get<double>();
  if (std::isnan(d) || (std::isfinite(d) && d != std::trunc(d))) {
    errors.add(path, "must be an integer", value_text(v));
    return std::nullopt;
  }
  if (!(d >= static_cast<double>(lo) && d <= static_cast<double>(hi))) {
    errors.add(path, range_rule, value_text(v));
    return std::nullopt;
  }
  return static_cast<std::int64_t>(d);
}

std::optional<std::uint64_t> read_uint64(const Json& v, const std::string& path, Errors& errors) {
  const std::string range_rule = "must be an integer in [0, 18446744073709551615]";
  if (!v.is_number()) {
    errors.add(path, "must be an integer", value_text(v));
    return std::nullopt;
  }
  if (v.is_number_unsigned()) return v.get<std::uint64_t>();
  if (v.is_number_integer()) {
    const auto i = v.get<std::int64_t>();
    if (i < 0) {
      errors.add(path, range_rule, value_text(v));
      return std::nullopt;
    }
    return static_cast<std::uint64_t>(i);
  }
  const double d = v.get<double>();
  if (std::isnan(d) || (std::isfinite(d) && d != std::trunc(d))) {
    errors.add(path, "must be an integer", value_text(v));
    return std::nullopt;
  }
  if (!(d >= 0.0 && d < 18446744073709551616.0)) {  // 2^64
    errors.add(path, range_rule, value_text(v));
    return std::nullopt;
  }
  return static_cast<std::uint64_t>(d);
}

std::optional<bool> read_boolean(const Json& v, const std::string& path, Errors& errors) {
  if (!v.is_boolean()) {
    errors.add(path, "must be a boolean", value_text(v));
    return std::nullopt;
  }
  return v.get<bool>();
}

// === Arrays ================================================================

bool expect_array(const Json& v, const std::string& path, std::size_t min_count,
                  std::size_t max_count, Errors& errors) {
  if (!v.is_array()) {
    errors.add(path, "must be an array", value_text(v));
    return false;
  }
  if (v.size() < min_count || v.size() > max_count) {
    errors.add(path, "must have " + std::to_string(min_count) + " to " + std::to_string(max_count) + " entries",
               entries_text(v.size()));
    return false;
  }
  return true;
}

std::optional<std::vector<double>> read_number_array(const Json& v, const std::string& path,
                                                     const ArrayRule& rule, Errors& errors) {
  if (!expect_array(v, path, rule.min_count, rule.max_count, errors)) return std::nullopt;
  std::vector<double> out;
  out.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = index_path(path, i);
    auto x = read_number(v[i], p, rule.range, errors);
    if (!x) return std::nullopt;
    if (rule.increasing && i > 0 && !(*x > out.back())) {
      errors.add(p, "must be greater than the previous entry (" + value_text(v[i - 1]) + ")",
                 value_text(v[i]));
      return std::nullopt;
    }
    out.push_back(*x);
  }
  return out;
}

// === Objects ===============================================================

bool expect_object(const Json& v, const std::string& path, Errors& errors) {
  if (v.is_object()) return true;
  errors.add(path, "must be an object", value_text(v));
  return false;
}

void Fields::allow_only(std::initializer_list<std::string_view> allowed) const {
  for (auto it = object_->begin(); it != object_->end(); ++it) {
    bool known = false;
    for (auto a : allowed) known = known || a == it.key();
    if (known) continue;
    errors_->add(child_path(path_, safe_key(it.key())),
                 "unknown field (allowed: " + join(std::vector<std::string_view>(allowed)) + ")");
  }
}

const Json* Fields::find(std::string_view name) const {
  auto it = object_->find(std::string(name));
  return it == object_->end() ? nullptr : &*it;
}

const Json* Fields::find_value(std::string_view name) const {
  const Json* v = find(name);
  return v && !v->is_null() ? v : nullptr;
}

bool Fields::number(std::string_view name, const Range& range, double& out) const {
  const Json* v = find(name);
  if (!v) return false;
  auto x = read_number(*v, path_of(name), range, *errors_);
  if (x) out = *x;
  return x.has_value();
}

bool Fields::optional_number(std::string_view name, const Range& range, std::optional<double>& out) const {
  const Json* v = find(name);
  if (!v) return false;
  if (v->is_null()) {
    out.reset();
    return true;
  }
  if (!v->is_number()) {
    errors_->add(path_of(name), "must be a number or null", value_text(*v));
    return false;
  }
  auto x = read_number(*v, path_of(name), range, *errors_);
  if (x) out = *x;
  return x.has_value();
}

bool Fields::integer(std::string_view name, std::int64_t lo, std::int64_t hi, int& out) const {
  const Json* v = find(name);
  if (!v) return false;
  auto x = read_integer(*v, path_of(name), lo, hi, *errors_);
  if (x) out = static_cast<int>(*x);
  return x.has_value();
}

bool Fields::boolean(std::string_view name, bool& out) const {
  const Json* v = find(name);
  if (!v) return false;
  auto x = read_boolean(*v, path_of(name), *errors_);
  if (x) out = *x;
  return x.has_value();
}

// === Body parsing ==========================================================

Json parse_json_object(std::string_view text, Errors& errors) {
  BodyScanner scanner(errors);
  const bool ok = Json::sax_parse(text.begin(), text.end(), &scanner);
  if (scanner.fatal) throw ValidationError({*scanner.fatal});
  Json body = ok ? Json::parse(text.begin(), text.end(), nullptr, false) : Json(Json::value_t::discarded);
  if (body.is_discarded()) throw ValidationError({FieldError{"", "malformed JSON", ""}});
  if (!body.is_object()) throw ValidationError({FieldError{"", "must be a JSON object", value_text(body)}});
  return body;
}

// === Spectral tables =======================================================

std::optional<SpectralTable> read_spectral_table(const Json& v, const std::string& path,
                                                 double max_value, Errors& errors, std::size_t min_count) {
  if (!v.is_object()) {
    errors.add(path, "must be an object {wavelengths_nm, values}", value_text(v));
    return std::nullopt;
  }
  Fields f(v, path, errors);
  f.allow_only({"wavelengths_nm", "values"});
  const Range values = std::isfinite(max_value) ? Range::closed(0, max_value) : Range::at_least(0);
  SpectralTable t;
  if (!read_xy(f, "wavelengths_nm", {min_count, kMaxTableEntries, Range::open_closed(0, 1e5), true}, "values",
               {1, kMaxTableEntries, values, false}, t.wavelengths_nm, t.values))
    return std::nullopt;
  return t;
}

Json spectral_table_json(const SpectralTable& table) {
  return {{"wavelengths_nm", numbers_json(table.wavelengths_nm)}, {"values", numbers_json(table.values)}};
}

// === Shared request fields =================================================

// "location"
void read_location(const Fields& top, Location& out) {
  const Json* v = top.find("location");
  if (!v || !expect_object(*v, top.path_of("location"), top.errors())) return;
  Fields f(*v, top.path_of("location"), top.errors());
  f.allow_only({"latitude_deg", "longitude_deg", "altitude_m"});
  f.number("latitude_deg", Range::closed(-90, 90), out.latitude_deg);
  f.number("longitude_deg", Range::closed(-180, 180), out.longitude_deg);
  f.number("altitude_m", Range::closed(0, 1e8), out.altitude_m);
}

// "time": ISO 8601 with a UTC offset, years 1800-2200; null = absent.
void read_time(const Fields& top, std::optional<UtcInstant>& time, std::optional<std::string>& time_text) {
  read_instant(top, "time", time, time_text);
}

void read_instant(const Fields& f, std::string_view name, std::optional<UtcInstant>& time,
                  std::optional<std::string>& time_text) {
  const Json* v = f.find_value(name);
  if (!v) return;
  Errors& e = f.errors();
  const std::string path = f.path_of(name);
  if (!v->is_string()) {
    e.add(path, "must be a string (ISO 8601 with a UTC offset)", value_text(*v));
    return;
  }
  const auto& s = v->get_ref<const std::string&>();
  std::string why;
  auto t = parse_iso8601(s, &why);
  if (!t) {
    why = printable(why, kPreviewChars);  // the reason may quote the rest of the text
    e.add(path, "must be ISO 8601 with a UTC offset" + (why.empty() ? std::string() : " (" + why + ")"),
          value_text(*v));
    return;
  }
  const int year = utc_year(*t);
  if (year < kMinYear || year > kMaxYear) {
    e.add(path, "year must be in [" + std::to_string(kMinYear) + ", " + std::to_string(kMaxYear) + "]",
          value_text(*v));
    return;
  }
  time = *t;
  time_text = s;
}

// "sun": both angles or neither.
void read_sun(const Fields& top, SunSpec& out) {
  const Json* v = top.find("sun");
  Errors& e = top.errors();
  if (!v || !expect_object(*v, top.path_of("sun"), e)) return;
  Fields f(*v, top.path_of("sun"), e);
  f.allow_only({"zenith_deg", "azimuth_deg", "angular_radius_deg", "irradiance"});
  f.optional_number("zenith_deg", Range::closed(0, 180), out.zenith_deg);
  f.optional_number("azimuth_deg", Range::closed(0, 360), out.azimuth_deg);
  const bool zenith = f.find_value("zenith_deg"), azimuth = f.find_value("azimuth_deg");
  if (zenith && !azimuth) e.add(f.path_of("azimuth_deg"), "required when sun.zenith_deg is given");
  if (azimuth && !zenith) e.add(f.path_of("zenith_deg"), "required when sun.azimuth_deg is given");
  f.number("angular_radius_deg", Range::closed(0, 5), out.angular_radius_deg);
  // The sun's own table is 0 outside its wavelengths, so one entry is no constant: >= 2.
  if (const Json* irr = f.find_value("irradiance"))
    out.irradiance = read_spectral_table(*irr, f.path_of("irradiance"), kInf, e, 2);
}

void require_time_or_sun(const Fields& top) {
  if (top.find_value("time")) return;
  if (const Json* sun = top.find("sun")) {
    if (!sun->is_object()) return;  // reported by read_sun
    const bool zenith = sun->contains("zenith_deg") && !(*sun)["zenith_deg"].is_null();
    const bool azimuth = sun->contains("azimuth_deg") && !(*sun)["azimuth_deg"].is_null();
    if (zenith || azimuth) return;  // both given, or "both or neither" reported by read_sun
  }
  top.errors().add(top.path_of("time"), "required unless sun.zenith_deg and sun.azimuth_deg are given");
}

// "atmosphere": preset plus overrides; constituents with preset custom only.
void read_atmosphere(const Fields& top, AtmosphereSpec& out) {
  const Json* v = top.find("atmosphere");
  Errors& e = top.errors();
  if (!v || !expect_object(*v, top.path_of("atmosphere"), e)) return;
  Fields f(*v, top.path_of("atmosphere"), e);
  f.allow_only({"preset", "ozone_du", "aerosol", "ground_albedo", "ground", "planet_radius_m", "top_altitude_m",
                "constituents", "refraction"});
  const bool preset_ok = !f.find("preset") || f.choice("preset", kPresets, out.preset);
  const bool custom = preset_ok && out.preset == AtmospherePreset::kCustom;
  const bool earth = preset_ok && !custom;
  if (out.preset == AtmospherePreset::kEarthClear) out.aerosol.reset();

  if (const Json* ozone = f.find("ozone_du")) {
    if (custom) e.add(f.path_of("ozone_du"), "not allowed with preset custom", value_text(*ozone));
    else f.number("ozone_du", Range::closed(0, 1000), out.ozone_du);
  }
  if (const Json* aerosol = f.find("aerosol")) {
    const std::string path = f.path_of("aerosol");
    if (custom) e.add(path, "not allowed with preset custom", value_text(*aerosol));
    else if (aerosol->is_null()) out.aerosol.reset();
    else if (expect_object(*aerosol, path, e)) out.aerosol = read_aerosol(Fields(*aerosol, path, e));
  }
  read_ground_albedo(f, out.ground_albedo);
  read_ground(f, out);
  f.number("planet_radius_m", Range::closed(1e5, 1e8), out.planet_radius_m);
  f.number("top_altitude_m", Range::closed(1e3, 1e7), out.top_altitude_m);
  f.boolean("refraction", out.refraction);

  const std::string cpath = f.path_of("constituents");
  if (const Json* c = f.find("constituents")) {
    if (earth) e.add(cpath, "only allowed with preset custom");
    else out.constituents = read_constituents(*c, cpath, e);
  } else if (custom) {
    e.add(cpath, "required with preset custom");
  }
  if (custom) {  // the preset's own air, ozone and aerosols are not used
    out.ozone_du = 0.0;
    out.aerosol.reset();
  }
}

void read_method(const Fields& top, Method& out) { top.choice("method", kMethods, out); }

void read_seed(const Fields& top, std::uint64_t& out) {
  if (const Json* v = top.find("seed"))
    if (auto s = read_uint64(*v, top.path_of("seed"), top.errors())) out = *s;
}

// === Canonical forms =======================================================

double canonical_number(double x) { return x == 0.0 ? 0.0 : x; }

double canonical_azimuth(double deg) { return deg == 360.0 ? 0.0 : canonical_number(deg); }

Json optional_number_json(const std::optional<double>& x) {
  return x ? Json(canonical_number(*x)) : Json(nullptr);
}

Json location_json(const Location& location) {
  return {{"latitude_deg", canonical_number(location.latitude_deg)},
          {"longitude_deg", canonical_number(location.longitude_deg)},
          {"altitude_m", canonical_number(location.altitude_m)}};
}

Json time_json(const std::optional<UtcInstant>& time) {
  return time ? Json(time->to_iso8601()) : Json(nullptr);
}

Json sun_json(const SunSpec& sun) {
  std::optional<double> azimuth = sun.azimuth_deg;
  if (azimuth) *azimuth = canonical_azimuth(*azimuth);
  return {{"zenith_deg", optional_number_json(sun.zenith_deg)},
          {"azimuth_deg", optional_number_json(azimuth)},
          {"angular_radius_deg", canonical_number(sun.angular_radius_deg)},
          {"irradiance", sun.irradiance ? spectral_table_json(*sun.irradiance) : Json(nullptr)}};
}

// earth_clear is earth without aerosols: both are written as preset "earth"
// with an explicit "aerosol" (null or the object), so that they hash alike.
Json atmosphere_json(const AtmosphereSpec& a) {
  const bool custom = a.preset == AtmospherePreset::kCustom;
  Json j = {{"preset", custom ? "custom" : "earth"},
            {"planet_radius_m", canonical_number(a.planet_radius_m)},
            {"top_altitude_m", canonical_number(a.top_altitude_m)}};
  // Only a ground that is a material writes "ground" (and then no
  // ground_albedo): the canonical text of every other request (its hash, its
  // job's seed) is as it always was.
  if (a.ground_material) j["ground"] = ground_json(*a.ground_material);
  else j["ground_albedo"] = albedo_json(a.ground_albedo);
  if (custom) {
    Json cs = Json::array();
    for (const auto& c : a.constituents) cs.push_back(constituent_json(c));
    j["constituents"] = cs;
  } else {
    j["ozone_du"] = canonical_number(a.ozone_du);
    j["aerosol"] = a.aerosol ? aerosol_json(*a.aerosol) : Json(nullptr);
  }
  // Written only when on, like "ground": requests without it keep their text.
  if (a.refraction) j["refraction"] = true;
  return j;
}

}  // namespace skyfarm::api
