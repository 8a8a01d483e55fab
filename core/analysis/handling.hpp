// Handling numbers of a car linearized at a steady motion (issue 39; Rajamani, Vehicle Dynamics
// and Control, ch. 3; Gillespie, Fundamentals of Vehicle Dynamics, ch. 6), from the linear model's
// steady-state gains from the steer input:
//   yaw-rate gain            G_r  = r / delta                         (1/s)
//   lateral-acceleration gain G_ay = a_y / delta  (= U G_r in a steady turn, when the model has no
//                              lateral-acceleration output)            (m/s^2 per rad)
//   sideslip gain            G_b  = beta / delta (when a sideslip output is named)
//   understeer gradient      K    = delta / a_y - L / U^2 = 1 / G_ay - L / U^2   (rad per m/s^2;
//                              also in deg/g), from delta = L / R + K a_y
//   characteristic speed     U_ch = sqrt(L / K) for K > 0 (understeer); critical speed
//                              U_crit = sqrt(-L / K) for K < 0 (oversteer)
//   yaw natural frequency and damping ratio: of the pair of poles that carry most of the yaw-rate
//                              response to steer (a complex pair, or two real poles:
//                              wn = sqrt(p1 p2), zeta = -(p1 + p2) / (2 wn))
// The steady-state gains are those of A x + B u = 0, y = C x + D u less what drifts unseen: the
// largest subspace of positions that the outputs do not read and the dynamics keep (the road
// position, the heading, the spin angles, in whatever combination of coordinates the chart gives
// them: a pitched chassis' forward position is its body x and z together) is taken out first. With
// a SpeedHold (the steady motion's other free inputs: a drive) the speed's change is held at zero
// by them: the constant-speed gains. A may still be singular (a coasting speed): the gain is taken
// when every solution gives the same output, and refused otherwise. The understeer gradient is per
// road-wheel angle: the steer input divided by the steering ratio. A planar joint's velocities are
// the world's: the caller puts them in body axes first (study_handling).
#pragma once

#include <string>

#include "analysis/linear_system.hpp"

namespace codyna {

struct HandlingNumbers {
  double speed = 0, wheelbase = 0;                     // U (m/s), L (m)
  double steering_ratio = 1;                           // steer input per road-wheel angle
  double yaw_rate_gain = 0, lateral_acceleration_gain = 0, sideslip_gain = 0;
  bool sideslip_given = false, lateral_acceleration_output = false;
  double understeer_gradient = 0;                      // rad per m/s^2
  double understeer_gradient_deg_per_g = 0;
  double characteristic_speed = 0;                     // m/s, K > 0 (0 otherwise)
  double critical_speed = 0;                           // m/s, K < 0 (0 otherwise)
  double yaw_natural_frequency = 0, yaw_damping_ratio = 0;
  // taken in a turn (the caller says): the gains hold the other inputs (a drive torque), not the
  // speed, so they are not the constant-speed gains of the bicycle model
  bool in_turn = false;
  bool speed_held = false;  // the gains hold the speed (SpeedHold given)
};

// The speed held in the steady state by some inputs that are not Plant/In (a drive torque): their
// columns of B and D in the same linearization, and the row of the speed's change in the state
// (the steady body's velocity direction). The gains are then the constant-speed gains.
struct SpeedHold {
  Eigen::MatrixXd B, D;    // [nx x nh], [ny x nh]
  Eigen::RowVectorXd speed;  // [nx]
};

// sys: the plant; steer: its input's index; yaw_rate, lateral_acceleration, sideslip: output
// indices (-1 when the model has none; yaw_rate is required); steering_ratio: the steer input per
// road-wheel angle (the gains are per steer input; the understeer gradient is per road-wheel
// angle, K = 1 / (ratio G_ay) - L / U^2). Throws std::invalid_argument when a gain is not defined
// (the steady state is not unique, or the steer does not reach the yaw rate).
HandlingNumbers handling_numbers(const LinearSystem& sys, int steer, int yaw_rate, int lateral_acceleration, int sideslip,
                                 double speed, double wheelbase, double steering_ratio = 1.0,
                                 const SpeedHold* hold = nullptr);

}  // namespace codyna
