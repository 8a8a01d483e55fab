#include "vehicle/tir_file.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace codyna {

namespace {

// The physical dimension of a key's value: what the [UNITS] conversion multiplies it by.
enum class TirDim { None, Length, Force, Stiffness, Damping, Pressure, Speed, Angle, Mass, Inertia, Accel, Frequency, Time, YawStiffness };

struct TirKey {
  const char* section;  // where the key belongs (used in messages when it is defaulted)
  const char* key;
  double MagicFormulaParameters::*member;
  TirDim dim;
};

#define TIR_K(sec, name, dim) {sec, #name, &MagicFormulaParameters::name, TirDim::dim}
const TirKey tir_keys[] = {
    TIR_K("MODEL", LONGVL, Speed), TIR_K("MODEL", VXLOW, Speed),
    TIR_K("DIMENSION", UNLOADED_RADIUS, Length), TIR_K("DIMENSION", WIDTH, Length),
    TIR_K("DIMENSION", ASPECT_RATIO, None), TIR_K("DIMENSION", RIM_RADIUS, Length), TIR_K("DIMENSION", RIM_WIDTH, Length),
    TIR_K("OPERATING_CONDITIONS", INFLPRES, Pressure), TIR_K("OPERATING_CONDITIONS", NOMPRES, Pressure),
    TIR_K("INERTIA", MASS, Mass), TIR_K("INERTIA", IXX, Inertia), TIR_K("INERTIA", IYY, Inertia),
    TIR_K("INERTIA", BELT_MASS, Mass), TIR_K("INERTIA", BELT_IXX, Inertia), TIR_K("INERTIA", BELT_IYY, Inertia),
    TIR_K("INERTIA", GRAVITY, Accel),
    TIR_K("VERTICAL", FNOMIN, Force), TIR_K("VERTICAL", VERTICAL_STIFFNESS, Stiffness),
    TIR_K("VERTICAL", VERTICAL_DAMPING, Damping), TIR_K("VERTICAL", MC_CONTOUR_A, None),
    TIR_K("VERTICAL", MC_CONTOUR_B, None), TIR_K("VERTICAL", BREFF, None), TIR_K("VERTICAL", DREFF, None),
    TIR_K("VERTICAL", FREFF, None), TIR_K("VERTICAL", Q_RE0, None), TIR_K("VERTICAL", Q_V1, None),
    TIR_K("VERTICAL", Q_V2, None), TIR_K("VERTICAL", Q_FZ2, None), TIR_K("VERTICAL", Q_FCX, None),
    TIR_K("VERTICAL", Q_FCY, None), TIR_K("VERTICAL", Q_CAM, None), TIR_K("VERTICAL", PFZ1, None),
    TIR_K("VERTICAL", Q_FCY2, None), TIR_K("VERTICAL", Q_CAM1, None), TIR_K("VERTICAL", Q_CAM2, None),
    TIR_K("VERTICAL", Q_CAM3, None), TIR_K("VERTICAL", Q_FYS1, None), TIR_K("VERTICAL", Q_FYS2, None),
    TIR_K("VERTICAL", Q_FYS3, None), TIR_K("VERTICAL", BOTTOM_OFFST, Length),
    TIR_K("VERTICAL", BOTTOM_STIFF, Stiffness),
    TIR_K("STRUCTURAL", LONGITUDINAL_STIFFNESS, Stiffness), TIR_K("STRUCTURAL", LATERAL_STIFFNESS, Stiffness),
    TIR_K("STRUCTURAL", YAW_STIFFNESS, YawStiffness), TIR_K("STRUCTURAL", FREQ_LONG, Frequency),
    TIR_K("STRUCTURAL", FREQ_LAT, Frequency), TIR_K("STRUCTURAL", FREQ_YAW, Frequency),
    TIR_K("STRUCTURAL", FREQ_WINDUP, Frequency), TIR_K("STRUCTURAL", DAMP_LONG, None),
    TIR_K("STRUCTURAL", DAMP_LAT, None), TIR_K("STRUCTURAL", DAMP_YAW, None), TIR_K("STRUCTURAL", DAMP_WINDUP, None),
    TIR_K("STRUCTURAL", DAMP_RESIDUAL, None), TIR_K("STRUCTURAL", DAMP_VLOW, None), TIR_K("STRUCTURAL", Q_BVX, None),
    TIR_K("STRUCTURAL", Q_BVT, None), TIR_K("STRUCTURAL", PCFX1, None), TIR_K("STRUCTURAL", PCFX2, None),
    TIR_K("STRUCTURAL", PCFX3, None), TIR_K("STRUCTURAL", PCFY1, None), TIR_K("STRUCTURAL", PCFY2, None),
    TIR_K("STRUCTURAL", PCFY3, None), TIR_K("STRUCTURAL", PCMZ1, None),
    TIR_K("CONTACT_PATCH", Q_RA1, None), TIR_K("CONTACT_PATCH", Q_RA2, None), TIR_K("CONTACT_PATCH", Q_RB1, None),
    TIR_K("CONTACT_PATCH", Q_RB2, None), TIR_K("CONTACT_PATCH", Q_A1, None), TIR_K("CONTACT_PATCH", Q_A2, None),
    TIR_K("INFLATION_PRESSURE_RANGE", PRESMIN, Pressure), TIR_K("INFLATION_PRESSURE_RANGE", PRESMAX, Pressure),
    TIR_K("VERTICAL_FORCE_RANGE", FZMIN, Force), TIR_K("VERTICAL_FORCE_RANGE", FZMAX, Force),
    TIR_K("LONG_SLIP_RANGE", KPUMIN, None), TIR_K("LONG_SLIP_RANGE", KPUMAX, None),
    TIR_K("SLIP_ANGLE_RANGE", ALPMIN, Angle), TIR_K("SLIP_ANGLE_RANGE", ALPMAX, Angle),
    TIR_K("INCLINATION_ANGLE_RANGE", CAMMIN, Angle), TIR_K("INCLINATION_ANGLE_RANGE", CAMMAX, Angle),
    TIR_K("SCALING_COEFFICIENTS", LFZO, None), TIR_K("SCALING_COEFFICIENTS", LCX, None),
    TIR_K("SCALING_COEFFICIENTS", LMUX, None), TIR_K("SCALING_COEFFICIENTS", LEX, None),
    TIR_K("SCALING_COEFFICIENTS", LKX, None), TIR_K("SCALING_COEFFICIENTS", LHX, None),
    TIR_K("SCALING_COEFFICIENTS", LVX, None), TIR_K("SCALING_COEFFICIENTS", LCY, None),
    TIR_K("SCALING_COEFFICIENTS", LMUY, None), TIR_K("SCALING_COEFFICIENTS", LEY, None),
    TIR_K("SCALING_COEFFICIENTS", LKY, None), TIR_K("SCALING_COEFFICIENTS", LHY, None),
    TIR_K("SCALING_COEFFICIENTS", LVY, None), TIR_K("SCALING_COEFFICIENTS", LTR, None),
    TIR_K("SCALING_COEFFICIENTS", LRES, None), TIR_K("SCALING_COEFFICIENTS", LXAL, None),
    TIR_K("SCALING_COEFFICIENTS", LYKA, None), TIR_K("SCALING_COEFFICIENTS", LVYKA, None),
    TIR_K("SCALING_COEFFICIENTS", LS, None), TIR_K("SCALING_COEFFICIENTS", LKYC, None),
    TIR_K("SCALING_COEFFICIENTS", LKZC, None), TIR_K("SCALING_COEFFICIENTS", LVMX, None),
    TIR_K("SCALING_COEFFICIENTS", LMX, None), TIR_K("SCALING_COEFFICIENTS", LMY, None),
    TIR_K("SCALING_COEFFICIENTS", LMP, None), TIR_K("SCALING_COEFFICIENTS", LSGKP, None),
    TIR_K("SCALING_COEFFICIENTS", LSGAL, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PCX1, None), TIR_K("LONGITUDINAL_COEFFICIENTS", PDX1, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PDX2, None), TIR_K("LONGITUDINAL_COEFFICIENTS", PDX3, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PEX1, None), TIR_K("LONGITUDINAL_COEFFICIENTS", PEX2, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PEX3, None), TIR_K("LONGITUDINAL_COEFFICIENTS", PEX4, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PKX1, None), TIR_K("LONGITUDINAL_COEFFICIENTS", PKX2, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PKX3, None), TIR_K("LONGITUDINAL_COEFFICIENTS", PHX1, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PHX2, None), TIR_K("LONGITUDINAL_COEFFICIENTS", PVX1, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PVX2, None), TIR_K("LONGITUDINAL_COEFFICIENTS", PPX1, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PPX2, None), TIR_K("LONGITUDINAL_COEFFICIENTS", PPX3, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PPX4, None), TIR_K("LONGITUDINAL_COEFFICIENTS", RBX1, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", RBX2, None), TIR_K("LONGITUDINAL_COEFFICIENTS", RBX3, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", RCX1, None), TIR_K("LONGITUDINAL_COEFFICIENTS", REX1, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", REX2, None), TIR_K("LONGITUDINAL_COEFFICIENTS", RHX1, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PTX1, None), TIR_K("LONGITUDINAL_COEFFICIENTS", PTX2, None),
    TIR_K("LONGITUDINAL_COEFFICIENTS", PTX3, None),
    TIR_K("OVERTURNING_COEFFICIENTS", QSX1, None), TIR_K("OVERTURNING_COEFFICIENTS", QSX2, None),
    TIR_K("OVERTURNING_COEFFICIENTS", QSX3, None), TIR_K("OVERTURNING_COEFFICIENTS", QSX4, None),
    TIR_K("OVERTURNING_COEFFICIENTS", QSX5, None), TIR_K("OVERTURNING_COEFFICIENTS", QSX6, None),
    TIR_K("OVERTURNING_COEFFICIENTS", QSX7, None), TIR_K("OVERTURNING_COEFFICIENTS", QSX8, None),
    TIR_K("OVERTURNING_COEFFICIENTS", QSX9, None), TIR_K("OVERTURNING_COEFFICIENTS", QSX10, None),
    TIR_K("OVERTURNING_COEFFICIENTS", QSX11, None), TIR_K("OVERTURNING_COEFFICIENTS", QSX12, None),
    TIR_K("OVERTURNING_COEFFICIENTS", QSX13, None), TIR_K("OVERTURNING_COEFFICIENTS", QSX14, None),
    TIR_K("OVERTURNING_COEFFICIENTS", PPMX1, None),
    TIR_K("LATERAL_COEFFICIENTS", PCY1, None), TIR_K("LATERAL_COEFFICIENTS", PDY1, None),
    TIR_K("LATERAL_COEFFICIENTS", PDY2, None), TIR_K("LATERAL_COEFFICIENTS", PDY3, None),
    TIR_K("LATERAL_COEFFICIENTS", PEY1, None), TIR_K("LATERAL_COEFFICIENTS", PEY2, None),
    TIR_K("LATERAL_COEFFICIENTS", PEY3, None), TIR_K("LATERAL_COEFFICIENTS", PEY4, None),
    TIR_K("LATERAL_COEFFICIENTS", PEY5, None), TIR_K("LATERAL_COEFFICIENTS", PKY1, None),
    TIR_K("LATERAL_COEFFICIENTS", PKY2, None), TIR_K("LATERAL_COEFFICIENTS", PKY3, None),
    TIR_K("LATERAL_COEFFICIENTS", PKY4, None), TIR_K("LATERAL_COEFFICIENTS", PKY5, None),
    TIR_K("LATERAL_COEFFICIENTS", PKY6, None), TIR_K("LATERAL_COEFFICIENTS", PKY7, None),
    TIR_K("LATERAL_COEFFICIENTS", PHY1, None), TIR_K("LATERAL_COEFFICIENTS", PHY2, None),
    TIR_K("LATERAL_COEFFICIENTS", PHY3, None), TIR_K("LATERAL_COEFFICIENTS", PVY1, None),
    TIR_K("LATERAL_COEFFICIENTS", PVY2, None), TIR_K("LATERAL_COEFFICIENTS", PVY3, None),
    TIR_K("LATERAL_COEFFICIENTS", PVY4, None), TIR_K("LATERAL_COEFFICIENTS", PPY1, None),
    TIR_K("LATERAL_COEFFICIENTS", PPY2, None), TIR_K("LATERAL_COEFFICIENTS", PPY3, None),
    TIR_K("LATERAL_COEFFICIENTS", PPY4, None), TIR_K("LATERAL_COEFFICIENTS", PPY5, None),
    TIR_K("LATERAL_COEFFICIENTS", RBY1, None), TIR_K("LATERAL_COEFFICIENTS", RBY2, None),
    TIR_K("LATERAL_COEFFICIENTS", RBY3, None), TIR_K("LATERAL_COEFFICIENTS", RBY4, None),
    TIR_K("LATERAL_COEFFICIENTS", RCY1, None), TIR_K("LATERAL_COEFFICIENTS", REY1, None),
    TIR_K("LATERAL_COEFFICIENTS", REY2, None), TIR_K("LATERAL_COEFFICIENTS", RHY1, None),
    TIR_K("LATERAL_COEFFICIENTS", RHY2, None), TIR_K("LATERAL_COEFFICIENTS", RVY1, None),
    TIR_K("LATERAL_COEFFICIENTS", RVY2, None), TIR_K("LATERAL_COEFFICIENTS", RVY3, None),
    TIR_K("LATERAL_COEFFICIENTS", RVY4, None), TIR_K("LATERAL_COEFFICIENTS", RVY5, None),
    TIR_K("LATERAL_COEFFICIENTS", RVY6, None), TIR_K("LATERAL_COEFFICIENTS", PTY1, None),
    TIR_K("LATERAL_COEFFICIENTS", PTY2, None),
    TIR_K("ROLLING_COEFFICIENTS", QSY1, None), TIR_K("ROLLING_COEFFICIENTS", QSY2, None),
    TIR_K("ROLLING_COEFFICIENTS", QSY3, None), TIR_K("ROLLING_COEFFICIENTS", QSY4, None),
    TIR_K("ROLLING_COEFFICIENTS", QSY5, None), TIR_K("ROLLING_COEFFICIENTS", QSY6, None),
    TIR_K("ROLLING_COEFFICIENTS", QSY7, None), TIR_K("ROLLING_COEFFICIENTS", QSY8, None),
    TIR_K("ALIGNING_COEFFICIENTS", QBZ1, None), TIR_K("ALIGNING_COEFFICIENTS", QBZ2, None),
    TIR_K("ALIGNING_COEFFICIENTS", QBZ3, None), TIR_K("ALIGNING_COEFFICIENTS", QBZ4, None),
    TIR_K("ALIGNING_COEFFICIENTS", QBZ5, None), TIR_K("ALIGNING_COEFFICIENTS", QBZ9, None),
    TIR_K("ALIGNING_COEFFICIENTS", QBZ10, None), TIR_K("ALIGNING_COEFFICIENTS", QCZ1, None),
    TIR_K("ALIGNING_COEFFICIENTS", QDZ1, None), TIR_K("ALIGNING_COEFFICIENTS", QDZ2, None),
    TIR_K("ALIGNING_COEFFICIENTS", QDZ3, None), TIR_K("ALIGNING_COEFFICIENTS", QDZ4, None),
    TIR_K("ALIGNING_COEFFICIENTS", QDZ6, None), TIR_K("ALIGNING_COEFFICIENTS", QDZ7, None),
    TIR_K("ALIGNING_COEFFICIENTS", QDZ8, None), TIR_K("ALIGNING_COEFFICIENTS", QDZ9, None),
    TIR_K("ALIGNING_COEFFICIENTS", QDZ10, None), TIR_K("ALIGNING_COEFFICIENTS", QDZ11, None),
    TIR_K("ALIGNING_COEFFICIENTS", QEZ1, None), TIR_K("ALIGNING_COEFFICIENTS", QEZ2, None),
    TIR_K("ALIGNING_COEFFICIENTS", QEZ3, None), TIR_K("ALIGNING_COEFFICIENTS", QEZ4, None),
    TIR_K("ALIGNING_COEFFICIENTS", QEZ5, None), TIR_K("ALIGNING_COEFFICIENTS", QHZ1, None),
    TIR_K("ALIGNING_COEFFICIENTS", QHZ2, None), TIR_K("ALIGNING_COEFFICIENTS", QHZ3, None),
    TIR_K("ALIGNING_COEFFICIENTS", QHZ4, None), TIR_K("ALIGNING_COEFFICIENTS", PPZ1, None),
    TIR_K("ALIGNING_COEFFICIENTS", PPZ2, None), TIR_K("ALIGNING_COEFFICIENTS", SSZ1, None),
    TIR_K("ALIGNING_COEFFICIENTS", SSZ2, None), TIR_K("ALIGNING_COEFFICIENTS", SSZ3, None),
    TIR_K("ALIGNING_COEFFICIENTS", SSZ4, None),
    TIR_K("TURNSLIP_COEFFICIENTS", PDXP1, None), TIR_K("TURNSLIP_COEFFICIENTS", PDXP2, None),
    TIR_K("TURNSLIP_COEFFICIENTS", PDXP3, None), TIR_K("TURNSLIP_COEFFICIENTS", PKYP1, None),
    TIR_K("TURNSLIP_COEFFICIENTS", PDYP1, None), TIR_K("TURNSLIP_COEFFICIENTS", PDYP2, None),
    TIR_K("TURNSLIP_COEFFICIENTS", PDYP3, None), TIR_K("TURNSLIP_COEFFICIENTS", PDYP4, None),
    TIR_K("TURNSLIP_COEFFICIENTS", PHYP1, None), TIR_K("TURNSLIP_COEFFICIENTS", PHYP2, None),
    TIR_K("TURNSLIP_COEFFICIENTS", PHYP3, None), TIR_K("TURNSLIP_COEFFICIENTS", PHYP4, None),
    TIR_K("TURNSLIP_COEFFICIENTS", PECP1, None), TIR_K("TURNSLIP_COEFFICIENTS", PECP2, None),
    TIR_K("TURNSLIP_COEFFICIENTS", QDTP1, None), TIR_K("TURNSLIP_COEFFICIENTS", QCRP1, None),
    TIR_K("TURNSLIP_COEFFICIENTS", QCRP2, None), TIR_K("TURNSLIP_COEFFICIENTS", QBRP1, None),
    TIR_K("TURNSLIP_COEFFICIENTS", QDRP1, None),
};
#undef TIR_K

// Keys of the coefficient sections that real files carry but the evaluation does not use (MF 5.2's
// camber scalings LGAX/LGAY/LGAZ, which MFeval replaces by LKYC/LKZC; the gyroscopic torque QTZ1,
// MBELT; book-only terms): accepted, checked to be numbers, and listed in `ignored`.
const char* const tir_unused_coefficient_keys[] = {"LGAX", "LGAY", "LGAZ", "LGYR", "LMUV", "LCZ", "QTZ1", "MBELT",
                                                    "QBZ6", "QBZ7", "QBZ8", "QDZ5"};

// The sections the reader knows (others are skipped whole, as [SHAPE]).
const char* const tir_known_sections[] = {
    "MDI_HEADER", "UNITS", "MODEL", "DIMENSION", "OPERATING_CONDITIONS", "INERTIA", "VERTICAL", "STRUCTURAL",
    "CONTACT_PATCH", "INFLATION_PRESSURE_RANGE", "VERTICAL_FORCE_RANGE", "LONG_SLIP_RANGE", "SLIP_ANGLE_RANGE",
    "INCLINATION_ANGLE_RANGE", "SCALING_COEFFICIENTS", "LONGITUDINAL_COEFFICIENTS", "OVERTURNING_COEFFICIENTS",
    "LATERAL_COEFFICIENTS", "ROLLING_COEFFICIENTS", "ALIGNING_COEFFICIENTS", "TURNSLIP_COEFFICIENTS"};

const char* const tir_required_sections[] = {"UNITS", "MODEL", "DIMENSION", "VERTICAL", "LONGITUDINAL_COEFFICIENTS",
                                             "LATERAL_COEFFICIENTS", "ALIGNING_COEFFICIENTS"};

struct TirEntry {
  std::string section, key, value;
  int line = 0;
  bool used = false;
};

std::string tir_upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}
std::string tir_lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}
std::string tir_trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n\f\v");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n\f\v");
  return s.substr(b, e - b + 1);
}

