// Named materials and their spectral constants, and custom ones from tables.
//
// Parameters
//   name   one of the known names (lower case, exact):
//            conductors (n + i k, tabulated)
//              gold, silver, copper  Johnson & Christy (1972), evaporated films
//              aluminium             Rakić (1995), evaporated film
//              chrome                Johnson & Christy (1974), chromium films
//            dielectrics (n + i k)
//              water         n: Daimon & Masumura (2007) Sellmeier, 20 °C;
//                            k: Hale & Querry (1973), 25 °C
//              ice           n, k: Warren & Brandt (2008), −7 °C
//              bk7           n: Schott N-BK7 Sellmeier; k: Schott's N-BK7 table
//              fused_silica  n: Malitson (1965) Sellmeier; k = 0 (no table:
//                            its absorption over 360-830 nm is negligible)
//            diffuse grounds (albedo)
//              grass, sand, loam, concrete (dry)  Feister & Grewe (1995), 360-800 nm
//              snow          dry fresh snow, Bowker et al. (1985), 390-830 nm
//          An unknown name throws std::invalid_argument listing the known ones.
//   custom materials: a name (for messages), and either wavelengths_nm, n, k
//          (see optical_constants.h for the rules; a conductor or a dielectric)
//          or wavelengths_nm, albedo.  Invalid tables throw
//          std::invalid_argument naming the material, the rule and the entry.
//
// All tables are data/ files embedded in the binary (data/README.md cites each
// source).  Outside a table's range values are clamped to its ends
// (optical_constants.h says why); SpectralIor::covers and
// SpectralAlbedo::covers tell where a material has data.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "common/material/optical_constants.h"

namespace skyfarm::material {

enum class MaterialId {
  kGold,
  kSilver,
  kCopper,
  kAluminium,
  kChrome,
  kWater,
  kIce,
  kBk7,
  kFusedSilica,
  kGrass,
  kSand,
  kLoam,
  kConcrete,
  kSnow,
};

// How the constants describe the surface: an opaque metal (n + i k), a
// transparent or absorbing dielectric (n + i k, k small), or a diffuse
// reflector known by its albedo only.
enum class MaterialKind { kConductor, kDielectric, kDiffuse };

class Material {
 public:
  // kind is kConductor or kDielectric; throws std::invalid_argument otherwise.
  Material(std::string name, MaterialKind kind, SpectralIor ior);
  // A kDiffuse material.
  Material(std::string name, SpectralAlbedo albedo);

  const std::string& name() const { return name_; }
  MaterialKind kind() const { return kind_; }
  bool has_ior() const { return std::holds_alternative<SpectralIor>(constants_); }
  // Throw std::logic_error naming the material when it has the other kind of
  // constants (asking a ground for its index, a metal for its albedo).
  const SpectralIor& ior() const;
  const SpectralAlbedo& albedo() const;

 private:
  std::string name_;
  MaterialKind kind_;
  std::variant<SpectralIor, SpectralAlbedo> constants_;
};

// Every named material, in the order of MaterialId.
std::span<const MaterialId> all_material_ids();
std::string_view material_name(MaterialId id);
std::optional<MaterialId> find_material(std::string_view name);
// "gold, silver, ..., snow": the known names, for messages.
std::string known_material_names();

// The named material's constants, read from the embedded tables on first use
// (thread-safe) and kept for the life of the program.
const Material& named_material(MaterialId id);
// Throws std::invalid_argument `unknown material "x"; known materials: gold, ...`.
const Material& named_material(std::string_view name);

Material custom_ior_material(std::string name, MaterialKind kind, const std::vector<double>& wavelengths_nm,
                             const std::vector<double>& n, const std::vector<double>& k);
Material custom_albedo_material(std::string name, const std::vector<double>& wavelengths_nm,
                                const std::vector<double>& albedo);

}  // namespace skyfarm::material
