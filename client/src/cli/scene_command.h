// `inscribe scene SCENE.json POSES`: a scene of posed objects in the service (SceneStream),
// a pose log replayed over it, and per frame the pairs of objects closer than a threshold.
#pragma once

#include <CLI/CLI.hpp>

#include "command_outcome.h"

namespace inscribe::cli {

void AddSceneCommand(CLI::App& app, CommandOutcome* outcome);

}  // namespace inscribe::cli
