#include "variational_formation_core/model/scenario.hpp"

#include <charconv>
#include <cmath>
#include <type_traits>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/model/validation.hpp"

namespace vf {

namespace {

std::string describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a list";
  return "a mapping";
}

const YAML::Node required(const YAML::Node& map, const std::string& key, const std::string& field) {
  const YAML::Node node = map[key];
  if (!node.IsDefined() || node.IsNull()) throw InvalidInput(field + ": missing");
  return node;
}

double toFiniteDouble(const YAML::Node& node, const std::string& field) {
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value)) {
    throw InvalidInput(field + ": expected a number, got " + describe(node));
  }
  if (!std::isfinite(value)) throw InvalidInput(field + ": must be finite, got " + node.Scalar());
  return value;
}

long toInteger(const YAML::Node& node, const std::string& field) {
  long value = 0;
  if (!node.IsScalar() || !YAML::convert<long>::decode(node, value)) {
    throw InvalidInput(field + ": expected an integer, got " + describe(node));
  }
  return value;
}

/// An optional two-valued field: true for `yes`, false for `no` or when absent.
bool choice(const YAML::Node& map, const std::string& key, const std::string& yes, const std::string& no) {
  const YAML::Node node = map[key];
  if (!node.IsDefined() || node.IsNull()) return false;
  const std::string value = node.IsScalar() ? node.Scalar() : "";
  if (value != yes && value != no) throw InvalidInput(key + ": expected " + yes + " or " + no + ", got " + describe(node));
  return value == yes;
}

void rejectUnknownKeys(const YAML::Node& map, const std::set<std::string>& known,
                       const std::string& field) {
  for (const auto& kv : map) {
    const std::string key = kv.first.Scalar();
    if (!known.count(key)) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw InvalidInput((field.empty() ? key : field + "." + key) + ": unknown field (known: " +
                         list + ")");
    }
  }
}

Eigen::VectorXd toVector(const YAML::Node& node, int dimension, const std::string& field) {
  if (!node.IsSequence()) throw InvalidInput(field + ": expected a list of numbers, got " + describe(node));
  if (static_cast<int>(node.size()) != dimension) {
    throw InvalidInput(field + ": expected " + std::to_string(dimension) + " coordinates (dimension " +
                       std::to_string(dimension) + "), got " + std::to_string(node.size()));
  }
  Eigen::VectorXd v(dimension);
  for (int a = 0; a < dimension; ++a) {
    v(a) = toFiniteDouble(node[a], field + "[" + std::to_string(a) + "]");
  }
  return v;
}

// doc/manoeuvres.md: a list of {until, velocity, angular_rate, scale}; the numbers are checked
// by validateManoeuvre (validation.cpp).
std::vector<ManoeuvreSegment> parseManoeuvre(const YAML::Node& list, int dimension) {
  if (!list.IsSequence() || list.size() == 0) {
    throw InvalidInput("manoeuvre: expected a non-empty list of segments, got " + describe(list));
  }
  std::vector<ManoeuvreSegment> segments;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string field = "manoeuvre[" + std::to_string(i) + "]";
    const YAML::Node node = list[i];
    if (!node.IsMap()) throw InvalidInput(field + ": expected a mapping, got " + describe(node));
    rejectUnknownKeys(node, {"until", "velocity", "angular_rate", "scale"}, field);
    const auto given = [&](const char* key) { return node[key].IsDefined() && !node[key].IsNull(); };
    ManoeuvreSegment segment;
    if (given("until")) {
      segment.until = toFiniteDouble(node["until"], field + ".until");
    } else if (i + 1 < list.size()) {
      throw InvalidInput(field + ".until: missing (only the last segment may omit it)");
    } else {
      segment.until = std::numeric_limits<double>::infinity();
    }
    if (given("velocity")) {
      segment.command.velocity.head(dimension) = toVector(node["velocity"], dimension, field + ".velocity");
    }
    if (given("angular_rate")) {
      const std::string rate = field + ".angular_rate";
      if (dimension == 2) {
        if (!node["angular_rate"].IsScalar()) {
          throw InvalidInput(rate + ": expected a number (the rate about z in 2D), got " + describe(node["angular_rate"]));
        }
        segment.command.angularRate.z() = toFiniteDouble(node["angular_rate"], rate);
      } else {
        segment.command.angularRate = toVector(node["angular_rate"], 3, rate);
      }
    }
    if (given("scale")) segment.command.scale = toFiniteDouble(node["scale"], field + ".scale");
    segments.push_back(segment);
  }
  return segments;
}

