#include "gui/scene3d.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <cstdio>
#include <limits>

#include "study/tools.hpp"

namespace codyna::gui {

namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Affine3d toAffine(const SE3& X) {
  Eigen::Affine3d A = Eigen::Affine3d::Identity();
  A.linear() = X.R;
  A.translation() = X.p;
  return A;
}

Eigen::Affine3d toAffine(const FrameSpec& F) {
  Eigen::Affine3d A = Eigen::Affine3d::Identity();
  A.linear() = F.rotation;
  A.translation() = F.position;
  return A;
}

// unit cylinder from a to b with the given radius
Eigen::Affine3d segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) {
  const Eigen::Vector3d d = b - a;
  const double len = d.norm();
  Eigen::Affine3d A = Eigen::Affine3d::Identity();
  A.translation() = 0.5 * (a + b);
  if (len > 0) A.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), d / len).toRotationMatrix();
  A.linear() = A.linear() * Eigen::Vector3d(radius, radius, len).asDiagonal();
  return A;
}

// arrow item (unit arrow spans z in [-0.5, 0.5]) centred at p along unit axis a
// (thickness scales the unit arrow's cross-section, like its length for an ordinary arrow)
Eigen::Affine3d arrowAt(const Eigen::Vector3d& p, const Eigen::Vector3d& a, double length, double thickness) {
  Eigen::Affine3d A = Eigen::Affine3d::Identity();
  A.translation() = p;
  A.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), a.normalized()).toRotationMatrix() *
               Eigen::Vector3d(thickness, thickness, length).asDiagonal();
  return A;
}

// box around a unit primitive
Eigen::AlignedBox3d primBox(Prim p) {
  switch (p) {
    case Prim::Box: return {Eigen::Vector3d::Constant(-0.5), Eigen::Vector3d::Constant(0.5)};
    case Prim::Cylinder: return {Eigen::Vector3d(-1, -1, -0.5), Eigen::Vector3d(1, 1, 0.5)};
    case Prim::Sphere: return {Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1)};
    case Prim::Cone: return {Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(1, 1, 1)};
    case Prim::Arrow: return {Eigen::Vector3d(-0.1, -0.1, -0.5), Eigen::Vector3d(0.1, 0.1, 0.5)};
    case Prim::Triad: return {Eigen::Vector3d::Constant(-0.1), Eigen::Vector3d::Constant(1)};
  }
  return {Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1)};
}

std::array<Eigen::Vector3d, 8> corners(Prim p, const Eigen::Affine3d& T) {
  const Eigen::AlignedBox3d b = primBox(p);
  std::array<Eigen::Vector3d, 8> c;
  for (int k = 0; k < 8; ++k) c[k] = T * b.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k));
  return c;
}

// a horizontal direction for "front": world z unless up is (nearly) z, then -y
Eigen::Vector3d frontFor(const Eigen::Vector3d& up) {
  Eigen::Vector3d pref = std::abs(up.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d(0, -1, 0);
  return (pref - pref.dot(up) * up).normalized();
}

// 1, 2 or 5 times a power of ten, at least x
double niceStep(double x) {
  const double e = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * e >= x * (1 - 1e-9)) return m * e;
  return 10 * e;
}

const std::array<Eigen::Vector4f, 6> kPalette = {{
    {0.25f, 0.45f, 0.80f, 1.0f},
    {0.90f, 0.55f, 0.15f, 1.0f},
    {0.25f, 0.65f, 0.30f, 1.0f},
    {0.75f, 0.25f, 0.25f, 1.0f},
    {0.55f, 0.35f, 0.70f, 1.0f},
    {0.20f, 0.60f, 0.65f, 1.0f},
}};


}  // namespace

// ---- meshes ----

void Mesh::addVertex(const Eigen::Vector3f& p, const Eigen::Vector3f& n, const Eigen::Vector3f& c) {
  data.insert(data.end(), {p.x(), p.y(), p.z(), n.x(), n.y(), n.z(), c.x(), c.y(), c.z()});
}

void Mesh::append(const Mesh& other, const Eigen::Affine3f& T, const Eigen::Vector3f& color) {
  const Eigen::Matrix3f N = T.linear().inverse().transpose();
  for (int v = 0; v < other.vertexCount(); ++v) {
    const float* s = &other.data[static_cast<size_t>(v) * kStride];
    const Eigen::Vector3f p = T * Eigen::Vector3f(s[0], s[1], s[2]);
    const Eigen::Vector3f n = (N * Eigen::Vector3f(s[3], s[4], s[5])).normalized();
    addVertex(p, n, color.x() >= 0 ? color : Eigen::Vector3f(s[6], s[7], s[8]));
  }
}

Mesh unitBox() {
  Mesh m;
  const Eigen::Vector3f white(1, 1, 1);
  for (int axis = 0; axis < 3; ++axis) {
    for (int sgn : {-1, 1}) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = static_cast<float>(sgn);
      // two in-face directions, ordered so that u x v = n (counter-clockwise from outside)
      Eigen::Vector3f u = Eigen::Vector3f::Zero(), v;
      u[(axis + 1) % 3] = 1;
      v = n.cross(u);
      const Eigen::Vector3f c = 0.5f * n;
      const Eigen::Vector3f q[4] = {c - 0.5f * u - 0.5f * v, c + 0.5f * u - 0.5f * v, c + 0.5f * u + 0.5f * v,
                                    c - 0.5f * u + 0.5f * v};
      for (int k : {0, 1, 2, 0, 2, 3}) m.addVertex(q[k], n, white);
    }
  }
  return m;
}

Mesh unitCylinder(int segments) {
  Mesh m;
  const Eigen::Vector3f white(1, 1, 1), up(0, 0, 1), down(0, 0, -1);
  for (int i = 0; i < segments; ++i) {
    const float a0 = static_cast<float>(2 * kPi * i / segments), a1 = static_cast<float>(2 * kPi * (i + 1) / segments);
    const Eigen::Vector3f n0(std::cos(a0), std::sin(a0), 0), n1(std::cos(a1), std::sin(a1), 0);
    const Eigen::Vector3f b0 = n0 + 0.5f * down, b1 = n1 + 0.5f * down, t0 = n0 + 0.5f * up, t1 = n1 + 0.5f * up;
    m.addVertex(b0, n0, white), m.addVertex(b1, n1, white), m.addVertex(t1, n1, white);
    m.addVertex(b0, n0, white), m.addVertex(t1, n1, white), m.addVertex(t0, n0, white);
    m.addVertex(0.5f * up, up, white), m.addVertex(t0, up, white), m.addVertex(t1, up, white);
    m.addVertex(0.5f * down, down, white), m.addVertex(b1, down, white), m.addVertex(b0, down, white);
  }
  return m;
}

Mesh unitSphere(int segments, int rings) {
  Mesh m;
  const Eigen::Vector3f white(1, 1, 1);
  auto at = [&](int i, int j) {
    const double th = kPi * j / rings, ph = 2 * kPi * i / segments;
    return Eigen::Vector3f(static_cast<float>(std::sin(th) * std::cos(ph)), static_cast<float>(std::sin(th) * std::sin(ph)),
                           static_cast<float>(std::cos(th)));
  };
  for (int j = 0; j < rings; ++j) {
    for (int i = 0; i < segments; ++i) {
      const Eigen::Vector3f a = at(i, j), b = at(i, j + 1), c = at(i + 1, j + 1), d = at(i + 1, j);
      if (j > 0) m.addVertex(a, a, white), m.addVertex(b, b, white), m.addVertex(d, d, white);
      if (j < rings - 1) m.addVertex(b, b, white), m.addVertex(c, c, white), m.addVertex(d, d, white);
    }
  }
  return m;
}

