// Private: numbers in messages and text files, written so that they read back exactly.
#pragma once

#include <charconv>
#include <string>

namespace inscribe::internal {

// The shortest decimal that std::from_chars / strtod read back as exactly `value` (finite).
inline std::string FormatDouble(double value) {
  // 24 bytes hold the longest shortest form ("-2.2250738585072014e-308" is 24 characters).
  char buffer[32];
  const std::to_chars_result result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

}  // namespace inscribe::internal