bool given(const YAML::Node& map, const char* key) { return map[key].IsDefined() && !map[key].IsNull(); }

// doc/scenarios.md, "Keeping agents apart"; the numbers are checked by validateSafety.
SafetySettings parseSafety(const YAML::Node& node) {
  if (!node.IsMap()) throw InvalidInput("safety: expected a mapping, got " + describe(node));
  rejectUnknownKeys(node, {"radius", "sensing_radius", "gamma", "max_speed", "blocked_after"}, "safety");
  SafetySettings s;
  s.radius = toFiniteDouble(required(node, "radius", "safety.radius"), "safety.radius");
  s.sensingRadius = toFiniteDouble(required(node, "sensing_radius", "safety.sensing_radius"), "safety.sensing_radius");
  s.gamma = toFiniteDouble(required(node, "gamma", "safety.gamma"), "safety.gamma");
  if (given(node, "max_speed")) s.maxSpeed = toFiniteDouble(node["max_speed"], "safety.max_speed");
  if (given(node, "blocked_after")) s.blockedAfter = toFiniteDouble(node["blocked_after"], "safety.blocked_after");
  return s;
}

std::vector<Obstacle> parseObstacles(const YAML::Node& list, int dimension) {
  if (!list.IsSequence()) throw InvalidInput("obstacles: expected a list, got " + describe(list));
  std::vector<Obstacle> obstacles;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string field = "obstacles[" + std::to_string(k) + "]";
    const YAML::Node node = list[k];
    if (!node.IsMap()) throw InvalidInput(field + ": expected a mapping, got " + describe(node));
    rejectUnknownKeys(node, {"center", "radius", "min", "max"}, field);
    Obstacle o;
    if (given(node, "center") || given(node, "radius")) {
      if (given(node, "min") || given(node, "max")) {
        throw InvalidInput(field + ": either {center, radius} (a disc or ball) or {min, max} (a box), not both");
      }
      o.centre.head(dimension) = toVector(required(node, "center", field + ".center"), dimension, field + ".center");
      o.radius = toFiniteDouble(required(node, "radius", field + ".radius"), field + ".radius");
    } else {
      o.shape = Obstacle::Shape::Box;
      o.min.head(dimension) = toVector(required(node, "min", field + ".min"), dimension, field + ".min");
      o.max.head(dimension) = toVector(required(node, "max", field + ".max"), dimension, field + ".max");
    }
    obstacles.push_back(o);
  }
  return obstacles;
}

