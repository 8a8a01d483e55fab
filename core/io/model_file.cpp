#include "io/model_file.hpp"

#include <algorithm>
#include <cassert>
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <vector>

#include "io/atomic_file.hpp"
#include "model/errors.hpp"

namespace codyna {
namespace {

using json = nlohmann::json;
using ojson = nlohmann::ordered_json;  // written files keep the fields in schema order

constexpr int kFormatVersion = 1;
constexpr double kUnitTolerance = 1e-14;      // a vector this close to unit length is kept bit-exact
constexpr double kRotationTolerance = 1e-9;   // largest entry of |R^T R - I|
constexpr double kSymmetryTolerance = 1e-12;  // of an inertia matrix, relative to its largest entry

std::string quote(std::string_view s) { return "\"" + std::string(s) + "\""; }

std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

std::string join(const std::vector<std::string_view>& names) {
  std::string s;
  for (std::string_view n : names) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}

// "got ..." part of an error message.
std::string describe(const json& j) {
  switch (j.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return "boolean " + dump(j);
    case json::value_t::string: return "string " + dump(j);
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float: return "number " + dump(j);
    case json::value_t::array:
      return "an array of " + std::to_string(j.size()) + (j.size() == 1 ? " element" : " elements");
    case json::value_t::object: return "an object";
    default: return j.type_name();
  }
}

// A key as a JSON-pointer token.
std::string pointer_token(std::string_view key) {
  std::string t;
  for (char c : key) t += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
  return t;
}

// ---------------------------------------------------------------------------
// Reading: a value together with where it is, so every error can name both.

class Node {
 public:
  Node(const json& j, std::string path, const std::string& file) : j_(&j), path_(std::move(path)), file_(&file) {}

  const json& value() const { return *j_; }
  std::string where() const { return (file_->empty() ? "" : *file_ + ": ") + (path_.empty() ? "/" : path_); }
  Node element(std::size_t i) const { return Node((*j_)[i], path_ + "/" + std::to_string(i), *file_); }
  Node member(const std::string& key) const { return Node(j_->at(key), path_ + "/" + pointer_token(key), *file_); }

  [[noreturn]] void fail(const std::string& detail) const { throw ModelError(*file_, path_, detail); }
  // a field this element does not have (ModelError::Kind::UnknownField)
  [[noreturn]] void fail_unknown(const std::string& detail) const {
    throw ModelError(*file_, path_, detail, ModelError::Kind::UnknownField);
  }
  // a required field this element lacks (ModelError::Kind::MissingField)
  [[noreturn]] void fail_missing(const std::string& key) const {
    throw ModelError(*file_, path_, "missing required field " + quote(key), ModelError::Kind::MissingField, key);
  }
  [[noreturn]] void expected(const std::string& what) const { fail("expected " + what + ", got " + describe(*j_)); }

 private:
  const json* j_;
  std::string path_;
  const std::string* file_;
};

// A JSON object whose fields are looked up by name.
class Object {
 public:
  explicit Object(const Node& n) : n_(n) {
    if (!n.value().is_object()) n.expected("an object");
  }
  // Every field must be one of `allowed`; `owner` ("a gravity effect") qualifies the message.
  void allow(const std::vector<std::string_view>& allowed, const std::string& owner = {}) const {
    for (const auto& item : n_.value().items()) {
      if (std::find(allowed.begin(), allowed.end(), item.key()) != allowed.end()) continue;
      n_.member(item.key()).fail_unknown("unknown field " + quote(item.key()) + " (allowed" +
                                 (owner.empty() ? "" : " for " + owner) + ": " + join(allowed) + ")");
    }
  }
  std::optional<Node> get(const std::string& key) const {
    if (!n_.value().contains(key)) return std::nullopt;
    return n_.member(key);
  }
  Node need(const std::string& key) const {
    if (auto f = get(key)) return *f;
    n_.fail_missing(key);
  }

 private:
  Node n_;
};

// A finite number of sane magnitude: nothing in a mechanism model needs more than
// 1e15 (in SI units), and larger values only overflow later, far from their field.
constexpr double kLargest = 1e15;
constexpr long kMaxModelBytes = 256L << 20;  // 256 MiB: far beyond any mechanism, far below memory

double read_number(const Node& n) {
  if (!n.value().is_number() || !std::isfinite(n.value().get<double>())) n.expected("a number");
  const double x = n.value().get<double>();
  if (std::abs(x) > kLargest) n.expected("a number of magnitude at most 1e15");
  return x;
}

// Integral values written as 2.0 are accepted too.
int read_integer(const Node& n) {
  if (n.value().is_number()) {
    const double x = n.value().get<double>();
    if (x == std::floor(x) && x >= std::numeric_limits<int>::min() && x <= std::numeric_limits<int>::max())
      return static_cast<int>(x);
  }
  n.expected("an integer");
}

std::string read_string(const Node& n) {
  if (!n.value().is_string()) n.expected("a string");
  return n.value().get<std::string>();
}

std::vector<Node> read_elements(const Node& n) {
  if (!n.value().is_array()) n.expected("an array");
  std::vector<Node> out;
  for (std::size_t i = 0; i < n.value().size(); ++i) out.push_back(n.element(i));
  return out;
}

std::vector<std::string> read_names(const Node& n) {
  std::vector<std::string> out;
  for (const Node& e : read_elements(n)) out.push_back(read_string(e));
  return out;
}

Eigen::VectorXd read_numbers(const Node& n, std::size_t size) {
  if (!n.value().is_array() || n.value().size() != size) n.expected("an array of " + std::to_string(size) + " numbers");
  Eigen::VectorXd v(size);
  for (std::size_t i = 0; i < size; ++i) v[i] = read_number(n.element(i));
  return v;
}

Eigen::Vector3d read_vec3(const Node& n) { return read_numbers(n, 3); }

double read_positive_length(const Node& n) {
  const double x = read_number(n);
  if (!(x > 0)) n.expected("a length > 0 (m)");
  return x;
}

// The values a model cannot hold, refused where they are read (a file, or codyna-gui's field, which
// goes through this reader): compile_structure checks the same of a spec built in code.
// A spring's or damper's coefficient (N/m, N s/m, N m/rad, N m s/rad) and a rest length: 0 or more
bool read_bool(const Node& n);  // true or false (below)

double read_coefficient(const Node& n) {
  const double x = read_number(n);
  if (!(x >= 0)) n.expected("a non-negative number (a negative stiffness, damping or length would feed energy in)");
  return x;
}

// the same for each axis of a bushing
Eigen::Vector3d read_coefficients(const Node& n) {
  Eigen::Vector3d v = read_vec3(n);
  if (!(v.minCoeff() >= 0)) n.expected("three non-negative numbers (x, y, z of the bushing's axes)");
  return v;
}

// a rolling ball's or disc's radius
double read_radius(const Node& n) {
  const double x = read_number(n);
  if (!(x > 0)) n.expected("a positive radius (m)");
  return x;
}

// a body's mass: 0 (a massless link between joints) or more
double read_mass(const Node& n) {
  const double x = read_number(n);
  if (!(x >= 0)) n.expected("a non-negative mass (kg)");
  return x;
}

Eigen::Matrix3d read_matrix3(const Node& n) {
  if (!n.value().is_array() || n.value().size() != 3) n.expected("a 3x3 array (3 rows of 3 numbers)");
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) m.row(r) = read_numbers(n.element(r), 3).transpose();
  return m;
}

// Scales v to unit length; false if v is zero. A vector already of unit length
// (within kUnitTolerance) is left alone, so a saved file reads back bit-exactly.
bool normalize(Eigen::Ref<Eigen::VectorXd> v) {
  const double norm = v.norm();
  if (norm == 0.0) return false;
  if (std::abs(norm - 1.0) > kUnitTolerance) v /= norm;
  return true;
}

// What the reader changed while reading one file (ModelSpec::notes); set by parse_model_spec.
thread_local std::vector<std::string>* g_notes = nullptr;

// An axis or direction: a non-zero vec3, normalized (with a note when it was not of unit length).
Eigen::Vector3d read_direction(const Node& n) {
  Eigen::Vector3d v = read_vec3(n);
  const double length = v.norm();
  if (!normalize(v)) n.fail("expected a non-zero vector, got " + dump(n.value()));
  if (g_notes && std::abs(length - 1.0) > 1e-9) {
    std::ostringstream os;
    os.precision(6);
    os << n.where() << ": the direction " << dump(n.value()) << " has length " << length << "; it is used normalized";
    g_notes->push_back(os.str());
  }
  return v;
}

Eigen::Vector4d read_quaternion(const Node& n) {
  Eigen::Vector4d wxyz = read_numbers(n, 4);
  if (!normalize(wxyz)) n.fail("expected a non-zero quaternion [w, x, y, z], got " + dump(n.value()));
  return wxyz;
}

Eigen::Matrix3d read_rotation_matrix(const Node& n) {
  const Eigen::Matrix3d R = read_matrix3(n);
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(error <= kRotationTolerance))
    n.fail("rotation matrix is not orthonormal (largest entry of |R^T R - I| is " + dump(error) +
           ", tolerance " + dump(kRotationTolerance) + ")");
  if (R.determinant() < 0) n.fail("rotation matrix has determinant -1 (a reflection); expected +1");
  return R;
}

