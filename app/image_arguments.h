// Image files named on the command line (`calibrate`, `calibrate-mount`): paths or glob patterns.
#pragma once

#include <string>
#include <vector>

namespace linetrack::app {

// Expands each argument as a glob (sorted matches); arguments without wildcards stay as they
// are. Throws InputError for a wildcard pattern that matches no file.
std::vector<std::string> ExpandImageArguments(const std::vector<std::string>& arguments);

}  // namespace linetrack::app