Mesh unitCone(int segments) {
  Mesh m;
  const Eigen::Vector3f white(1, 1, 1), apex(0, 0, 1), down(0, 0, -1);
  const float s = static_cast<float>(1 / std::sqrt(2.0));
  for (int i = 0; i < segments; ++i) {
    const float a0 = static_cast<float>(2 * kPi * i / segments), a1 = static_cast<float>(2 * kPi * (i + 1) / segments);
    const float am = 0.5f * (a0 + a1);
    const Eigen::Vector3f p0(std::cos(a0), std::sin(a0), 0), p1(std::cos(a1), std::sin(a1), 0);
    m.addVertex(p0, Eigen::Vector3f(s * std::cos(a0), s * std::sin(a0), s), white);
    m.addVertex(p1, Eigen::Vector3f(s * std::cos(a1), s * std::sin(a1), s), white);
    m.addVertex(apex, Eigen::Vector3f(s * std::cos(am), s * std::sin(am), s), white);
    m.addVertex(Eigen::Vector3f::Zero(), down, white), m.addVertex(p1, down, white), m.addVertex(p0, down, white);
  }
  return m;
}

Mesh arrowMesh(int segments) {
  const Mesh cyl = unitCylinder(segments), cone = unitCone(segments);
  Mesh m;
  const float shaft = 0.78f;  // z from -0.5 to 0.28, then the head
  Eigen::Affine3f T = Eigen::Affine3f::Identity();
  T.translate(Eigen::Vector3f(0, 0, -0.5f + 0.5f * shaft));
  T.scale(Eigen::Vector3f(0.022f, 0.022f, shaft));
  m.append(cyl, T);
  T = Eigen::Affine3f::Identity();
  T.translate(Eigen::Vector3f(0, 0, -0.5f + shaft));
  T.scale(Eigen::Vector3f(0.06f, 0.06f, 1.0f - shaft));
  m.append(cone, T);
  return m;
}

Mesh triadMesh(int segments) {
  const Mesh arrow = arrowMesh(segments);
  Mesh m;
  const Eigen::Vector3f colors[3] = {{0.90f, 0.15f, 0.15f}, {0.15f, 0.72f, 0.15f}, {0.15f, 0.30f, 0.95f}};
  const Eigen::Matrix3f rot[3] = {
      Eigen::AngleAxisf(static_cast<float>(kPi / 2), Eigen::Vector3f::UnitY()).toRotationMatrix(),
      Eigen::AngleAxisf(static_cast<float>(-kPi / 2), Eigen::Vector3f::UnitX()).toRotationMatrix(),
      Eigen::Matrix3f::Identity()};
  for (int k = 0; k < 3; ++k) {
    Eigen::Affine3f T = Eigen::Affine3f::Identity();
    T.linear() = rot[k] * Eigen::Vector3f(1.4f, 1.4f, 1.0f).asDiagonal();  // thicker than a joint axis, length 1
    T.translation() = rot[k] * Eigen::Vector3f(0, 0, 0.5f);
    m.append(arrow, T, colors[k]);
  }
  return m;
}

// ---- picking ----

double intersect(Prim prim, const Eigen::Affine3d& world, const Ray& ray) {
  if (std::abs(world.linear().determinant()) < 1e-30) return -1;
  const Eigen::Affine3d inv = world.inverse(Eigen::Affine);
  const Eigen::Vector3d o = inv * ray.origin, d = inv.linear() * ray.dir;
  constexpr double inf = std::numeric_limits<double>::infinity();
  switch (prim) {
    case Prim::Box: {
      double t0 = -inf, t1 = inf;
      for (int k = 0; k < 3; ++k) {
        if (std::abs(d[k]) < 1e-300) {
          if (std::abs(o[k]) > 0.5) return -1;
          continue;
        }
        double a = (-0.5 - o[k]) / d[k], b = (0.5 - o[k]) / d[k];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a), t1 = std::min(t1, b);
      }
      if (t0 > t1 || t1 < 0) return -1;
      return std::max(t0, 0.0);
    }
    case Prim::Sphere: {
      const double a = d.dot(d), b = 2 * o.dot(d), c = o.dot(o) - 1;
      const double disc = b * b - 4 * a * c;
      if (disc < 0) return -1;
      const double s = std::sqrt(disc), t0 = (-b - s) / (2 * a), t1 = (-b + s) / (2 * a);
      if (t1 < 0) return -1;
      return std::max(t0, 0.0);
    }
    case Prim::Cylinder: {
      double best = inf;
      if (o.head<2>().squaredNorm() <= 1 && std::abs(o.z()) <= 0.5) return 0;  // starts inside
      const double a = d.x() * d.x() + d.y() * d.y(), b = 2 * (o.x() * d.x() + o.y() * d.y()),
                   c = o.x() * o.x() + o.y() * o.y() - 1;
      if (a > 1e-300) {
        const double disc = b * b - 4 * a * c;
        if (disc >= 0) {
          for (double t : {(-b - std::sqrt(disc)) / (2 * a), (-b + std::sqrt(disc)) / (2 * a)})
            if (t >= 0 && std::abs(o.z() + t * d.z()) <= 0.5) best = std::min(best, t);
        }
      }
      if (std::abs(d.z()) > 1e-300) {
        for (double zc : {-0.5, 0.5}) {
          const double t = (zc - o.z()) / d.z();
          if (t >= 0 && (o.head<2>() + t * d.head<2>()).squaredNorm() <= 1) best = std::min(best, t);
        }
      }
      return best < inf ? best : -1;
    }
    default:
      return -1;
  }
}

// ---- scene ----

