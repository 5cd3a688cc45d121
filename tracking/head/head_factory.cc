#include "tracking/head/head_factory.h"

#include <stdexcept>

#include "models/errors.h"

namespace linetrack {

HeadSpec ParseHeadSpec(const std::string& spec) {
  HeadSpec parsed;
  if (spec == "sim") {
    parsed.kind = HeadKind::kSim;
    return parsed;
  }
  if (spec.rfind("ptu:", 0) == 0 && spec.size() > 4) {
    parsed.kind = HeadKind::kPtu;
    parsed.device = spec.substr(4);
    return parsed;
  }
  throw InputError("--head " + spec + ": expected ptu:/dev/ttyXXX or sim");
}

std::unique_ptr<PanTiltHead> OpenHead(const std::string& spec, const HeadOptions& options) {
  const HeadSpec parsed = ParseHeadSpec(spec);
  if (parsed.kind == HeadKind::kSim) {
    if (!options.make_sim)
      throw InputError("--head " + spec + ": the simulated head is not available here");
    return options.make_sim();
  }
  PtuOptions ptu = options.ptu;
  ptu.device = parsed.device;
  HeadResult result;
  std::unique_ptr<PtuDriver> driver = PtuDriver::Open(ptu, &result);
  if (driver) return driver;
  if (result.status == HeadStatus::kIoError)
    throw InputError("--head " + spec + ": " + result.message);
  throw std::runtime_error("--head " + spec + ": " + result.message);
}

}  // namespace linetrack
