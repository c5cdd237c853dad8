// What a call's reactor may use of the service (GenerateReactor, the frame streams), handed to
// it when its call starts: the reactors live outside InscribeService and reach nothing of it
// but these. Private to the server.
#pragma once

#include <atomic>
#include <cstdint>

#include "inscribe/server/inscribe_service.h"

namespace inscribe::server {

class Admission;
class FrameDispatcher;
class MeshSizes;
class ResultStore;

// References into the service, which owns every part and outlives every call.
struct ServiceParts {
  Admission& admission;                    // the checks before work, the calls in flight, drain
  ResultStore& store;                      // the typed cache
  FrameDispatcher& frames;                 // where a stream's frame runs
  const MeshSizes& mesh_sizes;             // stored meshes' sizes, for Generate's estimate
  const ServiceLimits& limits;             // the per-request flags
  std::atomic<std::int64_t>& open_scenes;  // SceneStreams open (InscribeService::open_scenes)
};

}  // namespace inscribe::server
