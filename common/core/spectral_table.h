// A user-supplied spectral table: values at wavelengths in nm (request field
// shape {"wavelengths_nm": [...], "values": [...]}).
#pragma once
#include <vector>

namespace skyfarm {

struct SpectralTable {
  std::vector<double> wavelengths_nm;
  std::vector<double> values;
};

}  // namespace skyfarm
