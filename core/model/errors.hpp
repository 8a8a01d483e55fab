// ModelError: what a bad model (file or spec) reports. It names the file (when
// there is one), the path of the offending field in JSON-pointer-like form
// ("/joints/2/parent"), and what was expected.
#pragma once

#include <stdexcept>
#include <string>

namespace codyna {

class ModelError : public std::runtime_error {
 public:
  // what kind of fault, for a front end that acts on it (an editor drops the fields of an
  // element's old type) without reading the message's words
  enum class Kind {
    Other,
    UnknownField,  // a field the element does not have (of another type, or of another tire law): path() ends with it
    MissingField,  // a required field the element lacks: path() is the element's, field() the field's name
  };

  ModelError(std::string file, std::string path, std::string what_expected, Kind kind = Kind::Other,
             std::string field = {})
      : std::runtime_error(compose(file, path, what_expected)),
        file_(std::move(file)), path_(std::move(path)), detail_(std::move(what_expected)), field_(std::move(field)),
        kind_(kind) {}

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const std::string& detail() const { return detail_; }
  Kind kind() const { return kind_; }
  const std::string& field() const { return field_; }  // MissingField: the field's name

  // The same error, attributed to a file (used when a spec error surfaces while loading a file).
  ModelError in_file(const std::string& f) const { return ModelError(f, path_, detail_, kind_, field_); }

 private:
  static std::string compose(const std::string& file, const std::string& path, const std::string& d) {
    std::string s;
    if (!file.empty()) s += file + ": ";
    if (!path.empty()) s += path + ": ";
    return s + d;
  }
  std::string file_, path_, detail_, field_;
  Kind kind_ = Kind::Other;
};

// A steady-state search (equilibrium, trim) that ended without converging: the residual it
// left is above the tolerance. Not bad input (the request was well formed) but a failure of
// the work: the front ends report it with exit code 2 and export or simulate nothing about
// the point. The message names the residual, the unknowns and what to free.
class ConvergenceError : public std::runtime_error {
 public:
  explicit ConvergenceError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace codyna
