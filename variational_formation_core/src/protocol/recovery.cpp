#include "variational_formation_core/protocol/recovery.hpp"

#include <algorithm>

namespace vf::protocol {

int chooseAgentResume(const std::vector<RecallAnswer>& answers) {
  int best = -1;
  long bestStep = 0;
  for (std::size_t k = 0; k < answers.size(); ++k) {
    const RecallAnswer& a = answers[k];
    if (a.answered && a.held && a.step > bestStep) {
      bestStep = a.step;
      best = static_cast<int>(k);
    }
  }
  return best;
}

MonitorResume chooseMonitorResume(const std::vector<ProgressAnswer>& answers, long window) {
  MonitorResume r;
  r.step = -1;
  for (const ProgressAnswer& a : answers) {
    if (a.answered && a.hasProgress && a.over && (!r.over || a.completedStep > r.overAt)) {
      r.over = true;
      r.finished = a.finished;
      r.overAt = a.completedStep;
    }
    if (a.answered && a.hasProgress && a.completedStep + 1 > r.step) {
      r.step = a.completedStep + 1;
      r.congruentSince = a.convergedStep;
    }
  }
  if (r.over) {
    r.step = 0;
    return r;
  }
  if (r.step <= 0) return MonitorResume();
  r.acceptUpTo = r.step + window + window / 4;
  return r;
}

std::string describeOver(const MonitorResume& r) {
  if (!r.over) return "";
  return std::string("the agents belong to a run that is already over (it ") + (r.finished ? "finished" : "failed") +
         " at step " + std::to_string(r.overAt) +
         "); this monitor did not witness it and starts no new run: start the agents again for a new run";
}

long recorderLead(long window) { return window + window / 4 + window / 4 + 1; }

long maxWindow(const RecorderBuffers& buffers) {
  const long limit = std::min(buffers.queue, buffers.keptSteps);
  long w = limit;
  while (w > 0 && recorderLead(w) > limit) --w;
  return w;
}

std::string checkBuffers(long window, const RecorderBuffers& buffers) {
  const long lead = recorderLead(window);
  if (buffers.keptSteps < lead) {
    return "~window " + std::to_string(window) + " lets states arrive up to " + std::to_string(lead) +
           " steps behind an agent's newest, but the recorder keeps only " + std::to_string(buffers.keptSteps) +
           " steps to compare repeats with: use ~window <= " + std::to_string(maxWindow(buffers)) + " when recording";
  }
  if (buffers.queue < lead) {
    return "~window " + std::to_string(window) + " lets " + std::to_string(lead) +
           " messages of one topic be in flight, but the recorder's queues hold " + std::to_string(buffers.queue) +
           ": use ~window <= " + std::to_string(maxWindow(buffers)) + " when recording";
  }
  return "";
}

}  // namespace vf::protocol
