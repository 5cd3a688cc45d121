#include "models/import/import_guards.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "models/errors.h"

namespace linetrack {
namespace {

// A PLY header longer than this (bytes) is not a header.
constexpr std::size_t kMaxPlyHeaderBytes = 1 << 16;

// Bytes of PLY's scalar types (PLY 1.0 names and the sized aliases); 0 for an unknown name.
std::size_t ScalarBytes(const std::string& type) {
  static const std::map<std::string, std::size_t> kBytes = {
      {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
      {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto it = kBytes.find(type);
  return it == kBytes.end() ? 0 : it->second;
}

std::vector<std::string> Words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;)
    words.push_back(w);
  return words;
}

// A decimal count, at most 2^31 - 1; false for anything else.
bool ParseCount(const std::string& word, std::uint64_t* count) {
  if (word.empty() || word.size() > 10 ||
      !std::all_of(word.begin(), word.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return false;
  }
  *count = std::stoull(word);
  return *count <= 0x7fffffffULL;
}

struct PlyProperty {
  bool list = false;
  std::string name;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::uint64_t min_record_bytes = 0;  // binary: the scalars, and one length byte per list
  std::vector<PlyProperty> properties;
};

// An integer in [lo, hi) written in decimal (sign allowed); false for anything else.
bool IntegerIn(const std::string& word, long long lo, long long hi) {
  if (word.empty() || word.size() > 12) return false;
  const size_t digits = word[0] == '-' || word[0] == '+' ? 1 : 0;
  if (digits == word.size() ||
      !std::all_of(word.begin() + static_cast<std::ptrdiff_t>(digits), word.end(),
                   [](unsigned char c) { return std::isdigit(c); })) {
    return false;
  }
  const long long value = std::stoll(word);
  return value >= lo && value < hi;
}

// The ASCII body: one line a record with the tokens its properties need; list lengths are
// integers (at least 1 in a face), and the vertex indices of faces refer to existing vertices.
void CheckPlyAsciiBody(std::istream& in, int line_no, const std::vector<PlyElement>& elements,
                       const std::string& path) {
  long long vertices = 0;
  for (const PlyElement& e : elements) {
    if (e.name == "vertex") vertices = static_cast<long long>(e.count);
  }
  std::string line;
  for (const PlyElement& e : elements) {
    for (std::uint64_t r = 0; r < e.count; ++r) {
      if (!std::getline(in, line)) {
        throw InputError(Located(path, line_no,
                                 "PLY body: the file ends before its " + std::to_string(e.count) +
                                     " " + e.name + " records"));
      }
      ++line_no;
      auto fail = [&](const std::string& why) {
        throw InputError(Located(path, line_no, "PLY body: " + e.name + " record: " + why));
      };
      const std::vector<std::string> w = Words(line);
      size_t k = 0;
      for (const PlyProperty& p : e.properties) {
        if (k >= w.size()) fail("too few values");
        if (!p.list) {
          ++k;
          continue;
        }
        const bool face = e.name == "face";
        if (!IntegerIn(w[k], face ? 1 : 0, 1 << 16)) fail("a list length is not an integer");
        const size_t n = static_cast<size_t>(std::stoll(w[k++]));
        if (w.size() - k < n) fail("too few values");
        const bool indices = face && (p.name == "vertex_indices" || p.name == "vertex_index");
        for (size_t i = 0; i < n && indices; ++i) {
          if (!IntegerIn(w[k + i], 0, vertices)) fail("a vertex index is not a vertex");
        }
        k += n;
      }
      if (k != w.size()) fail("too many values");
    }
  }
}

}  // namespace

void CheckPlyText(const std::string& text, std::uint64_t file_size, const std::string& path) {
  std::istringstream in(text);
  const std::size_t header_end = text.find("end_header");
  const std::size_t body_start = header_end == std::string::npos
                                     ? text.size()
                                     : std::min(text.find('\n', header_end), text.size() - 1) + 1;
  std::string line;
  int line_no = 0;
  std::string format;
  std::vector<PlyElement> elements;
  bool ended = false;
  while (!ended && std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::vector<std::string> w = Words(line);
    auto fail = [&](const std::string& why) {
      throw InputError(Located(path, line_no, "malformed PLY header: " + why));
    };
    if (line_no == 1) {
      if (w.size() != 1 || w[0] != "ply") fail("the first line must be 'ply'");
      continue;
    }
    if (w.empty()) fail("empty line");
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      if (!format.empty()) fail("a second format line");
      if (w.size() != 3 || w[2] != "1.0" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian")) {
        fail("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      }
      format = w[1];
    } else if (w[0] == "element") {
      PlyElement element;
      element.name = w[1 % w.size()];
      if (w.size() != 3 || !ParseCount(w[2], &element.count)) {
        fail("expected 'element NAME COUNT' with a count under 2^31");
      }
      elements.push_back(element);
    } else if (w[0] == "property") {
      if (elements.empty()) fail("a property before any element");
      const bool list = w.size() == 5 && w[1] == "list";
      if (list ? (ScalarBytes(w[2]) == 0 || ScalarBytes(w[3]) == 0)
               : (w.size() != 3 || ScalarBytes(w[1]) == 0)) {
        fail("expected 'property TYPE NAME' or 'property list TYPE TYPE NAME'");
      }
      elements.back().min_record_bytes += list ? ScalarBytes(w[2]) : ScalarBytes(w[1]);
      elements.back().properties.push_back({list, w.back()});
    } else if (w[0] == "end_header") {
      if (w.size() != 1) fail("extra words after end_header");
      ended = true;
    } else {
      fail("unknown keyword '" + w[0] + "'");
    }
  }
  if (!ended) throw InputError(Located(path, line_no, "malformed PLY header: no end_header"));
  if (format.empty()) throw InputError(Located(path, line_no, "malformed PLY header: no format"));
  // What the counts claim must fit the bytes after the header.
  const std::uint64_t header = std::min<std::uint64_t>(body_start, file_size);
  const std::uint64_t body = file_size - header;
  std::uint64_t needed = 0;
  for (const PlyElement& e : elements) {
    // An ASCII record takes at least one byte (its line break), a binary one its scalars.
    const std::uint64_t record =
        format == "ascii" ? 1 : std::max<std::uint64_t>(1, e.min_record_bytes);
    needed += e.count * record;  // below 2^31 * 2^16: no overflow
  }
  if (needed > body) {
    throw InputError(Located(path, line_no,
                             "malformed PLY header: its element counts need at least " +
                                 std::to_string(needed) + " bytes, the file holds " +
                                 std::to_string(body) + " after the header"));
  }
  if (format == "ascii") CheckPlyAsciiBody(in, line_no, elements, path);
}

void CheckBeforeAssimp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!in || ec) throw InputError(Located(path, 0, "cannot read the model file"));
  std::string head(std::min<std::uintmax_t>(size, kMaxPlyHeaderBytes), '\0');
  in.read(&head[0], static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  // Assimp picks its PLY reader by the extension or by the magic.
  const bool magic = head.compare(0, 3, "ply") == 0 &&
                     (head.size() == 3 || head[3] == '\n' || head[3] == '\r' || head[3] == ' ');
  if (ext != ".ply" && !magic) return;
  const std::size_t end = head.find("end_header");
  if (end == std::string::npos) {
    throw InputError(Located(path, 0,
                             "malformed PLY header: no end_header in its first " +
                                 std::to_string(kMaxPlyHeaderBytes) + " bytes"));
  }
  // An ASCII body is checked too: read the whole file.
  if (head.find("format ascii") < end && size > head.size()) {
    const std::size_t read = head.size();
    head.resize(static_cast<std::size_t>(size));
    in.read(&head[read], static_cast<std::streamsize>(size - read));
    head.resize(read + static_cast<std::size_t>(in.gcount()));
  }
  CheckPlyText(head, size, path);
}

}  // namespace linetrack
