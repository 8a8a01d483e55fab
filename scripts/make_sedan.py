#!/usr/bin/python3
"""Writes examples/sedan.json: the full car of issue 39 (docs/vehicles.md, "The sedan").

The geometry is written once here, for the left side, and mirrored; every point is in the
chassis frame (x forward, y left, z up, origin at the sprung mass's centre of mass) at the
design position, and each body's frame is parallel to the chassis there, its origin at its
joint, so a body's local point is the chassis point less the body's origin.
Run: /usr/bin/python3 scripts/make_sedan.py > examples/sedan.json

With --esc it writes examples/sedan_esc.json instead: the same car with a yaw-rate controller that
brakes one front wheel (docs/vehicles.md, "A yaw-rate controller"): the front brakes are its
Plant/In, limited to braking (-3000 .. 0 N m), and a P law on the yaw rate's error from the
driver's intended yaw rate (codyna maneuver gives it as the reference) brakes the outer front wheel
when the car yaws more than intended, the inner one when less. Its gain KP_ESC was designed on
the linearized car at 25 m/s: the loop from the differential front brake torque to the yaw rate
crosses over at 1 Hz (k = 1 / |G(j 2 pi)|, 7304 N m per rad/s, rounded; tests/core/yaw_control_test.cpp
designs it again from the linearization and checks the file's value).
Run: /usr/bin/python3 scripts/make_sedan.py --esc > examples/sedan_esc.json
"""
import json
import math
import sys

G = 9.81
A_FRONT, B_REAR = 1.20, 1.50              # axles from the sprung centre of mass (m)
HALF_TRACK = 0.775
TIR = "tires/MagicFormula61_Paramerters.tir"
R0, KZ = 0.393581, 322913.0               # the .tir's UNLOADED_RADIUS and VERTICAL_STIFFNESS
SPEED = 25.0
KP_ESC = 7300.0                           # N m of brake torque per rad/s of yaw-rate error
ESC = "--esc" in sys.argv[1:]

M_CHASSIS = 1350.0
FRONT_SPRING, REAR_SPRING = 75000.0, 45650.0
FRONT_DAMPER, REAR_DAMPER = 5500.0, 2900.0
FRONT_BAR, REAR_BAR = 3500.0, 1000.0      # N m/rad of twist
STEER_RATIO = 16.0                        # steering wheel angle per road-wheel angle
STEER_ARM = 0.12                          # tie rod's outer joint behind the kingpin (m)


def sub(a, b):
    return [round(x - y, 12) for x, y in zip(a, b)]


def mirror(p):
    return [p[0], -p[1], p[2]]


bodies, joints, constraints, effects = [], [], [], []


def body(name, mass, inertia, shapes=None):
    b = {"name": name, "mass": mass, "com": [0, 0, 0], "inertia": inertia}
    if shapes:
        b["shapes"] = shapes
    bodies.append(b)


def joint(name, type_, parent, child, at, **extra):
    j = {"name": name, "type": type_, "parent": parent, "child": child, "parent_frame": {"position": at}}
    j.update(extra)
    joints.append(j)


def ball(name, a, pa, b, pb):
    constraints.append({"name": name, "type": "ball", "body_a": a, "point_a": pa, "body_b": b, "point_b": pb})


def rod(a, b, radius, color):
    """a cylinder shape from local point a to local point b"""
    d = [y - x for x, y in zip(a, b)]
    length = math.sqrt(sum(x * x for x in d))
    mid = [(x + y) / 2 for x, y in zip(a, b)]
    # the cylinder's axis is z: rotate z onto d
    z = [0, 0, 1]
    axis = [z[1] * d[2] - z[2] * d[1], z[2] * d[0] - z[0] * d[2], z[0] * d[1] - z[1] * d[0]]
    s = math.sqrt(sum(x * x for x in axis))
    angle = math.atan2(s, d[2])
    frame = {"position": [round(x, 6) for x in mid]}
    if s > 1e-12:
        frame["rotation"] = {"axis": [round(x / s, 9) for x in axis], "angle": round(angle, 12)}
    return {"type": "cylinder", "radius": radius, "length": round(length, 6), "frame": frame, "color": color}


