// What an import of a foreign model (MJCF, URDF) mapped and what it did not: the report
// the front ends print (codyna import, codyna-gui's File > Import) and the rule that an
// element which would change the dynamics and cannot be represented stops the import
// unless its kind is ignored (docs/import.md).
#pragma once

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/model_spec.hpp"

namespace codyna {

// One kind of element that was not mapped (or not mapped exactly), said once with the
// elements it concerns.
struct ImportFinding {
  std::string kind;                   // the name --ignore takes: "armature", "contacts", ...
  std::string what;                   // what is not modelled, and what codyna does instead
  std::vector<std::string> elements;  // the elements, with their values where they matter
  bool changes_dynamics = false;      // true: the import fails unless the kind is ignored
  bool ignored = false;               // the kind was given to --ignore
};

struct ImportReport {
  std::string source;                 // the file imported
  std::string format;                 // "MJCF", "URDF"
  std::string reader;                 // "MuJoCo 2.2.2 (mj_loadXML)", "urdfdom"
  std::vector<std::string> mapped;    // one line per kind of element mapped
  std::vector<ImportFinding> findings;

  // the findings that stop the import (change the dynamics, not ignored)
  std::vector<const ImportFinding*> refusals() const;
  // the report as printed: "mapped:" lines, then "not modelled:" lines
  std::string text() const;
};

struct ImportOptions {
  std::set<std::string> ignore;  // kinds of findings accepted as not modelled
};

struct ImportResult {
  ModelSpec spec;
  ImportReport report;
};

// An import refused because of elements that change the dynamics and cannot be represented
// (or because the file is malformed): bad input, exit code 1. The report so far is kept.
class ImportRefused : public std::invalid_argument {
 public:
  ImportRefused(const std::string& what, ImportReport report)
      : std::invalid_argument(what), report_(std::move(report)) {}
  const ImportReport& report() const { return report_; }

 private:
  ImportReport report_;
};

// Every kind a finding may have (what --ignore accepts), with a line on each.
const std::vector<std::pair<std::string, std::string>>& import_kinds();

// Throws std::invalid_argument naming the kinds there are when `options` ignores an unknown one.
void check_import_options(const ImportOptions& options);

// Adds a finding to the report (marked ignored when its kind is in options.ignore); nothing is
// added when `elements` is empty.
void add_finding(ImportReport& r, const ImportOptions& options, const std::string& kind, const std::string& what,
                 std::vector<std::string> elements, bool changes_dynamics);

// Throws ImportRefused when a finding changes the dynamics and is not ignored; the message names
// the file, each such kind with its elements, and the --ignore that would accept it.
void refuse_if_needed(const ImportReport& r);

// Names made unique within one list: "base", "base_2", ...
class NameSet {
 public:
  std::string unique(const std::string& wanted);
  bool has(const std::string& n) const { return used_.count(n) != 0; }
  void reserve(const std::string& n) { used_.insert(n); }

 private:
  std::set<std::string> used_;
};

}  // namespace codyna
