#include "study/sweep.hpp"

#include "analysis/stability.hpp"


#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "io/atomic_file.hpp"
#include "io/model_file.hpp"
#include "model/errors.hpp"
#include "study/files.hpp"
#include "study/tools.hpp"

namespace codyna {
namespace {

constexpr long long kMaxVariants = 10'000'000;

struct Names {
  OptionStyle style;
  std::string operator()(const std::string& dashed) const { return option_name(style, dashed); }
};

std::string trim(std::string s) {
  const auto a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return {};
  const auto b = s.find_last_not_of(" \t");
  return s.substr(a, b - a + 1);
}

// SPEC begins NAME( (a distribution's call)
bool sweep_starts_call(const std::string& spec, const char* name) { return spec.rfind(std::string(name) + "(", 0) == 0; }

bool parse_number(const std::string& text, double& out) {
  const std::string t = trim(text);
  if (t.empty()) return false;
  const char* first = t.data();
  if (*first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, t.data() + t.size(), out);
  return ec == std::errc() && ptr == t.data() + t.size() && std::isfinite(out);
}

// ------------------------------------------------------------------ --vary parsing

SweepVary parse_vary(const std::string& text, const nlohmann::json& file, const std::string& model, const Names& opt) {
  const std::string label = opt("vary") + " " + text;
  const auto eq = text.find('=');
  if (eq == std::string::npos)
    throw std::invalid_argument(label + ": expected FIELD=SPEC (e.g. /bodies/1/mass=5:15:11)");
  SweepVary v;
  v.field = trim(text.substr(0, eq));
  v.spec = trim(text.substr(eq + 1));
  if (v.field.empty() || v.field[0] != '/')
    throw std::invalid_argument(label + ": the field must be a JSON pointer into the model file, starting with / "
                                "(e.g. /bodies/1/mass, /effects/0/stiffness, /joints/2/q0)");
  nlohmann::json::json_pointer ptr;
  try {
    ptr = nlohmann::json::json_pointer(v.field);
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(label + ": " + v.field + " is not a JSON pointer (" + e.what() + ")");
  }
  const nlohmann::json* at = nullptr;
  try {
    if (file.contains(ptr)) at = &file.at(ptr);
  } catch (const nlohmann::json::exception&) {
    at = nullptr;
  }
  if (!at) {
    // the longest part of the path that exists, to say where it went wrong
    nlohmann::json::json_pointer have = ptr;
    while (!have.empty()) {
      have = have.parent_pointer();
      bool ok = false;
      try {
        ok = file.contains(have);
      } catch (const nlohmann::json::exception&) {
      }
      if (ok) break;
    }
    std::string where;
    const nlohmann::json& p = have.empty() ? file : file.at(have);
    if (p.is_array()) where = " (" + (have.empty() ? std::string("/") : have.to_string()) + " has " + std::to_string(p.size()) + " entries)";
    else if (p.is_object()) {
      where = " (" + (have.empty() ? std::string("the top level") : have.to_string()) + " has ";
      int n = 0;
      for (auto it = p.begin(); it != p.end(); ++it) where += std::string(n++ ? ", " : "") + it.key();
      where += ")";
    }
    throw std::invalid_argument(label + ": the model file " + model + " has no field " + v.field + where);
  }
  if (!at->is_number())
    throw std::invalid_argument(label + ": " + v.field + " in " + model + " is not a number (it is " + at->type_name() +
                                "); vary one number, e.g. " + v.field + "/0");
  v.nominal = at->get<double>();
  const std::string& s = v.spec;
  const std::string grammar = "expected a:b:n (n values from a to b), [v1,v2,...], normal(mu,sigma) or uniform(a,b)";
  if (s.empty()) throw std::invalid_argument(label + ": no SPEC after = (" + grammar + ")");
  const auto two_args = [&](const char* name, double& x, double& y) {
    if (!sweep_starts_call(s, name)) return false;
    const std::string head = std::string(name) + "(";
    if (s.back() != ')') throw std::invalid_argument(label + ": " + name + "(...) is not closed by )");
    const std::string inner = s.substr(head.size(), s.size() - head.size() - 1);
    const auto comma = inner.find(',');
    if (comma == std::string::npos || !parse_number(inner.substr(0, comma), x) || !parse_number(inner.substr(comma + 1), y))
      throw std::invalid_argument(label + ": expected " + name + "(NUMBER,NUMBER)");
    return true;
  };
  if (s[0] == '[') {
    nlohmann::json list;
    try {
      list = nlohmann::json::parse(s);
    } catch (const nlohmann::json::exception&) {
      throw std::invalid_argument(label + ": the list is not [v1,v2,...] of numbers");
    }
    if (!list.is_array() || list.empty()) throw std::invalid_argument(label + ": the list is empty or not a list");
    for (const auto& x : list) {
      if (!x.is_number()) throw std::invalid_argument(label + ": the list holds " + x.dump() + ", not a number");
      v.values.push_back(x.get<double>());
    }
    v.kind = SweepVary::Grid;
  } else if (two_args("normal", v.a, v.b)) {
    if (!(v.b >= 0)) throw std::invalid_argument(label + ": normal(mu,sigma) needs sigma >= 0");
    v.kind = SweepVary::Normal;
  } else if (two_args("uniform", v.a, v.b)) {
    if (!(v.b > v.a)) throw std::invalid_argument(label + ": uniform(a,b) needs a < b");
    v.kind = SweepVary::Uniform;
  } else if (std::count(s.begin(), s.end(), ':') == 2) {
    const auto c1 = s.find(':'), c2 = s.find(':', c1 + 1);
    double a = 0, b = 0, n = 0;
    if (!parse_number(s.substr(0, c1), a) || !parse_number(s.substr(c1 + 1, c2 - c1 - 1), b) ||
        !parse_number(s.substr(c2 + 1), n))
      throw std::invalid_argument(label + ": " + grammar);
    if (n < 1 || n != std::floor(n) || n > kMaxVariants)
      throw std::invalid_argument(label + ": n in a:b:n must be a whole number from 1 to " + std::to_string(kMaxVariants));
    const long long count = static_cast<long long>(n);
    if (count == 1 && a != b) throw std::invalid_argument(label + ": a:b:1 holds one value; give a:a:1 or [a]");
    for (long long k = 0; k < count; ++k)
      v.values.push_back(k == count - 1 ? b : a + (b - a) * static_cast<double>(k) / static_cast<double>(count - 1));
    v.kind = SweepVary::Grid;
  } else {
    throw std::invalid_argument(label + ": " + grammar);
  }
  return v;
}

}  // namespace

SweepPlan study_sweep_plan(const SweepRequest& r, const nlohmann::json& file) {
  const Names opt{r.style};
  SweepPlan plan;
  if (r.vary.empty()) throw std::invalid_argument(opt("vary") + ": give at least one FIELD=SPEC (e.g. /bodies/1/mass=5:15:11)");
  std::vector<std::string> seen;
  for (const std::string& text : r.vary) {
    SweepVary v = parse_vary(text, file, r.model, opt);
    if (std::find(seen.begin(), seen.end(), v.field) != seen.end())
      throw std::invalid_argument(opt("vary") + " " + text + ": " + v.field + " is varied twice");
    seen.push_back(v.field);
    plan.vary.push_back(std::move(v));
  }
  long long grids = 0;
  std::string a_grid, a_random;
  for (const SweepVary& v : plan.vary) {
    if (v.kind == SweepVary::Grid) {
      ++grids;
      if (a_grid.empty()) a_grid = v.field + "=" + v.spec;
    } else if (a_random.empty()) {
      a_random = v.field + "=" + v.spec;
    }
  }
  if (grids > 0 && grids < static_cast<long long>(plan.vary.size()))
    throw std::invalid_argument(opt("vary") + ": a grid (" + a_grid + ") cannot be mixed with a distribution (" + a_random +
                                ") yet: vary grids only (a full grid) or distributions only (joint random samples)");
  plan.random = grids == 0;
  if (plan.random) {
    if (!r.samples) throw std::invalid_argument(opt("samples") + ": a random study (" + a_random + ") needs the number of samples");
    if (!r.seed) throw std::invalid_argument(opt("seed") + ": a random study (" + a_random + ") needs a seed (any whole number), so that it can be repeated");
    if (*r.samples < 1 || *r.samples > kMaxVariants)
      throw std::invalid_argument(opt("samples") + ": expected 1 to " + std::to_string(kMaxVariants));
    plan.count = *r.samples;
    plan.seed = *r.seed;
  } else {
    if (r.samples) throw std::invalid_argument(opt("samples") + ": a grid study's size is its grid's; " + opt("samples") + " is for distributions");
    if (r.seed) throw std::invalid_argument(opt("seed") + ": a grid study draws nothing; " + opt("seed") + " is for distributions");
    plan.count = 1;
    for (const SweepVary& v : plan.vary) {
      plan.count *= static_cast<long long>(v.values.size());
      if (plan.count > kMaxVariants)
        throw std::invalid_argument(opt("vary") + ": the full grid has more than " + std::to_string(kMaxVariants) + " variants");
    }
  }
  return plan;
}

bool study_sweep_spec_is_random(const std::string& spec) {
  const std::string s = trim(spec);
  return sweep_starts_call(s, "normal") || sweep_starts_call(s, "uniform");
}

}  // namespace codyna