STEEL = [0.55, 0.55, 0.6, 1]
TIRE_BLACK = [0.08, 0.08, 0.08, 1]

# the chassis
# drawn as a frame (two side rails, cross members) and a cabin above the axles' parts, so that the
# suspension stays in sight and every part can be picked in the 3-D view
RED = [0.62, 0.1, 0.1, 1]
body("chassis", M_CHASSIS, [520, 2100, 2300],
     [{"type": "box", "size": [3.9, 0.08, 0.1], "frame": {"position": [-0.1, 0.3, 0.2]}, "color": RED},
      {"type": "box", "size": [3.9, 0.08, 0.1], "frame": {"position": [-0.1, -0.3, 0.2]}, "color": RED},
      {"type": "box", "size": [0.08, 0.52, 0.08], "frame": {"position": [1.7, 0, 0.2]}, "color": RED},
      {"type": "box", "size": [0.08, 0.52, 0.08], "frame": {"position": [-1.95, 0, 0.2]}, "color": RED},
      {"type": "box", "size": [1.4, 1.2, 0.4], "frame": {"position": [-0.3, 0, 0.75]}, "color": [0.62, 0.1, 0.1, 0.6]}])
joints.append({"name": "body", "type": "free", "parent": "ground", "child": "chassis",
               "q0": [0, 0, 0.55, 1, 0, 0, 0], "v0": [0, 0, 0, SPEED, 0, 0]})

# steering: the driver's steering wheel (a motion input, massless: its acceleration reacts on nothing),
# the column's torsional compliance (a bushing about the column's axis, undamped) to the steering shaft, whose
# pinion drives the rack (a coupler), tie rods to the uprights' steering arms
SW = [0.55, 0.37, 0.30]
COLUMN_STIFFNESS, COLUMN_DAMPING = 2000.0, 5.0   # N m/rad, N m s/rad at the steering wheel
body("steering_wheel", 0, [0, 0, 0],
     [{"type": "cylinder", "radius": 0.19, "length": 0.12, "frame": {"rotation": {"axis": [0, 1, 0], "angle": math.pi / 2}}, "color": [0.55, 0.55, 0.6, 1]}])
joint("steering_column", "revolute", "chassis", "steering_wheel", SW, axis=[-1, 0, 0])
body("steering_shaft", 1.0, [0.01, 0.005, 0.005], [rod([0.08, 0, -0.07], [0.45, 0, -0.4], 0.015, STEEL)])
joint("steering_shaft", "revolute", "chassis", "steering_shaft", SW, axis=[-1, 0, 0])
effects.append({"name": "column_torsion", "type": "bushing", "body_a": "steering_wheel", "body_b": "steering_shaft",
                "rotational_stiffness": [COLUMN_STIFFNESS, 0, 0]})
# the steering system's damping, to the chassis (a damper across the compliance would make the car's
# acceleration respond to the steering wheel's rate: an improper transfer function)
effects.append({"name": "steering_damper", "type": "joint_damper", "joint": "steering_shaft", "damping": COLUMN_DAMPING})
RACK = [A_FRONT - STEER_ARM, 0, -0.15]
body("rack", 3.0, [0.05, 0.002, 0.05], [rod([0, -0.35, 0], [0, 0.35, 0], 0.02, STEEL)])
joint("rack", "prismatic", "chassis", "rack", RACK, axis=[0, 1, 0])
# road-wheel angle delta moves the tie rod's outer end (STEER_ARM behind the kingpin) by -STEER_ARM delta
# along y: the rack follows the shaft's angle theta as rack = -STEER_ARM theta / STEER_RATIO
constraints.append({"name": "pinion", "type": "coupler", "joint_a": "rack", "ratio_a": 1,
                    "joint_b": "steering_shaft", "ratio_b": round(STEER_ARM / STEER_RATIO, 12), "offset": 0})

