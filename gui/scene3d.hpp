// Scene3D: what the 3-D view draws and picks, without Qt or OpenGL.
//
// - Mesh: unit primitives (box, cylinder, sphere, cone, arrow, triad) as
//   triangle lists; every drawn object is one of them under an affine map.
// - Scene: the items of a Model (its declared shapes, or a default look for
//   bodies without shapes, joint axes, body triads, springs, ground anchors)
//   with their world transforms for one configuration, a ground grid and
//   ray picking against the same transforms that are drawn; the tires' contact forces at one
//   state as arrows at their contact points (setTireForces, core's study_tire_contacts).
// - Camera: an orbit camera (yaw about "up", pitch above the ground plane)
//   with projection to pixels and the pixel ray, for drawing and picking.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "study/tire_contacts.hpp"
#include "study/tools.hpp"
#include "model/model.hpp"

namespace codyna::gui {

// interleaved triangle vertices: x y z, nx ny nz, r g b
struct Mesh {
  static constexpr int kStride = 9;
  std::vector<float> data;
  int vertexCount() const { return static_cast<int>(data.size()) / kStride; }
  void addVertex(const Eigen::Vector3f& p, const Eigen::Vector3f& n, const Eigen::Vector3f& c);
  // appends `other` mapped by T (normals by T's inverse transpose), recoloured when `color` has x >= 0
  void append(const Mesh& other, const Eigen::Affine3f& T, const Eigen::Vector3f& color = Eigen::Vector3f(-1, 0, 0));
};

Mesh unitBox();                        // [-0.5, 0.5]^3
Mesh unitCylinder(int segments);       // radius 1, z in [-0.5, 0.5], capped
Mesh unitSphere(int segments, int rings);  // radius 1
Mesh unitCone(int segments);           // base radius 1 at z = 0, apex at z = 1
Mesh arrowMesh(int segments);          // z in [-0.5, 0.5], tip at +z, radius ~0.06 (length 1)
Mesh triadMesh(int segments);          // red x, green y, blue z arrows of length 1 from the origin

enum class Prim { Box, Cylinder, Sphere, Cone, Arrow, Triad };

enum class ItemKind {
  Shape,    // body geometry (declared or default); pickable
  Anchor,   // ground pivots; drawn, not pickable
  Axis,     // joint axis arrow (overlay)
  Frame,    // body frame triad (overlay)
  Spring,   // spring-damper between two bodies
  Com,      // centre of mass marker (overlay, shown on request)
  // the elements of docs/model-format.md drawn as they act (`element` names them):
  LineForce,  // two-point actuator: a barrel on body_a's point, a rod on body_b's (two tones)
  Bushing,    // a block at each of its two frames, and the line between their origins when apart
  Coupler,    // dashes between the coupled joints' frames F, and a dot on each
  Motion,     // a joint driven by a motion input: an arrow along its axis and a disc around it
  Actuator,   // an actuator driven by a mix: a force arrow from its point, a torque arrow and disc
  Contact,    // a rolling_ball: a thin disc of the plane under the ball at the contact, a dot on it
  Force,      // a body_force effect: an arrow along its force from its point, an arrow and a disc for its torque
  // a tire's contact force on the wheel, from its contact point: the load Fz ez (TireLoad) and the
  // in-plane force Fx ex + Fy ey (TireInPlane), tireForceScale() metres per newton; world items
  TireLoad,
  TireInPlane,
};

// how a two-point item spans the line from point_a (on `body`) to point_b (on body_b)
enum class Span {
  None,    // not a two-point item: world = pose of `body` * local
  Whole,   // the whole line
  Barrel,  // from a towards b: span_a long, or longer so that it meets the rod; at most the line
  Rod,     // from b towards a: span_b long, at most the line
  Dash,    // the fractions [span_a, span_b] of the line
  // not a line: the contact of a ball (centre point_b on body_b) with a plane of `body` whose
  // normal is `normal` (body frame): world = translation to the contact (the centre less `depth`
  // along the normal as turned now) * the body's rotation * local (local's z: the normal); for a
  // disc (`axle` not zero) the centre less `depth` along the contact direction d, the unit part of
  // the normal n normal to the axle a as turned now: d = (n - (n.a) a) / |n - (n.a) a|
  Contact,
};

struct Item {
  ItemKind kind = ItemKind::Shape;
  Prim prim = Prim::Box;
  int body = 0;                       // model body index (0 = ground)
  Eigen::Affine3d local = Eigen::Affine3d::Identity();  // unit primitive -> body frame
  Eigen::Affine3d world = Eigen::Affine3d::Identity();  // unit primitive -> world (update())
  Eigen::Vector4f color{0.7f, 0.7f, 0.75f, 1.0f};
  // two-point items (span != None: springs, struts, links): end points on body (a = `body`) and body_b
  Span span = Span::None;
  int body_b = 0;
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero(), point_b = Eigen::Vector3d::Zero();
  double thickness = 0.0;     // radius of the cylinder drawn along the line
  double span_a = 0.0, span_b = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // Span::Contact: the plane's normal, `body` frame (unit)
  double depth = 0.0;                                 // Span::Contact: the ball's or disc's radius
  Eigen::Vector3d axle = Eigen::Vector3d::Zero();     // Span::Contact of a disc: its axle, body_b frame
  // an arrow whose direction stays in world axes (an actuator with "frame": "world"): world =
  // translation to the pose of `body` * local's origin, then local's linear part unturned
  bool world_axes = false;
  std::string element;        // the model element it draws (LineForce .. Actuator), for tests and tips
};

// the cylinder of a two-point item from world points a to b (Scene::update uses it)
Eigen::Affine3d spanTransform(const Item& it, const Eigen::Vector3d& a, const Eigen::Vector3d& b);

struct Ray {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d dir = Eigen::Vector3d::UnitZ();  // unit
};

// distance along `ray` to the unit primitive under `world`, or a negative value on a miss
double intersect(Prim prim, const Eigen::Affine3d& world, const Ray& ray);

// A path drawn on the ground (a maneuver's target and the track a body left): world points,
// dropped onto the grid's plane and drawn as a flat ribbon `width` wide; with `markers`, a cone
// stands at each point instead (a lane's cones), `width` wide at its base
struct ScenePath {
  std::string name;
  std::vector<Eigen::Vector3d> points;
  Eigen::Vector3f color{0.2f, 0.2f, 0.2f};
  double width = 0.1;
  bool markers = false;
};

class Scene {
 public:
  // builds the items of `model` (nullptr: empty) and places them at model->q0
  // `held`: bodies a draft holds in place (study/model_issues.hpp), drawn without a ground anchor
  void build(const Model* model, const std::vector<int>& held = {});
  // recomputes the world transforms from body poses (oMi of forward_kinematics)
  void update(const std::vector<SE3>& oMi);
  // replaces the tire force arrows by those of `contacts` (one per tire of the model, as
  // study_tire_contacts gives them; empty: none drawn): per tire in contact a TireLoad arrow and,
  // unless it is zero, a TireInPlane arrow, from the contact point, tireForceScale() m per N long
  void setTireForces(const std::vector<TireContactReport>& contacts);
  // metres of arrow per newton: a round number (1, 2 or 5 times a power of ten) that draws a
  // tire's share of the weight about a quarter of the mechanism's size long; 0 without tires
  double tireForceScale() const { return tire_force_scale_; }
  // the scale as the legend says it: "1 kN = 0.2 m" ("" without tires)
  std::string tireForceScaleText() const;

