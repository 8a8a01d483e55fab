// compile(): indices, ordering, and one test per kind of bad model, each
// checking that the error names the file, the field path and what was expected.
#include "dynamics/prepare.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>
#include <optional>
#include <nlohmann/json.hpp>
#include <random>

#include "dynamics/constraints.hpp"
#include "dynamics/data.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/sensors.hpp"
#include "io/model_file.hpp"
#include "model/compile.hpp"
#include "test_util.hpp"

namespace codyna {
namespace {

ModelSpec two_links() {
  return parse_model_spec_text(R"({
    "name": "two_links",
    "bodies": [
      {"name": "a", "mass": 1, "com": [0.5, 0, 0], "inertia": [0.01, 0.1, 0.1]},
      {"name": "b", "mass": 2, "com": [0.5, 0, 0], "inertia": [0.01, 0.2, 0.2]}
    ],
    "joints": [
      {"name": "jb", "type": "revolute", "parent": "a", "child": "b", "parent_frame": {"position": [1, 0, 0]}},
      {"name": "ja", "type": "revolute", "parent": "ground", "child": "a"}
    ],
    "effects": [{"name": "g", "type": "gravity", "g": [0, -9.81, 0]}],
    "actuators": [{"name": "tau", "type": "joint_force", "joint": "ja"}],
    "sensors": [{"name": "angle", "type": "joint_position", "joint": "jb"}],
    "plant": {"inputs": ["tau"], "outputs": ["angle"]}
  })", "two_links.json");
}

// compile must throw a ModelError whose message holds the file, the path and the phrase
void expect_error(const ModelSpec& s, const std::string& path, const std::string& phrase) {
  try {
    compile(s, "model.json");
    ADD_FAILURE() << "no error for " << path;
  } catch (const ModelError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.path(), path) << what;
    EXPECT_NE(what.find("model.json: " + path + ": "), std::string::npos) << what;
    EXPECT_NE(what.find(phrase), std::string::npos) << what;
  }
}

TEST(Compile, OrdersTheTreeAndAssignsIndices) {
  const Model m = compile(two_links());
  EXPECT_EQ(m.nbodies, 3);
  EXPECT_EQ(m.body_names[1], "a");  // placed before its child although listed second
  EXPECT_EQ(m.body_names[2], "b");
  EXPECT_EQ(m.parent[2], 1);
  EXPECT_EQ(m.joints[1].name, "ja");
  EXPECT_EQ(m.joints[1].idx_v, 0);
  EXPECT_EQ(m.joints[2].idx_v, 1);
  EXPECT_EQ(m.v_names, (std::vector<std::string>{"ja", "jb"}));
  EXPECT_EQ(m.plant_inputs, std::vector<int>{0});
  EXPECT_EQ(m.sensors[0].iq, 1);
  EXPECT_EQ(m.actuators[0].unit, "N m");
  EXPECT_TRUE(m.has_gravity);
}

TEST(Compile, AllExamplesCompile) {
  for (const char* name : {"pendulum.json", "cart_pendulum.json", "double_pendulum.json", "four_bar.json",
                           "andrews_squeezer.json", "bricard.json", "heavy_top.json"}) {
    EXPECT_NO_THROW(test::load_example(name)) << name;
  }
}