Scenario parseRoot(const YAML::Node& root) {
  if (!root.IsMap()) throw InvalidInput("scenario: expected a YAML mapping at the top level");
  rejectUnknownKeys(root,
                    {"name", "dimension", "kappa", "time_step", "steps", "agents", "edges", "manoeuvre",
                     "require_convergence", "mirror", "assignment", "safety", "obstacles"},
                    "");
  Scenario s;
  const YAML::Node name = required(root, "name", "name");
  if (!name.IsScalar() || name.Scalar().empty()) {
    throw InvalidInput("name: expected a non-empty string, got " + describe(name));
  }
  s.name = name.Scalar();
  const long dimension = toInteger(required(root, "dimension", "dimension"), "dimension");
  if (dimension != 2 && dimension != 3) {
    throw InvalidInput("dimension: must be 2 or 3, got " + std::to_string(dimension));
  }
  s.dimension = static_cast<int>(dimension);
  s.dampingGain = toFiniteDouble(required(root, "kappa", "kappa"), "kappa");
  s.timeStep = toFiniteDouble(required(root, "time_step", "time_step"), "time_step");
  s.steps = toInteger(required(root, "steps", "steps"), "steps");
  if (root["require_convergence"].IsDefined() && !root["require_convergence"].IsNull()) {
    const YAML::Node r = root["require_convergence"];
    const std::string v = r.IsScalar() ? r.Scalar() : "";
    if (v == "true") {
      s.requireConvergence = true;
    } else if (v != "false") {
      throw InvalidInput("require_convergence: expected true or false, got " + describe(r));
    }
  }

  s.mirrorAllowed = choice(root, "mirror", "allowed", "forbidden");
  s.autoAssignment = choice(root, "assignment", "auto", "none");

  const YAML::Node agents = required(root, "agents", "agents");
  if (!agents.IsSequence() || agents.size() == 0) {
    throw InvalidInput("agents: expected a non-empty list, got " + describe(agents));
  }
  const int n = static_cast<int>(agents.size());
  s.initialPositions.resize(s.dimension, n);
  s.initialVelocities.setZero(s.dimension, n);
  s.desiredPositions.resize(s.dimension, n);
  for (int i = 0; i < n; ++i) {
    const std::string field = "agents[" + std::to_string(i) + "]";
    const YAML::Node agent = agents[i];
    if (!agent.IsMap()) throw InvalidInput(field + ": expected a mapping, got " + describe(agent));
    rejectUnknownKeys(agent, {"id", "initial_position", "initial_velocity", "desired_position",
                              "initial_heading"},
                      field);
    const long id = toInteger(required(agent, "id", field + ".id"), field + ".id");
    if (id != i) {
      throw InvalidInput(field + ".id: ids must be 0..n-1 in order; expected " +
                         std::to_string(i) + ", got " + std::to_string(id));
    }
    s.initialPositions.col(i) = toVector(required(agent, "initial_position", field + ".initial_position"),
                                         s.dimension, field + ".initial_position");
    if (agent["initial_velocity"].IsDefined() && !agent["initial_velocity"].IsNull()) {
      s.initialVelocities.col(i) =
          toVector(agent["initial_velocity"], s.dimension, field + ".initial_velocity");
    }
    s.desiredPositions.col(i) = toVector(required(agent, "desired_position", field + ".desired_position"),
                                         s.dimension, field + ".desired_position");
    if (agent["initial_heading"].IsDefined() && !agent["initial_heading"].IsNull()) {
      s.initialHeadings.resize(static_cast<std::size_t>(n), 0.0);
      s.initialHeadings[static_cast<std::size_t>(i)] =
          toFiniteDouble(agent["initial_heading"], field + ".initial_heading");
    }
  }

  const YAML::Node edges = root["edges"];
  if (edges.IsDefined() && !edges.IsNull()) {
    if (!edges.IsSequence()) throw InvalidInput("edges: expected a list of [i, j] pairs, got " + describe(edges));
    for (std::size_t e = 0; e < edges.size(); ++e) {
      const std::string field = "edges[" + std::to_string(e) + "]";
      const YAML::Node pair = edges[e];
      if (!pair.IsSequence() || pair.size() != 2) {
        throw InvalidInput(field + ": expected a pair [i, j], got " + describe(pair));
      }
      const long i = toInteger(pair[0], field + "[0]");
      const long j = toInteger(pair[1], field + "[1]");
      const auto clamp = [](long x) {
        return static_cast<int>(std::max<long>(std::min<long>(x, std::numeric_limits<int>::max()),
                                               std::numeric_limits<int>::min()));
      };
      s.edges.emplace_back(clamp(i), clamp(j));
    }
  }
  const YAML::Node manoeuvre = root["manoeuvre"];
  if (manoeuvre.IsDefined() && !manoeuvre.IsNull()) s.manoeuvre = parseManoeuvre(manoeuvre, s.dimension);
  if (given(root, "safety")) s.safety = parseSafety(root["safety"]);
  if (given(root, "obstacles")) s.obstacles = parseObstacles(root["obstacles"], s.dimension);
  return s;
}

}  // namespace

