#include "app/model_loading.h"

#include <spdlog/spdlog.h>

#include "models/errors.h"
#include "models/model_checks.h"

namespace linetrack::app {
namespace {

bool strict_checks = false;

}  // namespace

void SetStrictModelChecks(bool strict) {
  strict_checks = strict;
}

std::vector<ModelFinding> ReportModel(const WireframeModel& model) {
  for (const std::string& w : model.warnings())
    spdlog::warn("{}", w);
  for (const std::string& line : model.orientation_summary())
    spdlog::info("{}: {}", model.path(), line);
  const std::vector<ModelFinding> findings = CheckModel(model);
  if (strict_checks && !findings.empty()) {
    throw InputError(findings.front().message + " (refused under --strict)");
  }
  for (const ModelFinding& finding : findings)
    spdlog::warn("{}", finding.message);
  return findings;
}

WireframeModel LoadModel(const std::string& path, const WireframeOptions& options) {
  WireframeModel model = WireframeModel::Load(path, options);
  ReportModel(model);
  return model;
}

}  // namespace linetrack::app