  const Model* model() const { return model_; }
  const std::vector<Item>& items() const { return items_; }
  double length() const { return length_; }      // characteristic size of the mechanism
  Eigen::Vector3d up() const { return up_; }     // -gravity, or +y

  // world box of the shapes and anchors as placed now
  Eigen::AlignedBox3d bounds() const;
  // bounds() (and the overlays) with its shadow on the grid: what fitting the view frames
  Eigen::AlignedBox3d viewBounds(bool overlays) const;
  // nearest body hit by the ray: body index, 0 for a ground anchor, -1 for the background
  int pick(const Ray& ray, double* distance = nullptr) const;
  // a world point guaranteed on a body's geometry (centre of its largest shape); false if none
  bool bodyAnchor(int body, Eigen::Vector3d* point) const;

  // ground grid: square of half-size gridHalf() centred at gridCenter(), normal up(), line spacing gridStep()
  Eigen::Vector3d gridCenter() const { return grid_center_; }
  double gridHalf() const { return grid_half_; }
  double gridStep() const { return grid_step_; }
  // line vertices of the grid (x y z r g b pairs)
  std::vector<float> gridLines() const;

  // the paths drawn on the ground (replaces them; empty: none). The grid grows to hold them, its
  // lines at most about 120 each way (a coarser step over a long track); build() clears them.
  void setPaths(std::vector<ScenePath> paths);
  const std::vector<ScenePath>& paths() const { return paths_; }
  // their triangles (ribbons and cones, with normals), in world coordinates, on the ground road
  // plane of a model's tires (the plane their road is, when it is the ground's, normal to up), else
  // on the grid's plane
  Mesh pathMesh() const;

