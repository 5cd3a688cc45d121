#include "models/cao_reader.h"

#include <Eigen/Geometry>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "models/errors.h"

namespace linetrack {
namespace {

// ViSP refuses sections larger than this; so do we (and it bounds allocations on bad input).
constexpr long kMaxCount = 100000;
constexpr int kMaxIncludeDepth = 16;

struct Line {
  int number = 0;  // 1-based line number in the file
  std::vector<std::string> tokens;
};

// Splits text into non-empty lines of whitespace-separated tokens, comments ('#' to the end of
// the line) and carriage returns removed. A quoted parameter value (name="north door") stays one
// token.
std::vector<Line> Tokenize(const std::string& text) {
  std::vector<Line> lines;
  std::istringstream in(text);
  std::string raw;
  int number = 0;
  while (std::getline(in, raw)) {
    ++number;
    const size_t hash = raw.find('#');
    if (hash != std::string::npos) raw.resize(hash);
    for (char& c : raw) {
      if (c == '\r' || c == '\t' || c == '\v' || c == '\f') c = ' ';
    }
    std::istringstream words(raw);
    Line line{number, {}};
    std::string token;
    while (words >> token) {
      const size_t quote = token.find("=\"");
      std::string more;  // the rest of a quoted value, up to its closing quote
      while (quote != std::string::npos && (token.size() == quote + 2 || token.back() != '"') &&
             words >> more) {
        token += " " + more;
      }
      line.tokens.push_back(token);
    }
    if (!line.tokens.empty()) lines.push_back(std::move(line));
  }
  return lines;
}

bool ParseDouble(const std::string& s, double* out) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

bool ParseIndex(const std::string& s, long* out) {
  if (s.empty() || s.size() > 12) return false;
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (end != s.c_str() + s.size() || v < 0) return false;
  *out = v;
  return true;
}

// Parameters ViSP allows after an element, e.g. name="door" useLod=true.
bool IsParameter(const std::string& token) {
  return token.find('=') != std::string::npos;
}

// The value of the name="..." (or name=...) parameter among tokens[from...]; "" without one.
std::string NameParameter(const std::vector<std::string>& tokens, size_t from) {
  for (size_t i = from; i < tokens.size(); ++i) {
    if (tokens[i].rfind("name=", 0) != 0) continue;
    std::string value = tokens[i].substr(5);
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"') {
      value = value.substr(1, value.size() - 2);
    }
    return value;
  }
  return "";
}

std::string ParentDirectory(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return "";
  return path.substr(0, slash + 1);
}

class Parser {
 public:
  Parser(const std::string& path, const CaoIncludeReader& read_include, CaoModel* model,
         const Eigen::Isometry3d& model_from_file, int depth)
      : path_(path),
        read_include_(read_include),
        model_(model),
        model_from_file_(model_from_file),
        depth_(depth) {}

  void Parse(const std::string& text) {
    lines_ = Tokenize(text);
    model_->files.push_back(std::filesystem::path(path_).lexically_normal().string());
    ParseHeader();
    const int base = static_cast<int>(model_->points.size());
    const long num_points = ReadCount("number of points");
    if (num_points == 0 && !had_include_) Fail(last_line_, "the model defines no points");
    for (long k = 0; k < num_points; ++k)
      ReadPoint(k);
    ReadLines(base, num_points);
    ReadFacesFromLines();
    ReadFacesFromPoints(base, num_points);
    ReadIgnoredSection("cylinders", "cylinder", 3);
    ReadIgnoredSection("circles", "circle", 4);
    if (next_ < lines_.size()) {
      Fail(lines_[next_].number,
           "unexpected content after the circles section: '" + lines_[next_].tokens.front() + "'");
    }
  }

 private:
  [[noreturn]] void Fail(int line, const std::string& what) const {
    throw InputError(Located(path_, line, what));
  }

  const Line& Next(const std::string& expected) {
    if (next_ >= lines_.size()) Fail(last_line_, "file ends early: expected " + expected);
    last_line_ = lines_[next_].number;
    return lines_[next_++];
  }

