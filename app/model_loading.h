// Loading a model in every command: the reader's warnings, what orienting its faces changed and
// the model checks (models/model_checks.h) go to stderr; with `--strict` a finding refuses the
// model (exit 2).
#pragma once

#include <string>
#include <vector>

#include "models/model_checks.h"
#include "models/wireframe.h"

namespace linetrack::app {

// Makes every later LoadModel refuse a model with findings (the global --strict flag).
void SetStrictModelChecks(bool strict);

// Reports on stderr what the model's loading found: its warnings, the orientation summary, the
// checks' findings (returned). Throws InputError under --strict when there are findings.
std::vector<ModelFinding> ReportModel(const WireframeModel& model);

// Reads the .cao model and reports on stderr: its warnings, the orientation summary, the checks'
// findings. Throws InputError when the file is bad, or under --strict when there are findings.
WireframeModel LoadModel(const std::string& path, const WireframeOptions& options = {});

}  // namespace linetrack::app
