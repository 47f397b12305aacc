// What the monitor publishes and writes, in both modes: a completed step's status, markers and
// /clock, and at the end the result file and the final progress (MonitorNode, monitor_node.hpp).
#include <fstream>
#include <limits>
#include <sstream>

#include <rosgraph_msgs/Clock.h>

#include "variational_formation_core/agents/run_verdict.hpp"
#include "variational_formation_core/common/yaml_text.hpp"
#include "variational_formation/ros/markers.hpp"
#include "variational_formation/ros/monitor_node.hpp"
#include "variational_formation/ros/output_files.hpp"
#include "variational_formation/ros/progress_message.hpp"

namespace vf {

MonitorNode::Published MonitorNode::publishSnapshot(const FormationSnapshot& s, const ros::Time& stamp,
                                                    double dataAge, bool noetherHolds) {
  const ros::WallTime now = ros::WallTime::now();
  if (s.metrics.step == 0) firstStepAt_ = now;
  lastCompletedAt_ = now;
  trails_.add(s.metrics.step, s.positions);
  Published out;
  FormationStatus& status = out.first;
  status = toStatusMessage(s);
  status.header.stamp = stamp;
  status.header.frame_id = worldFrame_;
  status.dropped = static_cast<uint32_t>(dropped_);
  status.max_data_age = dataAge;
  status.commands = static_cast<uint32_t>(commandsIssued());
  status.shape_error = s.shape.shapeError;  // NaN at steps it skips (FormationSnapshot::shape)
  noteShape(s);
  status.min_separation = std::numeric_limits<double>::quiet_NaN();  // without a safety block (FormationStatus.msg)
  const bool blocked = watchSafety(s, status);
  watchRobots(s, status);
  if (!noetherHolds) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    status.linear_momentum_predicted.x = status.linear_momentum_predicted.y = status.linear_momentum_predicted.z = nan;
    status.angular_momentum_predicted.x = status.angular_momentum_predicted.y = nan;
    status.angular_momentum_predicted.z = nan;
  }
  statusPub_.publish(status);
  steerGoal(s, status.constraints_active > 0, stamp);
  const long step = s.metrics.step, last = scenario_.steps;
  const bool edge = step == 0 || (last > 0 && step == last);
  if (publishClock_) {
    clockDue_ = stamp;
    if (edge || (now - clockAt_).toSec() >= kClockPeriod) publishClock();
  }
  // Markers cost O(n + |E|) per step (trails thinned to a bound, Trails): built only when someone
  // takes them (the recorder, a viewer), every marker_every steps, and always at the first and
  // last step so that the latched one is right. The trails above still get every step. The
  // trails and the ghost, most of an array's bytes, come every allMarkersEvery_ steps only (and
  // at the first and last step): rviz keeps the last ones it got.
  if (edge || (step % markerEvery_ == 0 && (recording_ || markersPub_.getNumSubscribers() > 0))) {
    const bool all = edge || allMarkersStep_ < 0 || step < allMarkersStep_ || step - allMarkersStep_ >= allMarkersEvery_;
    if (all) allMarkersStep_ = step;
    // A robot run's agents are halos round the robots' bodies, which their world draws.
    out.second = makeMarkers(s, measure().formation(), trails_, commandSchedule(), scenario_.timeStep,
                             all ? MarkerParts::All : MarkerParts::Moving,
                             robots_ ? AgentSpheres::Halos : AgentSpheres::Solid);
    if (scenario_.safety) addSafetyMarkers(s, *scenario_.safety, scenario_.obstacles, out.second);
    for (auto& m : out.second.markers) {
      m.header.stamp = stamp;
      m.header.frame_id = worldFrame_;
    }
    markersPub_.publish(out.second);
  }
  congruentSince_ = s.congruentSince;
  finalError_ = s.metrics.maxDistanceError;
  // Congruent in a forbidden mirror image is not converged, and the line says so (ShapeOutcome).
  const char* shape = s.converged ? "the desired shape" : "the mirror image of the desired shape";
  if (s.congruent && reportedConvergence_ != s.congruentSince) {
    ROS_INFO("monitor: congruent with %s since step %ld (t = %.3f s)%s", shape, s.congruentSince,
             s.congruentSince * scenario_.timeStep, s.converged ? "" : ": not converged (mirror: forbidden)");
    reportedConvergence_ = s.congruentSince;
  } else if (!s.congruent && reportedConvergence_ >= 0) {
    ROS_INFO("monitor: no longer congruent at step %ld", s.metrics.step);
    reportedConvergence_ = -2;
  }
  if (blocked) report(protocol::Blocked{});  // the formation cannot form: say so instead of running on
  return out;
}