// {"axis", "angle"} | {"axis", "angle_deg"} | {"quaternion"} | {"matrix"} | {"rpy"}
Eigen::Matrix3d read_rotation(const Node& n) {
  using Eigen::AngleAxisd;
  using Eigen::Vector3d;
  const Object o(n);
  o.allow({"axis", "angle", "angle_deg", "quaternion", "matrix", "rpy"}, "a rotation");
  std::vector<std::string> forms;
  for (const char* key : {"axis", "quaternion", "matrix", "rpy"})
    if (o.get(key)) forms.push_back(key);
  if (forms.empty())
    n.fail("expected a rotation: {\"axis\", \"angle\"}, {\"axis\", \"angle_deg\"}, {\"quaternion\"}, "
           "{\"matrix\"} or {\"rpy\"}");
  if (forms.size() > 1) n.fail("expected one rotation form, got both " + quote(forms[0]) + " and " + quote(forms[1]));
  const std::optional<Node> angle = o.get("angle"), angle_deg = o.get("angle_deg");
  if (forms[0] != "axis") {
    if (angle || angle_deg)
      (angle ? *angle : *angle_deg).fail("an angle goes with \"axis\", not with " + quote(forms[0]));
    if (forms[0] == "quaternion") {
      const Eigen::Vector4d q = read_quaternion(o.need("quaternion"));
      return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
    }
    if (forms[0] == "matrix") return read_rotation_matrix(o.need("matrix"));
    const Vector3d rpy = read_vec3(o.need("rpy"));
    return (AngleAxisd(rpy.z(), Vector3d::UnitZ()) * AngleAxisd(rpy.y(), Vector3d::UnitY()) *
            AngleAxisd(rpy.x(), Vector3d::UnitX())).toRotationMatrix();
  }
  if (angle && angle_deg) angle_deg->fail("give \"angle\" or \"angle_deg\", not both");
  if (!angle && !angle_deg) n.fail("missing required field \"angle\" (or \"angle_deg\")");
  const double a = angle ? read_number(*angle) : read_number(*angle_deg) * std::numbers::pi / 180.0;
  return AngleAxisd(a, read_direction(o.need("axis"))).toRotationMatrix();
}

// [Ixx, Iyy, Izz] | [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] | 3x3 (symmetric)
Eigen::Matrix3d read_inertia(const Node& n) {
  const json& j = n.value();
  if (!j.is_array() || (j.size() != 3 && j.size() != 6))
    n.expected("[Ixx, Iyy, Izz], [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 array");
  if (j.size() == 3 && j[0].is_array()) {
    const Eigen::Matrix3d I = read_matrix3(n);
    const double asymmetry = (I - I.transpose()).cwiseAbs().maxCoeff();
    if (asymmetry > kSymmetryTolerance * I.cwiseAbs().maxCoeff())
      n.fail("inertia matrix is not symmetric (largest entry of |I - I^T| is " + dump(asymmetry) + ")");
    return I;  // as written, so that encode_inertia's 3x3 form reads back exactly
  }
  const Eigen::VectorXd d = read_numbers(n, j.size());
  Eigen::Matrix3d I = d.head<3>().asDiagonal();
  if (d.size() == 6) {
    I(0, 1) = I(1, 0) = d[3];
    I(0, 2) = I(2, 0) = d[4];
    I(1, 2) = I(2, 1) = d[5];
  }
  return I;
}

Eigen::Vector4d read_color(const Node& n) {
  const json& j = n.value();
  if (!j.is_array() || (j.size() != 3 && j.size() != 4)) n.expected("[r, g, b] or [r, g, b, a]");
  Eigen::Vector4d c(0.0, 0.0, 0.0, 1.0);
  for (std::size_t i = 0; i < j.size(); ++i) {
    const Node e = n.element(i);
    c[i] = read_number(e);
    if (c[i] < 0.0 || c[i] > 1.0) e.expected("a number in [0, 1]");
  }
  return c;
}

// "world" | "body" (axes of a force)
bool read_in_world(const Node& n) {
  const std::string s = read_string(n);
  if (s != "world" && s != "body") n.fail("unknown frame " + quote(s) + " (expected one of: world, body)");
  return s == "world";
}

// "x" | "y" | "z" | 0 | 1 | 2
int read_component(const Node& n) {
  if (n.value().is_string()) {
    const std::string s = read_string(n);
    if (s == "x" || s == "y" || s == "z") return s[0] - 'x';
  } else if (n.value().is_number()) {
    const int c = read_integer(n);
    if (c >= 0 && c < 3) return c;
  }
  n.expected("\"x\", \"y\", \"z\", 0, 1 or 2");
}

// The enumerators of E are 0, 1, ...; to_string gives "?" past the last one.
template <class E>
std::vector<std::string_view> enum_names() {
  std::vector<std::string_view> names;
  for (int i = 0; std::string_view(to_string(static_cast<E>(i))) != "?"; ++i)
    names.push_back(to_string(static_cast<E>(i)));
  return names;
}

template <class E>
E read_enum(const Node& n, const char* what, std::optional<E> (*from_string)(const std::string&)) {
  const std::string s = read_string(n);
  if (auto e = from_string(s)) return *e;
  n.fail("unknown " + std::string(what) + " " + quote(s) + " (expected one of: " + join(enum_names<E>()) + ")");
}

// q0 or v0 of a joint: a number (one value) or an array of exactly `size` numbers.
Eigen::VectorXd read_coordinates(const Node& n, int size, const std::string& what) {
  const json& j = n.value();
  if (!j.is_number() && !j.is_array()) n.expected("a number or an array of numbers");
  const std::size_t count = j.is_number() ? 1 : j.size();
  if (count != static_cast<std::size_t>(size))
    n.fail("expected " + std::to_string(size) + (size == 1 ? " value" : " values") + " (" + what + "), got " +
           std::to_string(count));
  return j.is_number() ? Eigen::VectorXd::Constant(1, read_number(n)) : read_numbers(n, count);
}

// a joint's armature (rotor inertia): a number >= 0 for every coordinate (also as an array of one),
// or (joints with several coordinates) an array of one number >= 0 per coordinate
Eigen::VectorXd read_armature(const Node& n, JointType type) {
  const int nv = joint_nv(type);
  auto one = [](const Node& e) {
    if (!e.value().is_number()) e.expected("a number >= 0 (kg m^2 on a rotation, kg on a translation)");
    const double x = read_number(e);
    if (!(x >= 0)) e.expected("a number >= 0 (kg m^2 on a rotation, kg on a translation)");
    return x;
  };
  if (n.value().is_array() && n.value().size() == 1) {  // (a bad value is named at the array: the field)
    const json& e = n.value()[0];
    if (!e.is_number() || !std::isfinite(e.get<double>()) || !(e.get<double>() >= 0))
      n.fail("expected a number >= 0 (kg m^2 on a rotation, kg on a translation), got " + describe(e));
    return Eigen::VectorXd::Constant(1, read_number(n.element(0)));
  }
  if (n.value().is_array() && nv > 1) {
    if (n.value().size() != static_cast<std::size_t>(nv))
      n.fail("expected one number (every coordinate) or an array of " + std::to_string(nv) + " numbers (one per coordinate of a " +
             std::string(to_string(type)) + " joint), got " + std::to_string(n.value().size()));
    Eigen::VectorXd a(nv);
    for (int k = 0; k < nv; ++k) a[k] = one(n.element(k));
    return a;
  }
  return Eigen::VectorXd::Constant(1, one(n));
}

int quaternion_index(JointType t) { return t == JointType::Spherical ? 0 : t == JointType::Free ? 3 : -1; }

FrameSpec read_frame(const Node& n);

// Arrays as in the table of model_spec.hpp; spherical joints also take
// {"rotation"} and free joints {"position", "rotation"}.
Eigen::VectorXd read_q0(const Node& n, JointType type) {
  const std::string joint = "a " + std::string(to_string(type)) + " joint";
  const int iq = quaternion_index(type);
  if (iq < 0 || !n.value().is_object()) {
    Eigen::VectorXd q = read_coordinates(n, joint_nq(type), "nq of " + joint);
    if (iq >= 0 && !normalize(q.segment<4>(iq)))
      n.fail("expected a non-zero quaternion (w, x, y, z) in q0, got " + dump(n.value()));
    return q;
  }
  if (type == JointType::Spherical) Object(n).allow({"rotation"}, "the q0 of " + joint);
  const FrameSpec f = read_frame(n);
  const Eigen::Quaterniond r(f.rotation);
  Eigen::VectorXd q(joint_nq(type));
  if (type == JointType::Free) q.head<3>() = f.position;
  q.segment<4>(iq) << r.w(), r.x(), r.y(), r.z();
  return q;
}

// "1 row", "2 rows"
std::string counted(Eigen::Index n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

std::string size_of(const Eigen::MatrixXd& m) { return std::to_string(m.rows()) + " x " + std::to_string(m.cols()); }

// A matrix: an array of rows, each a non-empty array of numbers, all of the
// same length; a number is a 1 x 1 matrix.
Eigen::MatrixXd read_matrix(const Node& n) {
  const json& j = n.value();
  if (j.is_number()) return Eigen::MatrixXd::Constant(1, 1, read_number(n));
  if (!j.is_array() || j.empty())
    n.expected("a matrix (an array of rows, each an array of numbers; a 1 x 1 matrix may be a number)");
  if (j[0].is_number()) n.expected("an array of rows (a row vector is written [[a, b, ...]])");
  const Node first = n.element(0);
  if (!first.value().is_array() || first.value().empty()) first.expected("a row (a non-empty array of numbers)");
  const auto rows = static_cast<Eigen::Index>(j.size());
  const auto cols = static_cast<Eigen::Index>(first.value().size());
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const Node row = n.element(r);
    if (!row.value().is_array()) row.expected("an array of " + counted(cols, "number") + " like the first row");
    if (const std::size_t size = row.value().size(); size != first.value().size())
      row.fail("expected " + counted(cols, "number") + " like the first row, got " + std::to_string(size));
    for (Eigen::Index c = 0; c < cols; ++c) m(r, c) = read_number(row.element(c));
  }
  return m;
}

// An array of numbers of any length.
Eigen::VectorXd read_vector(const Node& n) {
  if (!n.value().is_array()) n.expected("an array of numbers");
  return read_numbers(n, n.value().size());
}

// The diagonal of an LQR weight: numbers >= 0, or > 0 if `positive`.
std::vector<double> read_weights(const Node& n, bool positive) {
  std::vector<double> w;
  for (const Node& e : read_elements(n)) {
    const double x = read_number(e);
    if (positive && !(x > 0)) e.expected("a number > 0 (R = diag(r_weights) must be positive definite)");
    if (!positive && x < 0) e.expected("a number >= 0");
    w.push_back(x);
  }
  return w;
}

