#include "tracking/capture/source_factory.h"

#include "models/errors.h"

namespace linetrack {
namespace {

// True when `spec` is `word` alone or starts with "word:"; *rest gets what follows the colon.
bool HasPrefix(const std::string& spec, const std::string& word, std::string* rest) {
  if (spec == word) {
    rest->clear();
    return true;
  }
  if (spec.size() > word.size() && spec.compare(0, word.size(), word) == 0 &&
      spec[word.size()] == ':') {
    *rest = spec.substr(word.size() + 1);
    return true;
  }
  return false;
}

}  // namespace

SourceSpec ParseSourceSpec(const std::string& spec) {
  if (spec.empty()) throw InputError("--source: empty source");
  SourceSpec parsed;
  std::string rest;
  if (HasPrefix(spec, "aravis", &rest)) {
    parsed.kind = SourceKind::kAravis;
    parsed.argument = rest;
  } else if (HasPrefix(spec, "v4l2", &rest)) {
    parsed.kind = SourceKind::kV4l2;
    parsed.argument = rest.empty() ? "/dev/video0" : rest;
  } else if (HasPrefix(spec, "sim", &rest)) {
    parsed.kind = SourceKind::kSim;
    parsed.argument = rest;
  } else if (HasPrefix(spec, "file", &rest)) {
    if (rest.empty()) throw InputError("--source: 'file:' needs a path");
    parsed.kind = SourceKind::kVideo;
    parsed.argument = rest;
  } else {
    parsed.kind = SourceKind::kVideo;
    parsed.argument = spec;
  }
  return parsed;
}

std::unique_ptr<FrameSource> OpenFrameSource(const std::string& spec,
                                             const FrameSourceOptions& options) {
  const SourceSpec parsed = ParseSourceSpec(spec);
  switch (parsed.kind) {
    case SourceKind::kAravis: {
      AravisSourceOptions aravis = options.aravis;
      aravis.device_id = parsed.argument;
      return std::make_unique<AravisSource>(aravis);
    }
    case SourceKind::kV4l2:
      return std::make_unique<V4l2Source>(parsed.argument, options.v4l2);
    case SourceKind::kVideo:
      return std::make_unique<VideoSource>(parsed.argument, options.video);
    case SourceKind::kSim:
      if (!options.make_sim) {
        throw InputError("--source " + spec + ": the simulated camera is not available here");
      }
      return options.make_sim(parsed.argument);
  }
  throw InputError("--source " + spec + ": unknown source");
}

}  // namespace linetrack