void Scene::build(const Model* model, const std::vector<int>& held) {
  model_ = model;
  items_.clear();
  paths_.clear();
  up_ = Eigen::Vector3d::UnitY();
  length_ = 1.0;
  if (!model) {
    grid_center_.setZero();
    grid_half_ = 2.0, grid_step_ = 0.5;
    base_grid_center_ = grid_center_;
    base_grid_half_ = grid_half_, base_grid_step_ = grid_step_;
    return;
  }
  const Model& m = *model;
  if (m.has_gravity && m.gravity.norm() > 0) up_ = -m.gravity.normalized();

  codyna::StudyPoses poses(m);
  const std::vector<codyna::SE3>& oMi = poses.at(m.q0);

  // declared shapes
  std::vector<bool> has_shapes(m.nbodies, false);
  for (int i = 1; i < m.nbodies; ++i) {
    const int k = m.body_spec_index[i];
    if (k < 0 || k >= static_cast<int>(m.spec.bodies.size())) continue;
    for (const ShapeSpec& s : m.spec.bodies[k].shapes) {
      Item it;
      it.body = i;
      it.color = s.color.cast<float>();
      const Eigen::Affine3d F = toAffine(s.frame);
      switch (s.type) {
        case ShapeType::Box:
          it.prim = Prim::Box;
          it.local = F * Eigen::Scaling(s.size.cwiseMax(1e-9));
          break;
        case ShapeType::Cylinder:
          it.prim = Prim::Cylinder;
          it.local = F * Eigen::Scaling(s.radius, s.radius, s.length);
          break;
        case ShapeType::Sphere:
          it.prim = Prim::Sphere;
          it.local = F * Eigen::Scaling(s.radius, s.radius, s.radius);
          break;
      }
      items_.push_back(it);
      has_shapes[i] = true;
    }
  }

  // a provisional size from where the joints are, for bodies that have nothing else
  Eigen::AlignedBox3d joints_box;
  joints_box.extend(Eigen::Vector3d::Zero());
  for (int i = 1; i < m.nbodies; ++i) {
    joints_box.extend(oMi[i].p);
    joints_box.extend(oMi[i].act_point(m.com[i]));
  }
  length_ = std::max(joints_box.diagonal().norm(), 1e-3);
  for (int i = 1; i < m.nbodies; ++i)
    if (!has_shapes[i]) addDefaultLook(i);

  update(oMi);
  const Eigen::AlignedBox3d box = bounds();
  length_ = std::max(box.diagonal().norm(), 1e-6);
  const double L = length_;

  // body sizes in their own frames, for overlay sizes
  std::vector<double> size(m.nbodies, 0.0);
  for (const Item& it : items_)
    for (const auto& c : corners(it.prim, it.local)) size[it.body] = std::max(size[it.body], c.norm());
  for (int i = 1; i < m.nbodies; ++i) {
    size[i] = std::max(size[i], m.joints[i].X_CM.p.norm());
    for (int c = i + 1; c < m.nbodies; ++c)
      if (m.parent[c] == i) size[i] = std::max(size[i], m.joints[c].X_PF.p.norm());
  }

  // ground anchors where joints and loop closures meet the ground
  auto anchor = [&](const Eigen::Vector3d& p, const Eigen::Matrix3d& R, double s) {
    Item it;
    it.kind = ItemKind::Anchor;
    it.prim = Prim::Box;
    it.body = 0;
    it.local = Eigen::Affine3d::Identity();
    it.local.translation() = p;
    it.local.linear() = R * s;
    it.color = {0.36f, 0.37f, 0.40f, 1.0f};
    items_.push_back(it);
  };
  // a block a little larger than the ball of the body at that point, so that it shows
  auto anchorSize = [&](int body, const Eigen::Vector3d& p_body) {
    double ball = 0;
    for (const Item& it : items_)
      if (it.kind == ItemKind::Shape && it.body == body && it.prim == Prim::Sphere &&
          (it.local.translation() - p_body).norm() < 1e-9)
        ball = std::max(ball, it.local.linear().col(0).norm());
    return std::clamp(std::max(2.4 * ball, 0.04 * L), 0.01 * L, 0.1 * L);
  };
  for (int i = 1; i < m.nbodies; ++i)
    if (m.parent[i] == 0 && std::find(held.begin(), held.end(), i) == held.end()) anchor(m.joints[i].X_PF.p, m.joints[i].X_PF.R, anchorSize(i, m.joints[i].X_CM.p));
  for (const ConstraintModel& c : m.constraints) {
    if (c.type == ConstraintType::Coupler) continue;  // couples coordinates, at no point
    if (c.type == ConstraintType::RollingBall || c.type == ConstraintType::RollingDisc)
      continue;  // point_a is a point of a plane: drawn as its contact
    if (c.body_a == 0) anchor(c.point_a, Eigen::Matrix3d::Identity(), anchorSize(c.body_b, c.point_b));
    if (c.body_b == 0) anchor(c.point_b, Eigen::Matrix3d::Identity(), anchorSize(c.body_a, c.point_a));
  }
  for (const SpringDamperModel& sp : m.springs) {
    if (sp.body_a == 0) anchor(sp.point_a, Eigen::Matrix3d::Identity(), 0.5 * anchorSize(sp.body_b, sp.point_b));
    if (sp.body_b == 0) anchor(sp.point_b, Eigen::Matrix3d::Identity(), 0.5 * anchorSize(sp.body_a, sp.point_a));
  }

  // springs
  for (const SpringDamperModel& s : m.springs) {
    Item it;
    it.kind = ItemKind::Spring;
    it.prim = Prim::Cylinder;
    it.body = s.body_a, it.body_b = s.body_b;
    it.point_a = s.point_a, it.point_b = s.point_b;
    it.span = Span::Whole;
    it.thickness = 0.004 * L;
    it.color = {0.30f, 0.30f, 0.32f, 1.0f};
    items_.push_back(it);
  }
  addElements(oMi);

  // joint axes (on the parent's joint frame F; a universal's second axis on the child's M)
  const Eigen::Vector4f revolute_color{0.95f, 0.80f, 0.10f, 1.0f}, slide_color{0.85f, 0.20f, 0.75f, 1.0f};
  for (int i = 1; i < m.nbodies; ++i) {
    const JointModel& j = m.joints[i];
    const double thick = std::clamp(0.6 * size[i], 0.06 * L, 0.2 * L);
    double len = thick;
    if (j.type == JointType::Prismatic || j.type == JointType::Cylindrical)
      len = std::min(std::max(2.5 * size[i], 0.4 * L), L);  // a rail that reaches out of the slider
    auto axis = [&](int body, const SE3& X, const Eigen::Vector3d& a, const Eigen::Vector4f& color) {
      Item it;
      it.kind = ItemKind::Axis;
      it.prim = Prim::Arrow;
      it.body = body;
      it.local = arrowAt(X.p, X.R * a, len, thick);
      it.color = color;
      items_.push_back(it);
    };
    switch (j.type) {
      case JointType::Revolute: axis(j.parent, j.X_PF, j.axis, revolute_color); break;
      case JointType::Prismatic: axis(j.parent, j.X_PF, j.axis, slide_color); break;
      case JointType::Cylindrical:
        axis(j.parent, j.X_PF, j.axis, slide_color);
        break;
      case JointType::Universal:
        axis(j.parent, j.X_PF, j.axis, revolute_color);
        axis(i, j.X_CM, j.axis2, revolute_color);
        break;
      case JointType::Spherical: {  // a ball at the joint's centre
        Item it;
        it.kind = ItemKind::Axis;
        it.prim = Prim::Sphere;
        it.body = j.parent;
        it.local = Eigen::Translation3d(j.X_PF.p) * Eigen::Scaling(0.25 * thick);
        it.color = revolute_color;
        items_.push_back(it);
        break;
      }
      case JointType::Planar: axis(j.parent, j.X_PF, Eigen::Vector3d::UnitZ(), slide_color); break;  // the plane's normal
      default: break;  // fixed: welded; free: nowhere in particular
    }
  }

  // body frames, and the world frame
  for (int i = 0; i < m.nbodies; ++i) {
    Item it;
    it.kind = ItemKind::Frame;
    it.prim = Prim::Triad;
    it.body = i;
    const double len = i == 0 ? 0.08 * L : std::clamp(0.4 * size[i], 0.03 * L, 0.1 * L);
    it.local = Eigen::Affine3d(Eigen::Scaling(len));
    it.color = {1, 1, 1, 1};
    items_.push_back(it);
  }

  // centres of mass: a small two-tone ball (black and white octants read as the usual symbol
  // at a glance) of one size for all bodies, at com in body coordinates
  for (int i = 1; i < m.nbodies; ++i) {
    if (!(m.mass[i] > 0.0)) continue;
    Item it;
    it.kind = ItemKind::Com;
    it.prim = Prim::Sphere;
    it.body = i;
    it.local = Eigen::Translation3d(m.com[i]) * Eigen::Scaling(0.025 * L);
    it.color = {0.1f, 0.1f, 0.1f, 1.0f};
    items_.push_back(it);
  }

  // the tire forces' scale: a tire's share of the weight (1 kN without gravity) drawn about a
  // quarter of the mechanism's size long, rounded down to 1, 2 or 5 times a power of ten in the
  // legend's unit (kN from 1 kN on)
  tire_force_scale_ = 0.0;
  if (!m.tires.empty()) {
    double total = 0;
    for (int i = 1; i < m.nbodies; ++i) total += m.mass[i];
    double share = m.has_gravity ? total * m.gravity.norm() / static_cast<double>(m.tires.size()) : 0.0;
    if (!(share > 0)) share = 1000.0;
    tire_force_unit_ = share >= 1000.0 ? 1000.0 : 1.0;
    const double per_unit = 0.25 * L / share * tire_force_unit_;  // metres per unit force
    const double decade = std::pow(10.0, std::floor(std::log10(per_unit)));
    double nice = decade;
    for (double f : {2.0, 5.0})
      if (f * decade <= per_unit * (1 + 1e-12)) nice = f * decade;
    tire_force_scale_ = nice / tire_force_unit_;
  }

  update(oMi);
  placeGrid(oMi);
}

