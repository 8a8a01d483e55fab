// What bind_common.hpp declares: the Python keywords into request fields (Keywords, take_point,
// take_plant, with the TypeErrors and ValueErrors that name the keyword) and the result
// conversions several studies share. Conversion only.
#include "bind_common.hpp"

#include <algorithm>
#include <cstdio>

namespace codyna::python {

namespace {

// x with 17 significant digits: the core reads back the same double
std::string exact_text(double x) {
  char value[64];
  std::snprintf(value, sizeof value, "%.17g", x);
  return value;
}

}  // namespace

[[noreturn]] void type_error(const std::string& what) { throw py::type_error(what); }

std::string type_name(const py::handle& o) { return py::str(py::type::handle_of(o).attr("__name__")); }

std::string fspath(const py::handle& o) { return py::str(py::module_::import("os").attr("fspath")(o)); }

// ---------------------------------------------------------------------------------------------
// Keywords

Keywords::Keywords(const py::dict& given, std::string function) : function_(std::move(function)) {
  for (const auto& kv : given) {
    if (!py::isinstance<py::str>(kv.first)) type_error(function_ + "() keywords must be strings");
    if (kv.second.is_none()) continue;  // None: not given (the model file's value stays)
    items_.emplace_back(kv.first.cast<std::string>(), py::reinterpret_borrow<py::object>(kv.second));
  }
}

std::optional<py::object> Keywords::take(const std::string& key, const std::string& alias) {
  std::optional<py::object> found;
  std::string found_key;
  for (auto it = items_.begin(); it != items_.end();) {
    if (it->first == key || (!alias.empty() && it->first == alias)) {
      if (found) type_error(function_ + "(): " + found_key + " and " + it->first + " are the same keyword: give one");
      found = it->second;
      found_key = it->first;
      it = items_.erase(it);
    } else {
      ++it;
    }
  }
  return found;
}

std::optional<std::string> Keywords::text(const std::string& key) {
  const auto o = take(key);
  if (!o) return std::nullopt;
  return text_of(*o, key);
}

std::optional<std::string> Keywords::path(const std::string& key) {
  const auto o = take(key);
  if (!o) return std::nullopt;
  if (py::hasattr(*o, "__fspath__") && !py::isinstance<py::str>(*o))
    return text_of(py::module_::import("os").attr("fspath")(*o), key);
  return text_of(*o, key);
}

std::optional<double> Keywords::number(const std::string& key) {
  const auto o = take(key);
  if (!o) return std::nullopt;
  return number_of(*o, key);
}

bool Keywords::flag(const std::string& key) {
  const auto o = take(key);
  if (!o) return false;
  if (py::isinstance<py::str>(*o) || py::isinstance<py::bytes>(*o))
    type_error(function_ + "(): " + key + ": expected True or False, got " + type_name(*o));
  return py::bool_(*o);
}

std::optional<std::vector<std::string>> Keywords::names(const std::string& key, const std::string& alias) {
  const auto o = take(key, alias);
  if (!o) return std::nullopt;
  if (py::isinstance<py::str>(*o)) return std::vector<std::string>{o->cast<std::string>()};
  std::vector<std::string> v;
  for (const auto& item : iterable(*o, key, "a str or a list of str")) v.push_back(text_of(item, key));
  return v;
}

std::optional<std::vector<double>> Keywords::numbers(const std::string& key) {
  const auto o = take(key);
  if (!o) return std::nullopt;
  if (!py::isinstance<py::str>(*o) && !py::hasattr(*o, "__iter__")) return std::vector<double>{number_of(*o, key)};
  std::vector<double> v;
  for (const auto& item : iterable(*o, key, "a number or a sequence of numbers")) v.push_back(number_of(item, key));
  return v;
}

std::vector<std::string> Keywords::pairs(const std::string& key, const std::string& alias) {
  const auto o = take(key, alias);
  if (!o) return {};
  std::vector<std::string> v;
  if (py::isinstance<py::dict>(*o)) {
    for (const auto& kv : o->cast<py::dict>()) {
      const std::string value = exact_text(number_of(kv.second, key));  // the value's error first
      v.push_back(text_of(kv.first, key) + "=" + value);
    }
    return v;
  }
  if (py::isinstance<py::str>(*o)) return {o->cast<std::string>()};
  for (const auto& item : iterable(*o, key, "a dict {name: value} or \"NAME=VALUE\" strings")) v.push_back(text_of(item, key));
  return v;
}

std::optional<long long> Keywords::whole(const std::string& key, long long lo, long long hi) {
  const auto o = take(key);
  if (!o) return std::nullopt;
  const py::int_ i = int_of(*o, key);
  int overflow = 0;
  const long long x = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
  if (overflow != 0 || x < lo || x > hi)
    throw py::value_error(key + ": expected a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) +
                          ", got " + py::repr(i).cast<std::string>());
  return x;
}

std::optional<std::uint64_t> Keywords::whole_u64(const std::string& key) {
  const auto o = take(key);
  if (!o) return std::nullopt;
  const py::int_ i = int_of(*o, key);
  const bool negative = PyObject_RichCompareBool(i.ptr(), py::int_(0).ptr(), Py_LT) == 1;
  const unsigned long long x = negative ? 0 : PyLong_AsUnsignedLongLong(i.ptr());
  if (negative || (x == static_cast<unsigned long long>(-1) && PyErr_Occurred())) {
    PyErr_Clear();
    throw py::value_error(key + ": expected a whole number from 0 to " + std::to_string(UINT64_MAX) + ", got " +
                          py::repr(i).cast<std::string>());
  }
  return static_cast<std::uint64_t>(x);
}

std::vector<std::string> Keywords::field_specs(const std::string& key) {
  const auto o = take(key);
  if (!o) return {};
  if (py::isinstance<py::str>(*o)) return {o->cast<std::string>()};
  std::vector<std::string> v;
  if (py::isinstance<py::dict>(*o)) {
    for (const auto& kv : o->cast<py::dict>()) {
      const std::string field = text_of(kv.first, key);
      if (py::isinstance<py::str>(kv.second)) v.push_back(field + "=" + kv.second.cast<std::string>());
      else v.push_back(field + "=" + numbers_list(kv.second, key, field));
    }
    return v;
  }
  for (const auto& item : iterable(*o, key, "a dict {field: spec} or \"FIELD=SPEC\" strings")) v.push_back(text_of(item, key));
  return v;
}

// a field's numbers (a sequence, or one number) as the SPEC list "[v1,v2,...]"
std::string Keywords::numbers_list(const py::handle& o, const std::string& key, const std::string& field) const {
  std::vector<double> values;
  if (py::hasattr(o, "__iter__")) {
    for (const auto& item : iterable(py::reinterpret_borrow<py::object>(o), key + "[" + field + "]",
                                     "a SPEC str, a sequence of numbers or a number"))
      values.push_back(number_of(item, key + "[" + field + "]"));
  } else {
    values.push_back(number_of(o, key + "[" + field + "]"));
  }
  std::string list = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) list += ',';
    list += exact_text(values[i]);
  }
  return list + "]";
}

