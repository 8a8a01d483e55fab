// The reader of TYDEX/Adams tire property files (.tir) for the Magic Formula 5.2, 6.1 and 6.2
// (FITTYP 6 or 5, 61, 62), and the typed parameter set it gives (MagicFormulaParameters).
//
// The file: lines `[SECTION]`, `KEY = value` (a number, or a string in single or double quotes),
// `$` starting a comment anywhere outside quotes, lines starting with `!` comments; CRLF or LF line
// ends; section and key names are case-insensitive (as Adams reads them). [SHAPE] (MF 5.2's
// contour table) and sections the reader does not know are skipped.
//
// The values are converted to SI from the file's [UNITS] (LENGTH, FORCE, ANGLE, MASS, TIME and an
// optional PRESSURE; without PRESSURE, pressures are in FORCE per LENGTH squared). The Magic
// Formula coefficients themselves are dimensionless and taken as they stand (slips and angles in
// radians, as TNO and MFeval define them); only the dimensional keys (radii, loads, stiffnesses,
// pressures, speeds, angle ranges, inertia) are converted.
//
// A key the file does not give takes MFeval 4.0's default (its readTIR) and is named in
// MagicFormulaParameters::defaulted, so that a front end can say which values were not the
// file's. Refusals are TirFileError exceptions whose message names the file, the section and the
// key: a missing required section ([UNITS], [MODEL], [DIMENSION], [VERTICAL],
// [LONGITUDINAL_COEFFICIENTS], [LATERAL_COEFFICIENTS], [ALIGNING_COEFFICIENTS]) or key (FITTYP,
// UNLOADED_RADIUS, FNOMIN), a FITTYP other than 5, 6, 61, 62, a value that is not a number where
// a number belongs, a key the reader does not know in a coefficient section (*_COEFFICIENTS), a
// key given twice in one section, a unit it cannot convert, and values outside physical sense
// (FNOMIN, UNLOADED_RADIUS, VERTICAL_STIFFNESS, NOMPRES, LONGVL not > 0; a range whose minimum
// exceeds its maximum; ...).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace codyna {

class TirFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class MagicFormulaVersion { MF52, MF61, MF62 };
enum class TireSide { Left, Right, Symmetric };

// Every parameter the Magic Formula 5.2 / 6.1 / 6.2 evaluation (magic_formula.hpp) uses, plus the
// structural and inertia values a vehicle model will want, in SI units, named as in the .tir file.
struct MagicFormulaParameters {
  std::string file;                   // the path (or the name given to parse_tir_text)
  int FITTYP = 0;                     // 6 or 5: MF 5.2; 61: MF 6.1; 62: MF 6.2
  MagicFormulaVersion version = MagicFormulaVersion::MF61;
  TireSide TYRESIDE = TireSide::Left;  // the side the file describes (MFeval's default LEFT)
  std::vector<std::string> defaulted;  // "SECTION/KEY" of every known key the file did not give
  std::vector<std::string> ignored;    // sections ("SHAPE") and "SECTION/KEY"s read but not used

