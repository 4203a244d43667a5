#include "api/object_fields.h"

#include <cmath>

#include "api/surface_fields.h"

namespace skyfarm::api {
namespace {

constexpr Choice<ShapeKind> kShapes[] = {{"sphere", ShapeKind::kSphere},
                                         {"disc", ShapeKind::kDisc},
                                         {"rectangle", ShapeKind::kRectangle},
                                         {"box", ShapeKind::kBox},
                                         {"mesh", ShapeKind::kMesh}};
constexpr std::size_t kMaxNameChars = 64;
constexpr double kMinScale = 1e-6, kMaxScale = 1e6;
constexpr std::string_view kShorthandName = "albedo";

// "sha256:" and 64 lowercase hex digits.
bool asset_id_form(const std::string& s) {
  constexpr std::string_view prefix = "sha256:";
  if (s.size() != prefix.size() + 64 || s.compare(0, prefix.size(), prefix) != 0) return false;
  for (std::size_t i = prefix.size(); i < s.size(); ++i)
    if (!((s[i] >= '0' && s[i] <= '9') || (s[i] >= 'a' && s[i] <= 'f'))) return false;
  return true;
}

// A 3-vector field with each entry in `range`; absent leaves `out`.
void read_vec3(const Fields& f, std::string_view name, const Range& range, glm::dvec3& out) {
  const Json* v = f.find(name);
  if (!v) return;
  const auto values = read_number_array(*v, f.path_of(name), {3, 3, range, false}, f.errors());
  if (!values) {
    // read_number_array names the count or the first bad entry.
    return;
  }
  out = {(*values)[0], (*values)[1], (*values)[2]};
}

bool scale_ok(double s) { return std::abs(s) >= kMinScale && std::abs(s) <= kMaxScale; }

// "scale": a number or three; each non-zero with |s| in [kMinScale, kMaxScale].
void read_scale(const Fields& f, glm::dvec3& out) {
  const Json* v = f.find("scale");
  if (!v) return;
  const std::string path = f.path_of("scale");
  const std::string rule = "must be a number or 3 numbers, each with |s| in [1e-06, 1000000] (negative mirrors)";
  Errors& e = f.errors();
  if (v->is_number()) {
    const auto s = read_number(*v, path, Range::any(), e);
    if (!s) return;
    if (!scale_ok(*s)) {
      e.add(path, rule, value_text(*v));
      return;
    }
    out = glm::dvec3(*s);
    return;
  }
  if (!v->is_array()) {
    e.add(path, rule, value_text(*v));
    return;
  }
  const auto values = read_number_array(*v, path, {3, 3, Range::any(), false}, e);
  if (!values) return;
  for (std::size_t i = 0; i < 3; ++i)
    if (!scale_ok((*values)[i])) {
      e.add(index_path(path, i), rule, value_text((*v)[i]));
      return;
    }
  out = {(*values)[0], (*values)[1], (*values)[2]};
}

void read_object(const Fields& f, ObjectSpec& o) {
  f.allow_only({"name", "shape", "asset", "material", "albedo", "translate_m", "rotate_deg", "scale"});
  Errors& e = f.errors();
  if (const Json* name = f.find("name")) {
    if (name->is_string() && !name->get_ref<const std::string&>().empty() &&
        name->get_ref<const std::string&>().size() <= kMaxNameChars)
      o.name = name->get<std::string>();
    else
      e.add(f.path_of("name"), "must be a string of 1 to " + std::to_string(kMaxNameChars) + " characters",
            value_text(*name));
  }
  bool shape_read = false;
  if (!f.find("shape")) {
    e.add(f.path_of("shape"), "required (" + one_of_rule({"sphere", "disc", "rectangle", "box", "mesh"}) + ")");
  } else {
    shape_read = f.choice("shape", kShapes, o.shape);
  }
  const Json* asset = f.find("asset");
  if (shape_read && o.shape == ShapeKind::kMesh) {
    if (!asset) {
      e.add(f.path_of("asset"), "required for a mesh: the id POST /v1/assets answered (\"sha256:...\")");
    } else if (!asset->is_string() || !asset_id_form(asset->get_ref<const std::string&>())) {
      e.add(f.path_of("asset"), "must be an asset id, \"sha256:\" and 64 lowercase hex digits (POST /v1/assets)",
            value_text(*asset));
    } else {
      o.asset = asset->get<std::string>();
    }
  } else if (shape_read && asset) {
    e.add(f.path_of("asset"), "only for a mesh", value_text(*asset));
  }
  const Json* material = f.find("material");
  const Json* albedo = f.find("albedo");
  if (material && albedo) {
    e.add(f.path_of("albedo"), "give either material or albedo (its Lambertian shorthand), not both");
  } else if (material) {
    if (expect_object(*material, f.path_of("material"), e)) read_material(Fields(*material, f.path_of("material"), e), o.material);
  } else {
    double a = kDefaultObjectAlbedo;
    f.number("albedo", Range::closed(0, 1), a);
    o.material = lambertian_surface(a);
  }
  read_placement(f, o.placement);
}

Json vec3_json(const glm::dvec3& v) {
  return Json::array({canonical_number(v.x), canonical_number(v.y), canonical_number(v.z)});
}

}  // namespace

void read_placement(const Fields& f, Placement& out) {
  read_vec3(f, "translate_m", Range::closed(-kMaxObjectDistance_m, kMaxObjectDistance_m), out.translate_m);
  read_vec3(f, "rotate_deg", Range::closed(-360, 360), out.rotate_deg);
  // One spelling per orientation: each angle in (-180, 180] (fmod is exact).
  for (int i = 0; i < 3; ++i) {
    double& a = out.rotate_deg[i];
    a = std::fmod(a, 360.0);
    if (a > 180.0) a -= 360.0;
    if (a <= -180.0) a += 360.0;
  }
  read_scale(f, out.scale);
}

void placement_json(const Placement& placement, Json& out) {
  out["translate_m"] = vec3_json(placement.translate_m);
  out["rotate_deg"] = vec3_json(placement.rotate_deg);
  out["scale"] = vec3_json(placement.scale);
}

material::SurfaceSpec lambertian_surface(double albedo) {
  material::SurfaceSpec s;
  s.name = std::string(kShorthandName);
  s.custom = true;
  s.kind = material::MaterialKind::kDiffuse;
  s.wavelengths_nm = {kMinSpectralNm, kMaxSpectralNm};
  s.albedo = {albedo, albedo};
  return s;
}

bool is_lambertian_shorthand(const material::SurfaceSpec& s) {
  return s.custom && s.name == kShorthandName && s.kind == material::MaterialKind::kDiffuse && s.smooth() &&
         s.wavelengths_nm == std::vector<double>{kMinSpectralNm, kMaxSpectralNm} && s.albedo.size() == 2 &&
         s.albedo[0] == s.albedo[1] && s.distribution == material::MicrofacetModel::ggx && s.multiple_bounce;
}

void read_objects(const Fields& top, std::vector<ObjectSpec>& out) {
  const Json* v = top.find("objects");
  if (!v) return;
  const std::string path = top.path_of("objects");
  Errors& e = top.errors();
  if (!expect_array(*v, path, 0, kMaxObjects, e)) return;
  std::vector<ObjectSpec> objects(v->size());
  const std::size_t before = e.size();
  for (std::size_t i = 0; i < v->size(); ++i) {
    const std::string item = index_path(path, i);
    if (expect_object((*v)[i], item, e)) read_object(Fields((*v)[i], item, e), objects[i]);
  }
  if (e.size() == before) out = std::move(objects);
}

Json objects_json(const std::vector<ObjectSpec>& objects) {
  Json a = Json::array();
  for (const ObjectSpec& o : objects) {
    Json j = Json::object();
    if (!o.name.empty()) j["name"] = o.name;
    j["shape"] = std::string(name_of(kShapes, o.shape));
    if (o.shape == ShapeKind::kMesh) j["asset"] = o.asset;
    if (is_lambertian_shorthand(o.material))
      j["albedo"] = canonical_number(o.material.albedo[0]);
    else
      j["material"] = material_json(o.material);
    placement_json(o.placement, j);
    a.push_back(std::move(j));
  }
  return a;
}

}  // namespace skyfarm::api
