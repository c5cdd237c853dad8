// Private: says why CGAL's reader rejected a text mesh file. CGAL's readers return only
// false; users need "line 7: face 3 refers to vertex 9, but the file has 4 vertices". This is a
// diagnosis run after a failed read, not a second parser: its result is only a message.
#pragma once

#include <string>
#include <vector>

#include "absl/strings/string_view.h"

namespace inscribe::internal {

// For "off" and "obj" text, the first problem found (with its line number), or "" when none is
// recognised. Cost O(file size).
std::string DiagnoseMeshText(const std::string& bytes, const std::string& format);

// Guards for CGAL 5.5's readers, run before them. CGAL sizes arrays from counts in the file
// before reading what they count, and trusts header structure, so hostile files could make it
// allocate tens of GB or crash. Each returns "" when the file is safe to hand to CGAL, else why
// not, with a line number where there is one.

// OFF: the header's vertex and face counts must fit in the file, and every face's corner count
// in its line. Binary OFF is refused. Cost O(file), nothing stored.
std::string CheckOffCounts(const std::string& bytes);

// The numbers CGAL's OFF scanner takes from one record: `>> double` in a loop
// (IO::iformat<double> is plain `>>` outside MSVC) up to the first that fails, so "3-1" is 3
// then -1 and "3 x 1" is 3.
std::vector<double> CgalRecordNumbers(absl::string_view record);

// PLY: a well-formed header (CGAL crashes on a "property" before any "element"), and, for
// lists with counts wider than 16 bits, every list count within the rest of the file.
// Cost O(header), or O(file) with wide list counts.
std::string CheckPlyHeader(const std::string& bytes);

}  // namespace inscribe::internal
