#include "api/surface_fields.h"

#include <stdexcept>

#include "common/material/surface.h"

namespace skyfarm::api {
namespace {

using material::MaterialKind;
using material::MicrofacetModel;

constexpr Choice<MaterialKind> kKinds[] = {{"conductor", MaterialKind::kConductor},
                                           {"dielectric", MaterialKind::kDielectric},
                                           {"diffuse", MaterialKind::kDiffuse}};
constexpr Choice<MicrofacetModel> kDistributions[] = {{"ggx", MicrofacetModel::ggx},
                                                      {"beckmann", MicrofacetModel::beckmann}};
constexpr std::size_t kMaxLabelChars = 64;

std::string roughness_rule() {
  return "must be 0 (smooth) or in [" + format_number(material::kMinRoughness) + ", " +
         format_number(material::kMaxRoughness) + "]";
}

std::optional<double> read_alpha(const Json& v, const std::string& path, Errors& e) {
  const std::optional<double> a = read_number(v, path, Range::closed(0, material::kMaxRoughness), e);
  if (!a) return std::nullopt;
  if (*a != 0.0 && *a < material::kMinRoughness) {
    e.add(path, roughness_rule(), value_text(v));
    return std::nullopt;
  }
  return a;
}

// "roughness": alpha, or [alpha_x, alpha_y] (both 0 or both rough).
void read_roughness(const Fields& f, material::SurfaceSpec& out) {
  const Json* v = f.find("roughness");
  if (!v) return;
  const std::string path = f.path_of("roughness");
  Errors& e = f.errors();
  if (v->is_array()) {
    if (!expect_array(*v, path, 2, 2, e)) return;
    const auto x = read_alpha((*v)[0], index_path(path, 0), e);
    const auto y = read_alpha((*v)[1], index_path(path, 1), e);
    if (!x || !y) return;
    if ((*x == 0.0) != (*y == 0.0)) {
      e.add(path, "must be both 0 (smooth) or both rough", value_text(*v));
      return;
    }
    out.roughness_x = *x;
    out.roughness_y = *y;
  } else if (const auto a = read_alpha(*v, path, e)) {
    out.roughness_x = out.roughness_y = *a;
  }
}

// A table of the custom material, as long as wavelengths_nm.
bool read_column(const Fields& f, std::string_view name, const Range& range, std::size_t count,
                 std::vector<double>& out) {
  const Json* v = f.find(name);
  if (!v) {
    f.errors().add(f.path_of(name), "required");
    return false;
  }
  auto values = read_number_array(*v, f.path_of(name), {1, kMaxTableEntries, range, false}, f.errors());
  if (!values) return false;
  if (values->size() != count) {
    f.errors().add(f.path_of(name), "must have as many entries as wavelengths_nm (" + std::to_string(count) + ")",
                   entries_text(values->size()));
    return false;
  }
  out = std::move(*values);
  return true;
}

void forbid(const Fields& f, std::string_view name, const std::string& why) {
  if (const Json* v = f.find(name)) f.errors().add(f.path_of(name), why, value_text(*v));
}

// The custom material's tables; false if any is invalid.
bool read_tables(const Fields& f, material::SurfaceSpec& s) {
  Errors& e = f.errors();
  const std::size_t before = e.size();
  const Json* kind = f.find("kind");
  if (!kind) {
    e.add(f.path_of("kind"), "required with tables (" + one_of_rule({"conductor", "dielectric", "diffuse"}) + ")");
    return false;
  }
  if (!f.choice("kind", kKinds, s.kind)) return false;
  const Json* w = f.find("wavelengths_nm");
  if (!w) {
    e.add(f.path_of("wavelengths_nm"), "required with tables");
    return false;
  }
  auto wl = read_number_array(*w, f.path_of("wavelengths_nm"),
                              {2, kMaxTableEntries, Range::closed(kMinSpectralNm, kMaxSpectralNm), true}, e);
  if (!wl) return false;
  s.wavelengths_nm = std::move(*wl);
  const std::size_t count = s.wavelengths_nm.size();
  switch (s.kind) {
    case MaterialKind::kConductor:
      forbid(f, "albedo", "not allowed for a conductor (it has n and k)");
      read_column(f, "n", Range::open_closed(0, 100), count, s.n);
      read_column(f, "k", Range::closed(0, 100), count, s.k);
      break;
    case MaterialKind::kDielectric:
      forbid(f, "albedo", "not allowed for a dielectric (it has n and k)");
      // A dielectric under air has n >= 1 (n < 1 would mean total internal
      // reflection from the air side: not a material of this world).
      read_column(f, "n", Range::closed(1, 10), count, s.n);
      if (f.find("k")) read_column(f, "k", Range::closed(0, 10), count, s.k);
      break;
    case MaterialKind::kDiffuse:
      forbid(f, "n", "not allowed for a diffuse material (it has an albedo)");
      forbid(f, "k", "not allowed for a diffuse material (it has an albedo)");
      read_column(f, "albedo", Range::closed(0, 1), count, s.albedo);
      break;
  }
  return e.size() == before;
}

}  // namespace

void read_material(const Fields& f, material::SurfaceSpec& s) {
  f.allow_only({"name", "kind", "wavelengths_nm", "n", "k", "albedo", "roughness", "distribution",
                "multiple_bounce"});
  Errors& e = f.errors();
  const std::size_t before = e.size();
  const bool tables = f.find("wavelengths_nm") || f.find("n") || f.find("k") || f.find("albedo");
  const Json* name = f.find("name");
  if (name && !(name->is_string() && !name->get_ref<const std::string&>().empty() &&
                name->get_ref<const std::string&>().size() <= kMaxLabelChars)) {
    e.add(f.path_of("name"), "must be a string of 1 to " + std::to_string(kMaxLabelChars) + " characters",
          value_text(*name));
    name = nullptr;
  }
  bool ok = true;
  if (tables) {
    s.custom = true;
    s.name = name ? name->get<std::string>() : "custom";
    ok = read_tables(f, s);
  } else {
    forbid(f, "kind", "only for a custom material (with wavelengths_nm and its tables)");
    if (!f.find("name")) {
      e.add(f.path_of("name"), "required: a named material or a custom one with tables (known materials: " +
                                   material::known_material_names() + ")");
      ok = false;
    } else if (name) {
      s.name = name->get<std::string>();
      if (const auto id = material::find_material(s.name)) {
        s.kind = material::named_material(*id).kind();
      } else {
        e.add(f.path_of("name"), "unknown material (known materials: " + material::known_material_names() + ")",
              value_text(*name));
        ok = false;
      }
    } else {
      ok = false;
    }
  }
  read_roughness(f, s);
  f.choice("distribution", kDistributions, s.distribution);
  f.boolean("multiple_bounce", s.multiple_bounce);
  if (!ok || e.size() != before) return;
  // The tables' own rules (optical_constants.h) and anything the field rules
  // above did not catch: one error on the material, nothing built.
  try {
    const material::Surface surface(s);
  } catch (const std::exception& ex) {
    e.add(f.path(), ex.what());
  }
}

namespace {

Json column_json(const std::vector<double>& values) {
  Json a = Json::array();
  for (double x : values) a.push_back(x == 0.0 ? 0.0 : x);
  return a;
}

}  // namespace

void read_ground(const Fields& f, AtmosphereSpec& out) {
  const Json* v = f.find("ground");
  if (!v) return;
  const std::string path = f.path_of("ground");
  Errors& e = f.errors();
  if (f.find("ground_albedo")) {
    e.add(path, "give either ground or ground_albedo (its Lambertian shorthand), not both");
    return;
  }
  if (!expect_object(*v, path, e)) return;
  Fields ground(*v, path, e);
  ground.allow_only({"material"});
  const Json* m = ground.find("material");
  if (!m) {
    e.add(ground.path_of("material"), "required");
    return;
  }
  if (!expect_object(*m, ground.path_of("material"), e)) return;
  material::SurfaceSpec s;
  const std::size_t before = e.size();
  read_material(Fields(*m, ground.path_of("material"), e), s);
  if (e.size() == before) out.ground_material = std::move(s);
}

Json ground_json(const material::SurfaceSpec& s) { return {{"material", material_json(s)}}; }

Json material_json(const material::SurfaceSpec& s) {
  Json m = {{"name", s.name},
            {"roughness", Json::array({s.roughness_x, s.roughness_y})},
            {"distribution", name_of(kDistributions, s.distribution)},
            {"multiple_bounce", s.multiple_bounce}};
  if (s.custom) {
    m["kind"] = name_of(kKinds, s.kind);
    m["wavelengths_nm"] = column_json(s.wavelengths_nm);
    if (s.kind == MaterialKind::kDiffuse) {
      m["albedo"] = column_json(s.albedo);
    } else {
      m["n"] = column_json(s.n);
      if (!s.k.empty()) m["k"] = column_json(s.k);
    }
  }
  return m;
}

}  // namespace skyfarm::api