  void ParseHeader() {
    if (next_ < lines_.size() && !lines_[next_].tokens.empty() &&
        (lines_[next_].tokens[0] == "V1" || lines_[next_].tokens[0] == "V2")) {
      version_ = lines_[next_].tokens[0] == "V2" ? 2 : 1;
      ++next_;
    } else if (next_ < lines_.size() && lines_[next_].tokens[0][0] == 'V') {
      Fail(lines_[next_].number, "unsupported version '" + lines_[next_].tokens[0] + "'");
    }
    while (next_ < lines_.size() && lines_[next_].tokens[0].rfind("load", 0) == 0) {
      const Line& line = Next("load(...)");
      ParseInclude(line);
    }
  }

  // load("path.cao"[, t=[x;y;z]][, tu=[a;b;c]]) with tu in radians or with a "deg" suffix.
  void ParseInclude(const Line& line) {
    std::string joined;
    for (const std::string& t : line.tokens)
      joined += t + " ";
    const size_t q1 = joined.find('"');
    const size_t q2 = q1 == std::string::npos ? q1 : joined.find('"', q1 + 1);
    if (q1 == std::string::npos || q2 == std::string::npos || joined.find('(') > q1) {
      Fail(line.number, "malformed load(\"file.cao\") include");
    }
    std::string include = joined.substr(q1 + 1, q2 - q1 - 1);
    if (include.empty()) Fail(line.number, "load() names no file");
    if (include[0] != '/') include = ParentDirectory(path_) + include;
    Eigen::Isometry3d file_from_include = Eigen::Isometry3d::Identity();
    const std::string params = joined.substr(q2 + 1);
    Eigen::Vector3d t;
    if (ReadVectorParam(params, "t=[", line.number, &t, /*angles=*/false)) {
      file_from_include.translation() = t;
    }
    Eigen::Vector3d tu;
    if (ReadVectorParam(params, "tu=[", line.number, &tu, /*angles=*/true) && tu.norm() > 0.0) {
      file_from_include.linear() = Eigen::AngleAxisd(tu.norm(), tu.normalized()).toRotationMatrix();
    }
    if (!read_include_) Fail(line.number, "includes are not allowed here");
    if (depth_ + 1 > kMaxIncludeDepth) Fail(line.number, "includes nested too deeply");
    include = std::filesystem::path(include).lexically_normal().string();
    for (const std::string& seen : model_->files) {
      if (seen == include) {  // as ViSP does: warn and skip
        model_->warnings.push_back(
            Located(path_, line.number, "skipped repeated include of " + include));
        return;
      }
    }
    const std::optional<std::string> text = read_include_(include);
    if (!text) Fail(line.number, "cannot read included file " + include);
    Parser child(include, read_include_, model_, model_from_file_ * file_from_include, depth_ + 1);
    child.Parse(*text);
    had_include_ = true;
  }

  bool ReadVectorParam(const std::string& params, const std::string& prefix, int line,
                       Eigen::Vector3d* out, bool angles) const {
    const size_t start = params.find(prefix);
    if (start == std::string::npos) return false;
    const size_t end = params.find(']', start);
    if (end == std::string::npos) Fail(line, "unterminated " + prefix + "...]");
    std::string body = params.substr(start + prefix.size(), end - start - prefix.size());
    for (char& c : body) {
      if (c == ';') c = ' ';
    }
    std::istringstream in(body);
    std::string word;
    int k = 0;
    while (in >> word) {
      if (k >= 3) Fail(line, prefix + "...] takes three values");
      double scale = 1.0;
      if (angles && word.size() > 3 && word.compare(word.size() - 3, 3, "deg") == 0) {
        word.resize(word.size() - 3);
        scale = 3.14159265358979323846 / 180.0;
      } else if (angles && word.size() > 3 && word.compare(word.size() - 3, 3, "rad") == 0) {
        word.resize(word.size() - 3);
      }
      double v = 0.0;
      if (!ParseDouble(word, &v)) Fail(line, "not a number in " + prefix + "...]: '" + word + "'");
      (*out)[k++] = v * scale;
    }
    if (k != 3) Fail(line, prefix + "...] takes three values");
    return true;
  }

