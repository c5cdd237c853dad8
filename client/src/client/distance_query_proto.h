// How a distance query's bounding volume and tolerances go on the wire; shared by
// Client::Distance and DistanceSession, private to the client library.
#pragma once

#include <limits>

#include "inscribe/separation_distance.h"
#include "inscribe/sphere_hierarchy.h"
#include "inscribe/v1/service.pb.h"
#include "inscribe/v1/spheres.pb.h"

namespace inscribe::client {

inline v1::HierarchyVolume VolumeToProto(HierarchyVolume volume) {
  return volume == HierarchyVolume::kRss ? v1::RSS : v1::SPHERE;
}

// closer_than is sent only when asked (core's "unset" is +infinity, the wire's is absence);
// other values, NaN included, go as they are for the server to judge.
inline void ToleranceToProto(const DistanceRequest& tolerance, v1::DistanceTolerance* out) {
  out->set_abs_err(tolerance.abs_err);
  out->set_rel_err(tolerance.rel_err);
  if (tolerance.closer_than != std::numeric_limits<double>::infinity()) {
    out->set_closer_than(tolerance.closer_than);
  }
}

}  // namespace inscribe::client
