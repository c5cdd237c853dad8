// Private: says why CGAL's reader rejected a text mesh file. CGAL's readers return only
// false; users need "line 7: face 3 refers to vertex 9, but the file has 4 vertices". This is a
// diagnosis run after a failed read, not a second parser: its result is only a message.
#pragma once

#include <string>

namespace inscribe::internal {

// For "off" and "obj" text, the first problem found (with its line number), or "" when none is
// recognised. Cost O(file size).
std::string DiagnoseMeshText(const std::string& bytes, const std::string& format);

// For OFF text: "" when the counts in the header can fit in the file, else why not. CGAL's
// reader reserves memory for the announced counts before reading them, so a 30-byte file
// announcing a billion vertices would otherwise take tens of GB and minutes. Binary OFF and
// other formats return "". Cost O(header).
std::string CheckOffCounts(const std::string& bytes);

}  // namespace inscribe::internal
