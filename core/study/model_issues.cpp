#include "study/model_issues.hpp"


#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include "dynamics/prepare.hpp"
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

// the largest semi-axis of the body's solid ellipsoid of equal mass and inertia, else 0.1 m
double equivalent_reach(const BodySpec& b) {
  if (!(b.mass > 0) || !b.inertia.allFinite()) return 0.1;
  const Eigen::Vector3d I = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(b.inertia, Eigen::EigenvaluesOnly).eigenvalues();
  double r2 = 0;
  for (int k = 0; k < 3; ++k) r2 = std::max(r2, 2.5 * (I.sum() - 2 * I[k]) / b.mass);
  return r2 > 0 ? std::sqrt(r2) : 0.1;
}

}  // namespace

ModelDraft draft_model(const ModelSpec& spec, const std::string& file) {
  ModelDraft out;
  ModelSpec d = spec;
  d.plant = {};
  d.analysis = {};
  // bodies that no joint moves (at the start, or once their joint is left out): held in a row
  // along x, each clear of the one before
  std::vector<std::string> holders;
  double x = 0, previous = 0;
  const auto hold_unattached = [&] {
    std::set<std::string> children;
    for (const JointSpec& j : d.joints) children.insert(j.child);
    for (const BodySpec& b : std::vector<BodySpec>(d.bodies)) {
      if (b.name.empty() || b.name == kGroundName || children.count(b.name)) continue;
      const double reach = equivalent_reach(b);
      if (!holders.empty()) x += 1.5 * (previous + reach);
      previous = reach;
      JointSpec hold;
      hold.name = unique_name(d, ElementKind::Joint, "held_" + b.name);
      hold.type = JointType::Fixed;
      hold.parent = kGroundName;
      hold.child = b.name;
      hold.parent_frame.position = Eigen::Vector3d(x, 0, 0) - b.com;  // its centre of mass on the row
      d.joints.push_back(hold);
      holders.push_back(hold.name);
      children.insert(b.name);
    }
  };
  // one element left out per refusal: each compile either succeeds or names a field of an element
  const std::size_t most = [&] {
    std::size_t n = 0;
    for (ElementKind k : kElementKinds) n += static_cast<std::size_t>(element_count(d, k));
    return n + 1;
  }();
  for (std::size_t attempt = 0; attempt <= 2 * most; ++attempt) {
    hold_unattached();
    try {
      out.model = std::make_shared<const Model>(compile(d, file));
      for (const std::string& h : holders) {
        const int j = find_element(d, ElementKind::Joint, h);
        if (j >= 0) out.held.push_back(d.joints[static_cast<std::size_t>(j)].child);
      }
      return out;
    } catch (const ModelError& e) {
      const auto ref = element_at_path(e.path());
      if (!ref || ref->index < 0 || ref->index >= element_count(d, ref->kind)) return {};
      const std::string name = element_name(d, ref->kind, ref->index);
      const bool holder = ref->kind == ElementKind::Joint && std::count(holders.begin(), holders.end(), name);
      if (holder) {  // the body cannot be held either: leave it out, with its holder
        const std::string body = d.joints[static_cast<std::size_t>(ref->index)].child;
        remove_element(d, ref->kind, ref->index);
        const int b = find_element(d, ElementKind::Body, body);
        if (b >= 0) remove_element(d, ElementKind::Body, b);
        out.leaves_out.push_back("body " + body);
        continue;
      }
      out.leaves_out.push_back(std::string(to_string(ref->kind)) + " " + (name.empty() ? "(no name)" : name));
      remove_element(d, ref->kind, ref->index);
    } catch (const std::exception&) {
      return {};
    }
  }
  return {};
}

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
  out.draft = draft_model(spec, file);
  return out;
}

}  // namespace codyna