  long ReadCount(const std::string& what) {
    const Line& line = Next(what);
    long count = 0;
    if (!ParseIndex(line.tokens[0], &count)) {
      Fail(line.number, "expected the " + what + ", got '" + line.tokens[0] + "'");
    }
    if (count > kMaxCount)
      Fail(line.number, "the " + what + " exceeds " + std::to_string(kMaxCount));
    for (size_t i = 1; i < line.tokens.size(); ++i) {
      Fail(line.number, "unexpected '" + line.tokens[i] + "' after the " + what);
    }
    return count;
  }

  void ReadPoint(long k) {
    const Line& line = Next("point " + std::to_string(k));
    const size_t needed = version_ == 2 ? 5 : 3;
    if (line.tokens.size() < 3) {
      Fail(line.number, "point " + std::to_string(k) + " needs 3 coordinates");
    }
    Eigen::Vector3d p;
    for (int i = 0; i < 3; ++i) {
      if (!ParseDouble(line.tokens[i], &p[i])) {
        Fail(line.number,
             "point " + std::to_string(k) + ": not a finite number: '" + line.tokens[i] + "'");
      }
    }
    if (line.tokens.size() > needed && !IsParameter(line.tokens[needed])) {
      Fail(line.number,
           "point " + std::to_string(k) + ": unexpected '" + line.tokens[needed] + "'");
    }
    model_->points.push_back(model_from_file_ * p);
  }

  int ReadIndex(const Line& line, size_t token, long limit, const std::string& what) {
    if (token >= line.tokens.size()) Fail(line.number, what + ": missing index");
    long index = 0;
    if (!ParseIndex(line.tokens[token], &index)) {
      Fail(line.number, what + ": not an index: '" + line.tokens[token] + "'");
    }
    if (index >= limit) {
      Fail(line.number, what + ": index " + std::to_string(index) + " out of range (0.." +
                            std::to_string(limit - 1) + ")");
    }
    return static_cast<int>(index);
  }

  void CheckOnlyParameters(const Line& line, size_t from, const std::string& what) const {
    for (size_t i = from; i < line.tokens.size(); ++i) {
      if (!IsParameter(line.tokens[i])) {
        Fail(line.number, what + ": unexpected '" + line.tokens[i] + "'");
      }
    }
  }

  void ReadLines(int base, long num_points) {
    const long count = ReadCount("number of 3D lines");
    for (long k = 0; k < count; ++k) {
      const std::string what = "line " + std::to_string(k);
      const Line& line = Next(what);
      const int a = ReadIndex(line, 0, num_points, what);
      const int b = ReadIndex(line, 1, num_points, what);
      CheckOnlyParameters(line, 2, what);
      file_lines_.push_back({base + a, base + b});
      model_->lines.push_back({base + a, base + b});
      model_->line_names.push_back(NameParameter(line.tokens, 2));
    }
  }

  // A face from lines becomes the loop of points obtained by chaining its lines end to end.
  void ReadFacesFromLines() {
    const long count = ReadCount("number of faces from lines");
    for (long k = 0; k < count; ++k) {
      const std::string what = "face from lines " + std::to_string(k);
      const Line& line = Next(what);
      long n = 0;
      if (!ParseIndex(line.tokens[0], &n) || n < 3 || n > kMaxCount) {
        Fail(line.number, what + ": expected a line count >= 3, got '" + line.tokens[0] + "'");
      }
      std::vector<std::array<int, 2>> edges;
      for (long i = 0; i < n; ++i) {
        edges.push_back(file_lines_[ReadIndex(line, 1 + i, file_lines_.size(), what)]);
      }
      CheckOnlyParameters(line, 1 + n, what);
      model_->faces.push_back(ChainLines(edges, line.number, what));
      model_->face_names.push_back(NameParameter(line.tokens, 1 + n));
    }
  }