std::string Scene::tireForceScaleText() const {
  if (!(tire_force_scale_ > 0)) return {};
  char buf[64];
  std::snprintf(buf, sizeof buf, "1 %s = %.3g m", tire_force_unit_ > 1 ? "kN" : "N", tire_force_scale_ * tire_force_unit_);
  return buf;
}

void Scene::setTireForces(const std::vector<TireContactReport>& contacts) {
  items_.erase(std::remove_if(items_.begin(), items_.end(),
                              [](const Item& it) { return it.kind == ItemKind::TireLoad || it.kind == ItemKind::TireInPlane; }),
               items_.end());
  if (!model_ || !(tire_force_scale_ > 0)) return;
  // one thickness for every arrow (a shaft 0.8 % of the mechanism's size in radius), thinner for a
  // short one, so that a small force is a short thin arrow and not a blob
  const double thick_max = 0.35 * length_;
  auto arrow = [&](ItemKind kind, const TireContactReport& c, const Eigen::Vector3d& F, const Eigen::Vector4f& color) {
    const double len = F.norm() * tire_force_scale_;
    if (!(len > 1e-9 * length_)) return;  // no force, no direction
    Item it;
    it.kind = kind;
    it.prim = Prim::Arrow;
    it.body = 0;
    it.element = c.name;
    it.local = arrowAt(c.point + 0.5 * len * F / F.norm(), F / F.norm(), len, std::min(thick_max, 2.0 * len));
    it.world = it.local;
    it.color = color;
    items_.push_back(it);
  };
  for (const TireContactReport& c : contacts) {
    if (!c.in_contact) continue;
    arrow(ItemKind::TireLoad, c, c.Fz * c.ez, {0.12f, 0.38f, 0.95f, 1.0f});
    arrow(ItemKind::TireInPlane, c, c.Fx * c.ex + c.Fy * c.ey, {0.00f, 0.62f, 0.56f, 1.0f});
  }
}

void Scene::addDefaultLook(int i) {
  const Model& m = *model_;
  const Eigen::Vector3d com = m.com[i];
  const Eigen::Vector3d inboard = m.joints[i].X_CM.p;
  std::vector<Eigen::Vector3d> ends;  // link ends other than the inboard joint
  for (int c = i + 1; c < m.nbodies; ++c)
    if (m.parent[c] == i) ends.push_back(m.joints[c].X_PF.p);
  // a rolling ball or disc on this body (point_b its centre): the ball or the disc itself, not a pin
  // at its centre
  std::vector<const ConstraintModel*> rolling;
  for (const ConstraintModel& c : m.constraints) {
    if (c.type == ConstraintType::Coupler) continue;
    if (c.type == ConstraintType::RollingBall || c.type == ConstraintType::RollingDisc) {
      if (c.body_b == i) rolling.push_back(&c);
      continue;  // point_a is a point of the plane, not a link's end
    }
    if (c.body_a == i) ends.push_back(c.point_a);
    if (c.body_b == i) ends.push_back(c.point_b);
  }
  double extent = (inboard - com).norm();
  for (const auto& e : ends) extent = std::max({extent, (e - com).norm(), (e - inboard).norm()});

  double r_ball;
  // nothing further to connect (a body just added, a free body, the last link of a chain): the solid
  // ellipsoid of the body's mass and inertia, on its principal axes (semi-axis a_k^2 = 5 (I_1 + I_2 +
  // I_3 - 2 I_k) / (2 m)), joined to its joint by a link; a ball of a share of the scene (or of the
  // link) when the inertia does not make one
  Eigen::Affine3d ellipsoid = Eigen::Affine3d::Identity();
  bool has_ellipsoid = false;
  r_ball = extent > 1e-9 ? 0.12 * extent : 0.05 * length_;
  if (ends.empty()) {
    const int k = m.body_spec_index[i];
    const double mass = m.mass[i];
    if (k >= 0 && mass > 0) {
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m.spec.bodies[static_cast<std::size_t>(k)].inertia);
      const Eigen::Vector3d I = eig.eigenvalues();
      Eigen::Vector3d a;
      for (int c = 0; c < 3; ++c) a[c] = std::sqrt(std::max(0.0, 2.5 * (I.sum() - 2 * I[c]) / mass));
      if (eig.info() == Eigen::Success && a.maxCoeff() > 0) {
        r_ball = a.maxCoeff();
        ellipsoid.translation() = com;
        Eigen::Matrix3d R = eig.eigenvectors();
        if (R.determinant() < 0) R.col(2) *= -1;  // a rotation: a mirror would turn the triangles inside out
        ellipsoid.linear() = R * a.cwiseMax(1e-3 * r_ball).asDiagonal();  // a flat disc keeps a thickness
        has_ellipsoid = true;
      }
    }
  }
  const double r_link = 0.3 * (extent > 1e-9 ? std::min(r_ball, 0.12 * extent) : r_ball);
  const Eigen::Vector4f color = kPalette[static_cast<size_t>(i - 1) % kPalette.size()];

  auto add = [&](Prim p, const Eigen::Affine3d& local, const Eigen::Vector4f& c) {
    Item it;
    it.body = i;
    it.prim = p;
    it.local = local;
    it.color = c;
    items_.push_back(it);
  };
  Eigen::Affine3d ball = Eigen::Affine3d::Identity();
  ball.translation() = com;
  ball.linear() *= r_ball;
  add(Prim::Sphere, has_ellipsoid ? ellipsoid : ball, color);
  const Eigen::Vector4f pin{0.5f, 0.5f, 0.55f, 1.0f};
  for (const auto& e : ends) {
    if ((e - inboard).norm() < 1e-9) continue;
    add(Prim::Cylinder, segment(inboard, e, r_link), color);
    Eigen::Affine3d knob = Eigen::Affine3d::Identity();
    knob.translation() = e;
    knob.linear() *= 1.6 * r_link;
    add(Prim::Sphere, knob, pin);
  }
  if ((com - inboard).norm() > r_ball) add(Prim::Cylinder, segment(inboard, com, r_link), color);
  if (extent > 1e-9) {
    Eigen::Affine3d knob = Eigen::Affine3d::Identity();
    knob.translation() = inboard;
    knob.linear() *= 1.6 * r_link;
    add(Prim::Sphere, knob, pin);
  }
  for (const ConstraintModel* c : rolling) {
    if (c->type == ConstraintType::RollingDisc) {  // a thin cylinder about the axle
      Eigen::Affine3d T = Eigen::Affine3d::Identity();
      T.translation() = c->point_b;
      T.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), c->axis_b).toRotationMatrix() *
                   Eigen::Vector3d(c->radius, c->radius, 0.1 * c->radius).asDiagonal();
      add(Prim::Cylinder, T, color);
    } else add(Prim::Sphere, Eigen::Translation3d(c->point_b) * Eigen::Scaling(c->radius), color);
  }
  // a tire on this body: the tire itself, dark, its unloaded radius about its spin axis at its centre
  // (0.35 of the radius wide)
  for (const TireModel& t : m.tires) {
    if (t.body != i || !(t.unloaded_radius > 0)) continue;
    Eigen::Affine3d T = Eigen::Affine3d::Identity();
    T.translation() = t.center;
    const double r = t.unloaded_radius;
    T.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), t.axis).toRotationMatrix() *
                 Eigen::Vector3d(r, r, 0.35 * r).asDiagonal();
    add(Prim::Cylinder, T, {0.16f, 0.16f, 0.18f, 1.0f});
  }
}