double read_sample_time(const Node& n) {
  const double Ts = read_number(n);
  if (Ts < 0) n.expected("a number >= 0 (0 = continuous)");
  return Ts;
}

// Where the plant is linearized for a controller.
std::string read_operating_point(const Node& n) {
  static const std::vector<std::string_view> names{"initial", "equilibrium", "trim", "steady"};
  const std::string s = read_string(n);
  if (std::find(names.begin(), names.end(), s) == names.end())
    n.fail("unknown operating point " + quote(s) + " (expected one of: " + join(names) + ")");
  return s;
}

// ---------------------------------------------------------------------------
// Writing

ojson encode(double x) { return x; }
ojson encode(int x) { return x; }
ojson encode(const std::string& s) { return s; }
ojson encode(const std::optional<double>& x) { return x ? ojson(*x) : ojson(); }
ojson encode(const std::vector<std::string>& names) { return names; }
ojson encode(const std::vector<double>& v) { return v; }

ojson encode(const Eigen::Ref<const Eigen::VectorXd>& v) {
  ojson a = ojson::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

ojson encode_rotation(const Eigen::Matrix3d& R) {
  ojson rows = ojson::array();
  for (int r = 0; r < 3; ++r) rows.push_back(encode(R.row(r).transpose()));
  ojson o = ojson::object();
  o["matrix"] = rows;
  return o;
}

// A matrix as an array of rows (always, also when 1 x 1).
ojson encode_matrix(const Eigen::MatrixXd& m) {
  ojson rows = ojson::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) rows.push_back(encode(m.row(r).transpose()));
  return rows;
}

// Six numbers, unless rounding has left I slightly asymmetric: then all nine.
ojson encode_inertia(const Eigen::Matrix3d& I) {
  if (I != I.transpose())
    return {encode(I.row(0).transpose()), encode(I.row(1).transpose()), encode(I.row(2).transpose())};
  return {I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)};
}

ojson encode_in_world(bool in_world) { return in_world ? "world" : "body"; }

ojson encode_component(int c) { return c >= 0 && c < 3 ? ojson(std::string(1, char('x' + c))) : ojson(c); }

// An empty description or unit is left out of the file.
ojson encode_optional_text(const std::string& s) { return s.empty() ? ojson() : ojson(s); }

template <class E>
ojson encode_enum(E e) { return to_string(e); }

// ---------------------------------------------------------------------------
// Schemas: each spec struct is described once, as the fields of its JSON
// object; reading and writing both follow that description.

enum class Need { Optional, Required };

template <class S>
struct Field {
  std::string_view key;
  Need need;
  std::function<void(const Node&, S&)> read;
  std::function<void(ojson&, const S&)> write;  // sets j[key], or leaves an optional field out
};

template <class S>
struct Schema {
  std::vector<Field<S>> fields;
  const char* kind = nullptr;  // of a typed element ("effect"); names it in messages
  // Keys that apply to s, whose type has been read; all fields when null.
  std::vector<std::string_view> (*keys)(const S&) = nullptr;

  const Field<S>& field(std::string_view key) const {
    const auto f = std::find_if(fields.begin(), fields.end(), [&](const Field<S>& f) { return f.key == key; });
    assert(f != fields.end() && "a key without a field");
    return *f;
  }
  std::vector<std::string_view> keys_of(const S& s) const {
    if (keys) return keys(s);
    std::vector<std::string_view> all;
    for (const Field<S>& f : fields) all.push_back(f.key);
    return all;
  }
};

// a typed element whose type is a plain word (a reference signal's "step", ...)
[[maybe_unused]] const char* to_string(const std::string& word) { return word.c_str(); }

template <class S>
concept Typed = requires(S s) { s.type; };

template <class S>
const Schema<S>& schema();  // one specialization per spec struct, below

template <class S>
S read_struct(const Node& n) {
  const Schema<S>& sch = schema<S>();
  const Object o(n);
  S s;
  std::string owner;
  if constexpr (Typed<S>) {
    sch.field("type").read(o.need("type"), s);  // the type decides which other fields apply
    owner = "a " + std::string(to_string(s.type)) + " " + sch.kind;
  }
  const std::vector<std::string_view> keys = sch.keys_of(s);
  o.allow(keys, owner);
  for (std::string_view key : keys) {
    if (key == "type") continue;
    const Field<S>& f = sch.field(key);
    if (auto v = o.get(std::string(key)))
      f.read(*v, s);
    else if (f.need == Need::Required)
      n.fail_missing(std::string(key));
  }
  return s;
}

template <class S>
ojson write_struct(const S& s) {
  const Schema<S>& sch = schema<S>();
  ojson j = ojson::object();
  for (std::string_view key : sch.keys_of(s)) sch.field(key).write(j, s);
  return j;
}

template <class T>
std::vector<T> read_list(const Node& n) {
  std::vector<T> out;
  for (const Node& e : read_elements(n)) out.push_back(read_struct<T>(e));
  return out;
}

template <class T>
ojson write_list(const std::vector<T>& v) {
  ojson a = ojson::array();
  for (const T& e : v) a.push_back(write_struct(e));
  return a;
}

// A field stored in member m, read by `read` and written by `write`. Optional
// fields that write as null or as an empty array or object are left out.
template <class S, class T, class Read, class Write>
Field<S> field(std::string_view key, T S::*m, Read read, Write write, Need need = Need::Optional) {
  return {key, need, [m, read](const Node& n, S& s) { s.*m = read(n); },
          [key, m, write, need](ojson& j, const S& s) {
            ojson v = write(s.*m);
            const bool empty = v.is_null() || ((v.is_array() || v.is_object()) && v.empty());
            if (need == Need::Required || !empty) j[std::string(key)] = std::move(v);
          }};
}

template <class S, class T, class Read>
Field<S> field(std::string_view key, T S::*m, Read read, Need need = Need::Optional) {
  return field(key, m, read, [](const T& v) { return encode(v); }, need);
}

template <class S, class T>
Field<S> struct_field(std::string_view key, T S::*m) {
  return field(key, m, read_struct<T>, write_struct<T>);
}

template <class S, class T>
Field<S> list_field(std::string_view key, std::vector<T> S::*m, Need need = Need::Optional) {
  return field(key, m, read_list<T>, write_list<T>, need);
}

template <class S, class E>
Field<S> type_field(const char* what, std::optional<E> (*from_string)(const std::string&)) {
  return field("type", &S::type, [what, from_string](const Node& n) { return read_enum(n, what, from_string); },
               encode_enum<E>, Need::Required);
}

template <class S>
Field<S> name_field() {
  return field("name", &S::name, read_string, Need::Required);
}

// Keys of a typed element: "name", "type", the type's own, then `tail`.
std::vector<std::string_view> element_keys(const std::vector<std::string_view>& own,
                                           const std::vector<std::string_view>& tail = {}) {
  std::vector<std::string_view> k{"name", "type"};
  k.insert(k.end(), own.begin(), own.end());
  k.insert(k.end(), tail.begin(), tail.end());
  return k;
}

template <>
const Schema<FrameSpec>& schema<FrameSpec>() {
  static const Schema<FrameSpec> s{{
      field("position", &FrameSpec::position, read_vec3),
      field("rotation", &FrameSpec::rotation, read_rotation, encode_rotation),
  }};
  return s;
}

FrameSpec read_frame(const Node& n) { return read_struct<FrameSpec>(n); }

template <>
const Schema<ShapeSpec>& schema<ShapeSpec>() {
  static const Schema<ShapeSpec> s{
      {
          type_field<ShapeSpec>("shape type", shape_type_from_string),
          field("size", &ShapeSpec::size, [](const Node& n) {
            const Eigen::Vector3d v = read_vec3(n);
            if (!(v.minCoeff() > 0)) n.expected("three edge lengths > 0 (m)");
            return v;
          }),
          field("radius", &ShapeSpec::radius, read_positive_length),
          field("length", &ShapeSpec::length, read_positive_length),
          struct_field("frame", &ShapeSpec::frame),
          field("color", &ShapeSpec::color, read_color),
      },
      "shape",
      [](const ShapeSpec& s) -> std::vector<std::string_view> {
        switch (s.type) {
          case ShapeType::Box: return {"type", "size", "frame", "color"};
          case ShapeType::Cylinder: return {"type", "radius", "length", "frame", "color"};
          case ShapeType::Sphere: return {"type", "radius", "frame", "color"};
        }
        return {"type", "frame", "color"};
      }};
  return s;
}

template <>
const Schema<BodySpec>& schema<BodySpec>() {
  static const Schema<BodySpec> s{{
      name_field<BodySpec>(),
      field("mass", &BodySpec::mass, read_mass, Need::Required),
      field("com", &BodySpec::com, read_vec3),
      field("inertia", &BodySpec::inertia, read_inertia, encode_inertia, Need::Required),
      list_field("shapes", &BodySpec::shapes),
  }};
  return s;
}

bool joint_has_axis(JointType t) {
  return t == JointType::Revolute || t == JointType::Prismatic || t == JointType::Universal ||
         t == JointType::Cylindrical;
}

