// The contact of every tire at one state (q, v), as the tire effect computes it
// (dynamics/tire_effect.hpp, docs/tires.md): for a front end that shows the forces (the 3-D
// view's arrows) or a test that checks them. A thin door onto dynamics/: forward_kinematics at
// (q, v), then tire_contact on each tire's wheel and road bodies, as the tire sensors read it.
// Cost: one forward kinematics pass and one tire law per tire (a Data made per call).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "model/model.hpp"

namespace codyna {

// One tire, world axes. Out of contact (off the road, or a load that would pull): the forces,
// moments, load and slips are zero and `point` is the wheel centre.
struct TireContactReport {
  std::string name;                                 // the tire effect's name
  bool in_contact = false;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // contact point P on the road, m
  Eigen::Vector3d center = Eigen::Vector3d::Zero(); // wheel centre, m
  Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(),
                  ez = Eigen::Vector3d::UnitZ();    // ISO-W axes at P (ez the road's normal)
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  // on the wheel at P: Fx ex + Fy ey + Fz ez, N
  Eigen::Vector3d moment = Eigen::Vector3d::Zero(); // on the wheel about P: Mx ex + My ey + Mz ez, N m
  double Fx = 0, Fy = 0, Fz = 0;                    // N (Fz the normal load, >= 0)
  double Mz = 0;                                    // aligning moment, N m
  double kappa = 0, alpha = 0, gamma = 0;           // longitudinal slip (-), slip angle, camber (rad)
  double Vx = 0;                                    // forward speed of the contact point, m/s
  double penetration = 0;                           // tire deflection, m
};

// One report per tire of the model (Model::tires' order). q, v: nq and nv values; s: the effect
// states (Model::ns: the tires' deflections of their transient slip; a simulation's sample), or
// empty for those at rest at (q, v), as an operating point has them; other sizes throw
// std::invalid_argument.
std::vector<TireContactReport> study_tire_contacts(const Model& model, const Eigen::VectorXd& q,
                                                  const Eigen::VectorXd& v, const Eigen::VectorXd& s = {});

}  // namespace codyna
