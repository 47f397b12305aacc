#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

/**
 * The agents of one process handing their states to each other (doc/distributed.md, "Local
 * delivery"): agent j delivers each state here once, and every agent of the process that listens
 * to j gets it through its handler, without the middleware (a roscpp publish searches all of the
 * process's topics by name, so n agents publishing in one manager cost O(n^2) per step). A new
 * listener gets j's newest state at once, as a latched topic gives it; after that every state,
 * in order, none twice. `State` is a shared pointer to a message.
 *
 * Thread-safe. A handler runs on the delivering thread, under the lock of its source, so it
 * should only queue work (and must not call this exchange); once stopListening returns, no
 * handler of that listener runs or will run.
 */
template <class State>
class LocalExchange {
 public:
  using Handler = std::function<void(int source, const State& state)>;

  /// @param hosted the ids of the agents in this process (>= 0).
  explicit LocalExchange(const std::vector<int>& hosted) {
    for (int id : hosted) {
      if (id < 0) throw InvalidInput("local exchange: agent id " + std::to_string(id) + " is negative");
      if (static_cast<std::size_t>(id) >= sources_.size()) sources_.resize(static_cast<std::size_t>(id) + 1);
      sources_[static_cast<std::size_t>(id)] = std::make_unique<Source>();
    }
  }

  /// Whether agent `id` is in this process (its states come from here).
  bool hosts(int id) const { return find(id) != nullptr; }

  /**
   * `handler` gets every state of `source` from now on, under `listener` (an id of the caller's
   * choice, for stopListening); the newest one held first, if any.
   * @throws InvalidInput if `source` is not hosted here.
   */
  void listen(int source, std::uintptr_t listener, Handler handler) {
    Source& s = at(source);
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.newest) handler(source, s.newest);
    s.handlers.emplace_back(listener, std::move(handler));
  }

  /// Ends every listening of `listener`.
  void stopListening(std::uintptr_t listener) {
    for (const std::unique_ptr<Source>& s : sources_) {
      if (!s) continue;
      std::lock_guard<std::mutex> lock(s->mutex);
      auto& h = s->handlers;
      h.erase(std::remove_if(h.begin(), h.end(), [listener](const auto& e) { return e.first == listener; }), h.end());
    }
  }

  /// Agent `source`'s new state: held as its newest, and handed to each listener in the order
  /// they began listening. @throws InvalidInput if `source` is not hosted here.
  void deliver(int source, const State& state) {
    Source& s = at(source);
    std::lock_guard<std::mutex> lock(s.mutex);
    s.newest = state;
    for (const auto& h : s.handlers) h.second(source, state);
  }

  /// The newest state delivered by `source`; empty if none or not hosted here.
  State newest(int source) const {
    const Source* s = find(source);
    if (!s) return State();
    std::lock_guard<std::mutex> lock(s->mutex);
    return s->newest;
  }

 private:
  struct Source {
    mutable std::mutex mutex;
    State newest;
    std::vector<std::pair<std::uintptr_t, Handler>> handlers;
  };

  const Source* find(int id) const {
    if (id < 0 || static_cast<std::size_t>(id) >= sources_.size()) return nullptr;
    return sources_[static_cast<std::size_t>(id)].get();
  }
  Source& at(int id) {
    const Source* s = find(id);
    if (!s) throw InvalidInput("local exchange: agent " + std::to_string(id) + " is not in this process");
    return *const_cast<Source*>(s);
  }

  std::vector<std::unique_ptr<Source>> sources_;  // by agent id; null: not hosted (fixed after construction)
};

}  // namespace vf