# front suspension: double wishbones, the spring-damper on the lower arm, the tie rod on the upright
def front_corner(side):
    s = "l" if side == "left" else "r"
    m = (lambda p: p) if side == "left" else mirror
    sign = 1 if side == "left" else -1
    lower_pivot, lower_ball = m([A_FRONT, 0.35, -0.30]), m([A_FRONT, 0.70, -0.30])
    upper_pivot, upper_ball = m([A_FRONT, 0.40, 0.06]), m([A_FRONT, 0.66, 0.05])
    wheel = m([A_FRONT, HALF_TRACK, R0 - 4100 / KZ - 0.55])
    rod_in, rod_out = m([RACK[0], 0.35, RACK[2]]), m([RACK[0], 0.70, RACK[2]])
    spring_top, spring_bottom = m([A_FRONT, 0.55, 0.25]), m([A_FRONT, 0.60, -0.30])
    body("lower_arm_f" + s, 5.0, [0.05, 0.01, 0.05], [rod([0, 0, 0], sub(lower_ball, lower_pivot), 0.02, STEEL)])
    joint("lower_arm_f" + s, "revolute", "chassis", "lower_arm_f" + s, lower_pivot, axis=[1, 0, 0])
    body("upper_arm_f" + s, 3.0, [0.03, 0.006, 0.03], [rod([0, 0, 0], sub(upper_ball, upper_pivot), 0.015, STEEL)])
    joint("upper_arm_f" + s, "revolute", "chassis", "upper_arm_f" + s, upper_pivot, axis=[1, 0, 0])
    body("upright_f" + s, 15.0, [0.15, 0.12, 0.08], [rod([0, 0, 0], sub(upper_ball, lower_ball), 0.03, STEEL)])
    joint("lower_ball_f" + s, "spherical", "lower_arm_f" + s, "upright_f" + s, sub(lower_ball, lower_pivot))
    ball("upper_ball_f" + s, "upper_arm_f" + s, sub(upper_ball, upper_pivot), "upright_f" + s, sub(upper_ball, lower_ball))
    body("tie_rod_f" + s, 1.0, [0.01, 0.0004, 0.01], [rod([0, 0, 0], sub(rod_out, rod_in), 0.01, STEEL)])
    joint("tie_rod_f" + s, "universal", "rack", "tie_rod_f" + s, sub(rod_in, RACK), axis=[0, 0, 1], axis2=[1, 0, 0])
    ball("tie_rod_end_f" + s, "tie_rod_f" + s, sub(rod_out, rod_in), "upright_f" + s, sub(rod_out, lower_ball))
    wheel_body(side, "f" + s, "upright_f" + s, sub(wheel, lower_ball), sign)
    effects.append({"name": "spring_f" + s, "type": "spring_damper", "body_a": "chassis", "point_a": spring_top,
                    "body_b": "lower_arm_f" + s, "point_b": sub(spring_bottom, lower_pivot),
                    "stiffness": FRONT_SPRING, "damping": FRONT_DAMPER, "rest_length": 0.638})
    return lower_pivot


def wheel_body(side, tag, parent, at, sign):
    body("wheel_" + tag, 20.0, [0.9, 1.4, 0.9],
         [{"type": "cylinder", "radius": R0, "length": 0.255, "frame": {"rotation": {"axis": [1, 0, 0], "angle": math.pi / 2}}, "color": TIRE_BLACK}])
    joint("spin_" + tag, "revolute", parent, "wheel_" + tag, at, axis=[0, 1, 0], v0=round(SPEED / R0, 9))
    effects.append({"name": "tire_" + tag, "type": "tire", "body": "wheel_" + tag, "center": [0, 0, 0], "spin_axis": [0, 1, 0],
                    "law": "magic_formula", "file": TIR, "side": side})