std::optional<SweepShard> Keywords::shard(const std::string& key) {
  const auto o = take(key);
  if (!o) return std::nullopt;
  if (py::isinstance<py::str>(*o)) return study_parse_shard(o->cast<std::string>(), OptionStyle::Keyword);
  if (py::isinstance<py::dict>(*o) || py::isinstance<py::bytes>(*o) || !py::isinstance<py::sequence>(*o))
    type_error(function_ + "(): " + key + ": expected a tuple (K, N), a \"K/N\" str or \"slurm\", got " + type_name(*o));
  const std::string given = py::repr(*o).cast<std::string>();
  const py::sequence seq = o->cast<py::sequence>();
  if (seq.size() != 2) return study_check_shard(-1, 0, OptionStyle::Keyword, given);
  const auto whole = [&](const py::handle& x) {
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow(int_of(x, key).ptr(), &overflow);
    return overflow != 0 ? -1 : v;
  };
  const long long k = whole(seq[0]), n = whole(seq[1]);
  return study_check_shard(k, n, OptionStyle::Keyword, given);
}

std::optional<std::vector<std::string>> Keywords::signals(const std::string& key, const std::string& alias) {
  const auto o = take(key, alias);
  if (!o) return std::nullopt;
  if (py::isinstance<py::str>(*o) || py::isinstance<py::dict>(*o)) return std::vector<std::string>{signal_of(*o, key)};
  std::vector<std::string> v;
  for (const auto& item : iterable(*o, key, "a str, a dict or a list of them")) v.push_back(signal_of(item, key));
  return v;
}