// compile_numbers on the bodies (a parameter study's variants) against compiling the variant from scratch:
// every example, every body's mass, com and inertia changed, the same model bit for bit (numbers,
// names, indices, spec, the assembled state, the forward dynamics), and the same error for a bad mass
TEST(Compile, BodyNumbersOnTheStructureEqualCompilingAgain) {
  std::mt19937 rng(7);
  int examples = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const std::string file = entry.path().string();
    const ModelSpec nominal = load_model_spec(file);
    Model structure = compile_structure(nominal, file);
    structure.spec = ModelSpec{};
    ModelSpec variant = nominal;
    for (BodySpec& b : variant.bodies) {
      b.mass *= 1.25;
      b.com += Eigen::Vector3d(0.01, -0.02, 0.005);
      b.inertia *= 1.1;
    }
    const Model a = compile(variant, file);
    Model b = compile_numbers(structure, variant, {.bodies = true}, file);
    prepare_model(b);
    SCOPED_TRACE(file);
    EXPECT_EQ(a.mass, b.mass);
    EXPECT_EQ(a.com, b.com);
    EXPECT_EQ(a.inertia, b.inertia);
    EXPECT_EQ(a.body_names, b.body_names);
    EXPECT_EQ(a.v_names, b.v_names);
    EXPECT_EQ(a.q0, b.q0);
    EXPECT_EQ(a.v0, b.v0);
    EXPECT_EQ(to_json(a.spec), to_json(b.spec));
    Data da(a), db(b);
    const Eigen::VectorXd u = Eigen::VectorXd::Random(a.nu());
    const Eigen::VectorXd v = test::random_v(a, rng);
    EXPECT_EQ(forward_dynamics<double>(a, da, a.q0, v, u), forward_dynamics<double>(b, db, b.q0, v, u));
    // a bad mass: the error compile gives
    variant.bodies.back().mass = -1;
    std::string from_scratch, renumbered;
    try {
      compile(variant, file);
    } catch (const ModelError& e) {
      from_scratch = e.what();
    }
    try {
      compile_numbers(structure, variant, {.bodies = true}, file);
    } catch (const ModelError& e) {
      renumbered = e.what();
    }
    EXPECT_FALSE(from_scratch.empty());
    EXPECT_EQ(from_scratch, renumbered);
    ++examples;
  }
  EXPECT_GE(examples, 15);
  // another number of bodies is not a variant of the structure
  const Model structure = compile_structure(two_links());
  ModelSpec one = two_links();
  one.bodies.pop_back();
  EXPECT_THROW(compile_numbers(structure, one, {.bodies = true}), std::invalid_argument);
}

// compile_numbers(structure, variant, what) against compile(variant): the same error, or the same
// model (the effects, the assembled state, the nominal inputs, the spec, the constraint residual and
// the forward dynamics at a random velocity, bit for bit); returns false on an error
bool expect_same_as_compiling_again(const Model& structure, const ModelSpec& variant, NumbersChanged what,
                                    const std::string& file, std::mt19937& rng) {
  std::string from_scratch, renumbered;
  std::optional<Model> a, b;
  try {
    a = compile(variant, file);
  } catch (const ModelError& e) {
    from_scratch = e.what();
  }
  try {
    b = compile_numbers(structure, variant, what, file);
    prepare_model(*b);
  } catch (const ModelError& e) {
    renumbered = e.what();
  }
  EXPECT_EQ(from_scratch, renumbered);
  if (!a || !b) {
    EXPECT_EQ(a.has_value(), b.has_value());
    return false;
  }
  EXPECT_EQ(a->has_gravity, b->has_gravity);
  EXPECT_EQ(a->gravity, b->gravity);
  EXPECT_EQ(a->springs.size(), b->springs.size());
  EXPECT_EQ(a->bushings.size(), b->bushings.size());
  EXPECT_EQ(a->joint_springs.size(), b->joint_springs.size());
  EXPECT_EQ(a->joint_frictions.size(), b->joint_frictions.size());
  EXPECT_EQ(a->body_forces.size(), b->body_forces.size());
  EXPECT_EQ(a->q0, b->q0);
  EXPECT_EQ(a->v0, b->v0);
  EXPECT_EQ(a->u_nominal(), b->u_nominal());
  EXPECT_EQ(to_json(a->spec), to_json(b->spec));
  Data da(*a), db(*b);
  EXPECT_EQ(constraint_residual<double>(*a, da, a->q0), constraint_residual<double>(*b, db, b->q0));
  const Eigen::VectorXd u = Eigen::VectorXd::Random(a->nu());
  const Eigen::VectorXd v = test::random_v(*a, rng);
  EXPECT_EQ(forward_dynamics<double>(*a, da, a->q0, v, u), forward_dynamics<double>(*b, db, b->q0, v, u));
  EXPECT_EQ(a->plant_inputs, b->plant_inputs);
  EXPECT_EQ(a->plant_outputs, b->plant_outputs);
  EXPECT_EQ(a->motions, b->motions);
  EXPECT_EQ(a->nu(), b->nu());
  if (a->nu() != b->nu()) return false;
  for (int k = 0; k < a->nu(); ++k) {
    const ActuatorModel &x = a->actuators[k], &y = b->actuators[k];
    EXPECT_EQ(std::tie(x.name, x.type, x.iv, x.iq, x.body, x.body_b, x.in_world, x.unit, x.driven_by),
              std::tie(y.name, y.type, y.iv, y.iq, y.body, y.body_b, y.in_world, y.unit, y.driven_by));
    EXPECT_EQ(std::tie(x.gain, x.u0, x.min, x.max), std::tie(y.gain, y.u0, y.min, y.max));
    EXPECT_EQ(x.point, y.point);
    EXPECT_EQ(x.point_b, y.point_b);
    EXPECT_EQ(x.direction, y.direction);
  }
  EXPECT_EQ(a->ny(), b->ny());
  if (a->ny() != b->ny()) return false;
  std::vector<int> all(static_cast<std::size_t>(a->ny()));
  for (int k = 0; k < a->ny(); ++k) {
    all[static_cast<std::size_t>(k)] = k;
    EXPECT_EQ(a->sensors[k].name, b->sensors[k].name);
    EXPECT_EQ(a->sensors[k].unit, b->sensors[k].unit);
  }
  // the sensors read the kinematics and (acceleration, motion_force) the accelerations that
  // forward_dynamics keeps on the data
  Data sa(*a), sb(*b);
  forward_dynamics<double>(*a, sa, a->q0, v, a->u_nominal());
  forward_dynamics<double>(*b, sb, b->q0, v, b->u_nominal());
  EXPECT_EQ(sensor_outputs<double>(*a, sa, all, a->q0, v), sensor_outputs<double>(*b, sb, all, b->q0, v));
  return true;
}