template <>
const Schema<JointSpec>& schema<JointSpec>() {
  static const Schema<JointSpec> s{
      {
          name_field<JointSpec>(),
          type_field<JointSpec>("joint type", joint_type_from_string),
          field("parent", &JointSpec::parent, read_string, Need::Required),
          field("child", &JointSpec::child, read_string, Need::Required),
          struct_field("parent_frame", &JointSpec::parent_frame),
          struct_field("child_frame", &JointSpec::child_frame),
          field("axis", &JointSpec::axis, read_direction),
          field("axis2", &JointSpec::axis2, read_direction),
          {"q0", Need::Optional, [](const Node& n, JointSpec& j) { j.q0 = read_q0(n, j.type); },
           [](ojson& o, const JointSpec& j) { if (j.q0.size() > 0) o["q0"] = encode(j.q0); }},
          {"v0", Need::Optional,
           [](const Node& n, JointSpec& j) {
             j.v0 = read_coordinates(n, joint_nv(j.type), "nv of a " + std::string(to_string(j.type)) + " joint");
           },
           [](ojson& o, const JointSpec& j) { if (j.v0.size() > 0) o["v0"] = encode(j.v0); }},
          {"armature", Need::Optional, [](const Node& n, JointSpec& j) { j.armature = read_armature(n, j.type); },
           [](ojson& o, const JointSpec& j) {
             if (j.armature.size() == 1) o["armature"] = j.armature[0];
             else if (j.armature.size() > 1) o["armature"] = encode(j.armature);
           }},
      },
      "joint",
      [](const JointSpec& j) {
        std::vector<std::string_view> own{"parent", "child", "parent_frame", "child_frame"};
        if (joint_has_axis(j.type)) own.push_back("axis");
        if (j.type == JointType::Universal) own.push_back("axis2");
        if (joint_nv(j.type) == 0) return element_keys(own, {"q0", "v0"});
        return element_keys(own, {"q0", "v0", "armature"});
      }};
  return s;
}

template <class S>
std::vector<Field<S>> point_pair_fields() {
  return {field("body_a", &S::body_a, read_string, Need::Required), field("point_a", &S::point_a, read_vec3),
          field("body_b", &S::body_b, read_string, Need::Required), field("point_b", &S::point_b, read_vec3)};
}

template <class S>
std::vector<Field<S>> joint_dof_fields() {
  return {field("joint", &S::joint, read_string, Need::Required), field("dof", &S::dof, read_integer)};
}

// Concatenation of field lists.
template <class S>
std::vector<Field<S>> fields(std::initializer_list<std::vector<Field<S>>> parts) {
  std::vector<Field<S>> all;
  for (const auto& p : parts) all.insert(all.end(), p.begin(), p.end());
  return all;
}

constexpr std::string_view kPointPair[] = {"body_a", "point_a", "body_b", "point_b"};

std::vector<std::string_view> point_pair_and(std::vector<std::string_view> more) {
  more.insert(more.begin(), std::begin(kPointPair), std::end(kPointPair));
  return more;
}

template <>
const Schema<ConstraintSpec>& schema<ConstraintSpec>() {
  static const Schema<ConstraintSpec> s{
      fields<ConstraintSpec>({
          {name_field<ConstraintSpec>(), type_field<ConstraintSpec>("constraint type", constraint_type_from_string)},
          point_pair_fields<ConstraintSpec>(),
          {field("axis_a", &ConstraintSpec::axis_a, read_direction),
           field("axis_b", &ConstraintSpec::axis_b, read_direction),
           field("joint_a", &ConstraintSpec::joint_a, read_string, Need::Required),
           field("joint_b", &ConstraintSpec::joint_b, read_string, Need::Required),
           field("joint_c", &ConstraintSpec::joint_c, read_string,
                 [](const std::string& s) { return s.empty() ? ojson() : ojson(s); }),
           field("ratio_a", &ConstraintSpec::ratio_a, read_number, Need::Required),
           field("ratio_b", &ConstraintSpec::ratio_b, read_number, Need::Required),
           field("ratio_c", &ConstraintSpec::ratio_c, read_number,
                 [](double r) { return r == 0 ? ojson() : ojson(r); }),
           field("offset", &ConstraintSpec::offset, [](const Node& n) { return std::optional<double>(read_number(n)); }),
           field("radius", &ConstraintSpec::radius, read_radius, Need::Required)},
      }),
      "constraint",
      [](const ConstraintSpec& c) {
        switch (c.type) {
          case ConstraintType::Ball: return element_keys(point_pair_and({}));
          case ConstraintType::Revolute: return element_keys(point_pair_and({"axis_a", "axis_b"}));
          case ConstraintType::PlanarRevolute: return element_keys(point_pair_and({"axis_a"}));
          case ConstraintType::Coupler:
            return element_keys({"joint_a", "ratio_a", "joint_b", "ratio_b", "joint_c", "ratio_c", "offset"});
          case ConstraintType::RollingBall: return element_keys(point_pair_and({"axis_a", "radius"}));
          case ConstraintType::RollingDisc: return element_keys(point_pair_and({"axis_a", "axis_b", "radius"}));
        }
        return element_keys({});
      }};
  return s;
}

// roads of heights (docs/roads.md): the numbers as written; compile_model reads the CSV files and
// checks the grids
std::vector<double> read_road_numbers(const Node& n) {
  const Eigen::VectorXd v = read_vector(n);
  return std::vector<double>(v.data(), v.data() + v.size());
}

std::vector<double> read_road_interval(const Node& n) {
  const std::vector<double> v = read_road_numbers(n);
  if (v.size() != 2 || !(v[0] <= v[1])) n.expected("[min, max] with min <= max");
  return v;
}

std::optional<double> read_road_track_y(const Node& n) { return read_number(n); }

template <class S, class T>
Field<S> optional_struct_field(std::string_view key, std::optional<T> S::*m) {
  return field(key, m, [](const Node& n) { return std::optional<T>(read_struct<T>(n)); },
               [](const std::optional<T>& v) { return v ? write_struct(*v) : ojson(); });
}

template <>
const Schema<RoadGridSpec>& schema<RoadGridSpec>() {
  static const Schema<RoadGridSpec> s{{
      field("file", &RoadGridSpec::file, read_string),
      field("x", &RoadGridSpec::x, read_road_numbers),
      field("y", &RoadGridSpec::y, read_road_numbers),
      field("z", &RoadGridSpec::z, read_matrix, [](const Eigen::MatrixXd& z) { return z.size() ? encode_matrix(z) : ojson(); }),
  }};
  return s;
}

template <>
const Schema<RoadProfileSpec>& schema<RoadProfileSpec>() {
  static const Schema<RoadProfileSpec> s{{
      field("file", &RoadProfileSpec::file, read_string),
      field("s", &RoadProfileSpec::s, read_road_numbers),
      field("left", &RoadProfileSpec::left, read_road_numbers),
      field("right", &RoadProfileSpec::right, read_road_numbers),
      field("left_y", &RoadProfileSpec::left_y, read_road_track_y),
      field("right_y", &RoadProfileSpec::right_y, read_road_track_y),
  }};
  return s;
}

template <>
const Schema<RoadIso8608Spec>& schema<RoadIso8608Spec>() {
  static const Schema<RoadIso8608Spec> s{{
      field("class", &RoadIso8608Spec::road_class, read_string, Need::Required),
      field("length", &RoadIso8608Spec::length, read_positive_length, Need::Required),
      field("band", &RoadIso8608Spec::band, read_road_interval),
      field("spacing", &RoadIso8608Spec::spacing, read_positive_length),
      field("start", &RoadIso8608Spec::start, read_number),
      field("seed", &RoadIso8608Spec::seed, read_integer),
      field("left_y", &RoadIso8608Spec::left_y, read_road_track_y),
      field("right_y", &RoadIso8608Spec::right_y, read_road_track_y),
  }};
  return s;
}

template <>
const Schema<RoadFrictionSpec>& schema<RoadFrictionSpec>() {
  static const Schema<RoadFrictionSpec> s{{
      field("x", &RoadFrictionSpec::x, read_road_interval),
      field("y", &RoadFrictionSpec::y, read_road_interval),
      field("scale", &RoadFrictionSpec::scale, read_coefficient, Need::Required),
  }};
  return s;
}

template <>
const Schema<RoadSpec>& schema<RoadSpec>() {
  static const Schema<RoadSpec> s{{
      field("body", &RoadSpec::body, read_string),
      field("point", &RoadSpec::point, read_vec3),
      field("normal", &RoadSpec::normal, read_direction),
      field("surface", &RoadSpec::surface, read_string),
      optional_struct_field("grid", &RoadSpec::grid),
      optional_struct_field("profile", &RoadSpec::profile),
      optional_struct_field("iso8608", &RoadSpec::iso8608),
      list_field("friction", &RoadSpec::friction),
  }};
  return s;
}

template <>
const Schema<NamedRoadSpec>& schema<NamedRoadSpec>() {
  static const Schema<NamedRoadSpec> s{{
      name_field<NamedRoadSpec>(),
      optional_struct_field("grid", &NamedRoadSpec::grid),
      optional_struct_field("profile", &NamedRoadSpec::profile),
      optional_struct_field("iso8608", &NamedRoadSpec::iso8608),
      list_field("friction", &NamedRoadSpec::friction),
  }};
  return s;
}

// "linear" | "fiala" | "magic_formula"
std::string read_tire_law(const Node& n) {
  const std::string s = read_string(n);
  for (const char* law : kTireLawNames)
    if (s == law) return s;
  n.fail("unknown tire law " + quote(s) + " (expected one of: linear, fiala, magic_formula)");
}

// A tire law's own field: read only for a tire whose law (read before it) uses it, written only then.
template <class T, class Read>
Field<EffectSpec> tire_law_field(std::string_view key, T EffectSpec::*m, Read read,
                                 std::vector<std::string_view> laws) {
  const auto uses = [laws](const std::string& law) { return std::find(laws.begin(), laws.end(), law) != laws.end(); };
  return {key, Need::Optional,
          [key, m, read, laws, uses](const Node& n, EffectSpec& s) {
            if (!uses(s.law))
              n.fail_unknown("field " + quote(key) + " belongs to the tire law" + (laws.size() > 1 ? "s " : " ") + join(laws) +
                     ", not to " + quote(s.law));
            s.*m = read(n);
          },
          [key, m, uses](ojson& j, const EffectSpec& s) {
            if (uses(s.law)) j[std::string(key)] = encode(s.*m);
          }};
}

double read_positive_speed(const Node& n) {
  const double x = read_number(n);
  if (!(x > 0)) n.expected("a speed > 0 (m/s)");
  return x;
}