# rear suspension: trailing arms pivoting about the car's y axis
def rear_corner(side):
    s = "l" if side == "left" else "r"
    m = (lambda p: p) if side == "left" else mirror
    sign = 1 if side == "left" else -1
    pivot = m([-1.05, 0.60, -0.12])
    wheel = m([-B_REAR, HALF_TRACK, R0 - 3300 / KZ - 0.55])
    spring_top, spring_bottom = m([-1.40, 0.65, 0.20]), m([-1.40, 0.65, -0.15])
    body("trailing_arm_r" + s, 12.0, [0.05, 0.3, 0.3], [rod([0, 0, 0], sub(wheel, pivot), 0.03, STEEL)])
    joint("trailing_arm_r" + s, "revolute", "chassis", "trailing_arm_r" + s, pivot, axis=[0, 1, 0])
    wheel_body(side, "r" + s, "trailing_arm_r" + s, sub(wheel, pivot), sign)
    effects.append({"name": "spring_r" + s, "type": "spring_damper", "body_a": "chassis", "point_a": spring_top,
                    "body_b": "trailing_arm_r" + s, "point_b": sub(spring_bottom, pivot),
                    "stiffness": REAR_SPRING, "damping": REAR_DAMPER, "rest_length": 0.4364})
    return pivot


front_pivots = {side: front_corner(side) for side in ("left", "right")}
rear_pivots = {side: rear_corner(side) for side in ("left", "right")}


# anti-roll bars: two halves on the bar's axis (the right half turns on the left one: its angle is the
# twist, the torsion spring), drop links from the bars' arms to the lower arms / trailing arms
def anti_roll_bar(tag, pivot, arm_x, link_top_z, link_bottom_z, arms, stiffness):
    for side in ("left", "right"):
        s = "l" if side == "left" else "r"
        m = (lambda p: p) if side == "left" else mirror
        half = "bar_" + tag + s
        top, bottom = m([arm_x, 0.55, link_top_z]), m([arm_x, 0.55, link_bottom_z])
        body(half, 2.0, [0.02, 0.01, 0.02], [rod(m([0, 0, 0]), sub(top, pivot), 0.012, STEEL)])
        if side == "left":
            joint(half, "revolute", "chassis", half, pivot, axis=[0, 1, 0])
        else:
            joint("bar_twist_" + tag, "revolute", "bar_" + tag + "l", half, [0, 0, 0], axis=[0, 1, 0])
        link = "drop_link_" + tag + s
        body(link, 0.5, [0.002, 0.002, 0.0002], [rod([0, 0, 0], sub(bottom, top), 0.008, STEEL)])
        joint(link, "universal", half, link, sub(top, pivot), axis=[1, 0, 0], axis2=[0, 1, 0])
        arm, arm_pivot = arms[side]
        ball(link + "_end", link, sub(bottom, top), arm, sub(bottom, arm_pivot))
    effects.append({"name": "bar_" + tag, "type": "joint_spring_damper", "joint": "bar_twist_" + tag,
                    "stiffness": stiffness, "damping": 0})


anti_roll_bar("f", [A_FRONT + 0.25, 0, -0.10], A_FRONT, -0.10, -0.30,
              {"left": ("lower_arm_fl", front_pivots["left"]), "right": ("lower_arm_fr", front_pivots["right"])}, FRONT_BAR)
anti_roll_bar("r", [-1.55, 0, 0.05], -1.30, 0.05, -0.15,
              {"left": ("trailing_arm_rl", rear_pivots["left"]), "right": ("trailing_arm_rr", rear_pivots["right"])}, REAR_BAR)

effects.insert(0, {"name": "gravity", "type": "gravity", "g": [0, 0, -G]})

