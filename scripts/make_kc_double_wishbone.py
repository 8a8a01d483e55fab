#!/usr/bin/python3
"""Writes examples/kc_double_wishbone.json and tests/data/kc_double_wishbone_bushing.json: the sedan's
left front corner (scripts/make_sedan.py's numbers) on the K&C rig (codyna kc, docs/kc.md).

The chassis is welded to the ground where the sedan's free joint starts it (0.55 m up); the rack is a
prismatic joint driven by the motion input `rack` (m, positive to the left) instead of the sedan's
steering wheel, column and pinion. The bushing variant puts the lower arm on a free joint held to the
chassis at its pivot by a bushing (stiff in translation and about the arm's y and z axes, free about
its pivot axis x), so that loads at the contact patch steer and camber the wheel; it lives under
tests/data, not examples/, because the tests that take every example's plant at random states hold
their numbers to 1e-12, which a stiff bushing on a light arm does not keep. The rigid corner's plant
(the rack in, the lower arm's angle out) is only for those generic checks.
Run: /usr/bin/python3 scripts/make_kc_double_wishbone.py   (from the repository's root)
"""
import json
import sys

A_FRONT, HALF_TRACK = 1.20, 0.775
R0, KZ = 0.393581, 322913.0
FRONT_SPRING = 75000.0
STEER_ARM = 0.12
RACK = [A_FRONT - STEER_ARM, 0, -0.15]
LOWER_PIVOT, LOWER_BALL = [A_FRONT, 0.35, -0.30], [A_FRONT, 0.70, -0.30]
UPPER_PIVOT, UPPER_BALL = [A_FRONT, 0.40, 0.06], [A_FRONT, 0.66, 0.05]
WHEEL = [A_FRONT, HALF_TRACK, round(R0 - 4100 / KZ - 0.55, 9)]
ROD_IN, ROD_OUT = [RACK[0], 0.35, RACK[2]], [RACK[0], 0.70, RACK[2]]
SPRING_TOP, SPRING_BOTTOM = [A_FRONT, 0.55, 0.25], [A_FRONT, 0.60, -0.30]
BUSHING_K = [2.0e6, 2.0e6, 2.0e6]      # N/m
BUSHING_KR = [0.0, 1.0e5, 1.0e5]       # N m/rad: free about the pivot axis x


def sub(a, b):
    return [round(x - y, 12) for x, y in zip(a, b)]


def model(bushing):
    bodies = [
        {"name": "chassis", "mass": 1350.0, "inertia": [520, 2100, 2300]},
        {"name": "lower_arm", "mass": 5.0, "inertia": [0.05, 0.01, 0.05]},
        {"name": "upper_arm", "mass": 3.0, "inertia": [0.03, 0.006, 0.03]},
        {"name": "upright", "mass": 15.0, "inertia": [0.15, 0.12, 0.08]},
        {"name": "rack", "mass": 3.0, "inertia": [0.05, 0.002, 0.05]},
        {"name": "tie_rod", "mass": 1.0, "inertia": [0.01, 0.0004, 0.01]},
        {"name": "wheel", "mass": 20.0, "inertia": [0.9, 1.4, 0.9]},
    ]
    joints = [{"name": "weld", "type": "fixed", "parent": "ground", "child": "chassis", "parent_frame": {"position": [0, 0, 0.55]}}]
    if bushing:
        joints.append({"name": "lower_arm", "type": "free", "parent": "chassis", "child": "lower_arm",
                       "parent_frame": {"position": LOWER_PIVOT}})
    else:
        joints.append({"name": "lower_arm", "type": "revolute", "parent": "chassis", "child": "lower_arm",
                       "parent_frame": {"position": LOWER_PIVOT}, "axis": [1, 0, 0]})
    joints += [
        {"name": "upper_arm", "type": "revolute", "parent": "chassis", "child": "upper_arm",
         "parent_frame": {"position": UPPER_PIVOT}, "axis": [1, 0, 0]},
        {"name": "lower_ball", "type": "spherical", "parent": "lower_arm", "child": "upright",
         "parent_frame": {"position": sub(LOWER_BALL, LOWER_PIVOT)}},
        {"name": "rack", "type": "prismatic", "parent": "chassis", "child": "rack", "parent_frame": {"position": RACK},
         "axis": [0, 1, 0]},
        {"name": "tie_rod", "type": "universal", "parent": "rack", "child": "tie_rod",
         "parent_frame": {"position": sub(ROD_IN, RACK)}, "axis": [0, 0, 1], "axis2": [1, 0, 0]},
        {"name": "spin", "type": "revolute", "parent": "upright", "child": "wheel",
         "parent_frame": {"position": sub(WHEEL, LOWER_BALL)}, "axis": [0, 1, 0]},
    ]
    constraints = [
        {"name": "upper_ball", "type": "ball", "body_a": "upper_arm", "point_a": sub(UPPER_BALL, UPPER_PIVOT),
         "body_b": "upright", "point_b": sub(UPPER_BALL, LOWER_BALL)},
        {"name": "tie_rod_end", "type": "ball", "body_a": "tie_rod", "point_a": sub(ROD_OUT, ROD_IN),
         "body_b": "upright", "point_b": sub(ROD_OUT, LOWER_BALL)},
    ]
    effects = [
        {"name": "gravity", "type": "gravity", "g": [0, 0, -9.81]},
        {"name": "coil_over", "type": "spring_damper", "body_a": "chassis", "point_a": SPRING_TOP,
         "body_b": "lower_arm", "point_b": sub(SPRING_BOTTOM, LOWER_PIVOT), "stiffness": FRONT_SPRING,
         "damping": 5500.0, "rest_length": 0.638},
        {"name": "tire", "type": "tire", "body": "wheel", "law": "linear", "unloaded_radius": R0,
         "vertical_stiffness": KZ, "cornering_stiffness": 100000.0, "longitudinal_stiffness": 100000.0},
    ]
    if bushing:
        effects.append({"name": "lower_pivot_bushing", "type": "bushing", "body_a": "chassis",
                        "frame_a": {"position": LOWER_PIVOT}, "body_b": "lower_arm",
                        "translational_stiffness": BUSHING_K, "rotational_stiffness": BUSHING_KR})
    name = "kc_double_wishbone" + ("_bushing" if bushing else "")
    desc = ("The sedan's left front double-wishbone corner (scripts/make_sedan.py) on the K&C rig "
            "(codyna kc, docs/kc.md; written by scripts/make_kc_double_wishbone.py): chassis welded to the ground, "
            "coil-over on the lower arm, tie rod from a rack driven by the motion input rack (m, positive left)")
    if bushing:
        desc += "; the lower arm held at its pivot by a bushing instead of a revolute joint (compliance)"
    model = {"codyna_model": 1, "name": name, "description": desc + ".", "bodies": bodies, "joints": joints,
             "constraints": constraints, "effects": effects,
             "actuators": [{"name": "rack", "type": "motion", "joint": "rack", "unit": "m"}],
             "sensors": [{"name": "lower_arm_angle", "type": "joint_position", "joint": "lower_arm"}],
             "plant": {"inputs": ["rack"], "outputs": ["lower_arm_angle"]}}
    if bushing:
        del model["sensors"], model["plant"]
    return model


for bushing in (False, True):
    path = "tests/data/kc_double_wishbone_bushing.json" if bushing else "examples/kc_double_wishbone.json"
    with open(path, "w") as f:
        f.write(json.dumps(model(bushing), indent=1) + "\n")
    print("wrote", path, file=sys.stderr)