bool tir_in(const char* const* list, std::size_t n, const std::string& s) {
  for (std::size_t i = 0; i < n; ++i)
    if (s == list[i]) return true;
  return false;
}

[[noreturn]] void tir_fail(const std::string& file, const std::string& section, const std::string& key,
                           const std::string& what, int line = 0) {
  std::ostringstream m;
  m << file << ": [" << section << "]";
  if (!key.empty()) m << " " << key;
  m << ": " << what;
  if (line > 0) m << " (line " << line << ")";
  throw TirFileError(m.str());
}

// a quoted value's text, or "" with quoted = false
std::string tir_unquote(const std::string& v, bool& quoted) {
  quoted = v.size() >= 2 && (v.front() == '\'' || v.front() == '"') && v.back() == v.front();
  return quoted ? v.substr(1, v.size() - 2) : v;
}

// a number the whole text spells (Fortran's D exponent and a leading + accepted)
bool tir_number(std::string v, double& out) {
  if (v.empty()) return false;
  for (char& c : v)
    if (c == 'D' || c == 'd') c = 'e';
  std::size_t start = v[0] == '+' ? 1 : 0;
  if (start >= v.size()) return false;
  const char* b = v.data() + start;
  const char* e = v.data() + v.size();
  const auto r = std::from_chars(b, e, out);
  return r.ec == std::errc() && r.ptr == e && std::isfinite(out);
}

