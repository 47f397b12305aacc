#include "variational_formation/ros/state_batch.hpp"

#include <map>
#include <memory>
#include <sstream>

#include "variational_formation/core/error.hpp"

namespace vf {

namespace {
constexpr double kFlushAfter = 0.005;  // [s] a batch waits at most this long for the rest of a step
std::unique_ptr<StateBatch> gBatch;      // this process's, if it is an agent manager
}  // namespace

void StateBatch::start(ros::NodeHandle& pnh, const std::vector<int>& ids) {
  gBatch.reset(new StateBatch(pnh, ids));
}

void StateBatch::stop() { gBatch.reset(); }

StateBatch* StateBatch::local() { return gBatch.get(); }

StateBatch::StateBatch(ros::NodeHandle& pnh, const std::vector<int>& ids)
    : ids_(ids.begin(), ids.end()), pending_(boost::make_shared<variational_formation::AgentStates>()) {
  ros::AdvertiseOptions options = ros::AdvertiseOptions::create<variational_formation::AgentStates>(
      "states", 1000, [this](const ros::SingleSubscriberPublisher& s) { onConnect(s); },
      ros::SubscriberStatusCallback(), ros::VoidConstPtr(), nullptr);
  pub_ = pnh.advertise(options);
  pending_->states.reserve(ids_.size());
  timer_ = pnh.createWallTimer(ros::WallDuration(kFlushAfter), [this](const ros::WallTimerEvent&) { flush(); });
}

void StateBatch::add(const variational_formation::AgentState::ConstPtr& state) {
  const int id = static_cast<int>(state->id);
  if (ids_.count(id) == 0) return;
  variational_formation::AgentStatesPtr full;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    newest_[id] = state;
    pending_->states.push_back(*state);
    if (pending_->states.size() < ids_.size()) return;
    full = pending_;
    pending_ = boost::make_shared<variational_formation::AgentStates>();
    pending_->states.reserve(ids_.size());
  }
  pub_.publish(variational_formation::AgentStatesConstPtr(full));
}

void StateBatch::flush() {
  variational_formation::AgentStatesPtr held;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (pending_->states.empty()) return;
    held = pending_;
    pending_ = boost::make_shared<variational_formation::AgentStates>();
    pending_->states.reserve(ids_.size());
  }
  pub_.publish(variational_formation::AgentStatesConstPtr(held));
}

void StateBatch::onConnect(const ros::SingleSubscriberPublisher& subscriber) {
  variational_formation::AgentStates newest;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& held : newest_) newest.states.push_back(*held.second);
  }
  if (!newest.states.empty()) subscriber.publish(newest);
}

std::vector<int> parseAgentIds(const std::string& list, const std::string& parameter) {
  std::istringstream words(list);
  std::vector<int> ids;
  std::set<int> seen;
  for (std::string w; words >> w;) {
    std::size_t used = 0;
    int id = -1;
    try {
      id = std::stoi(w, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != w.size() || id < 0) throw InvalidInput(parameter + ": '" + w + "' is not an agent id (an integer >= 0)");
    if (!seen.insert(id).second) throw InvalidInput(parameter + ": agent " + w + " is listed twice");
    ids.push_back(id);
  }
  if (ids.empty()) throw InvalidInput(parameter + ": no agent ids in '" + list + "'");
  return ids;
}

std::vector<BatchSource> batchSources(const ros::NodeHandle& nh, const std::vector<std::string>& managers, int agents) {
  std::vector<BatchSource> sources;
  std::map<int, int> claims;
  for (const std::string& m : managers) {
    XmlRpc::XmlRpcValue value;
    const ros::NodeHandle manager(nh, m);  // its private namespace: m is a full name
    if (!manager.getParam("agents", value)) continue;  // a manager that does not batch
    std::string list;
    if (value.getType() == XmlRpc::XmlRpcValue::TypeInt) list = std::to_string(static_cast<int>(value));
    if (value.getType() == XmlRpc::XmlRpcValue::TypeString) list = static_cast<std::string>(value);
    BatchSource s{m, {}};
    try {
      for (int id : parseAgentIds(list, m + "/agents")) {
        if (id < agents) s.ids.insert(id);
      }
    } catch (const InvalidInput&) {
      continue;  // the manager itself refuses to start with it, saying why
    }
    for (int id : s.ids) ++claims[id];
    sources.push_back(s);
  }
  for (BatchSource& s : sources) {
    for (auto it = s.ids.begin(); it != s.ids.end();) it = claims[*it] > 1 ? s.ids.erase(it) : std::next(it);
  }
  return sources;
}

}  // namespace vf