void MonitorNode::publishClock() {
  if (clockDue_.isZero() || clockDue_ == clockSent_) return;
  clockAt_ = ros::WallTime::now();
  clockSent_ = clockDue_;
  // Never backwards: with several formations on one master, the one furthest ahead sets it.
  if (ros::Time::isSimTime() && clockDue_ < ros::Time::now()) return;
  rosgraph_msgs::Clock clock;
  clock.clock = clockDue_;
  clockPub_.publish(clock);
}

void MonitorNode::writeResult(const std::string& result, const std::string& reason) const {
  if (resultFile_.empty()) return;
  const ShapeOutcome formation = shapeVerdict();
  std::ostringstream f;
  f << "result: " << result << "\nscenario: " << yamlQuoted(scenario_.name) << "\nsteps: " << scenario_.steps
    << "\ncompleted_step: " << completedStep() << "\nconverged_step: " << formation.convergedStep
    << "\nshape_error: " << formation.findings.shapeError << "\nformation: "
    << yamlQuoted(formation.line) << "\nverdict: " << verdictName(formation) << "\nfinal_max_distance_error: " << finalError_ << "\ndropped: " << dropped_ << "\ncommands: " << commandsIssued()
    << "\ncommands_refused: " << commandsRefused_ << "\ncommands_saturated: " << desk_->saturated()
    << "\nreason: " << yamlQuoted(reason) << "\n" << safetyResultLines() << robotsResultLines();
  // Whole or not at all: a test or script polling the file never reads half of it.
  if (!replaceFileWith(resultFile_, f.str())) ROS_ERROR("monitor: cannot write the result file %s", resultFile_.c_str());
}

void MonitorNode::finish(const protocol::Progress& end) {
  if (ended()) return;
  uint8_t state = toMessage(end).state;
  std::string reason = end.reason;
  const long last = completedStep();
  goals_->end("the run ended at step " + std::to_string(last));
  const double h = scenario_.timeStep;
  const ShapeOutcome formation = shapeVerdict();
  const RunVerdict verdict = finishedRunVerdict(scenario_, formation);
  if (state == RunProgress::FINISHED) {
    const double seconds = (ros::WallTime::now() - firstStepAt_).toSec();
    ROS_INFO("monitor: %ld steps in %.3f s: %.0f steps/s, real-time factor %.1f at h = %g; %s; %ld dropped", last,
             seconds, last / seconds, last * h / seconds, h, formation.line.c_str(), dropped_);
  }
  if (state == RunProgress::FINISHED && !verdict.succeeded) {
    state = RunProgress::FAILED;  // the scenario asked for a formation that did not form
    reason = verdict.reason;
  }
  if (state == RunProgress::FINISHED) {
    writeResult("succeeded", "");
    // The last line says whether the formation formed: a run that never formed is no plain success,
    // and the line says what its success is (doc/ros_api.md, "monitor": the result file).
    const std::string what = formation.verdict == ShapeVerdict::DesiredShape
                                 ? ""
                                 : ": all " + std::to_string(last) + " steps ran (the scenario does not require convergence)";
    ROS_INFO("monitor: run succeeded%s; formation %s (%s)", what.c_str(), formation.line.c_str(),
             resultFile_.empty() ? "no result file" : resultFile_.c_str());
    exitStatus_ = 0;
  } else {
    writeResult("failed", reason);
    ROS_ERROR("monitor: run failed at step %ld: %s", last, reason.c_str());
    exitStatus_ = 1;
  }
  progress_.state = state;
  progress_.reason = reason;
  progress_.header.stamp = stampOf(progress_.completed_step);
  progressPub_.publish(progress_);
}

}  // namespace vf
