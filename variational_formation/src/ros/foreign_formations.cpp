// The agents of other formations on the master (doc/maths.md §10, "Other formations"): the
// parameter `avoid`, and the watcher that finds their topics and holds their newest states.
#include "variational_formation/ros/foreign_formations.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include <ros/callback_queue.h>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation_msgs/AgentState.h"

namespace vf {

namespace {

constexpr double kPollPeriod = 2.0;  // seconds between two looks at the master's topic list
const char* const kStateType = "variational_formation_msgs/AgentState";

using variational_formation_msgs::AgentState;

/// "/team_b/formation/agent_3/state" -> "/team_b/formation", 3; false for any other name.
bool agentTopic(const std::string& topic, std::string& formation, unsigned& id) {
  static const std::regex pattern("^(/.*)/agent_([0-9]{1,9})/state$");
  std::smatch m;
  if (!std::regex_match(topic, m, pattern)) return false;
  formation = m[1];
  id = static_cast<unsigned>(std::stoul(m[2]));
  return true;
}

class Watcher : public ForeignFormations {
 public:
  Watcher(std::string own, AvoidList avoid, int dimension)
      : own_(std::move(own)), avoid_(std::move(avoid)), table_(std::make_shared<ForeignAgents>(dimension)),
        spinner_(1, &queue_) {
    nh_.setCallbackQueue(&queue_);
    spinner_.start();
    thread_ = std::thread([this] { poll(); });
  }
  ~Watcher() override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    thread_.join();
    spinner_.stop();
    subscribers_.clear();
  }
  std::shared_ptr<const ForeignAgents> agents() const override { return table_; }

 private:
  void poll() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stopping_ && ros::ok()) {
      lock.unlock();
      discover();
      lock.lock();
      wake_.wait_for(lock, std::chrono::duration<double>(kPollPeriod), [this] { return stopping_; });
    }
  }

  void discover() {
    ros::master::V_TopicInfo topics;
    if (!ros::master::getTopics(topics)) return;  // the master is away: the next look tries again
    for (const ros::master::TopicInfo& t : topics) {
      std::string formation;
      unsigned id = 0;
      if (t.datatype != kStateType || !agentTopic(t.name, formation, id) || formation == own_ ||
          !avoid_.avoids(formation) || !subscribed_.insert(t.name).second) {
        continue;
      }
      if (formations_.insert(formation).second) {
        ROS_INFO("%s: keeping r from the agents of the formation %s (avoid: %s)", own_.c_str(), formation.c_str(),
                 avoid_.describe().c_str());
      }
      const std::string name = formation + "/agent_" + std::to_string(id);
      subscribers_.push_back(nh_.subscribe<AgentState>(
          t.name, 10,
          boost::function<void(const ros::MessageEvent<AgentState const>&)>(
              [this, name, formation, id](const ros::MessageEvent<AgentState const>& e) {
                onState(name, formation, id, e);
              }),
          ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
    }
  }

  void onState(const std::string& name, const std::string& formation, unsigned id,
               const ros::MessageEvent<AgentState const>& e) {
    const AgentState& m = *e.getConstMessage();
    const std::size_t d = static_cast<std::size_t>(table_->dimension());
    // From a node of that formation only: the agent itself, or a nodelet manager beside it.
    if (e.getPublisherName().compare(0, formation.size() + 1, formation + "/") != 0 || m.id != id) {
      ROS_WARN_THROTTLE(5.0, "%s: dropped a state on %s/state from %s, which is not of that formation", own_.c_str(),
                        name.c_str(), e.getPublisherName().c_str());
      return;
    }
    if (m.position.size() != d || m.previous_position.size() != d) {
      ROS_WARN_THROTTLE(60.0, "%s: not avoiding %s: its positions have %zu coordinates, this formation's %zu",
                        own_.c_str(), name.c_str(), m.position.size(), d);
      return;
    }
    if (!m.failure.empty()) return;  // a diverged step: not a position
    table_->hold(name, m.position.data(), m.previous_position.data(), ros::WallTime::now().toSec());
  }

  const std::string own_;
  const AvoidList avoid_;
  const std::shared_ptr<ForeignAgents> table_;
  ros::CallbackQueue queue_;
  ros::NodeHandle nh_;
  ros::AsyncSpinner spinner_;
  std::set<std::string> subscribed_, formations_;  // the poll thread's only
  std::vector<ros::Subscriber> subscribers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;  // last: starts once everything above is there
};

std::mutex gMutex;
std::map<std::string, std::weak_ptr<ForeignFormations>> gWatchers;  // by namespace and list

std::string normalised(std::string ns) {
  if (ns.empty() || ns.front() != '/') ns.insert(0, "/");
  while (ns.size() > 1 && ns.back() == '/') ns.pop_back();
  return ns;
}

}  // namespace

bool AvoidList::avoids(const std::string& formation) const {
  if (everyOther) return true;
  return std::any_of(namespaces.begin(), namespaces.end(), [&formation](const std::string& ns) {
    return formation == ns || formation == ns + "/formation";
  });
}

std::string AvoidList::describe() const {
  if (everyOther) return "every other formation on the master";
  if (namespaces.empty()) return "none";
  std::string text;
  for (const std::string& ns : namespaces) text += (text.empty() ? "" : " ") + ns;
  return text;
}

AvoidList avoidParameter(const ros::NodeHandle& pnh) {
  std::string key, value = "all";
  if (pnh.searchParam("avoid", key) && !pnh.getParam(key, value)) {
    throw InvalidInput(key + ": expected \"all\", \"none\" or formation namespaces (a string)");
  }
  AvoidList list;
  std::string text = value;
  std::replace(text.begin(), text.end(), ',', ' ');
  std::istringstream words(text);
  std::vector<std::string> entries;
  for (std::string w; words >> w;) entries.push_back(w);
  if (entries.size() == 1 && (entries[0] == "all" || entries[0] == "none")) {
    list.everyOther = entries[0] == "all";
    return list;
  }
  if (entries.empty()) {
    throw InvalidInput(key + ": got '" + value + "'; expected \"all\", \"none\" or formation namespaces (team_b)");
  }
  list.everyOther = false;
  static const std::regex name("^/?[A-Za-z][A-Za-z0-9_/]*$");
  for (const std::string& e : entries) {
    if (e == "all" || e == "none" || !std::regex_match(e, name)) {
      throw InvalidInput(key + ": '" + e + "' in '" + value + "' is not a namespace (\"all\" and \"none\" stand alone)");
    }
    list.namespaces.push_back(normalised(e));
  }
  return list;
}

std::shared_ptr<ForeignFormations> ForeignFormations::watch(const ros::NodeHandle& nh, const AvoidList& avoid,
                                                            int dimension) {
  if (avoid.none()) return nullptr;
  const std::string key = nh.getNamespace() + " " + avoid.describe();
  std::lock_guard<std::mutex> lock(gMutex);
  std::shared_ptr<ForeignFormations> watcher = gWatchers[key].lock();
  if (!watcher) {
    watcher = std::make_shared<Watcher>(normalised(nh.getNamespace()), avoid, dimension);
    gWatchers[key] = watcher;
  }
  return watcher;
}

}  // namespace vf