struct TirUnits {
  double length = 1, force = 1, angle = 1, mass = 1, time = 1, pressure = 0;  // pressure 0: force / length^2
};

double tir_unit_factor(const std::string& file, const TirEntry& e) {
  bool quoted = false;
  const std::string u = tir_lower(tir_trim(tir_unquote(e.value, quoted)));
  struct U {
    const char* name;
    double f;
  };
  static const U lengths[] = {{"meter", 1}, {"meters", 1}, {"metre", 1}, {"m", 1}, {"millimeter", 1e-3}, {"millimeters", 1e-3},
                              {"millimetre", 1e-3}, {"mm", 1e-3}, {"centimeter", 1e-2}, {"centimeters", 1e-2},
                              {"cm", 1e-2}, {"kilometer", 1e3}, {"km", 1e3}, {"inch", 0.0254}, {"in", 0.0254},
                              {"foot", 0.3048}, {"ft", 0.3048}};
  static const U forces[] = {{"newton", 1}, {"newtons", 1}, {"n", 1}, {"kilonewton", 1e3}, {"kilonewtons", 1e3},
                             {"kn", 1e3}, {"pound_force", 4.4482216152605}, {"lbf", 4.4482216152605}};
  static const U angles[] = {{"radians", 1}, {"radian", 1}, {"rad", 1}, {"degrees", 3.14159265358979323846 / 180},
                             {"degree", 3.14159265358979323846 / 180}, {"deg", 3.14159265358979323846 / 180}};
  static const U masses[] = {{"kg", 1}, {"kilogram", 1}, {"kilograms", 1}, {"gram", 1e-3}, {"grams", 1e-3}, {"g", 1e-3},
                             {"tonne", 1e3}, {"pound_mass", 0.45359237}, {"lbm", 0.45359237}};
  static const U times[] = {{"second", 1}, {"seconds", 1}, {"sec", 1}, {"s", 1}, {"millisecond", 1e-3}, {"ms", 1e-3},
                            {"minute", 60}, {"hour", 3600}};
  static const U pressures[] = {{"pascal", 1}, {"pa", 1}, {"kilopascal", 1e3}, {"kpa", 1e3}, {"megapascal", 1e6},
                                {"mpa", 1e6}, {"bar", 1e5}, {"mbar", 1e2}, {"psi", 6894.757293168361}};
  const U* table = nullptr;
  std::size_t n = 0;
  if (e.key == "LENGTH") table = lengths, n = std::size(lengths);
  else if (e.key == "FORCE") table = forces, n = std::size(forces);
  else if (e.key == "ANGLE") table = angles, n = std::size(angles);
  else if (e.key == "MASS") table = masses, n = std::size(masses);
  else if (e.key == "TIME") table = times, n = std::size(times);
  else if (e.key == "PRESSURE") table = pressures, n = std::size(pressures);
  for (std::size_t i = 0; i < n; ++i)
    if (u == table[i].name) return table[i].f;
  tir_fail(file, e.section, e.key, "unit '" + u + "' cannot be converted to SI", e.line);
}

