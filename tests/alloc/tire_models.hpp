// The allocation tests' model with tires (dynamics_alloc_test, jacobian_alloc_test): one tire of
// each law (core/dynamics/tire_effect.hpp): the book's Magic Formula .tir on the ground,
// Fiala on a moving road (a platform on a vertical slider), linear with a friction circle; every
// wheel touching its road, rolling with slip and sideslip
#pragma once

namespace codyna::alloc_test {

inline constexpr const char* kTires = R"({"name": "tires",
  "bodies": [{"name": "platform", "mass": 50, "inertia": [1, 1, 1]},
             {"name": "w1", "mass": 15, "inertia": [0.4, 0.8, 0.4]}, {"name": "w2", "mass": 15, "inertia": [0.4, 0.8, 0.4]},
             {"name": "w3", "mass": 15, "inertia": [0.4, 0.8, 0.4]}],
  "joints": [{"name": "lift", "type": "prismatic", "parent": "ground", "child": "platform", "axis": [0, 0, 1], "v0": 0.1},
             {"name": "j1", "type": "free", "parent": "ground", "child": "w1", "q0": [0, 0, 0.305, 1, 0, 0, 0], "v0": [0.1, 42, 0.2, 12, 0.5, 0.01]},
             {"name": "j2", "type": "free", "parent": "ground", "child": "w2", "q0": [2, 0, 0.39, 0.999, 0.03, 0, 0.02], "v0": [0, 38, 0.1, 11, -0.4, 0]},
             {"name": "j3", "type": "free", "parent": "ground", "child": "w3", "q0": [4, 0, 0.29, 1, 0, 0, 0], "v0": [0, 41, 0, 12, 0.3, 0]}],
  "effects": [{"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]},
              {"name": "t1", "type": "tire", "body": "w1", "law": "magic_formula", "file": "../tests/data/tires/PacejkaBook_Defaults.tir"},
              {"name": "t2", "type": "tire", "body": "w2", "unloaded_radius": 0.3, "law": "fiala", "longitudinal_stiffness": 9e4,
               "cornering_stiffness": 6e4, "friction": 1, "sliding_friction": 0.8, "width": 0.2, "rolling_resistance": 0.01,
               "vertical_stiffness": 2.5e5, "vertical_damping": 500, "road": {"body": "platform", "point": [0, 0, 0.1]}},
              {"name": "t3", "type": "tire", "body": "w3", "unloaded_radius": 0.3, "law": "linear", "longitudinal_stiffness": 8e4,
               "cornering_stiffness": 7e4, "camber_stiffness": 2e3, "friction": 1.1, "trail": 0.03, "vertical_stiffness": 2.5e5}],
  "actuators": [{"name": "push", "type": "joint_force", "joint": "lift"}],
  "sensors": [{"name": "h", "type": "joint_position", "joint": "lift"}],
  "plant": {"inputs": ["push"], "outputs": ["h"]}})";

}  // namespace codyna::alloc_test
