#include "variational_formation/ros/state_batch.hpp"

#include <map>
#include <memory>
#include <sstream>

#include "variational_formation_core/common/invalid_input.hpp"
#include "variational_formation/ros/pacer.hpp"

namespace vf {

namespace {
constexpr double kFlushAfter = 0.005;  // [s] a batch waits at most this long for the rest of a step
// Published batches kept for reuse: the states of the next ones are assigned over theirs instead of
// allocated, and freed on the agents' thread, not on roscpp's after sending (where at 1000 agents
// the frees of a batch's 2000 vectors overflowed the thread's cache and slowed every malloc).
constexpr std::size_t kSpentBatches = 4;
std::unique_ptr<StateBatch> gBatch;      // this process's, if it is an agent manager
}  // namespace

void StateBatch::start(ros::NodeHandle& pnh, const std::vector<int>& ids) {
  gBatch.reset(new StateBatch(pnh, ids));
}

void StateBatch::stop() { gBatch.reset(); }

StateBatch* StateBatch::local() { return gBatch.get(); }

StateBatch::StateBatch(ros::NodeHandle& pnh, const std::vector<int>& ids)
    : ids_(ids.begin(), ids.end()), pending_(boost::make_shared<variational_formation_msgs::AgentStates>()) {
  // The outgoing queue of each subscriber holds as many batches as 250 steps of single states
  // (more than twice the default window): a subscriber that is briefly busy loses nothing.
  const uint32_t depth = static_cast<uint32_t>(std::max<std::size_t>(1000, 250 * ids_.size()));
  ros::AdvertiseOptions options = ros::AdvertiseOptions::create<variational_formation_msgs::AgentStates>(
      "states", depth, [this](const ros::SingleSubscriberPublisher& s) { onConnect(s); },
      [this](const ros::SingleSubscriberPublisher& s) { onDisconnect(s); }, ros::VoidConstPtr(), nullptr);
  pub_ = pnh.advertise(options);
  pending_->states.reserve(ids_.size());
  const std::size_t size = ids_.empty() ? 0 : static_cast<std::size_t>(*ids_.rbegin()) + 1;
  batched_.assign(size, 0);
  for (int id : ids_) batched_[static_cast<std::size_t>(id)] = 1;
  newest_.resize(size);
  flusher_ = std::thread([this] { flushEvery5ms(); });
}

StateBatch::~StateBatch() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  flusher_.join();
}

void StateBatch::flushEvery5ms() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_.wait_for(lock, std::chrono::duration<double>(kFlushAfter), [this] { return stopping_; })) {
    lock.unlock();
    flush();
    lock.lock();
  }
}

void StateBatch::add(const variational_formation_msgs::AgentState::ConstPtr& state) {
  const std::size_t id = state->id;
  if (id >= batched_.size() || !batched_[id]) return;
  variational_formation_msgs::AgentStatesPtr full;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    newest_[id] = state;
    std::vector<variational_formation_msgs::AgentState>& states = pending_->states;
    // Into a reused batch, the copy is assigned over an old state: its vectors keep their memory.
    if (filled_ < states.size()) {
      states[filled_] = *state;
    } else {
      states.push_back(*state);
    }
    if (++filled_ < ids_.size()) return;
    full = takePending();
  }
  publish(full);
}

void StateBatch::flush() {
  variational_formation_msgs::AgentStatesPtr held;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (filled_ == 0) return;
    held = takePending();
  }
  publish(held);
}

variational_formation_msgs::AgentStatesPtr StateBatch::takePending() {
  variational_formation_msgs::AgentStatesPtr full = pending_;
  full->states.resize(filled_);  // shorter only when flushed before every agent added one
  filled_ = 0;
  pending_.reset();
  for (auto it = spent_.begin(); it != spent_.end(); ++it) {
    if (it->use_count() == 1) {  // roscpp let go of it: sent (or no subscriber)
      pending_ = *it;
      spent_.erase(it);
      break;
    }
  }
  if (!pending_) {
    pending_ = boost::make_shared<variational_formation_msgs::AgentStates>();
    pending_->states.reserve(ids_.size());
  }
  return full;
}

void StateBatch::publish(const variational_formation_msgs::AgentStatesPtr& batch) {
  pub_.publish(variational_formation_msgs::AgentStatesConstPtr(batch));
  std::lock_guard<std::mutex> lock(mutex_);
  spent_.push_back(batch);
  if (spent_.size() > kSpentBatches) spent_.pop_front();
}

