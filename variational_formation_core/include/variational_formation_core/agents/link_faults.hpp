#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <utility>
#include <vector>

namespace vf {

/// Faults imposed on the messages of one link (software fault injection: `tc netem` is not
/// available). All times in seconds.
struct LinkFaultSettings {
  double delay = 0.0;   ///< delay of every delivered message [s], >= 0
  double jitter = 0.0;  ///< half-width of the uniform spread around `delay` [s], >= 0
  double loss = 0.0;    ///< probability that a message is lost, in [0, 1]
};

/// delay >= 0, jitter >= 0, loss in [0, 1], all finite. @throws InvalidInput naming the field.
void validateLinkFaults(const LinkFaultSettings& settings);

/**
 * The fate of each message, drawn from a seeded std::mt19937_64 with distributions written out in
 * core/random.hpp, so a seed gives the same faults with every standard library. Each message
 * takes exactly two draws (loss, then jitter), whatever its fate: the delays do not depend on
 * the loss probability.
 */
class LinkFaultModel {
 public:
  /// @throws InvalidInput (validateLinkFaults).
  LinkFaultModel(const LinkFaultSettings& settings, std::uint64_t seed);

  /// Lost with probability `loss` (nullopt); else the delay max(0, delay + jitter u) [s] with u
  /// uniform in [-1, 1).
  std::optional<double> draw();
  const LinkFaultSettings& settings() const { return settings_; }
  /// No delay, jitter or loss: every message is delivered at once.
  bool transparent() const;

 private:
  LinkFaultSettings settings_;
  std::mt19937_64 engine_;
};

/**
 * A link with faults: messages offered at their arrival time come out of takeDue() at their
 * delivery time, in delivery order (ties in the order offered); lost ones never do.
 */
template <class Message>
class LinkFaults {
 public:
  /// @throws InvalidInput (validateLinkFaults).
  LinkFaults(const LinkFaultSettings& settings, std::uint64_t seed) : model_(settings, seed) {}

  /**
   * Offers a message that arrived at `now` [s].
   * @return its delivery time [s], or nullopt if it is lost.
   */
  std::optional<double> offer(Message message, double now) {
    ++offered_;
    const std::optional<double> delay = model_.draw();
    if (!delay) {
      ++lost_;
      return std::nullopt;
    }
    const double due = now + *delay;
    queue_.emplace(due, std::move(message));  // multimap: equal keys keep insertion order
    return due;
  }

  /// Removes and returns the messages due at or before `now` [s], in delivery order.
  std::vector<Message> takeDue(double now) {
    std::vector<Message> due;
    auto end = queue_.upper_bound(now);
    for (auto it = queue_.begin(); it != end; ++it) due.push_back(std::move(it->second));
    queue_.erase(queue_.begin(), end);
    return due;
  }

  /// Delivery time [s] of the next pending message, +inf if none.
  double nextDue() const {
    return queue_.empty() ? std::numeric_limits<double>::infinity() : queue_.begin()->first;
  }
  std::size_t pending() const { return queue_.size(); }
  long offered() const { return offered_; }
  long lost() const { return lost_; }
  const LinkFaultModel& model() const { return model_; }

 private:
  LinkFaultModel model_;
  std::multimap<double, Message> queue_;
  long offered_ = 0;
  long lost_ = 0;
};

}  // namespace vf