double tir_dim_factor(TirDim d, const TirUnits& u) {
  const double pressure = u.pressure > 0 ? u.pressure : u.force / (u.length * u.length);
  switch (d) {
    case TirDim::None: return 1;
    case TirDim::Length: return u.length;
    case TirDim::Force: return u.force;
    case TirDim::Stiffness: return u.force / u.length;
    case TirDim::Damping: return u.force * u.time / u.length;
    case TirDim::Pressure: return pressure;
    case TirDim::Speed: return u.length / u.time;
    case TirDim::Angle: return u.angle;
    case TirDim::Mass: return u.mass;
    case TirDim::Inertia: return u.mass * u.length * u.length;
    case TirDim::Accel: return u.length / (u.time * u.time);
    case TirDim::Frequency: return 1 / u.time;
    case TirDim::Time: return u.time;
    case TirDim::YawStiffness: return u.force * u.length / u.angle;
  }
  return 1;
}

}  // namespace

bool MagicFormulaParameters::was_defaulted(const std::string& key) const {
  const std::string k = tir_upper(key);
  for (const std::string& d : defaulted)
    if (d == k || (d.size() > k.size() && d.compare(d.size() - k.size(), k.size(), k) == 0 &&
                   d[d.size() - k.size() - 1] == '/'))
      return true;
  return false;
}