  // [MODEL]
  double LONGVL = 16.7, VXLOW = 1;
  // [DIMENSION]
  double UNLOADED_RADIUS = 0.3135, WIDTH = 0.205, ASPECT_RATIO = 0.6, RIM_RADIUS = 0.1905, RIM_WIDTH = 0.152;
  // [OPERATING_CONDITIONS]
  double INFLPRES = 220000, NOMPRES = 220000;
  // [INERTIA]
  double MASS = 9.3, IXX = 0.391, IYY = 0.736, BELT_MASS = 7, BELT_IXX = 0.34, BELT_IYY = 0.6, GRAVITY = -9.81;
  // [VERTICAL]
  double FNOMIN = 4000, VERTICAL_STIFFNESS = 200000, VERTICAL_DAMPING = 50, MC_CONTOUR_A = 0.5,
         MC_CONTOUR_B = 0.5, BREFF = 8.4, DREFF = 0.27, FREFF = 0.07, Q_RE0 = 1, Q_V1 = 0, Q_V2 = 0,
         Q_FZ2 = 1.0e-4, Q_FCX = 0, Q_FCY = 0, Q_CAM = 0, PFZ1 = 0, Q_FCY2 = 0, Q_CAM1 = 0, Q_CAM2 = 0,
         Q_CAM3 = 0, Q_FYS1 = 0, Q_FYS2 = 0, Q_FYS3 = 0, BOTTOM_OFFST = 0.01, BOTTOM_STIFF = 2000000;
  // [STRUCTURAL]
  double LONGITUDINAL_STIFFNESS = 300000, LATERAL_STIFFNESS = 100000, YAW_STIFFNESS = 5000, FREQ_LONG = 80,
         FREQ_LAT = 40, FREQ_YAW = 50, FREQ_WINDUP = 70, DAMP_LONG = 0.04, DAMP_LAT = 0.04, DAMP_YAW = 0.04,
         DAMP_WINDUP = 0.04, DAMP_RESIDUAL = 0.0020, DAMP_VLOW = 0.0010, Q_BVX = 0, Q_BVT = 0, PCFX1 = 0,
         PCFX2 = 0, PCFX3 = 0, PCFY1 = 0, PCFY2 = 0, PCFY3 = 0, PCMZ1 = 0;
  // [CONTACT_PATCH]
  double Q_RA1 = 0.5, Q_RA2 = 1, Q_RB1 = 1, Q_RB2 = -1, Q_A1 = 0, Q_A2 = 0;
  // ranges: [INFLATION_PRESSURE_RANGE], [VERTICAL_FORCE_RANGE], [LONG_SLIP_RANGE],
  // [SLIP_ANGLE_RANGE], [INCLINATION_ANGLE_RANGE]
  double PRESMIN = 10000, PRESMAX = 1000000, FZMIN = 100, FZMAX = 10000, KPUMIN = -1.5, KPUMAX = 1.5,
         ALPMIN = -1.5, ALPMAX = 1.5, CAMMIN = -0.175, CAMMAX = 0.175;
  // [SCALING_COEFFICIENTS]
  double LFZO = 1, LCX = 1, LMUX = 1, LEX = 1, LKX = 1, LHX = 1, LVX = 1, LCY = 1, LMUY = 1, LEY = 1, LKY = 1,
         LHY = 1, LVY = 1, LTR = 1, LRES = 1, LXAL = 1, LYKA = 1, LVYKA = 1, LS = 1, LKYC = 1, LKZC = 1,
         LVMX = 1, LMX = 1, LMY = 1, LMP = 1, LSGKP = 1, LSGAL = 1;
  // [LONGITUDINAL_COEFFICIENTS]
  double PCX1 = 1.65, PDX1 = 1.3, PDX2 = -0.15, PDX3 = 0, PEX1 = 0, PEX2 = 0, PEX3 = 0, PEX4 = 0, PKX1 = 20,
         PKX2 = 0, PKX3 = 0, PHX1 = 0, PHX2 = 0, PVX1 = 0, PVX2 = 0, PPX1 = 0, PPX2 = 0, PPX3 = 0, PPX4 = 0,
         RBX1 = 20, RBX2 = 15, RBX3 = 0, RCX1 = 1, REX1 = 0, REX2 = 0, RHX1 = 0, PTX1 = 0, PTX2 = 0, PTX3 = 0;
  // [OVERTURNING_COEFFICIENTS]
  double QSX1 = 0, QSX2 = 0, QSX3 = 0, QSX4 = 5, QSX5 = 1, QSX6 = 10, QSX7 = 0, QSX8 = 0, QSX9 = 0.4,
         QSX10 = 0, QSX11 = 5, QSX12 = 0, QSX13 = 0, QSX14 = 0, PPMX1 = 0;
  // [LATERAL_COEFFICIENTS]
  double PCY1 = 1.3, PDY1 = 1.1, PDY2 = -0.15, PDY3 = 0, PEY1 = 0, PEY2 = 0, PEY3 = 0, PEY4 = 0, PEY5 = 0,
         PKY1 = -20, PKY2 = 1, PKY3 = 0, PKY4 = 2, PKY5 = 0, PKY6 = -1, PKY7 = 0, PHY1 = 0, PHY2 = 0, PHY3 = 0,
         PVY1 = 0, PVY2 = 0, PVY3 = 0, PVY4 = 0, PPY1 = 0, PPY2 = 0, PPY3 = 0, PPY4 = 0, PPY5 = 0, RBY1 = 10,
         RBY2 = 10, RBY3 = 0, RBY4 = 0, RCY1 = 1, REY1 = 0, REY2 = 0, RHY1 = 0, RHY2 = 0, RVY1 = 0, RVY2 = 0,
         RVY3 = 0, RVY4 = 20, RVY5 = 2, RVY6 = 10, PTY1 = 0, PTY2 = 0;
  // [ROLLING_COEFFICIENTS]
  double QSY1 = 0.01, QSY2 = 0, QSY3 = 4.0e-4, QSY4 = 4.0e-5, QSY5 = 0, QSY6 = 0, QSY7 = 0.85, QSY8 = -0.4;
  // [ALIGNING_COEFFICIENTS]
  double QBZ1 = 10, QBZ2 = 0, QBZ3 = 0, QBZ4 = 0, QBZ5 = 0, QBZ9 = 10, QBZ10 = 0, QCZ1 = 1.1, QDZ1 = 0.12,
         QDZ2 = 0, QDZ3 = 0, QDZ4 = 0, QDZ6 = 0, QDZ7 = 0, QDZ8 = -0.05, QDZ9 = 0, QDZ10 = 0, QDZ11 = 0,
         QEZ1 = 0, QEZ2 = 0, QEZ3 = 0, QEZ4 = 0, QEZ5 = 0, QHZ1 = 0, QHZ2 = 0, QHZ3 = 0, QHZ4 = 0, PPZ1 = 0,
         PPZ2 = 0, SSZ1 = 0, SSZ2 = 0, SSZ3 = 0, SSZ4 = 0;
  // [TURNSLIP_COEFFICIENTS] (read and kept; the evaluation does not use turn slip yet)
  double PDXP1 = 0.4, PDXP2 = 0, PDXP3 = 0, PKYP1 = 1, PDYP1 = 0.4, PDYP2 = 0, PDYP3 = 0, PDYP4 = 0,
         PHYP1 = 1, PHYP2 = 0.15, PHYP3 = 0, PHYP4 = -4, PECP1 = 0.5, PECP2 = 0, QDTP1 = 10, QCRP1 = 0.2,
         QCRP2 = 0.1, QBRP1 = 0.1, QDRP1 = 1;

  bool was_defaulted(const std::string& key) const;  // key: "KEY" (any section) or "SECTION/KEY"
};

// Reads and checks a .tir file (throws TirFileError).
MagicFormulaParameters read_tir_file(const std::string& path);
// The same from the file's text; name stands for the file in messages.
MagicFormulaParameters parse_tir_text(const std::string& text, const std::string& name);

}  // namespace codyna
