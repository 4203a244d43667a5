// The embedded tables parse and carry the values their sources state (data/README.md).
#include "common/data/csv_table.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "common/data/embedded_files.h"

namespace skyfarm {
namespace {

TEST(CsvTable, ParsesHeaderAndNumbers) {
  const auto t = CsvTable::parse("a,b\n1,2.5\n-3,4e2\n", "inline");
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_DOUBLE_EQ(t.column("b")[1], 400.0);
  EXPECT_DOUBLE_EQ(t.column("a")[1], -3.0);
}

TEST(CsvTable, MalformedCellNamesSourceLineAndColumn) {
  try {
    CsvTable::parse("a,b\n1,x\n", "bad.csv");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:2: column 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(CsvTable::parse("a,b\n1\n", "short.csv"), std::runtime_error);
}

TEST(CsvTable, EveryEmbeddedTableParses) {
  for (const auto& name : embedded_file_names()) {
    // The Sellmeier coefficient files are `coefficient,value` rows, read by
    // name (tests/common/material/optical_constants_test.cpp parses them).
    if (embedded_file(name).starts_with("coefficient,value\n")) continue;
    const auto t = CsvTable::embedded(name);
    EXPECT_GT(t.rows(), 5u) << name;
  }
}

TEST(CsvTable, EmbeddedCieTableHasYbarOneAt555nm) {
  // data/README.md: ybar = 1.000000 at 555 nm (CIE 018:2004 1-nm table).
  const auto t = CsvTable::embedded("cie1931_2deg_xyz.csv");
  const auto& wl = t.column("wavelength_nm");
  const auto& y = t.column("ybar");
  for (std::size_t i = 0; i < wl.size(); ++i)
    if (wl[i] == 555.0) {
      EXPECT_DOUBLE_EQ(y[i], 1.0);
    }
  EXPECT_THROW(t.column("nope"), std::out_of_range);
}

}  // namespace
}  // namespace skyfarm