  std::vector<int> ChainLines(const std::vector<std::array<int, 2>>& edges, int line,
                              const std::string& what) const {
    std::vector<int> loop = {edges[0][0], edges[0][1]};
    for (size_t i = 1; i < edges.size(); ++i) {
      const int last = loop.back();
      int next = -1;
      if (edges[i][0] == last) next = edges[i][1];
      if (edges[i][1] == last) next = edges[i][0];
      if (i == 1 && next < 0) {  // the first line may be listed in reverse
        std::swap(loop[0], loop[1]);
        if (edges[i][0] == loop.back()) next = edges[i][1];
        if (edges[i][1] == loop.back()) next = edges[i][0];
      }
      if (next < 0) Fail(line, what + ": its lines do not form a closed chain");
      loop.push_back(next);
    }
    if (loop.back() != loop.front()) Fail(line, what + ": its lines do not form a closed chain");
    loop.pop_back();
    return loop;
  }

  void ReadFacesFromPoints(int base, long num_points) {
    const long count = ReadCount("number of faces from points");
    for (long k = 0; k < count; ++k) {
      const std::string what = "face from points " + std::to_string(k);
      const Line& line = Next(what);
      long n = 0;
      if (!ParseIndex(line.tokens[0], &n) || n < 3 || n > kMaxCount) {
        Fail(line.number, what + ": expected a point count >= 3, got '" + line.tokens[0] + "'");
      }
      std::vector<int> face;
      for (long i = 0; i < n; ++i)
        face.push_back(base + ReadIndex(line, 1 + i, num_points, what));
      CheckOnlyParameters(line, 1 + n, what);
      model_->faces.push_back(std::move(face));
      model_->face_names.push_back(NameParameter(line.tokens, 1 + n));
    }
  }

  // Cylinders (p1 p2 radius) and circles (radius centre p1 p2) are accepted and ignored.
  void ReadIgnoredSection(const std::string& name, const std::string& singular, size_t fields) {
    if (next_ >= lines_.size()) return;  // the trailing sections may be left out
    const long count = ReadCount("number of " + name);
    for (long k = 0; k < count; ++k) {
      const std::string what = singular + " " + std::to_string(k);
      const Line& line = Next(what);
      if (line.tokens.size() < fields) {
        Fail(line.number, what + ": needs " + std::to_string(fields) + " values");
      }
      for (size_t i = 0; i < fields; ++i) {
        double v = 0.0;
        if (!ParseDouble(line.tokens[i], &v)) {
          Fail(line.number, what + ": not a finite number: '" + line.tokens[i] + "'");
        }
      }
    }
    if (count > 0) {
      model_->warnings.push_back(Located(
          path_, 0,
          std::to_string(count) + " " + name + " ignored (linetrack uses straight edges only)"));
    }
  }

  const std::string path_;
  const CaoIncludeReader& read_include_;
  CaoModel* model_;
  const Eigen::Isometry3d model_from_file_;
  const int depth_;
  std::vector<Line> lines_;
  size_t next_ = 0;
  int last_line_ = 0;
  int version_ = 1;
  bool had_include_ = false;
  std::vector<std::array<int, 2>> file_lines_;  // this file's lines, global point indices
};

}  // namespace

CaoModel ParseCao(const std::string& text, const std::string& path,
                  const CaoIncludeReader& read_include) {
  CaoModel model;
  Parser parser(path, read_include, &model, Eigen::Isometry3d::Identity(), 0);
  parser.Parse(text);
  return model;
}

CaoModel ReadCao(const std::string& path) {
  const CaoIncludeReader read_file = [](const std::string& file) -> std::optional<std::string> {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) return std::nullopt;
    std::ifstream in(file, std::ios::binary);
    if (!in) return std::nullopt;
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) return std::nullopt;
    return buffer.str();
  };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(Located(path, 0, "no such model file"));
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(Located(path, 0, "not a regular file"));
  }
  const std::optional<std::string> text = read_file(path);
  if (!text) throw InputError(Located(path, 0, "cannot read the model file"));
  return ParseCao(*text, path, read_file);
}

}  // namespace linetrack
