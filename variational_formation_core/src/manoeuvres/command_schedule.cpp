#include "variational_formation_core/manoeuvres/command_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

#include "variational_formation_core/common/invalid_input.hpp"

namespace vf {

const char* const kCommandsHeader = "step,vx,vy,vz,wx,wy,wz,scale";

void CommandSchedule::add(long step, const Command& command, const std::string& field) {
  const long last = entries_.empty() ? -1 : entries_.back().first;
  if (step <= last) {
    throw InvalidInput(field + ": steps must increase" +
                       (entries_.empty() ? std::string(" from 0") : ", previous " + std::to_string(last)) +
                       ", got " + std::to_string(step));
  }
  entries_.emplace_back(step, command);
}

void CommandSchedule::replaceFrom(long step, const Command& command, const std::string& field) {
  if (step < 0) throw InvalidInput(field + ": must be >= 0, got " + std::to_string(step));
  entries_.erase(entries_.begin() + (entryIndex(step - 1) + 1), entries_.end());
  entries_.emplace_back(step, command);
}

long CommandSchedule::entryIndex(long step) const {
  // The last entry whose step is <= step.
  const auto it = std::upper_bound(entries_.begin(), entries_.end(), step,
                                   [](long s, const Entry& e) { return s < e.first; });
  return static_cast<long>(it - entries_.begin()) - 1;
}

const Command& CommandSchedule::at(long step) const {
  const long i = entryIndex(step);
  return i < 0 ? zero_ : entries_[static_cast<std::size_t>(i)].second;
}

bool CommandSchedule::rotates() const {
  for (const Entry& e : entries_) {
    if (e.second.rotates()) return true;
  }
  return false;
}

double CommandSchedule::largestScale() const {
  double s = 1.0;
  for (const Entry& e : entries_) s = std::max(s, e.second.scale);
  return s;
}

CommandSchedule scheduleFromSegments(const std::vector<ManoeuvreSegment>& segments, double timeStep) {
  CommandSchedule schedule;
  std::vector<CommandSchedule::Entry> entries;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    long step = 0;
    if (i > 0) {
      // The first k with t_k = k h >= until_{i-1}, t_k computed as the integrators do.
      const double until = segments[i - 1].until;
      step = static_cast<long>(std::ceil(until / timeStep));
      while (step > 0 && static_cast<double>(step - 1) * timeStep >= until) --step;
      while (static_cast<double>(step) * timeStep < until) ++step;
    }
    if (!entries.empty() && entries.back().first == step) {
      entries.back().second = segments[i].command;  // the later segment wins
    } else {
      entries.emplace_back(step, segments[i].command);
    }
  }
  for (const auto& e : entries) schedule.add(e.first, e.second);
  return schedule;
}

void writeCommands(std::ostream& out, const CommandSchedule& schedule) {
  out << kCommandsHeader << '\n';
  char buf[32];
  for (const auto& [step, c] : schedule.entries()) {
    out << step;
    for (double x : {c.velocity.x(), c.velocity.y(), c.velocity.z(), c.angularRate.x(), c.angularRate.y(),
                     c.angularRate.z(), c.scale}) {
      std::snprintf(buf, sizeof buf, "%.17g", x);
      out << ',' << buf;
    }
    out << '\n';
  }
}

}  // namespace vf
