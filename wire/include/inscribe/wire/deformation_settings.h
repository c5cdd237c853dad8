// What an UpdateDeformation request asks besides the mesh, the set and the vertices. A plain
// value, without gRPC, so that the client library's API can take it; convert.h maps it.
#pragma once

#include "inscribe/medial/sphere_deformation.h"

namespace inscribe::wire {

struct DeformationSettings {
  // xi, strict and direction. The oracle's backend is the server's to choose and is not sent.
  DeformationOptions options;
  bool bounds = false;  // also compute the error bounds (exact union volumes)
  bool store = false;   // also cache the moved set and return its key
};

}  // namespace inscribe::wire
