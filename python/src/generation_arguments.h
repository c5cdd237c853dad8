// The generation settings Python callers give (inscribe.generate, inscribe.Client.generate), as
// core's SphereSetParameters: one reading of them for both.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "inscribe/generation/sphere_set_generation.h"

namespace inscribe::python {

// Only what the caller gave overrides core's default in `field`.
template <typename T>
void Override(T& field, const std::optional<T>& value) {
  if (value) field = *value;
}

// The keyword arguments of generate; nullopt: not given (core's default).
struct GenerateArguments {
  std::optional<std::int64_t> max_spheres;
  std::optional<double> voxel_size;
  std::string kind = "internal";  // "internal", "dilated" or "cover"
  std::optional<double> object_angle;
  std::optional<double> epsilon;
  std::optional<int> samples;
  std::optional<bool> subdivide_boundary;
  std::optional<std::int64_t> max_voxels;
  std::optional<double> dilation_growth;
  std::optional<double> max_protrusion;
  std::optional<double> cover_resolution;
  bool evaluate = true;
  std::optional<std::int64_t> quality_samples;
  std::optional<std::string> selection;  // "paper" or "optimised"
};

// Core's parameters with the given arguments over its defaults, checked by
// CheckSphereSetParameters; ValueError (RaiseStatus) naming the field otherwise.
SphereSetParameters SphereSetParametersOf(const GenerateArguments& arguments);

}  // namespace inscribe::python
