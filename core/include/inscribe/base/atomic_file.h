// Replacing a file's contents so that readers see the old file or the new one, never a part.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace inscribe {

// Writes `bytes` to a unique temporary sibling of `path`, fsyncs it and renames it over
// `path`. On failure `path` is untouched and the temporary removed. Errors: NOT_FOUND (missing
// directory), PERMISSION_DENIED, INTERNAL for other I/O failures; messages name `path` and
// strerror.
absl::Status WriteFileAtomically(const std::string& path, absl::string_view bytes);

}  // namespace inscribe