actuators = [
    {"name": "steer", "type": "motion", "joint": "steering_column", "unit": "rad"},
    {"name": "drive_rl", "type": "joint_force", "joint": "spin_rl", "unit": "N m"},
    {"name": "drive_rr", "type": "joint_force", "joint": "spin_rr", "unit": "N m"},
    {"name": "brake_fl", "type": "joint_force", "joint": "spin_fl", "unit": "N m"},
    {"name": "brake_fr", "type": "joint_force", "joint": "spin_fr", "unit": "N m"},
    {"name": "drive", "type": "mix", "drives": ["drive_rl", "drive_rr"], "weights": [0.5, 0.5], "unit": "N m"},
    {"name": "brake", "type": "mix", "drives": ["brake_fl", "brake_fr", "drive_rl", "drive_rr"],
     "weights": [-0.35, -0.35, -0.15, -0.15], "unit": "N m"},
]
sensors = [
    {"name": "yaw_rate", "type": "angular_velocity", "body": "chassis", "component": "z", "frame": "chassis"},
    {"name": "lateral_acceleration", "type": "acceleration", "body": "chassis", "point": [0, 0, 0], "component": "y", "frame": "chassis"},
    {"name": "roll_rate", "type": "angular_velocity", "body": "chassis", "component": "x", "frame": "chassis"},
    {"name": "forward_speed", "type": "point_velocity", "body": "chassis", "point": [0, 0, 0], "component": "x", "frame": "chassis"},
    {"name": "lateral_velocity", "type": "point_velocity", "body": "chassis", "point": [0, 0, 0], "component": "y", "frame": "chassis"},
]
for t in ("fl", "fr", "rl", "rr"):
    sensors.append({"name": "Fz_" + t, "type": "tire", "tire": "tire_" + t, "quantity": "Fz"})
    sensors.append({"name": "slip_angle_" + t, "type": "tire", "tire": "tire_" + t, "quantity": "slip_angle"})

model = {
    "codyna_model": 1,
    "name": "sedan",
    "description": ("A full car for issue 39 (docs/vehicles.md, The sedan), written by scripts/make_sedan.py: chassis on a free joint, "
                    "double-wishbone front suspension steered by the steering wheel (motion input steer, rad at the wheel) through a "
                    "compliant column, a 16:1 pinion and a rack with tie rods; trailing-arm rear; coil-overs; anti-roll bars; "
                    "Magic Formula 6.1 tires; drive and brake torques. Operating point: steady, straight at 25 m/s, steer and drive solved; "
                    "a turn: --lateral-acceleration 3.92266 (0.4 g). Plant/In steer; Plant/Out yaw rate, lateral acceleration, roll rate."),
    "bodies": bodies, "joints": joints, "constraints": constraints, "effects": effects,
    "actuators": actuators, "sensors": sensors,
    "plant": {"inputs": ["steer"], "outputs": ["yaw_rate", "lateral_acceleration", "roll_rate"]},
    "solver": {"t_end": 2, "output_step": 0.01},
    "analysis": {"operating_point": "steady", "free_inputs": ["steer", "drive"],
                 "steady": {"body": "chassis", "speed": SPEED},
                 # the states: the chassis, the steering shaft, each corner's arm and wheel spin
                 "independent": ["body.rx", "body.ry", "body.rz", "body.x", "body.y", "body.z", "steering_shaft",
                                 "lower_arm_fl", "lower_arm_fr", "trailing_arm_rl", "trailing_arm_rr",
                                 "spin_fl", "spin_fr", "spin_rl", "spin_rr"],
                 "handling": {"steer": "steer", "yaw_rate": "yaw_rate", "lateral_acceleration": "lateral_acceleration",
                              "steering_ratio": STEER_RATIO}},
}
if ESC:
    for a in actuators:
        if a["name"] in ("brake_fl", "brake_fr"):
            a["min"], a["max"] = -3000.0, 0.0
    model["name"] = "sedan_esc"
    model["description"] = (
        "The sedan of examples/sedan.json (docs/vehicles.md) with a yaw-rate controller, written by scripts/make_sedan.py --esc: "
        "the front brakes are the Plant/In (limited to braking), a P law on the yaw rate's error from the driver's intended yaw "
        "rate brakes the outer front wheel when the car yaws more than intended, the inner one when less. The gain was designed "
        "on the car linearized at 25 m/s (the loop crosses over at 1 Hz). codyna maneuver runs it in the loop (--open-loop leaves "
        "it out): codyna maneuver examples/sedan_esc.json --type sine-with-dwell --steer 3.")
    model["plant"] = {"inputs": ["brake_fl", "brake_fr"], "outputs": ["yaw_rate", "lateral_acceleration", "roll_rate"]}
    model["controller"] = {"type": "pid", "kp": [[-KP_ESC, 0, 0], [KP_ESC, 0, 0]], "operating_point": "steady"}
print(json.dumps(model, indent=1))