Eigen::Affine3d spanTransform(const Item& it, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d d = b - a;
  const double len = d.norm();
  const Eigen::Vector3d u = len > 0 ? Eigen::Vector3d(d / len) : Eigen::Vector3d::Zero();
  switch (it.span) {
    case Span::Barrel: {
      const double l = std::min(std::max(it.span_a, len - it.span_b), len);
      return segment(a, a + l * u, it.thickness);
    }
    case Span::Rod: return segment(b - std::min(it.span_b, len) * u, b, it.thickness);
    case Span::Dash: return segment(a + it.span_a * d, a + it.span_b * d, it.thickness);
    default: return segment(a, b, it.thickness);
  }
}

// the elements that act between bodies or on joints, drawn as they act (docs/gui.md, "3-D view")
void Scene::addElements(const std::vector<SE3>& oMi) {
  const Model& m = *model_;
  const double L = length_;
  auto twoPoint = [&](ItemKind kind, const std::string& name, int body_a, const Eigen::Vector3d& pa, int body_b,
                      const Eigen::Vector3d& pb, Span span, double radius, const Eigen::Vector4f& color) {
    Item it;
    it.kind = kind;
    it.prim = Prim::Cylinder;
    it.element = name;
    it.body = body_a, it.body_b = body_b;
    it.point_a = pa, it.point_b = pb;
    it.span = span;
    it.thickness = radius;
    it.color = color;
    items_.push_back(it);
    return &items_.back();
  };
  auto local = [&](ItemKind kind, const std::string& name, int body, Prim prim, const Eigen::Affine3d& T,
                   const Eigen::Vector4f& color) {
    Item it;
    it.kind = kind;
    it.prim = prim;
    it.element = name;
    it.body = body;
    it.local = T;
    it.color = color;
    items_.push_back(it);
    return &items_.back();
  };
  // a flat disc of radius r about unit axis a at p
  auto disc = [](const Eigen::Vector3d& p, const Eigen::Vector3d& a, double r, double h) {
    Eigen::Affine3d T = Eigen::Affine3d::Identity();
    T.translation() = p;
    T.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), a).toRotationMatrix() *
                 Eigen::Vector3d(r, r, h).asDiagonal();
    return T;
  };
  // the body whose joint owns velocity index iv (0 if none)
  auto jointOf = [&](int iv) {
    for (int i = 1; i < m.nbodies; ++i)
      if (iv >= m.joints[i].idx_v && iv < m.joints[i].idx_v + m.joints[i].nv) return i;
    return 0;
  };

  // two-point actuators: a barrel (dark orange) on body_a's point and a rod (light steel) from body_b's,
  // each 0.6 of the length at q0, so that they slide in each other as the length changes
  for (const ActuatorModel& a : m.actuators) {
    if (a.type != ActuatorType::LineForce) continue;
    const double d0 = (oMi[a.body_b].act_point(a.point_b) - oMi[a.body].act_point(a.point)).norm();
    const double l0 = d0 > 1e-9 ? 0.6 * d0 : 0.1 * L;
    Item* barrel = twoPoint(ItemKind::LineForce, a.name, a.body, a.point, a.body_b, a.point_b, Span::Barrel, 0.014 * L,
                            {0.85f, 0.40f, 0.12f, 1.0f});
    barrel->span_a = l0, barrel->span_b = l0;
    Item* rod = twoPoint(ItemKind::LineForce, a.name, a.body, a.point, a.body_b, a.point_b, Span::Rod, 0.007 * L,
                         {0.82f, 0.84f, 0.88f, 1.0f});
    rod->span_a = l0, rod->span_b = l0;
  }

  // bushings: an amber block at each frame (turned with it), the line between the origins when apart
  for (const BushingModel& b : m.bushings) {
    const double s = 0.035 * L;
    const Eigen::Vector4f amber{0.95f, 0.62f, 0.08f, 1.0f};
    local(ItemKind::Bushing, b.name, b.body_a, Prim::Box, toAffine(b.X_a) * Eigen::Scaling(s), amber);
    local(ItemKind::Bushing, b.name, b.body_b, Prim::Box, toAffine(b.X_b) * Eigen::Scaling(0.7 * s),
          {0.20f, 0.20f, 0.22f, 1.0f});
    twoPoint(ItemKind::Bushing, b.name, b.body_a, b.X_a.p, b.body_b, b.X_b.p, Span::Whole, 0.006 * L, amber);
  }

  // couplers: violet dashes from each coupled joint's frame F to the next one's, a dot on each
  for (const ConstraintModel& c : m.constraints) {
    if (c.type != ConstraintType::Coupler) continue;
    const Eigen::Vector4f violet{0.40f, 0.25f, 0.90f, 1.0f};
    int prev = 0;
    for (int k = 0; k < c.ncoupled; ++k) {
      const int j = jointOf(c.iv[k]);
      if (j == 0) continue;
      const JointModel& J = m.joints[j];
      local(ItemKind::Coupler, c.name, J.parent, Prim::Sphere,
            Eigen::Translation3d(J.X_PF.p) * Eigen::Scaling(0.015 * L), violet);
      if (prev > 0) {
        const JointModel& P = m.joints[prev];
        constexpr int kDashes = 7;  // dash, gap, ..., dash: 2 kDashes - 1 equal parts
        for (int d = 0; d < kDashes; ++d) {
          Item* it = twoPoint(ItemKind::Coupler, c.name, P.parent, P.X_PF.p, J.parent, J.X_PF.p, Span::Dash,
                              0.004 * L, violet);
          it->span_a = 2.0 * d / (2 * kDashes - 1), it->span_b = (2.0 * d + 1) / (2 * kDashes - 1);
        }
      }
      prev = j;
    }
  }

  // rolling balls and discs: a thin green disc of the plane (turned with body_a) at the contact, the
  // centre less the radius along the plane's normal (a disc: along its contact direction), and a
  // dark dot at the contact; placed by update()
  for (const ConstraintModel& c : m.constraints) {
    if (c.type != ConstraintType::RollingBall && c.type != ConstraintType::RollingDisc) continue;
    const double r = c.radius;
    const Eigen::Matrix3d Rn = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), c.axis_a).toRotationMatrix();
    const double patch = std::clamp(3.0 * r, 0.02 * L, 0.2 * L), h = std::min(0.004 * L, 0.2 * patch);
    const double dot_r = std::clamp(0.3 * r, 0.004 * L, 0.02 * L);
    for (const bool dot : {false, true}) {
      const Eigen::Vector3d scale = dot ? Eigen::Vector3d::Constant(dot_r) : Eigen::Vector3d(patch, patch, h);
      Eigen::Affine3d T = Eigen::Affine3d::Identity();
      T.linear() = Rn * scale.asDiagonal();
      Item* it = local(ItemKind::Contact, c.name, c.body_a, dot ? Prim::Sphere : Prim::Cylinder, T,
                       dot ? Eigen::Vector4f(0.12f, 0.12f, 0.14f, 1.0f) : Eigen::Vector4f(0.25f, 0.72f, 0.45f, 1.0f));
      it->span = Span::Contact;
      it->body_b = c.body_b;
      it->point_b = c.point_b;
      it->normal = c.axis_a;
      it->depth = r;
      if (c.type == ConstraintType::RollingDisc) it->axle = c.axis_b;
    }
  }

  // motion inputs: a cyan arrow (thicker than a joint axis) along the driven joint's axis from its
  // frame F, and a disc around it
  for (const int k : m.motions) {
    const ActuatorModel& a = m.actuators[static_cast<size_t>(k)];
    const int j = jointOf(a.iv);
    if (j == 0) continue;
    const JointModel& J = m.joints[j];
    const Eigen::Vector3d axis = J.X_PF.R * J.axis;
    const Eigen::Vector4f cyan{0.0f, 0.78f, 0.92f, 1.0f};
    const double len = 0.3 * L;
    local(ItemKind::Motion, a.name, J.parent, Prim::Arrow, arrowAt(J.X_PF.p + 0.5 * len * axis, axis, len, 1.3 * len),
          cyan);
    local(ItemKind::Motion, a.name, J.parent, Prim::Cylinder, disc(J.X_PF.p, axis, 0.05 * L, 0.006 * L), cyan);
  }

  // actuators driven by a mix, coloured by the (first) mix: a body force as an arrow from its point
  // along its direction, a body torque as an arrow along its axis through the centre of mass and a disc
  std::vector<int> mix_rank(m.actuators.size(), -1);
  int nmix = 0;
  for (size_t k = 0; k < m.actuators.size(); ++k)
    if (m.actuators[k].type == ActuatorType::Mix) mix_rank[k] = nmix++;
  const std::array<Eigen::Vector4f, 4> mix_colors = {{
      {0.90f, 0.20f, 0.15f, 1.0f}, {0.15f, 0.45f, 0.90f, 1.0f}, {0.10f, 0.70f, 0.25f, 1.0f}, {0.70f, 0.30f, 0.80f, 1.0f}}};
  for (const ActuatorModel& a : m.actuators) {
    if (a.driven_by.empty()) continue;
    if (a.type != ActuatorType::BodyForce && a.type != ActuatorType::BodyTorque) continue;
    Eigen::Vector4f color{0.35f, 0.35f, 0.40f, 1.0f};  // driven by several mixes: neutral
    if (a.driven_by.size() == 1 && mix_rank[static_cast<size_t>(a.driven_by[0].first)] >= 0) color = mix_colors[static_cast<size_t>(mix_rank[static_cast<size_t>(a.driven_by[0].first)]) % 4];
    const Eigen::Vector3d p = a.type == ActuatorType::BodyForce ? a.point : m.com[a.body];
    const double len = (a.type == ActuatorType::BodyForce ? 0.25 : 0.2) * L;
    Item* it = local(ItemKind::Actuator, a.name, a.body, Prim::Arrow,
                     arrowAt(p + 0.5 * len * a.direction, a.direction, len, 0.6 * len), color);
    it->world_axes = a.in_world;
    if (a.type == ActuatorType::BodyTorque) {
      Item* d = local(ItemKind::Actuator, a.name, a.body, Prim::Cylinder, disc(p, a.direction, 0.06 * L, 0.005 * L),
                      color);
      d->world_axes = a.in_world;
    }
  }

  // body forces (constant loads, shown always): an arrow from the point along the force, and for a
  // torque an arrow along it through the point with a disc around it; dark red
  const Eigen::Vector4f load{0.62f, 0.10f, 0.10f, 1.0f};
  for (const BodyForceModel& f : m.body_forces) {
    const double len = 0.2 * L;
    if (f.force.norm() > 0) {
      const Eigen::Vector3d u = f.force.normalized();
      local(ItemKind::Force, f.name, f.body, Prim::Arrow, arrowAt(f.point + 0.5 * len * u, u, len, 0.6 * len), load)
          ->world_axes = f.in_world;
    }
    if (f.torque.norm() > 0) {
      const Eigen::Vector3d u = f.torque.normalized();
      local(ItemKind::Force, f.name, f.body, Prim::Arrow, arrowAt(f.point + 0.5 * len * u, u, len, 0.6 * len), load)
          ->world_axes = f.in_world;
      local(ItemKind::Force, f.name, f.body, Prim::Cylinder, disc(f.point, u, 0.05 * L, 0.005 * L), load)->world_axes = f.in_world;
    }
  }
}