template <>
const Schema<EffectSpec>& schema<EffectSpec>() {
  static const Schema<EffectSpec> s{
      fields<EffectSpec>({
          {name_field<EffectSpec>(), type_field<EffectSpec>("effect type", effect_type_from_string),
           field("g", &EffectSpec::g, read_vec3)},
          point_pair_fields<EffectSpec>(),
          joint_dof_fields<EffectSpec>(),
          {field("stiffness", &EffectSpec::stiffness, read_coefficient),
           field("damping", &EffectSpec::damping, read_coefficient),
           field("rest_length", &EffectSpec::rest_length, read_coefficient),
           field("rest_position", &EffectSpec::rest_position, read_number),
           field("body", &EffectSpec::body_a, read_string, Need::Required),
           field("point", &EffectSpec::point_a, read_vec3),
           field("force", &EffectSpec::force, read_vec3),
           field("torque", &EffectSpec::torque, read_vec3),
           field("frame", &EffectSpec::in_world, read_in_world, encode_in_world),
           struct_field("frame_a", &EffectSpec::frame_a), struct_field("frame_b", &EffectSpec::frame_b),
           field("translational_stiffness", &EffectSpec::translational_stiffness, read_coefficients),
           field("translational_damping", &EffectSpec::translational_damping, read_coefficients),
           field("rotational_stiffness", &EffectSpec::rotational_stiffness, read_coefficients),
           field("rotational_damping", &EffectSpec::rotational_damping, read_coefficients)},
          {field("center", &EffectSpec::center, read_vec3),
           field("spin_axis", &EffectSpec::spin_axis, read_direction),
           field("unloaded_radius", &EffectSpec::unloaded_radius,
                 [](const Node& n) { return std::optional<double>(read_positive_length(n)); }),
           field("rolling_radius", &EffectSpec::rolling_radius, read_positive_length,
                 [](double r) { return r > 0 ? ojson(r) : ojson(); }),
           struct_field("road", &EffectSpec::road),
           field("law", &EffectSpec::law, read_tire_law, Need::Required),
           tire_law_field("longitudinal_stiffness", &EffectSpec::longitudinal_stiffness, read_coefficient, {"linear", "fiala"}),
           tire_law_field("cornering_stiffness", &EffectSpec::cornering_stiffness, read_coefficient, {"linear", "fiala"}),
           tire_law_field("camber_stiffness", &EffectSpec::camber_stiffness, read_number, {"linear"}),
           tire_law_field("friction", &EffectSpec::friction, read_coefficient, {"linear", "fiala"}),
           tire_law_field("sliding_friction", &EffectSpec::sliding_friction, read_coefficient, {"fiala"}),
           tire_law_field("trail", &EffectSpec::trail, read_number, {"linear"}),
           tire_law_field("width", &EffectSpec::width, read_coefficient, {"fiala"}),
           tire_law_field("rolling_resistance", &EffectSpec::rolling_resistance, read_coefficient, {"fiala"}),
           tire_law_field("file", &EffectSpec::file, read_string, {"magic_formula"}),
           {"side", Need::Optional,
            [](const Node& n, EffectSpec& s) {
              if (s.law != "magic_formula")
                n.fail_unknown("field \"side\" belongs to the tire law magic_formula, not to " + quote(s.law));
              s.side = read_string(n);
              if (s.side != "left" && s.side != "right") n.fail("unknown side " + quote(s.side) + " (expected one of: left, right)");
            },
            [](ojson& j, const EffectSpec& s) {
              if (s.law == "magic_formula" && !s.side.empty()) j["side"] = s.side;
            }},
           field("vertical_stiffness", &EffectSpec::vertical_stiffness,
                 [](const Node& n) { return std::optional<double>(read_coefficient(n)); }),
           field("vertical_damping", &EffectSpec::vertical_damping,
                 [](const Node& n) { return std::optional<double>(read_coefficient(n)); }),
           field("low_speed", &EffectSpec::low_speed, read_positive_speed),
           field("longitudinal_relaxation_length", &EffectSpec::longitudinal_relaxation_length, read_coefficient,
                 [](double r) { return r > 0 ? ojson(r) : ojson(); }),
           field("lateral_relaxation_length", &EffectSpec::lateral_relaxation_length, read_coefficient,
                 [](double r) { return r > 0 ? ojson(r) : ojson(); }),
           {"relaxation_from_file", Need::Optional,
            [](const Node& n, EffectSpec& s) {
              if (s.law != "magic_formula")
                n.fail_unknown("field \"relaxation_from_file\" belongs to the tire law magic_formula, not to " + quote(s.law));
              s.relaxation_from_file = read_bool(n);
            },
            [](ojson& j, const EffectSpec& s) {
              if (s.relaxation_from_file) j["relaxation_from_file"] = true;
            }}},
      }),
      "effect",
      [](const EffectSpec& e) {
        switch (e.type) {
          case EffectType::Gravity: return element_keys({"g"});
          case EffectType::SpringDamper: return element_keys(point_pair_and({"stiffness", "damping", "rest_length"}));
          case EffectType::JointSpringDamper:
            return element_keys({"joint", "dof", "stiffness", "damping", "rest_position"});
          case EffectType::JointFriction: return element_keys({"joint", "dof", "damping"});
          case EffectType::JointDamper: return element_keys({"joint", "damping"});
          case EffectType::BodyForce: return element_keys({"body", "point", "force", "torque", "frame"});
          case EffectType::Bushing:
            return element_keys({"body_a", "frame_a", "body_b", "frame_b", "translational_stiffness", "translational_damping",
                                 "rotational_stiffness", "rotational_damping"});
          case EffectType::Tire:
            return element_keys({"body", "center", "spin_axis", "unloaded_radius", "rolling_radius", "road", "law",
                                 "longitudinal_stiffness", "cornering_stiffness", "camber_stiffness", "friction",
                                 "sliding_friction", "trail", "width", "rolling_resistance", "file", "side", "vertical_stiffness",
                                 "vertical_damping", "low_speed", "longitudinal_relaxation_length",
                                 "lateral_relaxation_length", "relaxation_from_file"});
        }
        return element_keys({});
      }};
  return s;
}

template <>
const Schema<ActuatorSpec>& schema<ActuatorSpec>() {
  static const Schema<ActuatorSpec> s{
      fields<ActuatorSpec>({
          {name_field<ActuatorSpec>(), type_field<ActuatorSpec>("actuator type", actuator_type_from_string)},
          joint_dof_fields<ActuatorSpec>(),
          {field("body", &ActuatorSpec::body, read_string, Need::Required),
           field("point", &ActuatorSpec::point, read_vec3),
           field("direction", &ActuatorSpec::direction, read_direction),
           field("frame", &ActuatorSpec::in_world, read_in_world, encode_in_world),
           field("gain", &ActuatorSpec::gain, read_number), field("u0", &ActuatorSpec::u0, read_number),
           field("min", &ActuatorSpec::min, read_number), field("max", &ActuatorSpec::max, read_number),
           field("unit", &ActuatorSpec::unit, read_string, encode_optional_text)},
          point_pair_fields<ActuatorSpec>(),
          {field("drives", &ActuatorSpec::drives, read_names, Need::Required),
           field("weights", &ActuatorSpec::weights, read_vector, Need::Required)},
      }),
      "actuator",
      [](const ActuatorSpec& a) {
        const std::vector<std::string_view> tail{"gain", "u0", "min", "max", "unit"};
        switch (a.type) {
          case ActuatorType::JointForce: return element_keys({"joint", "dof"}, tail);
          case ActuatorType::BodyForce: return element_keys({"body", "point", "direction", "frame"}, tail);
          case ActuatorType::BodyTorque: return element_keys({"body", "direction", "frame"}, tail);
          case ActuatorType::LineForce: return element_keys(point_pair_and({}), tail);
          case ActuatorType::Mix: return element_keys({"drives", "weights"}, {"u0", "min", "max", "unit"});
          case ActuatorType::Motion: return element_keys({"joint", "dof"}, {"min", "max", "unit"});
        }
        return element_keys({}, tail);
      }};
  return s;
}

// a tire sensor's quantity: one of kTireQuantityNames
std::string read_tire_quantity(const Node& n) {
  const std::string s = read_string(n);
  std::string all;
  for (const char* q : kTireQuantityNames) {
    if (s == q) return s;
    all += (all.empty() ? "" : ", ") + std::string(q);
  }
  n.fail("unknown tire quantity " + quote(s) + " (expected one of: " + all + ")");
}

bool read_sensor_flag(const Node& n) {
  if (!n.value().is_boolean()) n.expected("true or false");
  return n.value().get<bool>();
}

template <>
const Schema<SensorSpec>& schema<SensorSpec>() {
  static const Schema<SensorSpec> s{
      fields<SensorSpec>({
          {name_field<SensorSpec>(), type_field<SensorSpec>("sensor type", sensor_type_from_string)},
          joint_dof_fields<SensorSpec>(),
          point_pair_fields<SensorSpec>(),
          {field("body", &SensorSpec::body, read_string, Need::Required),
           field("point", &SensorSpec::point, read_vec3),
           field("component", &SensorSpec::component, read_component, encode_component),
           field("frame", &SensorSpec::frame, read_string), field("axis", &SensorSpec::axis, read_direction),
           field("specific_force", &SensorSpec::specific_force, read_sensor_flag, [](bool b) { return ojson(b); }),
           field("tire", &SensorSpec::tire, read_string, Need::Required),
           field("quantity", &SensorSpec::quantity, read_tire_quantity, Need::Required),
           field("unit", &SensorSpec::unit, read_string, encode_optional_text)},
      }),
      "sensor",
      [](const SensorSpec& s) {
        switch (s.type) {
          case SensorType::JointPosition:
          case SensorType::JointVelocity:
          case SensorType::MotionForce: return element_keys({"joint", "dof"}, {"unit"});
          case SensorType::PointPosition:
          case SensorType::PointVelocity: return element_keys({"body", "point", "component", "frame"}, {"unit"});
          case SensorType::BodyAngle: return element_keys({"body", "axis"}, {"unit"});
          case SensorType::Distance:
          case SensorType::DistanceRate: return element_keys(point_pair_and({}), {"unit"});
          case SensorType::AngularVelocity: return element_keys({"body", "component", "frame"}, {"unit"});
          case SensorType::Acceleration:
            return element_keys({"body", "point", "component", "frame", "specific_force"}, {"unit"});
          case SensorType::Tire: return element_keys({"tire", "quantity"}, {"unit"});
        }
        return element_keys({}, {"unit"});
      }};
  return s;
}

