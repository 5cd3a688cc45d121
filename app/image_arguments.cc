#include "app/image_arguments.h"

#include <glob.h>

#include <algorithm>

#include "models/errors.h"

namespace linetrack::app {
namespace {

bool HasGlobCharacters(const std::string& text) {
  return text.find_first_of("*?[") != std::string::npos;
}

}  // namespace

std::vector<std::string> ExpandImageArguments(const std::vector<std::string>& arguments) {
  std::vector<std::string> paths;
  for (const std::string& arg : arguments) {
    if (!HasGlobCharacters(arg)) {
      paths.push_back(arg);
      continue;
    }
    glob_t matches{};
    const int status = ::glob(arg.c_str(), 0, nullptr, &matches);
    std::vector<std::string> found;
    if (status == 0) {
      for (size_t i = 0; i < matches.gl_pathc; ++i)
        found.emplace_back(matches.gl_pathv[i]);
    }
    globfree(&matches);
    if (found.empty()) throw InputError("--images: '" + arg + "' matches no file");
    std::sort(found.begin(), found.end());
    paths.insert(paths.end(), found.begin(), found.end());
  }
  return paths;
}

}  // namespace linetrack::app