void Scene::update(const std::vector<SE3>& oMi) {
  for (Item& it : items_) {
    if (it.kind == ItemKind::TireLoad || it.kind == ItemKind::TireInPlane) continue;  // placed in world axes
    if (it.span == Span::Contact) {
      const SE3& A = oMi[it.body];
      Eigen::Affine3d X = Eigen::Affine3d::Identity();
      X.linear() = A.R;
      Eigen::Vector3d d = A.R * it.normal;
      if (!it.axle.isZero()) {  // a disc: the normal's part normal to its axle (lying flat: the normal)
        const Eigen::Vector3d a = oMi[it.body_b].R * it.axle, m = d - d.dot(a) * a;
        if (m.norm() > 1e-9) d = m.normalized();
      }
      X.translation() = oMi[it.body_b].act_point(it.point_b) - it.depth * d;
      it.world = X * it.local;
      continue;
    }
    if (it.span != Span::None) {
      it.world = spanTransform(it, oMi[it.body].act_point(it.point_a), oMi[it.body_b].act_point(it.point_b));
      continue;
    }
    if (it.world_axes) {
      it.world = it.local;
      it.world.translation() = oMi[it.body].act_point(it.local.translation());
      continue;
    }
    it.world = toAffine(oMi[it.body]) * it.local;
  }
}

Eigen::AlignedBox3d Scene::bounds() const {
  Eigen::AlignedBox3d box;
  for (const Item& it : items_) {
    if (it.kind != ItemKind::Shape && it.kind != ItemKind::Anchor && it.kind != ItemKind::Spring &&
        it.kind != ItemKind::LineForce && it.kind != ItemKind::Bushing)
      continue;
    for (const auto& c : corners(it.prim, it.world)) box.extend(c);
  }
  if (box.isEmpty()) {
    box.extend(Eigen::Vector3d::Constant(-1));
    box.extend(Eigen::Vector3d::Constant(1));
  }
  return box;
}

Eigen::AlignedBox3d Scene::viewBounds(bool overlays) const {
  Eigen::AlignedBox3d box = bounds();
  if (!model_) return box;
  // overlays: frames, joint axes and the elements' marks (motion inputs, mixed actuators, couplers)
  if (overlays)
    for (const Item& it : items_)
      if (it.kind == ItemKind::Axis || it.kind == ItemKind::Frame || it.kind == ItemKind::Motion ||
          it.kind == ItemKind::Actuator || it.kind == ItemKind::Coupler)
        for (const auto& c : corners(it.prim, it.world)) box.extend(c);
  const double h = grid_center_.dot(up_);
  Eigen::AlignedBox3d out = box;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d c = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k));
    out.extend(c - (c.dot(up_) - h) * up_);
  }
  return out;
}

