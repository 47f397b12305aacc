#include "variational_formation/world/mujoco_world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>

#include <mujoco/mujoco.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"

namespace vf {

namespace {

// MuJoCo's errors end the process by default after writing MUJOCO_LOG.TXT into the working
// folder; here they are one line on stderr. Warnings (counted in mjData) are not written anywhere.
void onMujocoError(const char* message) {
  std::fprintf(stderr, "MuJoCo error: %s\n", message);
  std::exit(1);
}
void onMujocoWarning(const char*) {}

void installHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = onMujocoError;
    mju_user_warning = onMujocoWarning;
  });
}

// MuJoCo's parser errors span lines; the package's errors are one line.
std::string oneLine(const char* text) {
  std::string line;
  for (const char* c = text; *c; ++c) {
    if (*c != '\n') line += *c;
    else if (c[1] != '\0') line += "; ";
  }
  return line;
}

mjModel* loadText(const std::string& mjcf, const std::string& source) {
  installHandlers();
  // The text goes through MuJoCo's virtual file system: no temporary file. mjVFS holds 2000
  // names, too large for the stack.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "variational_formation_world.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(mjcf.size())) != 0) {
    throw InvalidInput("model: " + source + ": MuJoCo cannot hold the text");
  }
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name)], mjcf.data(), mjcf.size());
  char error[1000] = "";
  mjModel* model = mj_loadXML(name, vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (!model) throw InvalidInput("model: " + source + ": " + oneLine(error));
  return model;
}

mjModel* loadFile(const std::string& path) {
  installHandlers();
  char error[1000] = "";
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  if (!model) throw InvalidInput("model: " + path + ": " + (error[0] ? oneLine(error) : "cannot be read"));
  return model;
}

double wrap(double angle) { return std::atan2(std::sin(angle), std::cos(angle)); }

}  // namespace

MujocoWorld::MujocoWorld(const std::string& mjcf, const std::string& source, int robots,
                         const WorldSettings& settings)
    : MujocoWorld(loadText(mjcf, source), source, robots, settings) {}

std::unique_ptr<MujocoWorld> MujocoWorld::fromFile(const std::string& path, int robots,
                                                   const WorldSettings& settings) {
  return std::unique_ptr<MujocoWorld>(new MujocoWorld(loadFile(path), path, robots, settings));
}

MujocoWorld::MujocoWorld(mjModel* model, const std::string& source, int robots, const WorldSettings& settings)
    : settings_(settings), model_(model), contacts_(robots) {
  try {
    validateWorldSettings(settings_);
    if (robots < 1) throw InvalidInput("robots: a world needs at least one robot, got " + std::to_string(robots));
    model_->opt.timestep = settings_.timeStep;
    data_ = mj_makeData(model_);
    if (!data_) throw InvalidInput("model: " + source + ": MuJoCo cannot allocate its data");
    bind(source, robots);
  } catch (...) {
    if (data_) mj_deleteData(data_);
    mj_deleteModel(model_);
    throw;
  }
  mj_forward(model_, data_);
  stale_ = false;
  if (settings_.kinematics == WorldKinematics::Unicycle) {
    for (Robot& r : robots_) {
      r.odometry = std::make_unique<WheelOdometry>(pose(static_cast<int>(&r - robots_.data())),
                                                   settings_.drive.wheelRadius, settings_.drive.track,
                                                   jointPosition(r.joints[0]), jointPosition(r.joints[1]));
    }
  }
}

MujocoWorld::~MujocoWorld() {
  mj_deleteData(data_);
  mj_deleteModel(model_);
}

void MujocoWorld::bind(const std::string& source, int robots) {
  const bool unicycle = settings_.kinematics == WorldKinematics::Unicycle;
  const std::vector<std::string> parts =
      unicycle ? std::vector<std::string>{"left_wheel", "right_wheel"} : std::vector<std::string>{"x", "y", "yaw"};
  participantOfBody_.assign(static_cast<std::size_t>(model_->nbody), -1);
  for (int i = 0; i < robots; ++i) {
    const std::string name = "robot_" + std::to_string(i);
    Robot r;
    r.body = mj_name2id(model_, mjOBJ_BODY, name.c_str());
    if (r.body < 0) throw InvalidInput("model: " + source + ": no body named " + name);
    if (model_->body_rootid[r.body] != r.body) {
      throw InvalidInput("model: " + source + ": body " + name + " must be a child of the worldbody");
    }
    for (const std::string& part : parts) {
      const std::string full = name + "_" + part;
      const int joint = mj_name2id(model_, mjOBJ_JOINT, full.c_str());
      const int actuator = mj_name2id(model_, mjOBJ_ACTUATOR, full.c_str());
      if (joint < 0 || actuator < 0) {
        throw InvalidInput("model: " + source + ": " + kinematicsName(settings_.kinematics) + " robot " + name +
                           " needs a joint and an actuator named " + full);
      }
      r.joints.push_back(joint);
      r.actuators.push_back(actuator);
      r.jointNames.push_back(part);
    }
    participantOfBody_[static_cast<std::size_t>(r.body)] = i;
    bodyGeoms_.push_back(mj_name2id(model_, mjOBJ_GEOM, (name + "_body").c_str()));
    robots_.push_back(std::move(r));
  }
  // Obstacles, numbered in the order of the model's geoms named obstacle_*.
  obstacleOfGeom_.assign(static_cast<std::size_t>(model_->ngeom), -1);
  int obstacles = 0;
  for (int g = 0; g < model_->ngeom; ++g) {
    const char* name = mj_id2name(model_, mjOBJ_GEOM, g);
    if (name && std::strncmp(name, "obstacle_", 9) == 0) obstacleOfGeom_[static_cast<std::size_t>(g)] = obstacles++;
  }
}