void Keywords::finish() const {
  if (!items_.empty()) type_error(function_ + "() got an unexpected keyword argument '" + items_.front().first + "'");
}

py::iterable Keywords::iterable(const py::object& o, const std::string& key, const char* expected) const {
  if (py::isinstance<py::dict>(o) || py::isinstance<py::bytes>(o) || !py::isinstance<py::iterable>(o))
    type_error(function_ + "(): " + key + ": expected " + expected + ", got " + type_name(o));
  return o.cast<py::iterable>();
}

std::string Keywords::text_of(const py::handle& o, const std::string& key) const {
  if (!py::isinstance<py::str>(o)) type_error(function_ + "(): " + key + ": expected a str, got " + type_name(o));
  return o.cast<std::string>();
}

double Keywords::number_of(const py::handle& o, const std::string& key) const {
  if (py::isinstance<py::str>(o) || py::isinstance<py::bool_>(o) || py::isinstance<py::bytes>(o) ||
      !py::hasattr(o, "__float__"))
    type_error(function_ + "(): " + key + ": expected a number, got " + type_name(o));
  return py::float_(py::reinterpret_borrow<py::object>(o)).cast<double>();
}

py::int_ Keywords::int_of(const py::handle& o, const std::string& key) const {
  if (py::isinstance<py::bool_>(o) || !py::hasattr(o, "__index__"))
    type_error(function_ + "(): " + key + ": expected a whole number (int), got " + type_name(o));
  PyObject* i = PyNumber_Index(o.ptr());
  if (!i) throw py::error_already_set();
  return py::reinterpret_steal<py::int_>(i);
}

std::string Keywords::signal_of(const py::handle& o, const std::string& key) const {
  if (py::isinstance<py::dict>(o)) return py::str(py::module_::import("json").attr("dumps")(o));
  if (!py::isinstance<py::str>(o))
    type_error(function_ + "(): " + key + ": expected a \"NAME=VALUE[@TIME]\" str or a dict, got " + type_name(o));
  return o.cast<std::string>();
}

void take_point(Keywords& k, PointRequest& p) {
  p.operating_point = k.text("operating_point");
  p.independent = k.names("independent");
  p.trim_free = k.names("trim_free");
  p.free_inputs = k.names("free_input", "free_inputs");
  p.hold = k.pairs("hold");
  p.initial = k.pairs("initial");
  p.targets = k.pairs("target", "targets");
  p.steady_body = k.text("steady_body");
  p.speed = k.number("speed");
  p.yaw_rate = k.number("yaw_rate");
  p.radius = k.number("radius");
  p.lateral_acceleration = k.number("lateral_acceleration");
}

void take_plant(Keywords& k, PlantRequest& p) {
  p.inputs = k.names("inputs");
  p.outputs = k.names("outputs");
  p.disabled_effects = k.names("disable_effect", "disable_effects");
  p.references = k.signals("reference", "references");
  p.disturbances = k.signals("disturbance", "disturbances");
}

// ---------------------------------------------------------------------------------------------
// Results -> Python values

py::array_t<double> vector_of(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::dict named(const std::vector<std::string>& names, const Eigen::VectorXd& v) {
  py::dict d;
  for (Eigen::Index k = 0; k < v.size() && static_cast<std::size_t>(k) < names.size(); ++k)
    d[py::str(names[static_cast<std::size_t>(k)])] = v[k];
  return d;
}

py::dict operating_point_of(const Model& m, const OperatingPoint& op, const Eigen::VectorXd& coordinates) {
  std::vector<std::string> actuators;
  for (const ActuatorModel& a : m.actuators) actuators.push_back(a.name);
  return py::dict("kind"_a = op.kind, "t"_a = op.t, "residual"_a = op.residual, "iterations"_a = op.iterations,
                  "coordinates"_a = named(m.v_names, coordinates), "rates"_a = named(m.rate_names, op.v),
                  "inputs"_a = named(actuators, op.u), "q"_a = op.q, "v"_a = op.v, "u"_a = op.u);
}

}  // namespace codyna::python
