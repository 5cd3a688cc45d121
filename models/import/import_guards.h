// Checks made on a model file before Assimp reads it: Assimp 5.2.5 does not return on some
// malformed input (a PLY element line with extra fields runs for minutes), and sizes its buffers
// from the counts a header claims. Bad input is an InputError naming the file and line.
#pragma once

#include <cstdint>
#include <string>

namespace linetrack {

// Validates a PLY file's text (the header, and for ASCII the body that follows; `file_size` bytes
// in all):
// the "ply" magic, one "format ascii|binary_little_endian|binary_big_endian 1.0" line, "element
// NAME COUNT" lines with a decimal count, "property TYPE NAME" and "property list TYPE TYPE NAME"
// lines of PLY's scalar types after an element, "comment" and "obj_info" lines; element counts
// must fit the file (an ASCII record takes at least 1 byte, a binary one its scalar sizes). An
// ASCII body has one line a record with the values its properties need, list lengths at least 1
// in faces, and face vertex indices within the vertices (Assimp 5.2.5 aborts on a face of none).
void CheckPlyText(const std::string& text, std::uint64_t file_size, const std::string& path);

// The checks of the file at `path` that apply to its format (PLY, by its magic or extension);
// throws InputError naming the file when it is unreadable or fails them.
void CheckBeforeAssimp(const std::string& path);

}  // namespace linetrack