int Scene::pick(const Ray& ray, double* distance) const {
  int best = -1;
  double best_t = std::numeric_limits<double>::infinity();
  for (const Item& it : items_) {
    if (it.kind != ItemKind::Shape && it.kind != ItemKind::Anchor) continue;  // anchors hide what is behind them
    const double t = intersect(it.prim, it.world, ray);
    // ties go to the later item, as with the depth test (GL_LEQUAL) in drawing order
    if (t >= 0 && t <= best_t) best_t = t, best = it.body;
  }
  if (distance) *distance = best >= 0 ? best_t : -1;
  return best;
}

bool Scene::bodyAnchor(int body, Eigen::Vector3d* point) const {
  double best = -1;
  for (const Item& it : items_) {
    if (it.kind != ItemKind::Shape || it.body != body) continue;
    const double v = std::abs(it.world.linear().determinant()) * (it.prim == Prim::Box ? 1.0 : kPi);
    if (v > best) best = v, *point = it.world.translation();
  }
  return best >= 0;
}

void Scene::placeGrid(const std::vector<SE3>& oMi) {
  const Model& m = *model_;
  const Eigen::AlignedBox3d box = bounds();
  const double L = length_;
  double low = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 8; ++k) low = std::min(low, box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k)).dot(up_));

  // how far each subtree reaches from its inboard joint, so that the grid
  // stays under the mechanism as it swings (a bound: loops reach less)
  std::vector<double> reach(m.nbodies, 0.0);
  for (const Item& it : items_)
    if (it.kind == ItemKind::Shape && it.body > 0)
      for (const auto& c : corners(it.prim, it.local))
        reach[it.body] = std::max(reach[it.body], (c - m.joints[it.body].X_CM.p).norm());
  for (int i = m.nbodies - 1; i >= 1; --i) {
    const int p = m.parent[i];
    if (p > 0) reach[p] = std::max(reach[p], (m.joints[i].X_PF.p - m.joints[p].X_CM.p).norm() + reach[i]);
  }
  // the lowest point each root subtree can reach: its own geometry exactly as
  // the root joint moves it, deeper subtrees as spheres of their reach
  double bound = low;
  for (int i = 1; i < m.nbodies; ++i) {
    if (m.parent[i] != 0) continue;
    const JointModel& j = m.joints[i];
    const Eigen::Vector3d J = j.X_PF.p, a = j.X_PF.R * j.axis;
    const double a_up = a.dot(up_), across = std::sqrt(std::max(0.0, 1 - a_up * a_up));
    std::function<double(const Eigen::Vector3d&)> lowest;  // lowest height of a point of body i (world, at q0)
    switch (j.type) {
      case JointType::Revolute:
        lowest = [&](const Eigen::Vector3d& x) {
          const double s = (x - J).dot(a);
          return J.dot(up_) + s * a_up - ((x - J) - s * a).norm() * across;
        };
        break;
      case JointType::Fixed:
        lowest = [&](const Eigen::Vector3d& x) { return x.dot(up_); };
        break;
      case JointType::Prismatic:
        if (std::abs(a_up) > 1e-9) continue;  // slides up and down without bound: trust q0
        lowest = [&](const Eigen::Vector3d& x) { return x.dot(up_); };
        break;
      case JointType::Spherical:
      case JointType::Universal:
      case JointType::Cylindrical:
        bound = std::min(bound, J.dot(up_) - reach[i]);
        continue;
      default:
        continue;  // free, planar: no useful bound
    }
    for (const Item& it : items_)
      if (it.kind == ItemKind::Shape && it.body == i)
        for (const auto& c : corners(it.prim, it.world)) bound = std::min(bound, lowest(c));
    for (int c = i + 1; c < m.nbodies; ++c)
      if (m.parent[c] == i) bound = std::min(bound, lowest(oMi[i].act_point(m.joints[c].X_PF.p)) - reach[c]);
  }
  // loops keep links from hanging at full reach, so trust the bound less there
  const double slack = m.constraints.empty() ? 1.2 : 0.5;
  const double height = std::min(low, std::max(bound, low - slack * L)) - 0.02 * L;
  // a car on the ground's road plane: paths are drawn on that plane (the grid stays under the
  // mechanism's lowest point)
  path_height_ = std::nan("");
  for (const EffectSpec& e : m.spec.effects) {
    if (e.type != EffectType::Tire || e.road.body != kGroundName || !e.road.surface.empty() || e.road.grid ||
        e.road.profile || e.road.iso8608 || e.road.normal.norm() == 0 || e.road.normal.normalized().dot(up_) < 1 - 1e-9)
      continue;
    path_height_ = e.road.point.dot(up_);
    break;
  }

  // centre under the mechanism, snapped to the grid so that lines go through the world origin
  grid_step_ = niceStep(L / 8);
  const double extent = std::max(0.75 * L, 4 * grid_step_);
  grid_half_ = grid_step_ * std::ceil(extent / grid_step_);
  const Eigen::Vector3d e1 = frontFor(up_), e2 = up_.cross(e1);
  const Eigen::Vector3d c = box.center();
  const double c1 = grid_step_ * std::round(c.dot(e1) / grid_step_), c2 = grid_step_ * std::round(c.dot(e2) / grid_step_);
  grid_center_ = c1 * e1 + c2 * e2 + height * up_;
  base_grid_center_ = grid_center_;
  base_grid_half_ = grid_half_;
  base_grid_step_ = grid_step_;
}

void Scene::setPaths(std::vector<ScenePath> paths) {
  paths_ = std::move(paths);
  grid_center_ = base_grid_center_;
  grid_half_ = base_grid_half_;
  grid_step_ = base_grid_step_;
  const Eigen::Vector3d e1 = frontFor(up_), e2 = up_.cross(e1);
  double lo1 = grid_center_.dot(e1) - grid_half_, hi1 = grid_center_.dot(e1) + grid_half_;
  double lo2 = grid_center_.dot(e2) - grid_half_, hi2 = grid_center_.dot(e2) + grid_half_;
  bool grown = false;
  for (const ScenePath& p : paths_)
    for (const Eigen::Vector3d& x : p.points) {
      if (!x.allFinite()) continue;
      const double a = x.dot(e1), b = x.dot(e2), m = p.width;
      if (a - m < lo1 || a + m > hi1 || b - m < lo2 || b + m > hi2) grown = true;
      lo1 = std::min(lo1, a - m), hi1 = std::max(hi1, a + m);
      lo2 = std::min(lo2, b - m), hi2 = std::max(hi2, b + m);
    }
  if (!grown) return;
  // a square over both, a margin of a tenth, lines at most ~120 each way
  const double half = 0.55 * std::max(hi1 - lo1, hi2 - lo2);
  grid_step_ = std::max(grid_step_, niceStep(half / 60));
  grid_half_ = grid_step_ * std::ceil(half / grid_step_);
  const double c1 = grid_step_ * std::round(0.5 * (lo1 + hi1) / grid_step_), c2 = grid_step_ * std::round(0.5 * (lo2 + hi2) / grid_step_);
  grid_center_ = c1 * e1 + c2 * e2 + grid_center_.dot(up_) * up_;
}