template <>
const Schema<PlantSpec>& schema<PlantSpec>() {
  static const Schema<PlantSpec> s{{
      field("inputs", &PlantSpec::inputs, read_names),
      field("outputs", &PlantSpec::outputs, read_names),
  }};
  return s;
}

// A matrix of a controller; `check` tests it against the fields read before it
// (sizes against the plant are checked when a simulation uses the controller).
Field<ControllerSpec> matrix_field(std::string_view key, Eigen::MatrixXd ControllerSpec::*m, Need need,
                                   void (*check)(const Node&, const ControllerSpec&) = nullptr) {
  Field<ControllerSpec> f = field(key, m, read_matrix, encode_matrix, need);
  if (check)
    f.read = [m, check](const Node& n, ControllerSpec& c) {
      c.*m = read_matrix(n);
      check(n, c);
    };
  return f;
}

void expect_size(const Node& n, const Eigen::MatrixXd& m, Eigen::Index rows, Eigen::Index cols,
                 const std::string& why) {
  if (m.rows() != rows || m.cols() != cols)
    n.fail("expected a " + std::to_string(rows) + " x " + std::to_string(cols) + " matrix (" + why + "), got " +
           size_of(m));
}

void expect_size_of_kp(const Node& n, const Eigen::MatrixXd& m, const ControllerSpec& c) {
  expect_size(n, m, c.kp.rows(), c.kp.cols(), "the size of kp");
}

std::string read_word(const Node& n, const std::vector<std::string>& words, const char* what);  // below

// the driver's numbers (simulation/driver.hpp)
double read_driver_positive(const Node& n) {
  const double x = read_number(n);
  if (!(x > 0)) n.expected("a number > 0");
  return x;
}
double read_driver_nonnegative(const Node& n) {
  const double x = read_number(n);
  if (!(x >= 0)) n.expected("a number >= 0");
  return x;
}
double read_driver_nonzero(const Node& n) {
  const double x = read_number(n);
  if (!(x != 0)) n.expected("a number other than 0");
  return x;
}
double read_driver_radius(const Node& n) {
  const double x = read_number(n);
  if (!(x != 0)) n.expected("a radius other than 0 (m, > 0 turns left)");
  return x;
}

template <>
const Schema<ControllerSpec>& schema<ControllerSpec>() {
  using C = ControllerSpec;
  static const Schema<C> s{
      {
          type_field<C>("controller type", controller_type_from_string),
          matrix_field("kp", &C::kp, Need::Required),
          matrix_field("ki", &C::ki, Need::Optional, [](const Node& n, const C& c) { expect_size_of_kp(n, c.ki, c); }),
          matrix_field("kd", &C::kd, Need::Optional, [](const Node& n, const C& c) { expect_size_of_kp(n, c.kd, c); }),
          {"setpoint", Need::Optional,
           [](const Node& n, C& c) {
             c.setpoint = read_vector(n);
             if (c.setpoint.size() != c.kp.cols())
               n.fail("expected " + counted(c.kp.cols(), "value") + " (one per column of kp), got " +
                      std::to_string(c.setpoint.size()));
           },
           [](ojson& j, const C& c) { if (c.setpoint.size() > 0) j["setpoint"] = encode(c.setpoint); }},
          matrix_field("K", &C::K, Need::Required),
          matrix_field("Ac", &C::Ac, Need::Required,
                       [](const Node& n, const C& c) {
                         if (c.Ac.rows() != c.Ac.cols()) n.fail("expected a square matrix, got " + size_of(c.Ac));
                       }),
          matrix_field("Bc", &C::Bc, Need::Required,
                       [](const Node& n, const C& c) {
                         if (c.Bc.rows() != c.Ac.rows())
                           n.fail("expected " + counted(c.Ac.rows(), "row") + " (as many as Ac), got " +
                                  std::to_string(c.Bc.rows()));
                       }),
          matrix_field("Cc", &C::Cc, Need::Required,
                       [](const Node& n, const C& c) {
                         if (c.Cc.cols() != c.Ac.cols())
                           n.fail("expected " + counted(c.Ac.cols(), "column") + " (as many as Ac), got " +
                                  std::to_string(c.Cc.cols()));
                       }),
          matrix_field("Dc", &C::Dc, Need::Required,
                       [](const Node& n, const C& c) {
                         expect_size(n, c.Dc, c.Cc.rows(), c.Bc.cols(), "rows of Cc by columns of Bc");
                       }),
          field("Ts", &C::Ts, read_sample_time),
          field("q_weights", &C::q_weights, [](const Node& n) { return read_weights(n, false); }),
          field("r_weights", &C::r_weights, [](const Node& n) { return read_weights(n, true); }),
          field("operating_point", &C::operating_point, read_operating_point),
          // the driver (simulation/driver.hpp)
          field("path", &C::path,
                [](const Node& n) { return read_word(n, {"straight", "circle", "double_lane_change", "table"}, "driver path"); }),
          field("radius", &C::radius, read_driver_radius),
          field("path_length", &C::path_length, read_driver_positive),
          field("vehicle_width", &C::vehicle_width, read_driver_positive),
          field("path_heading", &C::path_heading, read_number),
          field("path_start", &C::path_start, [](const Node& n) { return Eigen::Vector2d(read_numbers(n, 2)); }),
          matrix_field("path_points", &C::path_points, Need::Optional,
                       [](const Node& n, const C& c) {
                         if (c.path_points.cols() != 2 || c.path_points.rows() < 2)
                           n.fail("expected a table of at least 2 points [x, y] (N x 2), got " + size_of(c.path_points));
                         for (Eigen::Index k = 1; k < c.path_points.rows(); ++k)
                           if (c.path_points.row(k) == c.path_points.row(k - 1))
                             n.fail("point " + std::to_string(k) + " is the same as the one before it");
                       }),
          field("preview", &C::preview, read_driver_positive),
          field("wheelbase", &C::wheelbase, read_driver_positive),
          field("steering_ratio", &C::steering_ratio, read_driver_nonzero),
          field("lateral_gain", &C::lateral_gain, read_driver_nonnegative),
          field("speed", &C::speed, read_driver_nonnegative),
          field("speed_kp", &C::speed_kp, read_driver_nonnegative),
          field("speed_ki", &C::speed_ki, read_driver_nonnegative),
          field("sample_time", &C::sample_time, read_driver_positive),
          field("x", &C::x, read_string),
          field("y", &C::y, read_string),
          field("yaw", &C::yaw, read_string),
          field("forward_speed", &C::forward_speed, read_string),
          field("steer", &C::steer, read_string),
          field("drive", &C::drive, read_string),
      },
      "controller",
      [](const C& c) -> std::vector<std::string_view> {
        switch (c.type) {
          case ControllerType::None: return {"type"};
          case ControllerType::Pid: return {"type", "kp", "ki", "kd", "setpoint", "operating_point"};
          case ControllerType::StateFeedback: return {"type", "K", "operating_point"};
          case ControllerType::Lti: return {"type", "Ac", "Bc", "Cc", "Dc", "Ts", "operating_point"};
          case ControllerType::Lqr: return {"type", "q_weights", "r_weights", "operating_point"};
          case ControllerType::Driver:
            return {"type", "path", "radius", "path_length", "vehicle_width", "path_heading", "path_start", "path_points",
                    "preview", "wheelbase", "steering_ratio", "lateral_gain", "speed", "speed_kp", "speed_ki",
                    "sample_time", "x", "y", "yaw", "forward_speed", "steer", "drive", "operating_point"};
        }
        return {"type"};
      }};
  return s;
}

// No controller (type none) is left out of the file.
ojson write_controller(const ControllerSpec& c) {
  return c.type == ControllerType::None ? ojson() : write_struct(c);
}

template <>
const Schema<SolverSpec>& schema<SolverSpec>() {
  // each number in its range, so a run never starts from nonsense (the work bounds are checked when it starts)
  const auto in_range = [](bool (*ok)(double), const char* expected) {
    return [ok, expected](const Node& n) {
      const double x = read_number(n);
      if (!ok(x)) n.expected(expected);
      return x;
    };
  };
  static const Schema<SolverSpec> s{{
      field("integrator", &SolverSpec::integrator, read_string),
      field("rtol", &SolverSpec::rtol, in_range([](double x) { return x > 0 && x < 1; }, "a relative tolerance in (0, 1)")),
      field("atol", &SolverSpec::atol, in_range([](double x) { return x > 0; }, "an absolute tolerance > 0")),
      field("t_end", &SolverSpec::t_end, in_range([](double x) { return x > 0; }, "an end time > 0 (s)")),
      field("output_step", &SolverSpec::output_step, in_range([](double x) { return x > 0; }, "an output step > 0 (s)")),
      field("max_step", &SolverSpec::max_step, in_range([](double x) { return x >= 0; }, "a largest step >= 0 (s; 0 = no limit)")),
      // alf's settings, written only where they were given
      field("alf_penalty", &SolverSpec::alf_penalty,
            [](const Node& n) {
              const double x = read_number(n);
              if (!(x > 0) || !std::isfinite(x)) n.expected("a penalty > 0 (alf's default 1e11)");
              return std::optional<double>(x);
            }),
      field("alf_iterations", &SolverSpec::alf_iterations,
            [](const Node& n) {
              const int k = read_integer(n);
              if (k < 1) n.expected("a number of Newton iterations >= 1 (alf's default 100)");
              return std::optional<int>(k);
            },
            [](const std::optional<int>& k) { return k ? ojson(*k) : ojson(); }),
      field("alf_fixed_step", &SolverSpec::alf_fixed_step, read_bool,
            [](bool fixed) { return fixed ? ojson(true) : ojson(); }),
      field("alf_extrapolate", &SolverSpec::alf_extrapolate, read_bool,
            [](bool on) { return on ? ojson(true) : ojson(); }),
  }};
  return s;
}

