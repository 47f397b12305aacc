#pragma once

#include "variational_formation_msgs/RunProgress.h"
#include "variational_formation_core/protocol/progress.hpp"

namespace vf {

/// protocol::Progress as a RunProgress message (commands and the stamp left 0).
variational_formation_msgs::RunProgress toMessage(const protocol::Progress& progress);
/// What an agent reads of a RunProgress: the flow state and the commands it counts.
protocol::AgentProgress agentProgressOf(const variational_formation_msgs::RunProgress& message);

}  // namespace vf