Mesh Scene::pathMesh() const {
  Mesh mesh;
  // just over the road a car rolls on, else over the grid
  const double h = (std::isfinite(path_height_) ? path_height_ : grid_center_.dot(up_)) + 0.003 * length_;
  const auto onGround = [&](const Eigen::Vector3d& x) { return Eigen::Vector3d(x - (x.dot(up_) - h) * up_); };
  const Eigen::Vector3f n = up_.cast<float>();
  static const Mesh cone = unitCone(12);
  for (const ScenePath& p : paths_) {
    if (p.markers) {
      for (const Eigen::Vector3d& x : p.points) {
        if (!x.allFinite()) continue;
        // the cone's z along up, its base p.width across and twice as tall
        Eigen::Affine3f T = Eigen::Affine3f::Identity();
        const Eigen::Vector3f e1 = frontFor(up_).cast<float>(), e2 = n.cross(e1);
        T.linear().col(0) = e1 * float(0.5 * p.width);
        T.linear().col(1) = e2 * float(0.5 * p.width);
        T.linear().col(2) = n * float(2 * p.width);
        T.translation() = onGround(x).cast<float>();
        mesh.append(cone, T, p.color);
      }
      continue;
    }
    // a ribbon: each segment a quad, half the width either side of the line
    for (std::size_t k = 1; k < p.points.size(); ++k) {
      const Eigen::Vector3d a = onGround(p.points[k - 1]), b = onGround(p.points[k]);
      if (!a.allFinite() || !b.allFinite()) continue;
      const Eigen::Vector3d d = b - a;
      if (d.norm() < 1e-12) continue;
      const Eigen::Vector3f side = (0.5 * p.width * up_.cross(d).normalized()).cast<float>();
      const Eigen::Vector3f fa = a.cast<float>(), fb = b.cast<float>();
      for (const Eigen::Vector3f& v : {Eigen::Vector3f(fa - side), Eigen::Vector3f(fa + side), Eigen::Vector3f(fb + side),
                                       Eigen::Vector3f(fa - side), Eigen::Vector3f(fb + side), Eigen::Vector3f(fb - side)})
        mesh.addVertex(v, n, p.color);
    }
  }
  return mesh;
}

std::vector<float> Scene::gridLines() const {
  std::vector<float> v;
  const Eigen::Vector3d e1 = frontFor(up_), e2 = up_.cross(e1);
  const int n = static_cast<int>(std::lround(grid_half_ / grid_step_));
  const double o1 = grid_center_.dot(e1), o2 = grid_center_.dot(e2);
  auto put = [&](const Eigen::Vector3d& p, const Eigen::Vector3f& c) {
    v.insert(v.end(), {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()), c.x(), c.y(), c.z()});
  };
  const Eigen::Vector3f minor(0.66f, 0.68f, 0.72f), major(0.50f, 0.52f, 0.57f);
  for (int k = -n; k <= n; ++k) {
    for (int dir = 0; dir < 2; ++dir) {
      const Eigen::Vector3d a = dir == 0 ? e1 : e2, b = dir == 0 ? e2 : e1;  // line along b at offset k along a
      const double along_a = (dir == 0 ? o1 : o2) + k * grid_step_;
      const long idx = std::lround(along_a / grid_step_);
      const Eigen::Vector3f& col = idx % 5 == 0 ? major : minor;
      const Eigen::Vector3d base = grid_center_ + k * grid_step_ * a;
      put(base - grid_half_ * b, col);
      put(base + grid_half_ * b, col);
    }
  }
  return v;
}

// ---- camera ----

void Camera::setUp(const Eigen::Vector3d& u) {
  up = u.normalized();
  front = frontFor(up);
}

Eigen::Vector3d Camera::eye() const { return target - distance * forward(); }

Eigen::Vector3d Camera::forward() const {
  const Eigen::Vector3d side = up.cross(front);
  const Eigen::Vector3d to_eye =
      std::cos(pitch) * (std::cos(yaw) * front + std::sin(yaw) * side) + std::sin(pitch) * up;
  return -to_eye.normalized();
}

Eigen::Vector3d Camera::right() const { return forward().cross(up).normalized(); }

Eigen::Vector3d Camera::screenUp() const { return right().cross(forward()); }

Eigen::Matrix4d Camera::viewMatrix() const {
  const Eigen::Vector3d f = forward(), r = right(), u = screenUp(), e = eye();
  Eigen::Matrix4d V = Eigen::Matrix4d::Identity();
  V.block<1, 3>(0, 0) = r.transpose();
  V.block<1, 3>(1, 0) = u.transpose();
  V.block<1, 3>(2, 0) = -f.transpose();
  V(0, 3) = -r.dot(e), V(1, 3) = -u.dot(e), V(2, 3) = f.dot(e);
  return V;
}

double Camera::farPlane() const { return distance + 2.5 * scene_radius; }

double Camera::nearPlane() const { return std::max(distance - 2.5 * scene_radius, farPlane() * 1e-3); }

Eigen::Matrix4d Camera::projectionMatrix() const {
  const double n = nearPlane(), f = farPlane();
  const double t = 1.0 / std::tan(fovy / 2), aspect = double(std::max(width, 1)) / std::max(height, 1);
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = t / aspect;
  P(1, 1) = t;
  P(2, 2) = (f + n) / (n - f);
  P(2, 3) = 2 * f * n / (n - f);
  P(3, 2) = -1;
  return P;
}

bool Camera::project(const Eigen::Vector3d& world, Eigen::Vector2d* pixel) const {
  const Eigen::Vector3d d = world - eye();
  const double z = d.dot(forward());
  if (z <= 1e-12) return false;
  const double th = std::tan(fovy / 2), aspect = double(std::max(width, 1)) / std::max(height, 1);
  const double xn = d.dot(right()) / z / (th * aspect), yn = d.dot(screenUp()) / z / th;
  *pixel = {(xn + 1) / 2 * width, (1 - yn) / 2 * height};
  return true;
}

Ray Camera::rayAt(double px, double py) const {
  const double th = std::tan(fovy / 2), aspect = double(std::max(width, 1)) / std::max(height, 1);
  const double xn = 2 * px / std::max(width, 1) - 1, yn = 1 - 2 * py / std::max(height, 1);
  Ray r;
  r.origin = eye();
  r.dir = (forward() + xn * th * aspect * right() + yn * th * screenUp()).normalized();
  return r;
}

void Camera::fit(const Eigen::AlignedBox3d& box) {
  target = box.center();
  const double th_y = std::tan(fovy / 2), th_x = th_y * double(std::max(width, 1)) / std::max(height, 1);
  const Eigen::Vector3d f = forward(), r = right(), u = screenUp();
  // each corner must be inside the frustum: |x| <= (d - z) tan, z towards the eye
  double d = 1e-6;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d c = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k)) - target;
    const double x = c.dot(r), y = c.dot(u), z = -c.dot(f);
    d = std::max({d, std::abs(x) / th_x + z, std::abs(y) / th_y + z});
  }
  distance = 1.06 * d + 1e-9;  // a small margin
}

void Camera::orbit(double dx_px, double dy_px) {
  yaw -= 0.008 * dx_px;
  pitch = std::clamp(pitch + 0.008 * dy_px, -1.55, 1.55);
}

void Camera::pan(double dx_px, double dy_px) {
  const double per_px = 2 * distance * std::tan(fovy / 2) / std::max(height, 1);
  target += per_px * (-dx_px * right() + dy_px * screenUp());
}

void Camera::zoom(double steps) { distance = std::max(distance * std::pow(0.85, steps), 1e-9); }

}  // namespace codyna::gui