// One of `words`, or the operating-point form "time=T".
std::string read_word(const Node& n, const std::vector<std::string>& words, const char* what) {
  const std::string s = read_string(n);
  if (std::find(words.begin(), words.end(), s) == words.end()) {
    std::vector<std::string_view> v(words.begin(), words.end());
    n.fail("unknown " + std::string(what) + " " + quote(s) + " (expected one of: " + join(v) + ")");
  }
  return s;
}

std::string read_study_operating_point(const Node& n) {
  const std::string s = read_string(n);
  if (s == "initial" || s == "equilibrium" || s == "trim" || s == "steady") return s;
  if (s.rfind("time=", 0) == 0) {
    char* end = nullptr;
    const double t = std::strtod(s.c_str() + 5, &end);
    if (end != s.c_str() + 5 && *end == 0 && std::isfinite(t) && t >= 0) return s;
  }
  n.fail("unknown operating point " + quote(s) + " (expected one of: initial, equilibrium, trim, steady, time=T with T >= 0 seconds)");
}

std::vector<std::pair<std::string, double>> read_set(const Node& n) {
  const Object o(n);
  std::vector<std::pair<std::string, double>> out;
  for (const auto& item : n.value().items()) out.emplace_back(item.key(), read_number(n.member(item.key())));
  return out;
}

ojson encode_set(const std::vector<std::pair<std::string, double>>& set) {
  ojson j = ojson::object();
  for (const auto& [name, value] : set) j[name] = value;
  return j;
}

template <>
const Schema<SignalSpec>& schema<SignalSpec>() {
  using T = SignalSpec;
  static const Schema<T> s{
      {
          field("output", &T::output, read_string, Need::Required),
          field("type", &T::type, [](const Node& n) { return read_word(n, signal_types(), "signal type"); }, Need::Required),
          field("time", &T::time, [](const Node& n) {
            const double x = read_number(n);
            if (x < 0) n.expected("a time >= 0 (s)");
            return x;
          }),
          field("value", &T::value, read_number),
          field("slope", &T::slope, read_number),
          field("amplitude", &T::amplitude, read_number),
          field("frequency", &T::frequency, [](const Node& n) {
            const double x = read_number(n);
            if (x < 0) n.expected("a frequency >= 0 (Hz)");
            return x;
          }),
          field("phase", &T::phase, read_number),
          field("file", &T::file,
                [](const Node& n) {
                  const std::string f = read_string(n);
                  if (f.empty()) n.expected("a file name (CSV or .mat)");
                  return f;
                },
                Need::Required),
          field("points", &T::points,
                [](const Node& n) {
                  std::vector<std::pair<double, double>> p;
                  for (const Node& e : read_elements(n)) {
                    const Eigen::VectorXd v = read_numbers(e, 2);
                    if (!p.empty() && !(v[0] > p.back().first)) e.expected("times that increase along the table");
                    p.emplace_back(v[0], v[1]);
                  }
                  if (p.empty()) n.expected("at least one [t, r] point");
                  return p;
                },
                [](const std::vector<std::pair<double, double>>& p) {
                  ojson a = ojson::array();
                  for (const auto& [t, r] : p) a.push_back(ojson::array({t, r}));
                  return a;
                }),
      },
      "reference",
      [](const T& x) -> std::vector<std::string_view> {
        if (x.type == "step") return {"output", "type", "time", "value"};
        if (x.type == "ramp") return {"output", "type", "time", "slope"};
        if (x.type == "sine") return {"output", "type", "time", "amplitude", "frequency", "phase"};
        if (x.type == "file") return {"output", "type", "file"};
        return {"output", "type", "points"};
      }};
  return s;
}

// A disturbance is a signal on an actuator: the signal's fields, "actuator" in place of "output".
template <>
const Schema<DisturbanceSpec>& schema<DisturbanceSpec>() {
  using T = DisturbanceSpec;
  static const Schema<T> s = [] {
    Schema<T> d;
    d.kind = "disturbance";
    d.fields.push_back(field("actuator", &T::actuator, read_string, Need::Required));
    for (const Field<SignalSpec>& f : schema<SignalSpec>().fields) {
      if (f.key == "output") continue;
      d.fields.push_back({f.key, f.need, [r = f.read](const Node& n, T& x) { r(n, x); },
                          [w = f.write](ojson& j, const T& x) { w(j, x); }});
    }
    d.keys = [](const T& x) {
      std::vector<std::string_view> k = schema<SignalSpec>().keys_of(x);
      std::replace(k.begin(), k.end(), std::string_view("output"), std::string_view("actuator"));
      return k;
    };
    return d;
  }();
  return s;
}

bool read_bool(const Node& n) {
  if (!n.value().is_boolean()) n.expected("true or false");
  return n.value().get<bool>();
}

template <>
const Schema<ClosedLoopSpec>& schema<ClosedLoopSpec>() {
  using T = ClosedLoopSpec;
  const auto at_least = [](double lowest, const char* expected) {
    return [lowest, expected](const Node& n) {
      const double x = read_number(n);
      if (!(x >= lowest)) n.expected(expected);
      return x;
    };
  };
  const auto count = [](int lowest, int highest, const char* expected) {
    return [lowest, highest, expected](const Node& n) {
      const int k = read_integer(n);
      if (k < lowest || k > highest) n.expected(expected);
      return k;
    };
  };
  static const Schema<T> s{{
      field("enabled", &T::enabled, read_bool, [](bool b) { return ojson(b); }),
      field("step_time", &T::step_time, at_least(0.0, "a time >= 0 (s; 0 = from the slowest pole)")),
      field("step_points", &T::step_points, count(2, 1000000, "an integer from 2 to 1000000")),
      field("frequency_min", &T::frequency_min, at_least(0.0, "a frequency >= 0 (rad/s; 0 = from the poles)")),
      {"frequency_max", Need::Optional,
       [](const Node& n, T& c) {
         c.frequency_max = read_number(n);
         if (!(c.frequency_max >= 0)) n.expected("a frequency >= 0 (rad/s; 0 = from the poles)");
         if (c.frequency_max > 0 && c.frequency_min > 0 && !(c.frequency_max > c.frequency_min))
           n.expected("a frequency above frequency_min " + dump(c.frequency_min));
       },
       [](ojson& j, const T& c) { j["frequency_max"] = c.frequency_max; }},
      field("frequency_points", &T::frequency_points, count(2, 100000, "an integer from 2 to 100000")),
  }};
  return s;
}

template <>
const Schema<SteadySpec>& schema<SteadySpec>() {
  using T = SteadySpec;
  const auto finite = [](const Node& n) { return std::optional<double>(read_number(n)); };
  static const Schema<T> s{{
      field("body", &T::body, read_string, encode_optional_text),
      field("speed", &T::speed, finite),
      field("yaw_rate", &T::yaw_rate, finite),
      field("radius", &T::radius,
            [](const Node& n) {
              const double r = read_number(n);
              if (!(std::abs(r) > 0)) n.expected("a path radius, not 0 (m; > 0 turns left, < 0 right)");
              return std::optional<double>(r);
            }),
      field("lateral_acceleration", &T::lateral_acceleration, finite),
  }};
  return s;
}

ojson write_steady(const SteadySpec& c) { return c == SteadySpec{} ? ojson() : write_struct(c); }

template <>
const Schema<HandlingSpec>& schema<HandlingSpec>() {
  using T = HandlingSpec;
  static const Schema<T> s{{
      field("steer", &T::steer, read_string, encode_optional_text),
      field("yaw_rate", &T::yaw_rate, read_string, encode_optional_text),
      field("lateral_acceleration", &T::lateral_acceleration, read_string, encode_optional_text),
      field("sideslip", &T::sideslip, read_string, encode_optional_text),
      field("wheelbase", &T::wheelbase, [](const Node& n) { return std::optional<double>(read_positive_length(n)); }),
      field("steering_ratio", &T::steering_ratio,
            [](const Node& n) {
              const double r = read_number(n);
              if (!(std::abs(r) > 0) || !std::isfinite(r)) n.expected("a steering ratio: steer input per road-wheel angle, not 0");
              return std::optional<double>(r);
            }),
  }};
  return s;
}

ojson write_handling(const HandlingSpec& c) { return c == HandlingSpec{} ? ojson() : write_struct(c); }

// A default closed-loop analysis is left out of the file.
ojson write_closed_loop(const ClosedLoopSpec& c) { return c == ClosedLoopSpec{} ? ojson() : write_struct(c); }