MagicFormulaParameters parse_tir_text(const std::string& text, const std::string& name) {
  MagicFormulaParameters p;
  p.file = name;

  // 1. lines into (section, key, value) entries
  std::vector<TirEntry> entries;
  std::vector<std::string> sections_seen;
  std::string section;
  bool section_known = false;
  int line_no = 0;
  std::size_t pos = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;  // a UTF-8 byte order mark
  while (pos <= text.size()) {
    std::size_t end = text.find_first_of("\r\n", pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    ++line_no;
    if (end < text.size() && text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n') ++end;
    pos = end + 1;
    // the comment: '$' (or '!') outside quotes to the end of the line
    char quote = 0;
    for (std::size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quote) {
        if (c == quote) quote = 0;
      } else if (c == '\'' || c == '"') {
        quote = c;
      } else if (c == '$' || c == '!') {
        line.resize(i);
        break;
      }
    }
    line = tir_trim(line);
    if (line.empty()) continue;
    if (line.front() == '[') {
      const auto close = line.find(']');
      if (close == std::string::npos) tir_fail(name, line.substr(1), "", "section header without ']'", line_no);
      section = tir_upper(tir_trim(line.substr(1, close - 1)));
      section_known = tir_in(tir_known_sections, std::size(tir_known_sections), section);
      if (std::find(sections_seen.begin(), sections_seen.end(), section) != sections_seen.end() && section_known)
        tir_fail(name, section, "", "section given twice", line_no);
      sections_seen.push_back(section);
      if (!section_known && std::find(p.ignored.begin(), p.ignored.end(), section) == p.ignored.end())
        p.ignored.push_back(section);
      continue;
    }
    if (section.empty()) tir_fail(name, "", "", "a line before the first [SECTION]: '" + line + "'", line_no);
    if (!section_known) continue;  // [SHAPE] tables and sections the reader does not know
    const auto eq = line.find('=');
    if (eq == std::string::npos) tir_fail(name, section, "", "expected KEY = value, found '" + line + "'", line_no);
    TirEntry e;
    e.section = section;
    e.key = tir_upper(tir_trim(line.substr(0, eq)));
    e.value = tir_trim(line.substr(eq + 1));
    e.line = line_no;
    if (e.key.empty()) tir_fail(name, section, "", "a value without a key", line_no);
    for (const TirEntry& o : entries)
      if (o.section == e.section && o.key == e.key)
        tir_fail(name, section, e.key, "given twice (lines " + std::to_string(o.line) + " and " + std::to_string(line_no) + ")",
                 line_no);
    entries.push_back(e);
  }
  for (const char* req : tir_required_sections)
    if (std::find(sections_seen.begin(), sections_seen.end(), req) == sections_seen.end())
      tir_fail(name, req, "", "required section missing");

  // 2. units first
  TirUnits units;
  bool unit_given[6] = {false, false, false, false, false, false};
  const char* const unit_keys[] = {"LENGTH", "FORCE", "ANGLE", "MASS", "TIME", "PRESSURE"};
  for (TirEntry& e : entries) {
    if (e.section != "UNITS") continue;
    e.used = true;
    double* target[] = {&units.length, &units.force, &units.angle, &units.mass, &units.time, &units.pressure};
    bool known = false;
    for (int i = 0; i < 6; ++i)
      if (e.key == unit_keys[i]) *target[i] = tir_unit_factor(name, e), unit_given[i] = known = true;
    if (!known) p.ignored.push_back("UNITS/" + e.key);
  }
  for (int i = 0; i < 5; ++i)
    if (!unit_given[i]) p.defaulted.push_back(std::string("UNITS/") + unit_keys[i]);

  // 3. every other value
  const std::size_t nkeys = std::size(tir_keys);
  std::vector<int> given(nkeys, 0);  // the line a key came from
  std::vector<std::string> given_section(nkeys);
  bool fittyp_given = false, side_given = false;
  for (TirEntry& e : entries) {
    if (e.used) continue;
    e.used = true;
    bool quoted = false;
    const std::string unq = tir_unquote(e.value, quoted);
    if (e.key == "FITTYP" || e.key == "TYRESIDE") {
      if (e.key == "FITTYP") {
        double v = 0;
        if (quoted || !tir_number(e.value, v)) tir_fail(name, e.section, e.key, "not a number: '" + e.value + "'", e.line);
        if (v != 5 && v != 6 && v != 61 && v != 62)
          tir_fail(name, e.section, e.key,
                   "unknown Magic Formula version " + e.value + " (known: 6 or 5 for MF 5.2, 61 for MF 6.1, 62 for MF 6.2)",
                   e.line);
        p.FITTYP = static_cast<int>(v);
        fittyp_given = true;
      } else {
        const std::string s = tir_upper(tir_trim(unq));
        if (s == "LEFT" || s == "L") p.TYRESIDE = TireSide::Left;
        else if (s == "RIGHT" || s == "R") p.TYRESIDE = TireSide::Right;
        else if (s == "SYMMETRIC" || s == "SYMMETRICAL") p.TYRESIDE = TireSide::Symmetric;
        else tir_fail(name, e.section, e.key, "unknown side '" + unq + "' (LEFT, RIGHT or SYMMETRIC)", e.line);
        side_given = true;
      }
      continue;
    }
    std::size_t k = nkeys;
    for (std::size_t i = 0; i < nkeys; ++i)
      if (e.key == tir_keys[i].key) {
        k = i;
        break;
      }
    if (k < nkeys) {
      double v = 0;
      if (quoted || !tir_number(e.value, v)) tir_fail(name, e.section, e.key, "not a number: '" + e.value + "'", e.line);
      if (given[k])
        tir_fail(name, e.section, e.key,
                 "given twice (also in [" + given_section[k] + "], line " + std::to_string(given[k]) + ")", e.line);
      given[k] = e.line;
      given_section[k] = e.section;
      p.*(tir_keys[k].member) = v * tir_dim_factor(tir_keys[k].dim, units);
      continue;
    }
    const bool coefficient_section =
        e.section.size() > 13 && e.section.compare(e.section.size() - 13, 13, "_COEFFICIENTS") == 0;
    if (coefficient_section) {
      if (!tir_in(tir_unused_coefficient_keys, std::size(tir_unused_coefficient_keys), e.key))
        tir_fail(name, e.section, e.key, "unknown key", e.line);
      double v = 0;
      if (quoted || !tir_number(e.value, v)) tir_fail(name, e.section, e.key, "not a number: '" + e.value + "'", e.line);
    }
    p.ignored.push_back(e.section + "/" + e.key);
  }
  if (!fittyp_given) tir_fail(name, "MODEL", "FITTYP", "required key missing");
  if (!side_given) p.defaulted.push_back("MODEL/TYRESIDE");
  for (std::size_t i = 0; i < nkeys; ++i)
    if (!given[i]) p.defaulted.push_back(std::string(tir_keys[i].section) + "/" + tir_keys[i].key);
  p.version = p.FITTYP == 61 ? MagicFormulaVersion::MF61
              : p.FITTYP == 62 ? MagicFormulaVersion::MF62
                               : MagicFormulaVersion::MF52;

  // 4. required keys and physical sense
  auto where = [&](const char* key) {
    for (std::size_t i = 0; i < nkeys; ++i)
      if (std::string(key) == tir_keys[i].key) return given[i] ? given_section[i] : std::string(tir_keys[i].section);
    return std::string();
  };
  auto line_of = [&](const char* key) {
    for (std::size_t i = 0; i < nkeys; ++i)
      if (std::string(key) == tir_keys[i].key) return given[i];
    return 0;
  };
  for (const char* req : {"UNLOADED_RADIUS", "FNOMIN"})
    if (!line_of(req)) tir_fail(name, where(req), req, "required key missing");
  auto positive = [&](const char* key, double v) {
    if (!(v > 0)) {
      std::ostringstream m;
      m << "must be > 0, is " << v;
      tir_fail(name, where(key), key, m.str(), line_of(key));
    }
  };
  positive("FNOMIN", p.FNOMIN);
  positive("UNLOADED_RADIUS", p.UNLOADED_RADIUS);
  positive("VERTICAL_STIFFNESS", p.VERTICAL_STIFFNESS);
  positive("NOMPRES", p.NOMPRES);
  positive("INFLPRES", p.INFLPRES);
  positive("LONGVL", p.LONGVL);
  positive("LFZO", p.LFZO);
  auto not_negative = [&](const char* key, double v) {
    if (v < 0) {
      std::ostringstream m;
      m << "must not be negative, is " << v;
      tir_fail(name, where(key), key, m.str(), line_of(key));
    }
  };
  not_negative("VXLOW", p.VXLOW);
  not_negative("WIDTH", p.WIDTH);
  not_negative("FZMIN", p.FZMIN);
  not_negative("PRESMIN", p.PRESMIN);
  auto ordered = [&](const char* lo, double a, const char* hi, double b) {
    if (a > b) {
      std::ostringstream m;
      m << "the minimum " << a << " exceeds " << hi << " " << b;
      tir_fail(name, where(lo), lo, m.str(), line_of(lo));
    }
  };
  ordered("FZMIN", p.FZMIN, "FZMAX", p.FZMAX);
  ordered("PRESMIN", p.PRESMIN, "PRESMAX", p.PRESMAX);
  ordered("KPUMIN", p.KPUMIN, "KPUMAX", p.KPUMAX);
  ordered("ALPMIN", p.ALPMIN, "ALPMAX", p.ALPMAX);
  ordered("CAMMIN", p.CAMMIN, "CAMMAX", p.CAMMAX);
  return p;
}

MagicFormulaParameters read_tir_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TirFileError(path + ": cannot be opened");
  std::ostringstream s;
  s << in.rdbuf();
  return parse_tir_text(s.str(), path);
}

}  // namespace codyna