Scenario parseScenario(const std::string& yamlText, const std::string& source) {
  try {
    Scenario s = parseRoot(YAML::Load(yamlText));
    validateScenario(s);
    if (s.autoAssignment) {
      applySlotAssignment(s);
      validateScenario(s);  // the warnings of the assigned formation (its start and edges changed)
    }
    return s;
  } catch (const YAML::Exception& e) {
    std::ostringstream msg;
    msg << source << ": YAML error at line " << e.mark.line + 1 << ", column " << e.mark.column + 1
        << ": " << e.msg;
    throw InvalidInput(msg.str());
  } catch (const InvalidInput& e) {
    throw InvalidInput(source + ": " + e.what());
  }
}

namespace {

/// The whole text of a file; `what` names it in errors ("<path>: cannot open the <what> file").
std::string readTextFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InvalidInput(path + ": is a directory, not a " + what + " file");
  std::ifstream in(path);
  if (!in) throw InvalidInput(path + ": cannot open the " + what + " file");
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InvalidInput(path + ": cannot read the " + what + " file");
  return text.str();
}

}  // namespace

Scenario loadScenario(const std::string& path) { return parseScenario(readTextFile(path, "scenario"), path); }

namespace {

std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) return fields;
    start = comma + 1;
  }
}

template <class T>
T parseField(const std::string& text, const std::string& field) {
  T value{};
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, value);
  if (text.empty() || result.ec != std::errc() || result.ptr != end) {
    throw InvalidInput(field + ": expected " + (std::is_integral<T>::value ? "an integer" : "a number") +
                       ", got '" + text + "'");
  }
  return value;
}

}  // namespace

