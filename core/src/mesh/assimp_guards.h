// Private: what assimp 5.2 (Debian's, which inscribe cannot patch) cannot be trusted with in a
// COLLADA or glTF file, refused before assimp reads it. Each check in assimp_guards.cpp names
// the assimp bug it stands in front of; docs/reliability.md lists them with their seeds.
#pragma once

#include <string>

#include "absl/status/status.h"

namespace inscribe::internal {

// "COLLADA", "glTF" or "binary glTF" for the lowercase extension "dae", "gltf" or "glb".
const char* SceneFormatName(const std::string& format);

// OK, or INVALID_ARGUMENT naming `what` and the problem, for the bytes of a file of `format`
// ("dae", "gltf" or "glb"). Cost: a pass over the bytes and a parse of the XML or JSON.
absl::Status CheckSceneBeforeAssimp(const std::string& bytes, const std::string& format,
                                    const std::string& what);

}  // namespace inscribe::internal