 private:
  void addDefaultLook(int body);
  void addElements(const std::vector<SE3>& oMi);
  void placeGrid(const std::vector<SE3>& oMi);

  const Model* model_ = nullptr;
  std::vector<Item> items_;
  double length_ = 1.0;
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitY();
  Eigen::Vector3d grid_center_ = Eigen::Vector3d::Zero();
  double grid_half_ = 2.0, grid_step_ = 0.5;
  double tire_force_scale_ = 0.0;  // m per N
  double tire_force_unit_ = 1.0;   // N in the legend's unit (1 or 1000)
  std::vector<ScenePath> paths_;
  double path_height_ = std::nan("");  // along up: the ground road plane of the tires (NaN: the grid's)
  // the grid placeGrid() chose for the mechanism, before paths grew it
  Eigen::Vector3d base_grid_center_ = Eigen::Vector3d::Zero();
  double base_grid_half_ = 2.0, base_grid_step_ = 0.5;
};

// Orbit camera. Pixel coordinates are widget coordinates: x right, y down.
struct Camera {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();     // world up (unit)
  Eigen::Vector3d front = Eigen::Vector3d::UnitZ();  // horizontal direction to the eye at yaw 0 (unit, _|_ up)
  double distance = 5.0;
  double yaw = 0.0, pitch = 0.0;   // rad; pitch > 0 looks down on the ground
  double fovy = 0.61;              // rad (35 degrees)
  int width = 640, height = 480;   // viewport, pixels
  double scene_radius = 1.0;       // for the clip planes

  static constexpr double kDefaultYaw = 0.45, kDefaultPitch = 0.35;

  void setUp(const Eigen::Vector3d& u);  // also picks `front`
  Eigen::Vector3d eye() const;
  Eigen::Vector3d forward() const;       // unit, eye -> target
  Eigen::Vector3d right() const;         // unit, screen x
  Eigen::Vector3d screenUp() const;      // unit, screen -y
  Eigen::Matrix4d viewMatrix() const;
  Eigen::Matrix4d projectionMatrix() const;
  double nearPlane() const;
  double farPlane() const;

  // pixel position of a world point; false when behind the eye
  bool project(const Eigen::Vector3d& world, Eigen::Vector2d* pixel) const;
  Ray rayAt(double px, double py) const;

  // frames a world box (whole box visible whatever the aspect ratio)
  void fit(const Eigen::AlignedBox3d& box);
  void orbit(double dx_px, double dy_px);
  void pan(double dx_px, double dy_px);
  void zoom(double steps);  // > 0: closer
};

}  // namespace codyna::gui
