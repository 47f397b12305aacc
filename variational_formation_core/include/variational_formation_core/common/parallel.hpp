#pragma once

#include <functional>

namespace vf {

/**
 * Runs task(0) .. task(tasks - 1) on `threads` threads (at least 1), each task exactly once,
 * taken in increasing order from a shared counter. Tasks must write to disjoint places, so the
 * results cannot depend on the thread count.
 * @param weight how many units of work task t counts as in the progress report (default 1).
 * @param progress if given, called from the calling thread about every 100 ms with the units
 *        done so far, and once more at the end.
 */
void parallelFor(int tasks, int threads, const std::function<void(int)>& task,
                 const std::function<long(int)>& weight = {},
                 const std::function<void(long)>& progress = {});

}  // namespace vf