const MujocoWorld::Robot& MujocoWorld::robot(int i) const {
  if (i < 0 || i >= robotCount()) {
    throw InvalidInput("robot: expected an index in [0, " + std::to_string(robotCount()) + "), got " +
                       std::to_string(i));
  }
  return robots_[static_cast<std::size_t>(i)];
}

bool MujocoWorld::setCommand(int i, double linear, double lateral, double angular) {
  const Robot& r = robot(i);
  if (!std::isfinite(linear) || !std::isfinite(lateral) || !std::isfinite(angular)) {
    throw InvalidInput("cmd_vel: must be finite, got linear " + formatNumber(linear) + ", " + formatNumber(lateral) +
                       " and angular " + formatNumber(angular));
  }
  double* ctrl = data_->ctrl;
  if (settings_.kinematics == WorldKinematics::Unicycle) {
    const DifferentialDriveSettings& d = settings_.drive;
    // Wheel speeds of (v, w); both scaled by one factor, so the path's curvature is kept.
    double left = (linear - 0.5 * d.track * angular) / d.wheelRadius;
    double right = (linear + 0.5 * d.track * angular) / d.wheelRadius;
    const double fastest = std::max(std::abs(left), std::abs(right));
    const bool saturated = fastest > d.maxWheelSpeed;
    if (saturated) {
      left *= d.maxWheelSpeed / fastest;
      right *= d.maxWheelSpeed / fastest;
    }
    ctrl[r.actuators[0]] = left;
    ctrl[r.actuators[1]] = right;
    return saturated;
  }
  const double speed = std::hypot(linear, lateral);
  const bool saturated = speed > settings_.base.maxSpeed;
  const double scale = saturated ? settings_.base.maxSpeed / speed : 1.0;
  ctrl[r.actuators[0]] = scale * linear;
  ctrl[r.actuators[1]] = scale * lateral;
  ctrl[r.actuators[2]] = angular;
  return saturated;
}

std::vector<Touch> MujocoWorld::touching() const {
  std::map<std::pair<int, int>, Touch> pairs;
  std::map<std::pair<int, int>, int> points;  // contact points per pair, for their mean
  const int robots = robotCount();
  for (int k = 0; k < data_->ncon; ++k) {
    const mjContact& c = data_->contact[k];
    int side[2];
    for (int s = 0; s < 2; ++s) {
      const int geom = s == 0 ? c.geom1 : c.geom2;
      const int root = model_->body_rootid[model_->geom_bodyid[geom]];
      const int obstacle = obstacleOfGeom_[static_cast<std::size_t>(geom)];
      side[s] = participantOfBody_[static_cast<std::size_t>(root)];
      if (side[s] < 0 && obstacle >= 0) side[s] = robots + obstacle;
    }
    // Robot-robot and robot-obstacle only: the floor, and a robot's own parts, are not contacts.
    if (side[0] < 0 || side[1] < 0 || side[0] == side[1] || (side[0] >= robots && side[1] >= robots)) continue;
    mjtNum force[6];
    mj_contactForce(model_, data_, k, force);
    Touch& t = pairs[std::minmax(side[0], side[1])];
    t.a = std::min(side[0], side[1]);
    t.b = std::max(side[0], side[1]);
    t.normalForce += force[0];
    t.penetration = std::max(t.penetration, -c.dist);
    t.x += c.pos[0];
    t.y += c.pos[1];
    ++points[{t.a, t.b}];
  }
  std::vector<Touch> out;
  for (auto& entry : pairs) {
    const int count = points[entry.first];
    entry.second.x /= count;
    entry.second.y /= count;
    out.push_back(entry.second);
  }
  return out;
}