template <>
const Schema<StudySpec>& schema<StudySpec>() {
  using T = StudySpec;
  static const Schema<T> s{{
      field("disabled_effects", &T::disabled_effects, read_names),
      field("operating_point", &T::operating_point, read_study_operating_point),
      field("set", &T::set, read_set, encode_set),
      field("initial", &T::initial, read_set, encode_set),
      field("start", &T::start, [](const Node& n) { return read_word(n, study_starts(), "start"); },
            [](const std::string& v) { return v == "model" ? ojson() : ojson(v); }),
      field("independent", &T::independent, read_names),
      field("trim_free", &T::trim_free, read_names),
      field("free_inputs", &T::free_inputs, read_names),
      field("output_targets", &T::output_targets, read_set, encode_set),
      field("steady", &T::steady, read_struct<SteadySpec>, write_steady),
      field("handling", &T::handling, read_struct<HandlingSpec>, write_handling),
      field("method", &T::method, [](const Node& n) { return read_word(n, study_methods(), "method"); }),
      field("discrete", &T::discrete,
            [](const Node& n) {
              const double Ts = read_number(n);
              if (Ts < 0) n.expected("a sample time >= 0 (0 = continuous)");
              return Ts;
            },
            [](double Ts) { return Ts > 0 ? ojson(Ts) : ojson(); }),
      field("mat_version", &T::mat_version, [](const Node& n) { return read_word(n, {"5", "7.3"}, "MAT version"); }),
      field("export_name", &T::export_name, read_string, encode_optional_text),
      field("export_dir", &T::export_dir, read_string, encode_optional_text),
      field("controller", &T::controller, [](const Node& n) { return read_word(n, study_controllers(), "controller source"); }),
      field("controller_file", &T::controller_file, read_string, encode_optional_text),
      field("q_weights", &T::q_weights, [](const Node& n) { return read_weights(n, false); }),
      field("r_weights", &T::r_weights, [](const Node& n) { return read_weights(n, true); }),
      field("lqr_controllable_part", &T::lqr_controllable_part, read_bool, [](bool b) { return b ? ojson(true) : ojson(); }),
      list_field("references", &T::references),
      field("compare_linear", &T::compare_linear, read_bool, [](bool b) { return b ? ojson(true) : ojson(); }),
      field("linear_region", &T::linear_region,
            [](const Node& n) {
              const double x = read_number(n);
              if (!(x > 0)) n.expected("a bound > 0 (rad or m)");
              return x;
            },
            [](double x) { return x != 0.5 ? ojson(x) : ojson(); }),
      list_field("disturbances", &T::disturbances),
      field("anti_windup", &T::anti_windup,
            [](const Node& n) { return read_word(n, anti_windup_methods(), "anti-windup method"); },
            [](const std::string& a) { return a == "none" ? ojson() : ojson(a); }),
      field("tracking_time", &T::tracking_time,
            [](const Node& n) {
              const double x = read_number(n);
              if (!(x > 0)) n.expected("a time constant > 0 (s)");
              return x;
            },
            [](double x) { return x > 0 ? ojson(x) : ojson(); }),
      field("closed_loop", &T::closed_loop, read_struct<ClosedLoopSpec>, write_closed_loop),
  }};
  return s;
}

// A study with every choice at its default is left out of the file.
ojson write_study(const StudySpec& a) { return a == StudySpec{} ? ojson() : write_struct(a); }

template <>
const Schema<ModelSpec>& schema<ModelSpec>() {
  static const Schema<ModelSpec> s{{
      {"codyna_model", Need::Optional,
       [](const Node& n, ModelSpec&) {
         if (read_integer(n) != kFormatVersion)
           n.fail("unsupported format version " + dump(n.value()) + " (this codyna reads version " +
                  std::to_string(kFormatVersion) + ")");
       },
       [](ojson& j, const ModelSpec&) { j["codyna_model"] = kFormatVersion; }},
      name_field<ModelSpec>(),
      field("description", &ModelSpec::description, read_string, encode_optional_text),
      list_field("bodies", &ModelSpec::bodies, Need::Required),
      list_field("joints", &ModelSpec::joints, Need::Required),
      list_field("constraints", &ModelSpec::constraints),
      list_field("effects", &ModelSpec::effects),
      list_field("actuators", &ModelSpec::actuators),
      list_field("sensors", &ModelSpec::sensors),
      list_field("roads", &ModelSpec::roads),
      struct_field("plant", &ModelSpec::plant),
      field("controller", &ModelSpec::controller, read_struct<ControllerSpec>, write_controller),
      struct_field("solver", &ModelSpec::solver),
      field("analysis", &ModelSpec::analysis, read_struct<StudySpec>, write_study),
  }};
  return s;
}

// "line L, column C" of the byte at 1-based offset `byte` (as nlohmann counts).
std::string location(const std::string& text, std::size_t byte) {
  const std::size_t pos = std::min(byte > 0 ? byte - 1 : 0, text.size());
  const std::size_t line = 1 + std::count(text.begin(), text.begin() + pos, '\n');
  const std::size_t line_start = pos == 0 ? 0 : text.rfind('\n', pos - 1) + 1;  // npos + 1 == 0
  return "line " + std::to_string(line) + ", column " + std::to_string(pos - line_start + 1);
}

// nlohmann's message without its "[json.exception...] parse error at ...: " prefix.
std::string reason(const json::exception& e) {
  std::string s = e.what();
  if (auto p = s.find("] "); p != std::string::npos) s.erase(0, p + 2);
  if (s.rfind("parse error", 0) == 0)
    if (auto p = s.find(": "); p != std::string::npos) s.erase(0, p + 2);
  return s;
}

// A value that goes on one line: a scalar, an empty container or an array of scalars.
bool is_flat(const ojson& j) {
  return j.empty() || j.is_primitive() ||
         (j.is_array() && std::all_of(j.begin(), j.end(), [](const ojson& e) { return e.is_primitive(); }));
}

// Like dump(2), but a vector, or a row of a matrix, stays on one line: "position": [0.0, 0.5, 0.0].
void print(const ojson& j, std::string& out, int depth = 0) {
  const bool object = j.is_object();
  if (is_flat(j)) {
    if (!j.is_array()) return void(out += j.dump());
    out += "[";
    for (std::size_t i = 0; i < j.size(); ++i) out += (i ? ", " : "") + j[i].dump();
    return void(out += "]");
  }
  const std::string indent(2 * depth + 2, ' ');
  out += object ? "{\n" : "[\n";
  std::size_t i = 0;
  for (const auto& item : j.items()) {
    out += (i++ ? ",\n" : "") + indent;
    if (object) out += ojson(item.key()).dump() + ": ";
    print(item.value(), out, depth + 1);
  }
  out += "\n" + std::string(2 * depth, ' ') + (object ? "}" : "]");
}

struct Closer {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, Closer>;

std::string error_text(int err) { return std::generic_category().message(err); }

}  // namespace

ModelSpec parse_model_spec(const nlohmann::json& j, const std::string& file_label) {
  std::vector<std::string> notes;
  g_notes = &notes;
  struct Reset {
    ~Reset() { g_notes = nullptr; }
  } reset;
  ModelSpec spec = read_struct<ModelSpec>(Node(j, "", file_label));
  spec.notes = std::move(notes);
  return spec;
}

bool parse_model_element(ModelSpec& spec, const std::string& section, std::size_t index, const nlohmann::json& element,
                         const std::string& file_label) {
  const Node n(element, "/" + section + "/" + std::to_string(index), file_label);
  const auto read = [&](auto& list) {
    using T = typename std::decay_t<decltype(list)>::value_type;
    if (index >= list.size()) return false;
    list[index] = read_struct<T>(n);
    return true;
  };
  if (section == "bodies") return read(spec.bodies);
  if (section == "joints") return read(spec.joints);
  if (section == "constraints") return read(spec.constraints);
  if (section == "effects") return read(spec.effects);
  if (section == "actuators") return read(spec.actuators);
  if (section == "sensors") return read(spec.sensors);
  return false;
}

ModelSpec parse_model_spec_text(const std::string& text, const std::string& file_label) {
  json j;
  // the path of the value being read, so that a JSON error inside a field (a number that
  // overflows a double) is reported with the field's path as well as its line and column
  struct Frame {
    bool array = false;
    std::size_t index = 0;
    std::string key;
  };
  std::vector<Frame> frames;
  const auto path_of = [](const std::vector<Frame>& fs) {
    std::string path;
    for (const Frame& f : fs) path += "/" + (f.array ? std::to_string(f.index) : pointer_token(f.key));
    return path;
  };
  const auto track = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start: frames.push_back({false, 0, {}}); break;
      case json::parse_event_t::array_start: frames.push_back({true, 0, {}}); break;
      case json::parse_event_t::key: if (!frames.empty()) frames.back().key = parsed.get<std::string>(); break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!frames.empty()) frames.pop_back();
        [[fallthrough]];
      case json::parse_event_t::value:
        if (!frames.empty() && frames.back().array) ++frames.back().index;
        break;
    }
    return true;
  };
  try {
    j = json::parse(text, track);
  } catch (const json::parse_error& e) {
    // a syntax error is located by line and column (the path of an unfinished value would mislead)
    throw ModelError(file_label, "", "invalid JSON at " + location(text, e.byte) + ": " + reason(e));
  } catch (const json::exception& e) {  // e.g. a number that overflows a double
    throw ModelError(file_label, path_of(frames), "invalid JSON: " + reason(e) + " (numbers must fit a double)");
  }
  return parse_model_spec(j, file_label);
}

ModelSpec load_model_spec(const std::string& path) {
  // only regular files of a model's size: a FIFO would block, /dev/zero would never end
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) throw ModelError(path, "", "cannot open file: " + error_text(errno));
  if (S_ISDIR(st.st_mode)) throw ModelError(path, "", "is a directory, not a model file");
  if (!S_ISREG(st.st_mode)) throw ModelError(path, "", "is not a regular file (a FIFO, socket or device): not a model file");
  if (st.st_size > kMaxModelBytes)
    throw ModelError(path, "", "is " + std::to_string(st.st_size) + " bytes, more than a model file's limit of " +
                                   std::to_string(kMaxModelBytes));
  File f(std::fopen(path.c_str(), "rb"));
  if (!f) throw ModelError(path, "", "cannot open file: " + error_text(errno));
  std::string text;
  char buffer[1 << 16];
  while (const std::size_t n = std::fread(buffer, 1, sizeof buffer, f.get())) {
    text.append(buffer, n);
    if (text.size() > static_cast<std::size_t>(kMaxModelBytes)) throw ModelError(path, "", "grew past a model file's size limit while read");
  }
  if (std::ferror(f.get())) throw ModelError(path, "", "cannot read file: " + error_text(errno));
  return parse_model_spec_text(text, path);
}

nlohmann::json to_json(const ModelSpec& spec) { return nlohmann::json(write_struct(spec)); }

void save_model_spec(const ModelSpec& spec, const std::string& path) {
  std::string text;
  try {
    print(write_struct(spec), text);
  } catch (const ojson::exception& e) {  // e.g. a name that is not valid UTF-8
    throw std::runtime_error(path + ": cannot save the model: " + e.what());
  }
  write_file_atomically(path, text + "\n");
}

}  // namespace codyna
