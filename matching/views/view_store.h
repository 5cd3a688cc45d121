// The view database on disk (docs/views.md): a directory with
//   index.json   {"format": "linetrack-views", "version": 1, "camera": {...}, "model": "...",
//                 "tokens": {...}, "views": "views.jsonl", "count": N}
//   views.jsonl  one key view per line: {"id", "pose": {"x", "y", "heading_deg", "height",
//                "tilt_deg"}, "segments": [[u1, v1, u2, v2, line_id], ...],
//                "junctions": [[point_id, u, v, [line_id, ...]], ...]}
// Pixels are undistorted; the equalisation and tokens are derived again on loading.
#pragma once

#include <string>

#include "matching/views/key_view.h"

namespace linetrack {

inline constexpr const char* kViewIndexFile = "index.json";
inline constexpr const char* kViewLinesFile = "views.jsonl";

// The text of index.json and views.jsonl for `db`.
std::string ViewIndexJson(const ViewDatabase& db);
std::string KeyViewJsonLine(const KeyView& view);

// Parses the two files' texts (`dir` names them in errors) and computes the tokens. Throws
// InputError "DIR/file:line: what" on a missing or malformed field.
ViewDatabase ParseViewDatabase(const std::string& index_text, const std::string& views_text,
                               const std::string& dir);

// Reads DIR/index.json and DIR/views.jsonl (throws InputError naming the file at fault).
ViewDatabase LoadViewDatabase(const std::string& dir);

}  // namespace linetrack
