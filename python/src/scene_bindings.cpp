// inscribe.Scene: many posed objects, a broad phase, and per frame every pair closer than a
// threshold (core's Scene); inscribe.SceneFrame shows a frame's pairs as numpy views.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bindings.h"
#include "distance_types.h"
#include "inscribe/scene/scene.h"
#include "interruptible.h"
#include "status_errors.h"

namespace inscribe::python {
namespace {

// Scene ids are keys: an unknown one is a KeyError and a repeated one a ValueError; every
// other status maps as everywhere (RaiseStatus).
void SceneOkOrRaise(const absl::Status& status) {
  if (status.code() == absl::StatusCode::kNotFound) {
    throw py::key_error(std::string(status.message()));
  }
  if (status.code() == absl::StatusCode::kAlreadyExists) {
    throw py::value_error(std::string(status.message()));
  }
  OkOrRaise(status);
}

// A frame's pairs, owned here and shown to Python as strided views (no copies).
struct PySceneFrame {
  SceneFrame frame;
};

template <typename T, typename Field>
py::array PairField(py::object self, Field field, py::ssize_t cols) {
  const std::vector<ScenePair>& pairs = self.cast<const PySceneFrame&>().frame.pairs;
  static const ScenePair kEmpty;
  const ScenePair& first = pairs.empty() ? kEmpty : pairs.front();
  return ReadOnlyView<T>(field(first), static_cast<py::ssize_t>(pairs.size()), cols,
                         static_cast<py::ssize_t>(sizeof(ScenePair)), self);
}

}  // namespace

void BindScene(py::module_& m) {
  py::class_<PySceneFrame>(m, "SceneFrame",
                           "One frame's close pairs, sorted by (a, b), as read-only numpy views "
                           "(no copies).")
      .def_property_readonly(
          "a",
          [](py::object s) {
            return PairField<std::uint64_t>(
                s, [](const ScenePair& p) { return &p.a; }, 0);
          },
          "(K,) uint64 id of each pair's first object (the smaller id)")
      .def_property_readonly(
          "b",
          [](py::object s) {
            return PairField<std::uint64_t>(
                s, [](const ScenePair& p) { return &p.b; }, 0);
          },
          "(K,) uint64 id of each pair's second object")
      .def_property_readonly(
          "distance",
          [](py::object s) {
            return PairField<double>(
                s, [](const ScenePair& p) { return &p.result.distance; }, 0);
          },
          "(K,) float64 sphere distance (the covers' for certified pairs), mesh units")
      .def_property_readonly(
          "sphere_a",
          [](py::object s) {
            return PairField<std::int32_t>(
                s, [](const ScenePair& p) { return &p.result.sphere_a; }, 0);
          },
          "(K,) int32 closest sphere of a")
      .def_property_readonly(
          "sphere_b",
          [](py::object s) {
            return PairField<std::int32_t>(
                s, [](const ScenePair& p) { return &p.result.sphere_b; }, 0);
          },
          "(K,) int32 closest sphere of b")
      .def_property_readonly(
          "point_a",
          [](py::object s) {
            return PairField<double>(
                s, [](const ScenePair& p) { return p.result.point_a.data(); }, 3);
          },
          "(K, 3) float64 witness on a's spheres, world frame")
      .def_property_readonly(
          "point_b",
          [](py::object s) {
            return PairField<double>(
                s, [](const ScenePair& p) { return p.result.point_b.data(); }, 3);
          },
          "(K, 3) float64 witness on b's spheres, world frame")
      .def_property_readonly(
          "certified",
          [](py::object s) {
            return PairField<bool>(
                s, [](const ScenePair& p) { return &p.certified; }, 0);
          },
          "(K,) bool: both objects certified, lower/upper hold the exact distance")
      .def_property_readonly(
          "lower",
          [](py::object s) {
            return PairField<double>(
                s, [](const ScenePair& p) { return &p.lower; }, 0);
          },
          "(K,) float64 certified lower bound (where certified), mesh units")
      .def_property_readonly(
          "upper",
          [](py::object s) {
            return PairField<double>(
                s, [](const ScenePair& p) { return &p.upper; }, 0);
          },
          "(K,) float64 certified upper bound (where certified), mesh units")
      .def_property_readonly(
          "candidate_pairs", [](const PySceneFrame& f) { return f.frame.candidate_pairs; },
          "pairs the broad phase handed to the distance queries")
      .def_property_readonly(
          "close_pairs", [](const PySceneFrame& f) { return f.frame.close_pairs; },
          "pairs found close, before max_pairs")
      .def_property_readonly(
          "truncated", [](const PySceneFrame& f) { return f.frame.truncated; },
          "more pairs were close than max_pairs; the nearest are kept")
      .def("__len__", [](const PySceneFrame& f) { return f.frame.pairs.size(); })
      .def("__repr__", [](const PySceneFrame& f) {
        return absl::StrCat("SceneFrame(pairs=", f.frame.pairs.size(),
                            ", candidate_pairs=", f.frame.candidate_pairs,
                            ", truncated=", f.frame.truncated ? "True" : "False", ")");
      });

  py::class_<Scene>(m, "Scene",
                    "Many posed objects: each frame, every pair closer than a threshold "
                    "(sweep-and-prune broad phase, then pruned sphere distances). Not "
                    "thread-safe: one thread at a time.")
      .def(py::init<>())
      .def(
          "add",
          [](Scene& scene, SceneObjectId id, py::handle spheres, py::handle pose,
             const CertifiedObjectHandle* certified, std::uint32_t group, std::uint32_t mask) {
            SceneObject object;
            object.id = id;
            object.spheres = HierarchyOf(spheres);
            if (!pose.is_none()) {
              const std::vector<RigidPose> poses = PosesOf(pose, "pose");
              if (poses.size() != 1) throw py::value_error("pose: give one (7,) pose");
              object.pose = poses.front();
            }
            if (certified != nullptr) {
              object.internal = certified->internal;
              object.cover = certified->cover;
              object.cover_delta = certified->object.cover_delta;
            }
            object.group = group;
            object.mask = mask;
            SceneOkOrRaise(scene.Add(std::move(object)));
          },
          py::arg("id"), py::arg("spheres"), py::arg("pose") = py::none(), py::kw_only(),
          py::arg("certified") = nullptr, py::arg("group") = 1u, py::arg("mask") = kAllSceneGroups,
          R"doc(Adds object `id` (an int >= 0, unique in the scene).

spheres: Hierarchy, SphereSet or (N, 4) float64 array (build a Hierarchy once to share it
    between objects of the same shape).
pose: (7,) [qw, qx, qy, qz, tx, ty, tz], world frame; default identity.
certified: a CertifiedObject of the same solid: pairs of two certified objects get intervals.
group, mask: pair (a, b) is considered when a.group & b.mask and b.group & a.mask are both
    non-zero (defaults: group 1, every bit of the mask).
ValueError for a repeated id or bad values.)doc")
      .def(
          "remove", [](Scene& scene, SceneObjectId id) { SceneOkOrRaise(scene.Remove(id)); },
          py::arg("id"), "Removes object `id` and its ignored pairs; KeyError if unknown.")
      .def(
          "set_poses",
          [](Scene& scene, const std::vector<SceneObjectId>& ids, py::handle poses) {
            const std::vector<RigidPose> values = PosesOf(poses, "poses");
            if (values.size() != ids.size()) {
              throw py::value_error(absl::StrCat("ids has ", ids.size(), " entries but poses ",
                                                 values.size(), " rows"));
            }
            std::vector<std::pair<SceneObjectId, RigidPose>> moves(ids.size());
            for (std::size_t i = 0; i < ids.size(); ++i) moves[i] = {ids[i], values[i]};
            SceneOkOrRaise(scene.SetPoses(moves));
          },
          py::arg("ids"), py::arg("poses"),
          "New world poses for some objects: ids (N,) ints, poses (N, 7) float64. All or "
          "nothing: KeyError for an unknown id, ValueError for a bad pose.")
      .def(
          "ignore",
          [](Scene& scene, SceneObjectId a, SceneObjectId b) {
            SceneOkOrRaise(scene.Ignore(a, b));
          },
          py::arg("a"), py::arg("b"), "Never report pair (a, b) (e.g. adjacent links).")
      .def("__len__", &Scene::size)
      .def("__contains__", &Scene::contains)
      .def(
          "close_pairs",
          [](Scene& scene, double threshold, double abs_err, double rel_err, std::size_t max_pairs,
             bool stop_at_first, const py::object& progress) {
            SceneQuery query;
            query.threshold = threshold;
            query.abs_err = abs_err;
            query.rel_err = rel_err;
            query.max_pairs = max_pairs;
            query.stop_at_first = stop_at_first;
            absl::StatusOr<SceneFrame> frame;
            OkOrRaise(RunInterruptible(progress, [&](const GenerationControl& control) {
              frame = scene.ClosePairs(query, control.cancel);
              return frame.status();
            }));
            return PySceneFrame{ValueOrRaise(std::move(frame))};
          },
          py::arg("threshold") = 0.0, py::kw_only(), py::arg("abs_err") = 0.0,
          py::arg("rel_err") = 0.0, py::arg("max_pairs") = SceneQuery{}.max_pairs,
          py::arg("stop_at_first") = false, py::arg("progress") = py::none(),
          R"doc(Every considered pair closer than `threshold` (mesh units; negative: overlaps
deeper than -threshold; float('inf'): every pair), as a SceneFrame.

A certified pair is reported when its solids may be closer (its lower bound before clamping at
0 is below the threshold); its interval is exact over the sphere pairs. abs_err, rel_err:
tolerances of the plain distances. max_pairs: keep the nearest, flag `truncated`.
stop_at_first: collision checking; each plain pair's search stops at the first sphere pair
below the threshold (the same pairs, cheaper; distances below the threshold, not minima).
Runs without the GIL; Ctrl-C cancels it.)doc");
}

}  // namespace inscribe::python
