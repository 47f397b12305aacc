#include "variational_formation/ros/participants.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include <ros/master.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_core/protocol/recovery.hpp"
#include "variational_formation/ros/service_call.hpp"

namespace vf {

geometry_msgs::TransformStamped frameAt(const std_msgs::Header& header, const std::string& child,
                                        const std::vector<double>& position) {
  geometry_msgs::TransformStamped t;
  t.header = header;
  t.child_frame_id = child;
  t.transform.translation.x = position.size() > 0 ? position[0] : 0.0;
  t.transform.translation.y = position.size() > 1 ? position[1] : 0.0;
  t.transform.translation.z = position.size() > 2 ? position[2] : 0.0;
  t.transform.rotation.w = 1.0;
  return t;
}

Recalled recallNewest(const ros::NodeHandle& nh, int id, const std::vector<int>& neighbours, const std::string& monitor) {
  std::vector<std::string> holders;
  for (int j : neighbours) holders.push_back(agentNodeName(nh, j));
  holders.push_back(monitor);
  std::vector<std::string> services;
  for (const std::string& holder : holders) services.push_back(holder + "/recall");
  std::vector<variational_formation_msgs::RecallState> calls(holders.size());
  for (auto& call : calls) call.request.id = static_cast<uint32_t>(id);
  const std::vector<bool> answered = callAllWithTimeout(services, calls, 2.0);
  std::vector<protocol::RecallAnswer> answers;
  for (std::size_t k = 0; k < holders.size(); ++k) {
    answers.push_back({answered[k], answered[k] && calls[k].response.held, static_cast<long>(calls[k].response.step)});
  }
  Recalled r;
  const int k = protocol::chooseAgentResume(answers);
  if (k >= 0) {
    r.step = calls[static_cast<std::size_t>(k)].response.step;
    r.found = calls[static_cast<std::size_t>(k)].response;
    r.from = holders[static_cast<std::size_t>(k)];
  }
  return r;
}


std::string agentNodeName(const ros::NodeHandle& nh, int id) {
  return participantName(nh, "agent_" + std::to_string(id));
}

Scenario sharedScenario(const std::string& path) {
  static std::mutex mutex;
  static std::map<std::string, Scenario> loaded;  // by path and content
  std::ifstream file(path);
  std::ostringstream content;
  content << file.rdbuf();
  if (!file) return loadScenario(path);  // its error names the file
  const std::string key = path + '\n' + content.str();
  const std::lock_guard<std::mutex> lock(mutex);
  const auto found = loaded.find(key);
  if (found != loaded.end()) return found->second;
  return loaded.emplace(key, loadScenario(path)).first->second;
}

void subscribeToFormation(
    ros::NodeHandle& nh, const std::vector<int>& neighbours, uint32_t stateQueue,
    const std::function<void(int, const ros::MessageEvent<variational_formation_msgs::AgentState const>&)>& onState,
    const std::function<void(const ros::MessageEvent<variational_formation_msgs::RunProgress const>&)>& onProgress,
    std::vector<ros::Subscriber>& states, ros::Subscriber& progress) {
  using variational_formation_msgs::AgentState;
  using variational_formation_msgs::RunProgress;
  for (int j : neighbours) {
    states.push_back(nh.subscribe<AgentState>(
        "agent_" + std::to_string(j) + "/state", stateQueue,
        boost::function<void(const ros::MessageEvent<AgentState const>&)>(
            [onState, j](const ros::MessageEvent<AgentState const>& e) { onState(j, e); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  progress = nh.subscribe<RunProgress>("progress", 10,
                                       boost::function<void(const ros::MessageEvent<RunProgress const>&)>(onProgress),
                                       ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
}

std::string framePrefix(const ros::NodeHandle& nh) {
  std::string ns = nh.getNamespace();
  while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
  return ns.empty() ? "" : ns + "/";
}

Command commandOf(const variational_formation_msgs::FormationCommand& m) {
  Command c;
  c.velocity = {m.velocity.x, m.velocity.y, m.velocity.z};
  c.angularRate = {m.angular_rate.x, m.angular_rate.y, m.angular_rate.z};
  c.scale = m.scale;
  return c;
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

std::string participantName(const ros::NodeHandle& nh, const std::string& relative) {
  return nh.resolveName(relative, /*remap=*/false);
}

std::vector<std::string> agentManagers(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) {
  std::string list;
  pnh.param<std::string>("agent_manager", list, "");
  std::istringstream words(list);
  std::vector<std::string> managers;
  for (std::string w; words >> w;) managers.push_back(participantName(nh, w));
  return managers;
}

namespace {

/// host and port of an "http://host:port/" URI.
bool splitUri(const std::string& uri, std::string& host, int& port) {
  const std::string scheme = "http://";
  if (uri.compare(0, scheme.size(), scheme) != 0) return false;
  const std::string rest = uri.substr(scheme.size());
  const auto colon = rest.rfind(':');
  if (colon == std::string::npos) return false;
  host = rest.substr(0, colon);
  try {
    port = std::stoi(rest.substr(colon + 1));
  } catch (const std::exception&) {
    return false;
  }
  return port > 0 && port < 65536;
}

/// A TCP connection to host:port succeeds within timeoutMs.
/// Connects to host:port: Alive if it accepts, Busy if it neither accepts nor refuses within
/// `timeoutMs` (a full listen backlog), NotAnswering if refused (nothing listens: killed).
Liveness accepts(const std::string& host, int port, int timeoutMs) {
  addrinfo hints{}, *found = nullptr;
  hints.ai_socktype = SOCK_STREAM;
  if (getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0 || !found) {
    return Liveness::NotAnswering;
  }
  Liveness l = Liveness::NotAnswering;
  for (addrinfo* a = found; a && l != Liveness::Alive; a = a->ai_next) {
    const int fd = socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    if (connect(fd, a->ai_addr, a->ai_addrlen) == 0) {
      l = Liveness::Alive;
    } else if (errno == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      int error = 0;
      socklen_t size = sizeof error;
      const int ready = poll(&p, 1, timeoutMs);
      if (ready == 0) {
        l = Liveness::Busy;
      } else if (ready == 1 && getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &size) == 0 && error == 0) {
        l = Liveness::Alive;
      }
    }
    close(fd);
  }
  freeaddrinfo(found);
  return l;
}

}  // namespace

Liveness nodeLiveness(const std::string& fullName) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  request[1] = fullName;
  if (!ros::master::execute("lookupNode", request, response, payload, false)) {
    // The master said "unknown node" (a status code in its answer), or did not answer at all.
    return response.getType() == XmlRpc::XmlRpcValue::TypeArray ? Liveness::NotRegistered : Liveness::Busy;
  }
  std::string host;
  int port = 0;
  if (payload.getType() != XmlRpc::XmlRpcValue::TypeString || !splitUri(static_cast<std::string>(payload), host, port)) {
    return Liveness::NotAnswering;
  }
  return accepts(host, port, 500);
}

void createParentDirectory(const std::string& path, const std::string& parameter) {
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) return;
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw InvalidInput(parameter + ": cannot create the directory '" + dir.string() + "': " + error.message());
}

const char* describe(Liveness liveness) {
  switch (liveness) {
    case Liveness::Alive: return "alive";
    case Liveness::NotRegistered: return "not registered with the master";
    case Liveness::NotAnswering: return "registered but its process does not answer (killed?)";
    case Liveness::Busy: return "it or the master is too busy to answer; not taken as gone";
  }
  return "?";
}

}  // namespace vf