void StateBatch::onConnect(const ros::SingleSubscriberPublisher& subscriber) {
  variational_formation_msgs::AgentStates newest;
  std::vector<Waiter> ready;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& held : newest_) {
      if (held) newest.states.push_back(*held);
    }
    const std::string name = subscriber.getSubscriberName();
    subscribers_.insert(name);
    for (auto it = waiters_.begin(); it != waiters_.end();) {
      if (it->node == name) {
        ready.push_back(std::move(*it));
        it = waiters_.erase(it);
      } else {
        ++it;
      }
    }
  }
  if (!newest.states.empty()) subscriber.publish(newest);
  for (Waiter& w : ready) w.queue->addCallback(boost::make_shared<QueuedCall>(std::move(w.call)));
}

void StateBatch::onDisconnect(const ros::SingleSubscriberPublisher& subscriber) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = subscribers_.find(subscriber.getSubscriberName());
  if (it != subscribers_.end()) subscribers_.erase(it);
}

bool StateBatch::connectedOrLater(const std::string& node, ros::CallbackQueueInterface* queue,
                                  std::function<void()> call) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (subscribers_.count(node) > 0) return true;
  waiters_.push_back({node, queue, std::move(call)});
  return false;
}

namespace {
std::unique_ptr<AgentThreads> gThreads;  // this process's, if it is an agent manager
constexpr int kLaneBurst = 64;           // soon() calls run between two looks at the queue
thread_local const ros::CallbackQueueInterface* tServed = nullptr;  // the queue this thread serves
thread_local std::vector<std::shared_ptr<AgentThreads::Task>> tLane;  // soon(): newest last
}  // namespace

bool AgentThreads::serves(const ros::CallbackQueueInterface* queue) { return queue != nullptr && tServed == queue; }

void AgentThreads::soon(std::shared_ptr<Task> task) { tLane.push_back(std::move(task)); }

void AgentThreads::start(int threads, std::size_t agents) { gThreads.reset(new AgentThreads(threads, agents)); }

void AgentThreads::stop() { gThreads.reset(); }

AgentThreads* AgentThreads::local() { return gThreads.get(); }

AgentThreads::AgentThreads(int threads, std::size_t agents) : agents_(agents) {
  for (int k = 0; k < std::max(1, threads); ++k) queues_.push_back(std::make_unique<ros::CallbackQueue>());
  for (auto& q : queues_) {
    threads_.emplace_back([this, queue = q.get()] {
      tServed = queue;
      while (!stopping_) {
        // With work of its own waiting, only a look at the queue; else wait for a callback.
        queue->callAvailable(tLane.empty() ? ros::WallDuration(0.1) : ros::WallDuration());
        for (int k = 0; k < kLaneBurst && !tLane.empty() && !stopping_; ++k) {
          const std::shared_ptr<Task> next = std::move(tLane.back());
          tLane.pop_back();
          next->run();
        }
      }
      tLane.clear();
    });
  }
}

AgentThreads::~AgentThreads() { halt(); }

void AgentThreads::halt() {
  stopping_ = true;
  for (auto& q : queues_) q->disable();  // wakes a thread waiting in callAvailable
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
}

ros::CallbackQueue* AgentThreads::nextQueue() {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::size_t k = next_++, t = queues_.size();
  return queues_[k < agents_ ? k * t / agents_ : k % t].get();
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

namespace {
/// Hands roscpp a message to read a batch into: one that nothing holds any more (roscpp and the
/// callbacks let go of it: its use count is 1), or a new one; at most kKept kept.
class RecycledBatches {
 public:
  variational_formation_msgs::AgentStatesPtr operator()() {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& held : kept_) {
      if (held.use_count() == 1) return held;
    }
    auto fresh = boost::make_shared<variational_formation_msgs::AgentStates>();
    if (kept_.size() < kKept) kept_.push_back(fresh);
    return fresh;
  }

 private:
  static constexpr std::size_t kKept = 16;
  std::mutex mutex_;
  std::vector<variational_formation_msgs::AgentStatesPtr> kept_;
};
}  // namespace

ros::Subscriber subscribeToBatches(
    ros::NodeHandle& nh, const std::string& topic, uint32_t depth,
    const std::function<void(const ros::MessageEvent<variational_formation_msgs::AgentStates const>&)>& callback) {
  using Event = const ros::MessageEvent<variational_formation_msgs::AgentStates const>&;
  auto recycled = std::make_shared<RecycledBatches>();
  ros::SubscribeOptions options;
  options.initByFullCallbackType<Event>(topic, depth, boost::function<void(Event)>(callback),
                                        [recycled] { return (*recycled)(); });
  options.transport_hints = ros::TransportHints().tcpNoDelay();
  return nh.subscribe(options);
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

std::vector<variational_formation_msgs::AgentState::ConstPtr> sharedStates(
    const std::vector<variational_formation_msgs::AgentState>& states) {
  std::vector<variational_formation_msgs::AgentState::ConstPtr> shared;
  shared.reserve(states.size());
  for (const auto& s : states) shared.push_back(boost::make_shared<variational_formation_msgs::AgentState>(s));
  return shared;
}

}  // namespace vf
