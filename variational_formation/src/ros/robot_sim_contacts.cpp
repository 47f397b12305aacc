// robot_sim's body contacts (RobotSimNode, robot_sim_node.hpp; doc/robots.md "Contacts"): the
// robots' true poses, BodyContacts, ~contacts, the diagnostics and the result file's lines.
#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/common/number_checks.hpp"
#include "variational_formation/ros/parameters.hpp"
#include "variational_formation/ros/output_files.hpp"
#include "variational_formation/ros/robot_sim_node.hpp"
#include "variational_formation/ros/world_contact.hpp"

namespace vf {

void RobotSimNode::setUpContacts(ros::NodeHandle& nh, ros::NodeHandle& pnh, int id) {
  const int robots = optionalParam(pnh, "robots", 0);
  const double bodyRadius = optionalParam(pnh, "body_radius", kBurgerBodyRadius);
  resultFile_ = optionalParam<std::string>(pnh, "result_file", "");
  const bool count = optionalParam(pnh, "count_contacts", !resultFile_.empty());
  if (robots < 0) throw InvalidInput("~robots: must be >= 0, got " + std::to_string(robots));
  if (robots == 0) {
    if (count) throw InvalidInput("~count_contacts, ~result_file: contacts are counted only with ~robots > 0");
    return;
  }
  if (id >= robots) {
    throw InvalidInput("~id: must be below ~robots (" + std::to_string(robots) + "), got " + std::to_string(id));
  }
  if (!resultFile_.empty() && !count) throw InvalidInput("~result_file: needs ~count_contacts true");
  try {
    contacts_ = std::make_unique<BodyContacts>(robots, bodyRadius);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("~") + e.what());
  }
  // Every robot tells where its body is; one robot (or a few) reads them all and counts.
  truthPub_ = nh.advertise<nav_msgs::Odometry>("ground_truth", 10);
  if (!count) return;
  // The other robots are robot_<j> beside this one: formation/robot_0 -> formation/robot_<j>.
  const std::string parent = ros::names::parentNamespace(nh.getNamespace());
  const std::string beside = parent == "/" ? "/" : parent + "/";
  for (int j = 0; j < robots; ++j) {
    if (j == id) continue;
    others_.push_back(nh.subscribe<nav_msgs::Odometry>(
        beside + "robot_" + std::to_string(j) + "/ground_truth", 10,
        [this, j](const nav_msgs::Odometry::ConstPtr& m) {
          const auto& p = m->pose.pose.position;
          contacts_->setPosition(j, p.x, p.y, p.z);
        },
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  contactPub_ = pnh.advertise<variational_formation_msgs::WorldContact>("contacts", 100);
  if (!resultFile_.empty()) {
    resultFile_ = outputPath(ros::NodeHandle(parent), resultFile_);  // {ns}: the formation's, as the monitor's
    progressSub_ = nh.subscribe(beside + "progress", 10, &RobotSimNode::onProgress, this);
  }
  counting_ = true;
  diagnostics_ = std::make_unique<diagnostic_updater::Updater>(nh, pnh);
  diagnostics_->setHardwareID(childFrame_);
  diagnostics_->add("robot_sim", this, &RobotSimNode::diagnose);
}

void RobotSimNode::checkContacts(const ros::Time& stamp) {
  // Times from the run's start (the monitor's RUNNING progress), else from this robot's first
  // tick: as the MuJoCo world's, from 0.
  if (origin_.isZero()) origin_ = stamp;
  for (const ContactEvent& c : contacts_->check((stamp - origin_).toSec())) {
    contactPub_.publish(worldContactMessage(c, stamp, worldFrame_, contacts_->log().count()));
    ROS_WARN("%s: contact %ld at t = %.3f s: %s and %s (bodies closer than %g m)", ros::this_node::getName().c_str(),
             contacts_->log().count(), c.time, c.first.c_str(), c.second.c_str(), 2.0 * contacts_->bodyRadius());
  }
  if (runOver_ && !resultWritten_) {
    // The monitor writes the file before it says the run is over; this robot adds its lines.
    const Appended appended = appendToResult(resultFile_, contacts_->log().resultLines());
    resultWritten_ = appended != Appended::notYet;  // a failure is said once, not every tick
    if (appended == Appended::done) {
      ROS_INFO("%s: %ld contacts; closest body centres %.4f m (diameter %g m)", ros::this_node::getName().c_str(),
               contacts_->log().count(), contacts_->closest(), 2.0 * contacts_->bodyRadius());
    }
  }
  diagnostics_->update();
}

void RobotSimNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const ContactLog& c = contacts_->log();
  status.summary(c.count() > 0 ? diagnostic_msgs::DiagnosticStatus::WARN : diagnostic_msgs::DiagnosticStatus::OK,
                 c.count() > 0 ? std::to_string(c.count()) + " contacts" : "no contacts");
  status.add("contacts", c.count());
  status.add("touching now", c.active());
  status.add("first contact", c.first() ? "t = " + formatNumber(c.first()->time) + " s, " + c.first()->first +
                                              " and " + c.first()->second
                                        : std::string("none"));
  status.add("closest body distance [m]", contacts_->closest());
  status.add("body radius [m]", contacts_->bodyRadius());
  status.add("cmd_vel dropped", malformed_);
}

void RobotSimNode::onProgress(const variational_formation_msgs::RunProgress::ConstPtr& msg) {
  if (msg->state == variational_formation_msgs::RunProgress::RUNNING && !runStarted_) {
    runStarted_ = true;
    origin_ = ros::Time::now();
  }
  runOver_ = msg->state == variational_formation_msgs::RunProgress::FINISHED ||
             msg->state == variational_formation_msgs::RunProgress::FAILED;
}

}  // namespace vf