// every example: its file, its JSON and its compiled structure, the structure's spec dropped
// (compile_numbers must not need it)
template <class F>
void for_each_example_structure(F&& f) {
  for (const auto& entry : std::filesystem::directory_iterator(CODYNA_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    const std::string file = entry.path().string();
    std::ifstream in(file);
    const nlohmann::json j = nlohmann::json::parse(in);
    Model structure = compile_structure(parse_model_spec(j, file), file);
    structure.spec = ModelSpec{};
    f(file, j, structure);
  }
}

// compile_numbers on the effects: every number of every effect of every example changed (a
// component at a time, x 1.1 + 0.01: stiffnesses, dampings, gravity, rest lengths, frames; integers
// + 1: coordinate indices, made invalid), each variant the model compile gives bit for bit, or its error
TEST(Compile, EffectNumbersOnTheStructureEqualCompilingAgain) {
  std::mt19937 rng(5);
  int variants = 0, errors = 0;
  for_each_example_structure([&](const std::string& file, const nlohmann::json& j, const Model& structure) {
    if (!j.contains("effects")) return;
    const nlohmann::json flat = j["effects"].flatten();
    for (const auto& [pointer, value] : flat.items()) {
      if (!value.is_number()) continue;
      nlohmann::json edited = j;
      const nlohmann::json::json_pointer at("/effects" + pointer);
      if (value.is_number_integer())
        edited[at] = value.get<long long>() + 1;
      else
        edited[at] = value.get<double>() * 1.1 + 0.01;
      SCOPED_TRACE(file + ": /effects" + pointer);
      const ModelSpec variant = parse_model_spec(edited, file);
      ++variants;
      errors += !expect_same_as_compiling_again(structure, variant, {.effects = true}, file, rng);
    }
  });
  EXPECT_GE(variants, 40);
  RecordProperty("variants", variants);
  RecordProperty("errors", errors);
}

// compile_numbers on the actuators and the sensors: every number of every actuator's and sensor's
// fields that NumbersChanged names, in every example (a component at a time, x 1.1 + 0.01; and each
// actuator made invalid, its min above its max), each variant the model compile gives bit for bit (the actuators'
// fields, the forward dynamics with every input nonzero, every sensor's value), or its error
TEST(Compile, ActuatorAndSensorNumbersOnTheStructureEqualCompilingAgain) {
  std::mt19937 rng(9);
  int variants = 0, errors = 0, refused = 0, actuators = 0, sensors = 0;
  const std::map<std::string, std::vector<std::string>> fields{
      {"actuators", {"gain", "u0", "min", "max", "point", "direction", "point_a", "point_b", "weights"}},
      {"sensors", {"point", "axis", "point_a", "point_b"}}};
  for_each_example_structure([&](const std::string& file, const nlohmann::json& j, const Model& structure) {
    // refused the same way: each actuator's min above its max
    if (j.contains("actuators"))
      for (std::size_t k = 0; k < j["actuators"].size(); ++k) {
        nlohmann::json edited = j;
        edited["actuators"][k]["min"] = 2.0;
        edited["actuators"][k]["max"] = 1.0;
        SCOPED_TRACE(file + ": /actuators/" + std::to_string(k) + "/min");
        ++variants;
        ++actuators;
        refused += !expect_same_as_compiling_again(structure, parse_model_spec(edited, file), {.actuators = true}, file, rng);
      }
    for (const auto& [section, names] : fields) {
      if (!j.contains(section)) continue;
      for (std::size_t k = 0; k < j[section].size(); ++k)
        for (const std::string& name : names) {
          if (!j[section][k].contains(name)) continue;
          const std::string at = "/" + section + "/" + std::to_string(k) + "/" + name;
          const nlohmann::json leaves = j[section][k][name].is_number() ? nlohmann::json::object({{"", j[section][k][name]}})
                                                                         : j[section][k][name].flatten();
          for (const auto& [leaf, value] : leaves.items()) {
            if (!value.is_number()) continue;
            nlohmann::json edited = j;
            const std::string field = at + leaf;
            edited[nlohmann::json::json_pointer(field)] = value.get<double>() * 1.1 + 0.01;
            SCOPED_TRACE(file + ": " + field);
            const ModelSpec variant = parse_model_spec(edited, file);
            ++variants;
            (section == "actuators" ? actuators : sensors) += 1;
            NumbersChanged what;
            (section == "actuators" ? what.actuators : what.sensors) = true;
            errors += !expect_same_as_compiling_again(structure, variant, what, file, rng);
          }
        }
    }
  });
  EXPECT_GE(actuators, 15);
  EXPECT_GE(sensors, 5);
  EXPECT_GE(refused, 15);  // every one of those edits is refused, by both
  EXPECT_EQ(errors, 0);
  RecordProperty("variants", variants);
  RecordProperty("refused", refused);
}

// compile_numbers on the joints' q0 and v0: every component of every joint's q0 and v0 in every
// example moved (+0.05), each variant the model compile gives bit for bit (the assembled state, the
// motion inputs' nominal values, the couplers' offsets through the constraint residual, the forward
// dynamics), or its error
TEST(Compile, InitialValuesOnTheStructureEqualCompilingAgain) {
  std::mt19937 rng(3);
  int variants = 0, errors = 0;
  for_each_example_structure([&](const std::string& file, const nlohmann::json& j, const Model& structure) {
    for (std::size_t k = 0; k < j["joints"].size(); ++k) {
      for (const char* key : {"q0", "v0"}) {
        if (!j["joints"][k].contains(key)) continue;
        // a number, a list, or an object of them (a free joint's position and rotation)
        const std::string at = "/joints/" + std::to_string(k) + "/" + key;
        const nlohmann::json leaves = j["joints"][k][key].flatten();
        for (const auto& [leaf, value] : leaves.items()) {
          if (!value.is_number()) continue;
          nlohmann::json edited = j;
          const std::string field = at + leaf;
          edited[nlohmann::json::json_pointer(field)] = value.get<double>() + 0.05;
          SCOPED_TRACE(file + ": " + field);
          const ModelSpec variant = parse_model_spec(edited, file);
          ++variants;
          errors += !expect_same_as_compiling_again(structure, variant, {.initial = true}, file, rng);
        }
      }
    }
  });
  EXPECT_GE(variants, 30);
  RecordProperty("variants", variants);
  RecordProperty("errors", errors);
}

TEST(CompileErrors, NegativeMass) {
  ModelSpec s = two_links();
  s.bodies[1].mass = -2;
  expect_error(s, "/bodies/1/mass", "non-negative mass");
}

TEST(CompileErrors, InertiaNotPositiveSemiDefinite) {
  ModelSpec s = two_links();
  s.bodies[0].inertia = Eigen::Vector3d(0.1, -0.1, 0.1).asDiagonal();
  expect_error(s, "/bodies/0/inertia", "positive semi-definite");
}

TEST(CompileErrors, InertiaViolatesTriangleInequality) {
  ModelSpec s = two_links();
  s.bodies[0].inertia = Eigen::Vector3d(0.01, 0.01, 0.5).asDiagonal();
  expect_error(s, "/bodies/0/inertia", "triangle inequality");
}

TEST(CompileErrors, JointNamesMissingBody) {
  ModelSpec s = two_links();
  s.joints[0].parent = "nobody";
  expect_error(s, "/joints/0/parent", "unknown body \"nobody\"");
}

TEST(CompileErrors, CycleInTheTree) {
  ModelSpec s = two_links();
  s.joints[1].parent = "b";  // a is moved by b and b by a
  expect_error(s, "/joints/0", "cycle");
}

TEST(CompileErrors, BodyWithoutJoint) {
  ModelSpec s = two_links();
  s.joints.erase(s.joints.begin());
  s.sensors.clear();
  s.plant.outputs.clear();
  expect_error(s, "/bodies/1", "not the child of any joint");
}

TEST(CompileErrors, BodyMovedTwice) {
  ModelSpec s = two_links();
  JointSpec j = s.joints[0];
  j.name = "again";
  j.parent = kGroundName;
  s.joints.push_back(j);
  expect_error(s, "/joints/2/child", "already moved by joint");
}

TEST(CompileErrors, DuplicateNames) {
  ModelSpec s = two_links();
  s.bodies[1].name = "a";
  expect_error(s, "/bodies/1/name", "duplicate body name");
}

TEST(CompileErrors, UnknownPlantInput) {
  ModelSpec s = two_links();
  s.plant.inputs = {"force"};
  expect_error(s, "/plant/inputs/0", "unknown actuator \"force\"");
}

TEST(CompileErrors, DofOutOfRange) {
  ModelSpec s = two_links();
  s.actuators[0].dof = 1;
  expect_error(s, "/actuators/0/dof", "coordinate index from 0 to 0");
}

TEST(CompileErrors, LoopThatCannotBeAssembled) {
  ModelSpec s = two_links();
  ConstraintSpec c;
  c.name = "too_far";
  c.type = ConstraintType::Ball;
  c.body_a = "b";
  c.point_a = Eigen::Vector3d(1, 0, 0);  // reaches at most 2 m from the origin
  c.body_b = kGroundName;
  c.point_b = Eigen::Vector3d(5, 0, 0);
  s.constraints.push_back(c);
  expect_error(s, "/constraints/0", "cannot be assembled");
}

TEST(CompileErrors, MasslessCoordinate) {
  ModelSpec s = two_links();
  s.bodies[1].mass = 0;
  s.bodies[1].inertia.setZero();
  expect_error(s, "/bodies", "mass matrix is singular");
}

TEST(CompileErrors, UnknownIntegrator) {
  ModelSpec s = two_links();
  s.solver.integrator = "euler";
  expect_error(s, "/solver/integrator", "unknown integrator");
}


// A long chain whose mass matrix spans many decades is a valid model (the singularity
// check is per joint and scale-aware), and a coordinate that moves nothing is still refused.
TEST(CompileErrors, LongChainIsNotSingularButAMasslessTipIs) {
  ModelSpec s;
  s.name = "chain";
  const int n = 1500;
  for (int i = 0; i < n; ++i) {
    BodySpec b;
    b.name = "b" + std::to_string(i);
    b.mass = 1;
    b.com = Eigen::Vector3d(0.5, 0, 0);
    b.inertia = Eigen::Vector3d(0.01, 0.1, 0.1).asDiagonal();
    s.bodies.push_back(b);
    JointSpec j;
    j.name = "j" + std::to_string(i);
    j.parent = i ? "b" + std::to_string(i - 1) : "ground";
    j.child = b.name;
    j.axis = i % 2 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
    j.parent_frame.position = Eigen::Vector3d(i ? 1.0 : 0.0, 0, 0);
    s.joints.push_back(j);
  }
  const Model m = compile(s);
  EXPECT_EQ(m.dof(), n);
  s.bodies.back().mass = 0;
  s.bodies.back().inertia.setZero();
  expect_error(s, "/bodies", "coordinate \"j1499\" moves no mass");
}

}  // namespace
}  // namespace codyna