CommandSchedule parseCommands(const std::string& text, const std::string& source, const Scenario& scenario) {
  std::istringstream in(text);
  std::string line;
  long number = 0;
  const auto next = [&]() {
    if (!std::getline(in, line)) return false;
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  try {
    if (!next() || line != kCommandsHeader) {
      throw InvalidInput("line 1: expected the header '" + std::string(kCommandsHeader) + "', got '" + line + "'");
    }
    static const char* const kColumns[] = {"step", "vx", "vy", "vz", "wx", "wy", "wz", "scale"};
    CommandSchedule schedule;
    while (next()) {
      if (line.empty()) continue;
      const std::string where = "line " + std::to_string(number);
      const std::vector<std::string> fields = splitFields(line);
      if (fields.size() != 8) {
        throw InvalidInput(where + ": expected 8 columns (" + kCommandsHeader + "), got " + std::to_string(fields.size()));
      }
      const long step = parseField<long>(fields[0], where + ": step");
      double x[7];
      for (int c = 0; c < 7; ++c) x[c] = parseField<double>(fields[c + 1], where + ": " + kColumns[c + 1]);
      Command command;
      command.velocity = Vector3(x[0], x[1], x[2]);
      command.angularRate = Vector3(x[3], x[4], x[5]);
      command.scale = x[6];
      validateCommand(command, scenario.dimension, scenario.timeStep, CommandFieldNames::columns(where));
      if (step < 0) throw InvalidInput(where + ": step: must be >= 0, got " + std::to_string(step));
      schedule.add(step, command, where + ": step");
    }
    if (schedule.empty()) throw InvalidInput("no command rows after the header");
    if (schedule.rotates()) checkFormationCanTurn(makeFormation(scenario), "wx,wy,wz");
    return schedule;
  } catch (const InvalidInput& e) {
    throw InvalidInput(source + ": " + e.what());
  }
}

Positions parseStartPositions(const std::string& text, const std::string& source, const Scenario& scenario) {
  std::istringstream in(text);
  std::string line;
  long number = 0;
  const int n = scenario.agentCount();
  Positions q(scenario.dimension, n);
  std::vector<bool> seen(static_cast<std::size_t>(n), false);
  try {
    if (!std::getline(in, line) || (++number, line) != "agent,x,y,z") {
      throw InvalidInput("line 1: expected the header 'agent,x,y,z', got '" + line + "'");
    }
    while (std::getline(in, line)) {
      ++number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.empty()) continue;
      const std::string where = "line " + std::to_string(number);
      const std::vector<std::string> fields = splitFields(line);
      if (fields.size() != 4) throw InvalidInput(where + ": expected 4 columns (agent,x,y,z), got " + std::to_string(fields.size()));
      const long id = parseField<long>(fields[0], where + ": agent");
      if (id < 0 || id >= n) {
        throw InvalidInput(where + ": agent: " + std::to_string(id) + " is not in the scenario (ids 0.." + std::to_string(n - 1) + ")");
      }
      if (seen[static_cast<std::size_t>(id)]) throw InvalidInput(where + ": agent: " + std::to_string(id) + " given twice");
      seen[static_cast<std::size_t>(id)] = true;
      static const char* const kAxes[] = {"x", "y", "z"};
      for (int a = 0; a < 3; ++a) {
        const double x = parseField<double>(fields[a + 1], where + ": " + kAxes[a]);
        if (!std::isfinite(x)) throw InvalidInput(where + ": " + kAxes[a] + ": must be finite, got " + fields[a + 1]);
        if (a < scenario.dimension) {
          q(a, id) = x;
        } else if (x != 0.0) {
          throw InvalidInput(where + ": z: must be 0 in a 2D scenario, got " + fields[3]);
        }
      }
    }
    for (int i = 0; i < n; ++i) {
      if (!seen[static_cast<std::size_t>(i)]) throw InvalidInput("agent " + std::to_string(i) + ": no row (every agent needs one)");
    }
    return q;
  } catch (const InvalidInput& e) {
    throw InvalidInput(source + ": " + e.what());
  }
}

Positions loadStartPositions(const std::string& path, const Scenario& scenario) {
  return parseStartPositions(readTextFile(path, "start positions"), path, scenario);
}

CommandSchedule loadCommands(const std::string& path, const Scenario& scenario) {
  return parseCommands(readTextFile(path, "commands"), path, scenario);
}

void applySlotAssignment(Scenario& s) {
  const int n = s.agentCount();
  if (n > kMaxAssignedAgents) {
    throw InvalidInput("assignment: auto is for at most " + std::to_string(kMaxAssignedAgents) +
                       " agents (every agent runs the O(n^3) Hungarian method at start-up), got " + std::to_string(n) +
                       "; run assign_slots once and launch its output");
  }
  s.assignment = assignSlots(s.initialPositions, s.desiredPositions, s.mirrorAllowed);
  const std::vector<int>& slot = s.assignment.slotOfAgent;
  std::vector<int> agentOf(static_cast<std::size_t>(n));
  const Positions slots = s.desiredPositions;
  for (int i = 0; i < n; ++i) {
    s.desiredPositions.col(i) = slots.col(slot[i]);
    agentOf[static_cast<std::size_t>(slot[i])] = i;
  }
  // Edges join slots: the agents that took slots a and b are linked.
  for (auto& e : s.edges) e = {agentOf[static_cast<std::size_t>(e.first)], agentOf[static_cast<std::size_t>(e.second)]};
}

Formation makeFormation(const Scenario& s) {
  if (s.initialPositions.cols() != s.desiredPositions.cols() ||
      s.initialVelocities.cols() != s.desiredPositions.cols()) {
    throw InvalidInput("agents: initial and desired positions differ in count");
  }
  return Formation(s.dimension, s.desiredPositions, s.edges);
}

}  // namespace vf
