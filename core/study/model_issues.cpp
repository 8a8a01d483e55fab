#include "study/model_issues.hpp"

#include <algorithm>
#include <set>
#include <tuple>

#include "model/compile.hpp"
#include "model/spec_edit.hpp"
#include "study/workflow.hpp"

namespace codyna {

namespace {

std::string in_quotes(const std::string& s) { return "\"" + s + "\""; }

std::string names_or_none(const std::vector<std::string>& names) {
  if (names.empty()) return "none yet";
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + names[i];
  return out;
}

// the file's order: the sections as a model file lists them, then indices as numbers, then the field
std::tuple<int, int, std::string> file_order_key(const std::string& path) {
  if (const auto ref = element_at_path(path)) return {static_cast<int>(ref->kind), ref->index, ref->field};
  return {static_cast<int>(std::size(kElementKinds)), 0, path};
}

}  // namespace

ModelCheck check_model(const ModelSpec& spec, const std::string& file) {
  ModelCheck out;
  try {
    out.model = std::make_shared<const Model>(study_model(spec, file));
    return out;
  } catch (const ModelError& e) {
    out.issues.push_back(e);
  } catch (const std::exception& e) {  // not the spec's fault as far as it can tell: no field to name
    out.issues.emplace_back(file, "", e.what());
    return out;
  }

  std::vector<ModelError> found;
  for (const ReferenceField& r : reference_fields(spec)) {
    if (r.target == ElementKind::Body && r.name == kGroundName) continue;
    if (r.name.empty() && r.target == ElementKind::Body && r.path.size() > 6 && r.path.compare(r.path.size() - 6, 6, "/frame") == 0)
      continue;  // a sensor's axes: empty is the ground's
    if (find_element(spec, r.target, r.name) >= 0) continue;
    const std::string detail = r.name.empty()
                                   ? std::string("expected the name of a ") + to_string(r.target) + " (" + section_of(r.target) + ": " +
                                         names_or_none(element_names(spec, r.target)) + ")"
                                   : std::string("unknown ") + to_string(r.target) + " " + in_quotes(r.name) + " (" + section_of(r.target) +
                                         ": " + names_or_none(element_names(spec, r.target)) + ")";
    found.emplace_back(file, r.path, detail);
  }
  std::set<std::string> children;
  for (const JointSpec& j : spec.joints) children.insert(j.child);
  for (std::size_t i = 0; i < spec.bodies.size(); ++i)
    if (!spec.bodies[i].name.empty() && !children.count(spec.bodies[i].name))
      found.emplace_back(file, "/bodies/" + std::to_string(i), unattached_body_detail(spec.bodies[i].name));

  // the compile's own error first in its place, and no field twice
  std::set<std::string> paths{out.issues.front().path()};
  for (ModelError& e : found)
    if (paths.insert(e.path()).second) out.issues.push_back(std::move(e));
  const std::string compiled = out.issues.front().path();
  std::stable_sort(out.issues.begin(), out.issues.end(),
                   [](const ModelError& a, const ModelError& b) { return file_order_key(a.path()) < file_order_key(b.path()); });
  for (std::size_t i = 0; i < out.issues.size(); ++i)
    if (out.issues[i].path() == compiled) out.first = i;
  return out;
}

}  // namespace codyna
