#include "common/material/material_library.h"

#include <array>
#include <stdexcept>
#include <utility>

#include "common/data/csv_table.h"
#include "common/data/embedded_files.h"

namespace skyfarm::material {
namespace {

constexpr std::array kIds = {
    MaterialId::kGold,  MaterialId::kSilver, MaterialId::kCopper, MaterialId::kAluminium, MaterialId::kChrome, MaterialId::kWater,
    MaterialId::kIce,   MaterialId::kBk7,    MaterialId::kFusedSilica, MaterialId::kGrass, MaterialId::kSand,
    MaterialId::kLoam,  MaterialId::kConcrete, MaterialId::kSnow,
};

constexpr std::array<std::string_view, kIds.size()> kNames = {
    "gold", "silver", "copper", "aluminium", "chrome", "water", "ice", "bk7", "fused_silica",
    "grass", "sand", "loam", "concrete", "snow",
};

std::size_t index_of(MaterialId id) { return static_cast<std::size_t>(id); }

// A `wavelength_nm, n_1, k_1` table of data/.
SpectralIor nk_table(std::string_view file, const std::string& name) {
  const CsvTable t = CsvTable::embedded(file);
  return SpectralIor::tabulated(t.column("wavelength_nm"), t.column("n_1"), t.column("k_1"), name);
}

SellmeierDispersion sellmeier_file(std::string_view file) {
  return SellmeierDispersion::parse_coefficients(embedded_file(file), "data/" + std::string(file));
}

SpectralAlbedo albedo_column(std::string_view file, std::string_view column, const std::string& name) {
  const CsvTable t = CsvTable::embedded(file);
  return SpectralAlbedo(t.column("wavelength_nm"), t.column(column), name);
}

Material load(MaterialId id) {
  const std::string name(material_name(id));
  constexpr std::string_view kGround = "ground_albedo_feister_grewe1995.csv";
  switch (id) {
    case MaterialId::kGold:
      return {name, MaterialKind::kConductor, nk_table("metal_nk_au_johnson_christy1972.csv", name)};
    case MaterialId::kSilver:
      return {name, MaterialKind::kConductor, nk_table("metal_nk_ag_johnson_christy1972.csv", name)};
    case MaterialId::kCopper:
      return {name, MaterialKind::kConductor, nk_table("metal_nk_cu_johnson_christy1972.csv", name)};
    case MaterialId::kAluminium:
      return {name, MaterialKind::kConductor, nk_table("metal_nk_al_rakic1995.csv", name)};
    case MaterialId::kChrome:
      return {name, MaterialKind::kConductor, nk_table("metal_nk_cr_johnson_christy1974.csv", name)};
    case MaterialId::kWater: {
      // Daimon's Sellmeier n is given to 5 decimals where Hale & Querry's
      // table has 3; the table supplies k, which the formula cannot.
      const CsvTable hq = CsvTable::embedded("water_nk_hale_querry1973.csv");
      return {name, MaterialKind::kDielectric,
              SpectralIor::sellmeier(sellmeier_file("water_sellmeier_daimon_masumura2007_20C.csv"),
                                     hq.column("wavelength_nm"), hq.column("k_1"), name)};
    }
    case MaterialId::kIce:
      return {name, MaterialKind::kDielectric, nk_table("ice_nk_warren_brandt2008.csv", name)};
    case MaterialId::kBk7: {
      const CsvTable k = CsvTable::embedded("glass_n_bk7_k_schott.csv");
      return {name, MaterialKind::kDielectric,
              SpectralIor::sellmeier(sellmeier_file("glass_n_bk7_sellmeier_schott.csv"), k.column("wavelength_nm"),
                                     k.column("k_1"), name)};
    }
    case MaterialId::kFusedSilica:
      return {name, MaterialKind::kDielectric,
              SpectralIor::sellmeier(sellmeier_file("fused_silica_sellmeier_malitson1965.csv"))};
    case MaterialId::kGrass:
      return {name, albedo_column(kGround, "grass_albedo_1", name)};
    case MaterialId::kSand:
      return {name, albedo_column(kGround, "sand_albedo_1", name)};
    case MaterialId::kLoam:
      return {name, albedo_column(kGround, "loam_albedo_1", name)};
    case MaterialId::kConcrete:
      return {name, albedo_column(kGround, "concrete_dry_albedo_1", name)};
    case MaterialId::kSnow:
      return {name, albedo_column("snow_albedo_bowker1985.csv", "dry_fresh_snow_reflectance_1", name)};
  }
  throw std::invalid_argument("unknown material id " + std::to_string(index_of(id)));
}

const std::vector<Material>& library() {
  static const std::vector<Material> materials = [] {
    std::vector<Material> all;
    all.reserve(kIds.size());
    for (const MaterialId id : kIds) all.push_back(load(id));
    return all;
  }();
  return materials;
}

}  // namespace

Material::Material(std::string name, MaterialKind kind, SpectralIor ior)
    : name_(std::move(name)), kind_(kind), constants_(std::move(ior)) {
  if (kind_ == MaterialKind::kDiffuse)
    throw std::invalid_argument(name_ + ": a material given by n and k is a conductor or a dielectric, not diffuse");
}

Material::Material(std::string name, SpectralAlbedo albedo)
    : name_(std::move(name)), kind_(MaterialKind::kDiffuse), constants_(std::move(albedo)) {}

const SpectralIor& Material::ior() const {
  if (const auto* ior = std::get_if<SpectralIor>(&constants_)) return *ior;
  throw std::logic_error(name_ + " is a diffuse material: it has an albedo, not an index of refraction");
}

const SpectralAlbedo& Material::albedo() const {
  if (const auto* albedo = std::get_if<SpectralAlbedo>(&constants_)) return *albedo;
  throw std::logic_error(name_ + " is given by its index of refraction, not by an albedo");
}

std::span<const MaterialId> all_material_ids() { return kIds; }

std::string_view material_name(MaterialId id) {
  const std::size_t i = index_of(id);
  if (i >= kNames.size()) throw std::invalid_argument("unknown material id " + std::to_string(i));
  return kNames[i];
}

std::optional<MaterialId> find_material(std::string_view name) {
  for (std::size_t i = 0; i < kNames.size(); ++i)
    if (kNames[i] == name) return kIds[i];
  return std::nullopt;
}

std::string known_material_names() {
  std::string out;
  for (const std::string_view name : kNames) {
    if (!out.empty()) out += ", ";
    out += name;
  }
  return out;
}

const Material& named_material(MaterialId id) { return library().at(index_of(id)); }

const Material& named_material(std::string_view name) {
  const std::optional<MaterialId> id = find_material(name);
  if (!id)
    throw std::invalid_argument("unknown material \"" + std::string(name) +
                                "\"; known materials: " + known_material_names());
  return named_material(*id);
}

Material custom_ior_material(std::string name, MaterialKind kind, const std::vector<double>& wavelengths_nm,
                             const std::vector<double>& n, const std::vector<double>& k) {
  SpectralIor ior = SpectralIor::tabulated(wavelengths_nm, n, k, name);
  return {std::move(name), kind, std::move(ior)};
}

Material custom_albedo_material(std::string name, const std::vector<double>& wavelengths_nm,
                                const std::vector<double>& albedo) {
  SpectralAlbedo table(wavelengths_nm, albedo, name);
  return {std::move(name), std::move(table)};
}

}  // namespace skyfarm::material