void MujocoWorld::step() {
  const double before = data_->time;
  mj_step(model_, data_);
  stale_ = true;
  // MuJoCo resets the state when an acceleration is not finite: the run is no longer physics.
  const int unstable = data_->warning[mjWARN_BADQACC].number;
  if (unstable > unstableSeen_) {
    unstableSeen_ = unstable;
    throw InvalidInput("time_step: the physics became unstable at t = " + formatNumber(before) +
                       " s and MuJoCo reset it; a smaller time_step or more wheel_armature steadies it");
  }
  // The contacts and forces of this step are those of the state it started from.
  touches_ = touching();
  newContacts_ = contacts_.record(before, touches_);
  for (Robot& r : robots_) {
    if (r.odometry) r.odometry->update(jointPosition(r.joints[0]), jointPosition(r.joints[1]));
  }
}

double MujocoWorld::time() const { return data_->time; }

double MujocoWorld::jointPosition(int joint) const { return data_->qpos[model_->jnt_qposadr[joint]]; }

void MujocoWorld::refresh() const {
  if (!stale_) return;
  // Body poses and velocities of the current qpos, qvel (mj_step leaves those of the step's start).
  mj_kinematics(model_, data_);
  mj_comPos(model_, data_);
  mj_comVel(model_, data_);
  stale_ = false;
}

PlanarPose MujocoWorld::pose(int i) const {
  const Robot& r = robot(i);
  refresh();
  const mjtNum* p = data_->xpos + 3 * r.body;
  const mjtNum* q = data_->xquat + 4 * r.body;  // w, x, y, z
  const double heading = std::atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]));
  return {p[0], p[1], wrap(heading)};
}

BaseTwist MujocoWorld::twist(int i) const {
  const Robot& r = robot(i);
  refresh();
  mjtNum v[6];  // angular, then linear, in the body's frame
  mj_objectVelocity(model_, data_, mjOBJ_XBODY, r.body, v, 1);  // XBODY: the body frame, not the inertial one
  return {v[3], v[4], v[2]};
}

PlanarPose MujocoWorld::wheelOdometry(int i) const {
  const Robot& r = robot(i);
  if (!r.odometry) throw InvalidInput("odometry: wheel odometry needs kinematics unicycle (wheels)");
  return r.odometry->pose();
}

JointReadings MujocoWorld::joints(int i) const {
  const Robot& r = robot(i);
  JointReadings out;
  out.names = r.jointNames;
  for (std::size_t k = 0; k < r.joints.size(); ++k) {
    out.position.push_back(jointPosition(r.joints[k]));
    out.velocity.push_back(data_->qvel[model_->jnt_dofadr[r.joints[k]]]);
    out.effort.push_back(data_->actuator_force[r.actuators[k]]);
  }
  return out;
}

std::vector<double> MujocoWorld::actuatorForces(int i) const {
  const Robot& r = robot(i);
  std::vector<double> out;
  for (int a : r.actuators) out.push_back(data_->actuator_force[a]);
  return out;
}

BodyOutline MujocoWorld::bodyOutline(int i) const {
  const Robot& r = robot(i);
  refresh();
  const int geom = bodyGeoms_[static_cast<std::size_t>(i)];
  if (geom >= 0 && model_->geom_type[geom] == mjGEOM_CYLINDER) {
    const mjtNum* p = data_->geom_xpos + 3 * geom;
    return {p[0], p[1], p[2], model_->geom_size[3 * geom], model_->geom_size[3 * geom + 1]};
  }
  const mjtNum* p = data_->xpos + 3 * r.body;
  return {p[0], p[1], p[2], settings_.bodyRadius, 0.04};
}

std::vector<ObstacleGeom> MujocoWorld::obstacleGeoms() const {
  refresh();
  std::vector<ObstacleGeom> out;
  for (int g = 0; g < model_->ngeom; ++g) {
    if (obstacleOfGeom_[static_cast<std::size_t>(g)] < 0) continue;
    ObstacleGeom o;
    switch (model_->geom_type[g]) {
      case mjGEOM_CYLINDER: o.type = ObstacleGeom::Type::Cylinder; break;
      case mjGEOM_BOX: o.type = ObstacleGeom::Type::Box; break;
      case mjGEOM_SPHERE: o.type = ObstacleGeom::Type::Sphere; break;
      default: o.type = ObstacleGeom::Type::Other; break;
    }
    mju_copy(o.position, data_->geom_xpos + 3 * g, 3);
    mju_mat2Quat(o.quaternion, data_->geom_xmat + 9 * g);
    mju_copy(o.size, model_->geom_size + 3 * g, 3);
    out.push_back(o);
  }
  return out;
}

}  // namespace vf
