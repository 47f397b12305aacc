// The recorder's bag (RecorderNode, recorder_node.hpp): its files and their limits, and the
// whole steps written in order.
#include <algorithm>
#include <cmath>

#include "variational_formation/ros/frames.hpp"
#include "variational_formation/ros/recorder_node.hpp"

namespace vf {

namespace {
/// Bag time of a message stamped with simulated time t_k (a bag cannot hold time 0).
ros::Time bagTime(const ros::Time& stamp) { return stamp.isZero() ? ros::TIME_MIN : stamp; }
}  // namespace

void RecorderNode::openPart() {
  std::string path = path_;
  if (part_ > 0) {
    const std::string stem = path_.size() > 4 && path_.compare(path_.size() - 4, 4, ".bag") == 0
                                 ? path_.substr(0, path_.size() - 4) : path_;
    path = stem + "_" + std::to_string(part_) + ".bag";
  }
  try {
    // Chunks written whole (BagWriter), LZ4 or plain (~compression). The file grows a chunk at a
    // time: chunks of at most an eighth of the limits keep the parts within them (rosbag's
    // default is 768 kB).
    const double limit = std::min(splitBytes_ > 0.0 ? splitBytes_ : HUGE_VAL, maxBytes_ > 0.0 ? maxBytes_ : HUGE_VAL);
    bag_.open(path, compression_, static_cast<uint32_t>(std::clamp(limit / 8.0, 16e3, 768e3)));
    open_ = true;
  } catch (const std::exception& e) {
    throw InvalidInput(std::string("~bag: cannot write ") + e.what());
  }
}

void RecorderNode::enforceLimits() {
  const double size = static_cast<double>(bag_.size());
  if (maxBytes_ > 0.0 && closedBytes_ + size >= maxBytes_) {
    limited_ = true;
    ROS_WARN("recorder: the size limit of %.0f MB ends the recording (%d files); the run goes on", maxBytes_ / 1e6,
             part_ + 1);
    close("size limit");
  } else if (splitBytes_ > 0.0 && size >= splitBytes_) {
    closedBytes_ += size;
    close("split");
    ++part_;
    try {
      openPart();
    } catch (const std::exception& e) {
      fail(e.what());
    }
  }
}

template <typename M>
void RecorderNode::write(BagWriter::Topic& topic, const M& msg, const ros::Time& stamp) {
  if (!open_) return;
  try {
    bag_.write(topic, bagTime(stamp), msg);
    ++written_;
    enforceLimits();
  } catch (const std::exception& e) {
    fail(std::string("cannot write ") + e.what());
  }
}

void RecorderNode::writeStep(const Protocol::Write& w) {
  // Steps come whole and in order, so the bag's messages are in time order: readers that trust
  // it (Python's rosbag merges chunks assuming it) see every stream in step order.
  const Protocol::Step& step = w.step;
  if (w.commands > 0) writeListedCommands(w.commands, step.step);
  // The step's transforms in one /tf message, as a broadcaster of many frames sends them: a
  // bag message costs the same whatever it holds, and 1000 agents wrote 2000 a step. The message
  // is reused, so its frame names keep their memory from step to step.
  tf_.transforms.resize(step.states.size());
  for (std::size_t i = 0; i < step.states.size(); ++i) {
    const AgentState& msg = *step.states[i];
    write(stateTopics_[i], msg, msg.header.stamp);
    setFrameAt(tf_.transforms[i], msg.header, frameIds_[i], msg.position);
  }
  if (!tf_.transforms.empty()) write(tfTopic_, tf_, tf_.transforms.front().header.stamp);
  write(statusTopic_, *step.status, step.status->header.stamp);
  if (step.hasMarkers) write(markersTopic_, *step.markers, markersStamp(*step.markers));
}

void RecorderNode::writeListedCommands(std::size_t count, long step) {
  variational_formation_msgs::FormationCommands so_far;
  so_far.header.stamp = ros::Time(static_cast<double>(step) * timeStep_);
  so_far.commands.assign(commands_.commands.begin(), commands_.commands.begin() + static_cast<long>(count));
  write(commandsTopic_, so_far, so_far.header.stamp);
}

void RecorderNode::close(const std::string& how) {
  if (!open_) return;
  open_ = false;
  try {
    bag_.close();
  } catch (const std::exception& e) {
    // A bag that failed to write fails again at its close: the run already failed, naming it.
    ROS_ERROR("recorder: closing %s: %s", path_.c_str(), e.what());
  }
  ROS_INFO("recorder: %s closed (%s): %ld messages, %ld repeated states not written again (%ld equal to the "
           "written copy bit for bit, %ld too old to compare), %ld dropped", path_.c_str(), how.c_str(), written_,
           protocol_->repeats(), protocol_->repeats() - protocol_->uncompared(), protocol_->uncompared(), dropped_);
}

}  // namespace vf
