#include "variational_formation/ros/frames.hpp"


#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

std::string framePrefix(const ros::NodeHandle& nh) {
  std::string ns = nh.getNamespace();
  while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
  return ns.empty() ? "" : ns + "/";
}

std::string worldFrame(const ros::NodeHandle& pnh) {
  std::string key, frame = "world";
  if (pnh.searchParam("world_frame", key) && !pnh.getParam(key, frame)) {
    throw InvalidInput(key + ": expected a frame name (a string)");
  }
  if (frame.empty() || frame.find_first_of(" \t\n") != std::string::npos) {
    throw InvalidInput("world_frame: expected a frame name without spaces, got '" + frame + "'");
  }
  return frame;
}

bool isFrame(const std::string& frame, const std::string& world) {
  const auto bare = [](const std::string& f) { return f.compare(0, 1, "/") == 0 ? f.substr(1) : f; };
  return bare(frame) == bare(world);
}

geometry_msgs::TransformStamped frameAt(const std_msgs::Header& header, const std::string& child,
                                        const std::vector<double>& position) {
  geometry_msgs::TransformStamped t;
  setFrameAt(t, header, child, position);
  return t;
}

void setFrameAt(geometry_msgs::TransformStamped& t, const std_msgs::Header& header, const std::string& child,
                const std::vector<double>& position) {
  t.header = header;
  t.child_frame_id = child;
  t.transform.translation.x = position.size() > 0 ? position[0] : 0.0;
  t.transform.translation.y = position.size() > 1 ? position[1] : 0.0;
  t.transform.translation.z = position.size() > 2 ? position[2] : 0.0;
  t.transform.rotation.x = t.transform.rotation.y = t.transform.rotation.z = 0.0;
  t.transform.rotation.w = 1.0;
}

}  // namespace vf
