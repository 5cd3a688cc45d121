// The subcommands that need ROS 1: registered by the `linetrack` binary, which links app/ros/.
#pragma once

#include "app/cli_common.h"

namespace linetrack::app {

// `linetrack ros`: the node (ros_node.h).
void AddRos(CLI::App& cli, CommandAction* action);

// `linetrack bench ros`: the node's latency beyond the tracking step on rendered frames, with a
// roscore of its own on a free port.
void AddBenchRos(CLI::App& cli, CommandAction* action);

}  // namespace linetrack::app
