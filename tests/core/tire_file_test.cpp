// The .tir reader (core/vehicle/tir_file.hpp): MFeval's four files, line ends, comments and case,
// units converted to SI, MFeval's defaults and the list of defaulted keys, and the refusals, each
// of which must name the file, the section and the key.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "vehicle/tir_file.hpp"

using namespace codyna;

namespace {

const std::string tir_test_dir = std::string(CODYNA_TEST_DATA_DIR) + "/tires/";

std::string tir_test_read(const std::string& name) {
  std::ifstream in(tir_test_dir + name, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// a small MF 6.1 file in SI (LF line ends), the base of the variations below
const std::string tir_test_small =
    "[MDI_HEADER]\n"
    "FILE_TYPE = 'tir'\n"
    "$ a comment line\n"
    "! another comment line\n"
    "[UNITS]\n"
    "LENGTH = 'meter'\n"
    "FORCE = 'newton'\n"
    "ANGLE = 'radians'\n"
    "MASS = 'kg'\n"
    "TIME = 'second'\n"
    "[MODEL]\n"
    "FITTYP = 61 $Magic Formula version\n"
    "TYRESIDE = 'RIGHT'\n"
    "LONGVL = 16.7\n"
    "[DIMENSION]\n"
    "UNLOADED_RADIUS = 0.3135\n"
    "WIDTH = 0.205\n"
    "[OPERATING_CONDITIONS]\n"
    "INFLPRES = 220000\n"
    "NOMPRES = 220000\n"
    "[VERTICAL]\n"
    "FNOMIN = 4000\n"
    "VERTICAL_STIFFNESS = 200000\n"
    "[SLIP_ANGLE_RANGE]\n"
    "ALPMIN = -1.5\n"
    "ALPMAX = 1.5\n"
    "[LONGITUDINAL_COEFFICIENTS]\n"
    "PCX1 = 1.6\n"
    "PKX1 = 16\n"
    "[LATERAL_COEFFICIENTS]\n"
    "PCY1 = 1.3\n"
    "PKY1 = -15\n"
    "[ALIGNING_COEFFICIENTS]\n"
    "QBZ1 = 10\n";

std::string tir_test_replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// the message of the refusal of text (empty if it was read)
std::string tir_test_refusal(const std::string& text) {
  try {
    parse_tir_text(text, "bad.tir");
  } catch (const TirFileError& e) {
    return e.what();
  }
  return "";
}

void tir_test_names(const std::string& message, const std::string& section, const std::string& key) {
  EXPECT_NE(message.find("bad.tir"), std::string::npos) << message;
  EXPECT_NE(message.find("[" + section + "]"), std::string::npos) << message;
  if (!key.empty()) {
    EXPECT_NE(message.find(key), std::string::npos) << message;
  }
}

}  // namespace

TEST(TirFile, ReadsMFevalsFourFiles) {
  const MagicFormulaParameters book = read_tir_file(tir_test_dir + "PacejkaBook_Defaults.tir");
  EXPECT_EQ(book.FITTYP, 61);
  EXPECT_EQ(book.version, MagicFormulaVersion::MF61);
  EXPECT_EQ(book.TYRESIDE, TireSide::Left);  // 'Left' in the file
  EXPECT_EQ(book.FNOMIN, 4000);
  EXPECT_EQ(book.UNLOADED_RADIUS, 0.3135);
  EXPECT_EQ(book.PKY1, -15);
  EXPECT_EQ(book.PCX1, 1.6);
  const MagicFormulaParameters mf61 = read_tir_file(tir_test_dir + "MagicFormula61_Paramerters.tir");
  EXPECT_EQ(mf61.TYRESIDE, TireSide::Right);
  EXPECT_EQ(mf61.FNOMIN, 6752);
  EXPECT_GT(mf61.PKY1, 0);  // this fitted file carries the opposite sign of PKY1
  EXPECT_TRUE(mf61.was_defaulted("Q_FCY2"));
  const MagicFormulaParameters mf62 = read_tir_file(tir_test_dir + "MagicFormula62_Paramerters.tir");
  EXPECT_EQ(mf62.version, MagicFormulaVersion::MF62);
  EXPECT_EQ(mf62.Q_FCY2, -0.4751);
  EXPECT_EQ(mf62.Q_FYS1, -20496.4);
  EXPECT_FALSE(mf62.was_defaulted("Q_FCY2"));
  const MagicFormulaParameters mf52 = read_tir_file(tir_test_dir + "MagicFormula52_Paramerters.tir");
  EXPECT_EQ(mf52.FITTYP, 6);
  EXPECT_EQ(mf52.version, MagicFormulaVersion::MF52);
  EXPECT_EQ(mf52.PHY3, 0.006973);
  EXPECT_EQ(mf52.PTX1, 1.1898);
  EXPECT_EQ(mf52.FNOMIN, 9416.6);
  // [SHAPE]'s table is skipped, MF 5.2's camber scalings are read and listed as not used
  EXPECT_NE(std::find(mf52.ignored.begin(), mf52.ignored.end(), "SHAPE"), mf52.ignored.end());
  EXPECT_NE(std::find(mf52.ignored.begin(), mf52.ignored.end(), "SCALING_COEFFICIENTS/LGAY"), mf52.ignored.end());
}

// The MF 5.2 file does not define MF 6.1's keys: they take MFeval's defaults and are listed.
TEST(TirFile, MF52ReportsTheDefaultedKeys) {
  const MagicFormulaParameters p = read_tir_file(tir_test_dir + "MagicFormula52_Paramerters.tir");
  for (const char* k : {"PKY4", "PKY6", "INFLPRES", "NOMPRES", "PRESMIN", "PRESMAX", "QSX4", "Q_RE0", "PPZ1", "LKYC",
                        "TYRESIDE"})
    EXPECT_TRUE(p.was_defaulted(k)) << k;
  for (const char* k : {"PKY1", "PKY3", "FNOMIN", "QBZ1", "PHY3", "FZMAX", "VXLOW"}) EXPECT_FALSE(p.was_defaulted(k)) << k;
  EXPECT_TRUE(p.was_defaulted("LATERAL_COEFFICIENTS/PKY4"));
  EXPECT_FALSE(p.was_defaulted("DIMENSION/PKY4"));
  EXPECT_EQ(p.PKY4, 2);
  EXPECT_EQ(p.PKY6, -1);
  EXPECT_EQ(p.INFLPRES, 220000);
  EXPECT_EQ(p.NOMPRES, 220000);
  EXPECT_EQ(p.QSX4, 5);
  EXPECT_EQ(p.LKYC, 1);
  EXPECT_EQ(p.TYRESIDE, TireSide::Left);
}

// CRLF (the files as upstream) and LF give the same; section and key names in any case; '$'
// comments after values and '!' comment lines.
TEST(TirFile, LineEndsCaseAndComments) {
  const std::string crlf = tir_test_read("MagicFormula61_Paramerters.tir");
  ASSERT_NE(crlf.find("\r\n"), std::string::npos);
  std::string lf;
  for (char c : crlf)
    if (c != '\r') lf += c;
  const MagicFormulaParameters a = parse_tir_text(crlf, "crlf.tir");
  const MagicFormulaParameters b = parse_tir_text(lf, "lf.tir");
  EXPECT_EQ(a.PKY1, b.PKY1);
  EXPECT_EQ(a.QSX14, b.QSX14);
  EXPECT_EQ(a.defaulted, b.defaulted);
  std::string lower = tir_test_replace(tir_test_small, "[LATERAL_COEFFICIENTS]", "[lateral_coefficients]");
  lower = tir_test_replace(lower, "PKY1 = -15", "pky1 = -15 $ cornering stiffness ! still a comment");
  lower = tir_test_replace(lower, "TYRESIDE = 'RIGHT'", "tyreside = 'right'");
  const MagicFormulaParameters c = parse_tir_text(lower, "lower.tir");
  EXPECT_EQ(c.PKY1, -15);
  EXPECT_EQ(c.TYRESIDE, TireSide::Right);
  EXPECT_EQ(c.PCX1, 1.6);
  // a UTF-8 byte order mark before the first section
  EXPECT_EQ(parse_tir_text("\xEF\xBB\xBF" + tir_test_small, "bom.tir").PKY1, -15);
  // a number in Fortran's notation
  EXPECT_EQ(parse_tir_text(tir_test_replace(tir_test_small, "PKX1 = 16", "PKX1 = 1.6D+1"), "d.tir").PKX1, 16);
}

// [UNITS] other than SI: the dimensional values are converted; the Magic Formula coefficients
// (dimensionless) are not.
TEST(TirFile, UnitsAreConvertedToSI) {
  std::string t = tir_test_small;
  t = tir_test_replace(t, "LENGTH = 'meter'", "LENGTH = 'mm'");
  t = tir_test_replace(t, "FORCE = 'newton'", "FORCE = 'kN'");
  t = tir_test_replace(t, "ANGLE = 'radians'", "ANGLE = 'degree'");
  t = tir_test_replace(t, "TIME = 'second'", "TIME = 'second'\nPRESSURE = 'bar'");
  t = tir_test_replace(t, "UNLOADED_RADIUS = 0.3135", "UNLOADED_RADIUS = 313.5");
  t = tir_test_replace(t, "FNOMIN = 4000", "FNOMIN = 4");
  t = tir_test_replace(t, "VERTICAL_STIFFNESS = 200000", "VERTICAL_STIFFNESS = 0.2");  // kN/mm
  t = tir_test_replace(t, "INFLPRES = 220000", "INFLPRES = 2.2");
  t = tir_test_replace(t, "NOMPRES = 220000", "NOMPRES = 2.4");
  t = tir_test_replace(t, "ALPMAX = 1.5", "ALPMAX = 30");
  t = tir_test_replace(t, "LONGVL = 16.7", "LONGVL = 16700");  // mm/s
  const MagicFormulaParameters p = parse_tir_text(t, "units.tir");
  EXPECT_DOUBLE_EQ(p.UNLOADED_RADIUS, 0.3135);
  EXPECT_DOUBLE_EQ(p.FNOMIN, 4000);
  EXPECT_DOUBLE_EQ(p.VERTICAL_STIFFNESS, 200000);
  EXPECT_DOUBLE_EQ(p.INFLPRES, 220000);
  EXPECT_DOUBLE_EQ(p.NOMPRES, 240000);
  EXPECT_DOUBLE_EQ(p.ALPMAX, 30 * 3.14159265358979323846 / 180);
  EXPECT_DOUBLE_EQ(p.LONGVL, 16.7);
  EXPECT_EQ(p.PKY1, -15);
  EXPECT_EQ(p.PKX1, 16);
  // without a PRESSURE unit, pressures are in FORCE / LENGTH^2 (here kN/mm^2 = 1e9 Pa)
  std::string t2 = tir_test_replace(tir_test_small, "FORCE = 'newton'", "FORCE = 'kilonewton'");
  t2 = tir_test_replace(t2, "LENGTH = 'meter'", "LENGTH = 'millimeter'");
  t2 = tir_test_replace(t2, "UNLOADED_RADIUS = 0.3135", "UNLOADED_RADIUS = 313.5");
  t2 = tir_test_replace(t2, "INFLPRES = 220000", "INFLPRES = 0.00022");
  t2 = tir_test_replace(t2, "NOMPRES = 220000", "NOMPRES = 0.00022");
  EXPECT_DOUBLE_EQ(parse_tir_text(t2, "kn_mm.tir").NOMPRES, 220000);
}

TEST(TirFile, RefusesMissingSection) {
  const std::string m = tir_test_refusal(tir_test_replace(tir_test_small, "[ALIGNING_COEFFICIENTS]\nQBZ1 = 10\n", ""));
  ASSERT_FALSE(m.empty());
  tir_test_names(m, "ALIGNING_COEFFICIENTS", "");
  EXPECT_NE(m.find("missing"), std::string::npos) << m;
}

TEST(TirFile, RefusesMissingRequiredKey) {
  const std::string m = tir_test_refusal(tir_test_replace(tir_test_small, "FNOMIN = 4000\n", ""));
  tir_test_names(m, "VERTICAL", "FNOMIN");
  const std::string f = tir_test_refusal(tir_test_replace(tir_test_small, "FITTYP = 61 $Magic Formula version\n", ""));
  tir_test_names(f, "MODEL", "FITTYP");
}

TEST(TirFile, RefusesUnknownFittyp) {
  const std::string m = tir_test_refusal(tir_test_replace(tir_test_small, "FITTYP = 61", "FITTYP = 99"));
  tir_test_names(m, "MODEL", "FITTYP");
  EXPECT_NE(m.find("99"), std::string::npos) << m;
  EXPECT_NE(m.find("line 12"), std::string::npos) << m;
}

TEST(TirFile, RefusesNonNumericValue) {
  const std::string m = tir_test_refusal(tir_test_replace(tir_test_small, "PCX1 = 1.6", "PCX1 = 1.6x"));
  tir_test_names(m, "LONGITUDINAL_COEFFICIENTS", "PCX1");
  EXPECT_NE(m.find("not a number"), std::string::npos) << m;
  tir_test_names(tir_test_refusal(tir_test_replace(tir_test_small, "PKY1 = -15", "PKY1 = 'abc'")), "LATERAL_COEFFICIENTS",
                 "PKY1");
  tir_test_names(tir_test_refusal(tir_test_replace(tir_test_small, "PKY1 = -15", "PKY1 =")), "LATERAL_COEFFICIENTS",
                 "PKY1");
}

TEST(TirFile, RefusesUnknownKeyInCoefficientSection) {
  const std::string m = tir_test_refusal(tir_test_replace(tir_test_small, "PCX1 = 1.6", "PCX1 = 1.6\nPCX9 = 2"));
  tir_test_names(m, "LONGITUDINAL_COEFFICIENTS", "PCX9");
  EXPECT_NE(m.find("unknown key"), std::string::npos) << m;
  // outside the coefficient sections an unknown key is read and listed as not used
  const MagicFormulaParameters p = parse_tir_text(tir_test_replace(tir_test_small, "WIDTH = 0.205", "WIDTH = 0.205\nPLY = 4"), "ok.tir");
  EXPECT_NE(std::find(p.ignored.begin(), p.ignored.end(), "DIMENSION/PLY"), p.ignored.end());
}

TEST(TirFile, RefusesValuesOutsidePhysicalSense) {
  tir_test_names(tir_test_refusal(tir_test_replace(tir_test_small, "FNOMIN = 4000", "FNOMIN = -4000")), "VERTICAL", "FNOMIN");
  tir_test_names(tir_test_refusal(tir_test_replace(tir_test_small, "UNLOADED_RADIUS = 0.3135", "UNLOADED_RADIUS = 0")),
                 "DIMENSION", "UNLOADED_RADIUS");
  tir_test_names(tir_test_refusal(tir_test_replace(tir_test_small, "VERTICAL_STIFFNESS = 200000", "VERTICAL_STIFFNESS = -1")),
                 "VERTICAL", "VERTICAL_STIFFNESS");
  tir_test_names(tir_test_refusal(tir_test_replace(tir_test_small, "ALPMIN = -1.5", "ALPMIN = 2")), "SLIP_ANGLE_RANGE",
                 "ALPMIN");
  tir_test_names(tir_test_refusal(tir_test_replace(tir_test_small, "NOMPRES = 220000", "NOMPRES = 0")),
                 "OPERATING_CONDITIONS", "NOMPRES");
}

TEST(TirFile, RefusesUnconvertibleUnit) {
  const std::string m = tir_test_refusal(tir_test_replace(tir_test_small, "LENGTH = 'meter'", "LENGTH = 'furlong'"));
  tir_test_names(m, "UNITS", "LENGTH");
  EXPECT_NE(m.find("furlong"), std::string::npos) << m;
  tir_test_names(tir_test_refusal(tir_test_replace(tir_test_small, "TIME = 'second'", "TIME = 'second'\nPRESSURE = 'atm'")),
                 "UNITS", "PRESSURE");
}

TEST(TirFile, RefusesKeyGivenTwiceAndMissingFile) {
  tir_test_names(tir_test_refusal(tir_test_replace(tir_test_small, "PCX1 = 1.6", "PCX1 = 1.6\nPCX1 = 1.7")),
                 "LONGITUDINAL_COEFFICIENTS", "PCX1");
  try {
    read_tir_file(tir_test_dir + "no_such_file.tir");
    FAIL() << "a missing file was read";
  } catch (const TirFileError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_file.tir"), std::string::npos) << e.what();
  }
}
