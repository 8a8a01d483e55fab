#include "io/import_report.hpp"

#include <sstream>

namespace codyna {

const std::vector<std::pair<std::string, std::string>>& import_kinds() {
  static const std::vector<std::pair<std::string, std::string>> kinds = {
      {"contacts", "collision geometry and contact pairs (reported; the geoms become display shapes)"},
      {"limits", "joint limits and velocity limits (reported; kept in the model's description)"},
      {"armature", "rotor inertia (MJCF armature): mapped to the joints' armature, refused on free joints "
                   "(refused unless ignored); --ignore armature leaves it out"},
      {"frictionloss", "dry joint friction (MJCF frictionloss, URDF dynamics friction) (refused unless ignored)"},
      {"springs", "joint stiffness on ball and free joints (refused unless ignored)"},
      {"fluid", "fluid forces (MJCF density, viscosity, wind) (refused unless ignored)"},
      {"equality", "equality constraints other than connect and linear joint couplings (weld, tendon, polynomial) (refused unless ignored)"},
      {"soft_constraints", "MuJoCo's constraint softness (solref, solimp): codyna closes loops exactly (reported)"},
      {"tendons", "tendons, and actuators that pull on them (refused unless ignored when they act)"},
      {"muscles", "muscle actuators (refused unless ignored)"},
      {"actuators", "actuators codyna cannot represent: slider-crank, site and adhesion transmissions, "
                    "activation dynamics, gains that vary (refused unless ignored)"},
      {"forcerange", "force limits of servo actuators (reported)"},
      {"mimic", "URDF mimic joints that are not between two scalar joints (refused unless ignored)"},
      {"sensors", "sensors with no codyna equivalent (reported)"},
      {"shapes", "geometry shown approximately or not at all (reported)"},
      {"other", "sites, cameras, lights, keyframes, mocap bodies and other elements with no effect on the "
                "dynamics (reported)"},
  };
  return kinds;
}

void check_import_options(const ImportOptions& options) {
  for (const std::string& k : options.ignore) {
    bool known = false;
    for (const auto& [name, line] : import_kinds()) known = known || name == k;
    if (!known) {
      std::string names;
      for (const auto& [name, line] : import_kinds()) names += (names.empty() ? "" : ", ") + name;
      throw std::invalid_argument("--ignore " + k + ": unknown kind (kinds: " + names + ")");
    }
  }
}

void add_finding(ImportReport& r, const ImportOptions& options, const std::string& kind, const std::string& what,
                 std::vector<std::string> elements, bool changes_dynamics) {
  if (elements.empty()) return;
  ImportFinding f;
  f.kind = kind;
  f.what = what;
  f.elements = std::move(elements);
  f.changes_dynamics = changes_dynamics;
  f.ignored = options.ignore.count(kind) != 0;
  r.findings.push_back(std::move(f));
}

std::vector<const ImportFinding*> ImportReport::refusals() const {
  std::vector<const ImportFinding*> out;
  for (const ImportFinding& f : findings)
    if (f.changes_dynamics && !f.ignored) out.push_back(&f);
  return out;
}

namespace {
std::string element_list(const std::vector<std::string>& e) {
  std::string s;
  const std::size_t shown = e.size() > 30 ? 25 : e.size();
  for (std::size_t i = 0; i < shown; ++i) s += (i ? ", " : "") + e[i];
  if (shown < e.size()) s += ", and " + std::to_string(e.size() - shown) + " more";
  return s;
}
}  // namespace

std::string ImportReport::text() const {
  std::ostringstream os;
  os << "read " << source << " (" << format << ", by " << reader << ")\n";
  os << "mapped:\n";
  for (const std::string& m : mapped) os << "  " << m << "\n";
  if (!findings.empty()) {
    os << "not modelled:\n";
    for (const ImportFinding& f : findings) {
      os << "  " << f.kind;
      if (f.changes_dynamics) os << (f.ignored ? " (changes the dynamics; ignored by --ignore " + f.kind + ")"
                                               : " (changes the dynamics: refused)");
      else if (f.ignored) os << " (ignored)";
      os << ": " << f.what << ": " << element_list(f.elements) << "\n";
    }
  }
  return os.str();
}

void refuse_if_needed(const ImportReport& r) {
  const auto refused = r.refusals();
  if (refused.empty()) return;
  std::ostringstream os;
  os << r.source << ": cannot import without changing the dynamics: ";
  std::string kinds;
  for (std::size_t i = 0; i < refused.size(); ++i) {
    const ImportFinding& f = *refused[i];
    os << (i ? "; " : "") << f.kind << ": " << f.what << ": " << element_list(f.elements);
    kinds += " --ignore " + f.kind;
  }
  os << " (to import without them:" << kinds << ")";
  throw ImportRefused(os.str(), r);
}

std::string NameSet::unique(const std::string& wanted) {
  std::string n = wanted.empty() ? std::string("unnamed") : wanted;
  if (used_.insert(n).second) return n;
  for (int k = 2;; ++k) {
    const std::string c = n + "_" + std::to_string(k);
    if (used_.insert(c).second) return c;
  }
}

}  // namespace codyna
