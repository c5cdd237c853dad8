// inscribe.Hierarchy and separation distance: one pose, or batches of (N, 7) poses; certified
// intervals when both solids have covers.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bindings.h"
#include "distance_types.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/geometry/rigid_pose.h"
#include "interruptible.h"
#include "sphere_set.h"
#include "status_errors.h"

namespace inscribe::python {

HierarchyVolume VolumeOf(const std::string& name) {
  for (HierarchyVolume volume : {HierarchyVolume::kSphere, HierarchyVolume::kRss}) {
    if (name == HierarchyVolumeName(volume)) return volume;
  }
  throw py::value_error("volume must be 'sphere' or 'rss', got '" + name + "'");
}

namespace {

HierarchyPtr BuildHierarchy(py::handle spheres, const std::string& volume) {
  const HierarchyVolume kind = VolumeOf(volume);
  std::vector<Sphere> balls = SpheresOf(spheres);
  absl::StatusOr<SphereHierarchy> built;
  {
    py::gil_scoped_release release;
    built = SphereHierarchy::Build(std::move(balls), kind);
  }
  return std::make_shared<const SphereHierarchy>(ValueOrRaise(std::move(built)));
}

// Results of a batch, owned here and shown to Python as strided views (no copies).
struct DistanceBatch {
  std::vector<DistanceResult> results;
};

template <typename T, typename Field>
py::array BatchField(py::object self, Field field, py::ssize_t cols) {
  const std::vector<DistanceResult>& results = self.cast<const DistanceBatch&>().results;
  static const DistanceResult kEmpty;
  const DistanceResult& first = results.empty() ? kEmpty : results.front();
  return ReadOnlyView<T>(field(first), static_cast<py::ssize_t>(results.size()), cols,
                         static_cast<py::ssize_t>(sizeof(DistanceResult)), self);
}

struct CertifiedBatch {
  std::vector<double> lower, upper;
  std::vector<std::string> closer;
};

std::vector<PosedPair> PairsOf(const SphereHierarchy& a, const SphereHierarchy& b,
                               const std::vector<RigidPose>& poses_a,
                               const std::vector<RigidPose>& poses_b) {
  if (poses_a.size() != 1 && poses_a.size() != poses_b.size()) {
    throw py::value_error(absl::StrCat("pose_a must hold one pose or one per pose of b (",
                                       poses_b.size(), "), got ", poses_a.size()));
  }
  std::vector<PosedPair> pairs(poses_b.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    pairs[i] = PosedPair{&a, &b, poses_a.size() == 1 ? poses_a[0] : poses_a[i], poses_b[i]};
  }
  return pairs;
}

// A (7,) pose rather than an (N, 7) batch; numpy arrays are looked at, not copied.
bool IsOnePose(py::handle poses) {
  return py::module_::import("numpy").attr("ndim")(poses).cast<int>() == 1;
}

}  // namespace

HierarchyPtr HierarchyOf(py::handle value) {
  if (py::isinstance<SphereHierarchy>(value)) return value.cast<HierarchyPtr>();
  return BuildHierarchy(value, HierarchyVolumeName(HierarchyVolume::kSphere));
}

std::vector<RigidPose> PosesOf(py::handle value, const char* name) {
  py::array_t<double> array = RequireRowOrMatrix<double>(value, 7, name);
  auto rows = array.unchecked<2>();
  std::vector<RigidPose> poses(static_cast<std::size_t>(rows.shape(0)));
  for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
    RigidPose pose;
    pose.rotation = Eigen::Quaterniond(rows(i, 0), rows(i, 1), rows(i, 2), rows(i, 3));
    pose.translation = Vector3(rows(i, 4), rows(i, 5), rows(i, 6));
    absl::StatusOr<RigidPose> normalized = NormalizedPose(pose);
    if (!normalized.ok()) {
      throw py::value_error(absl::StrCat(name, "[", i, "]: ", normalized.status().message()));
    }
    poses[static_cast<std::size_t>(i)] = *normalized;
  }
  return poses;
}

void BindDistance(py::module_& m) {
  py::class_<SphereHierarchy, std::shared_ptr<SphereHierarchy>>(
      m, "Hierarchy",
      "A binary bounding-volume hierarchy over a sphere set, for distance queries. Immutable; "
      "safe to share between threads.")
      .def(py::init([](py::handle spheres, const std::string& volume) {
             return std::const_pointer_cast<SphereHierarchy>(BuildHierarchy(spheres, volume));
           }),
           py::arg("spheres"), py::arg("volume") = "sphere",
           "Hierarchy(spheres, volume='sphere'|'rss'): spheres a SphereSet or an (N, 4) float64 "
           "array. Cost O(N log N).")
      .def_property_readonly(
          "volume", [](const SphereHierarchy& h) { return HierarchyVolumeName(h.volume()); })
      .def_property_readonly("depth", &SphereHierarchy::depth)
      .def_property_readonly("num_nodes", &SphereHierarchy::num_nodes)
      .def("__len__", [](const SphereHierarchy& h) { return h.spheres().size(); })
      .def(
          "serialize", [](const SphereHierarchy& h) { return py::bytes(h.Serialize()); },
          "The self-contained 'inscribe.hierarchy' v1 bytes (as the service ships them).")
      .def_static(
          "deserialize",
          [](const py::bytes& bytes) {
            return std::make_shared<SphereHierarchy>(
                ValueOrRaise(SphereHierarchy::Deserialize(std::string(bytes))));
          },
          py::arg("data"), "A hierarchy from serialize()'s bytes, checked (ValueError if bad).");

  py::class_<DistanceResult>(m, "DistanceResult",
                             "One separation-distance answer (mesh units, world frame).")
      .def_readonly("distance", &DistanceResult::distance,
                    "> 0 gap between the unions, < 0 the deepest overlap of two spheres")
      .def_readonly("sphere_a", &DistanceResult::sphere_a)
      .def_readonly("sphere_b", &DistanceResult::sphere_b)
      .def_property_readonly(
          "point_a",
          [](const DistanceResult& r) { return py::array_t<double>(3, r.point_a.data()); })
      .def_property_readonly(
          "point_b",
          [](const DistanceResult& r) { return py::array_t<double>(3, r.point_b.data()); })
      .def_readonly("closer", &DistanceResult::closer)
      .def("__repr__", [](const DistanceResult& r) {
        return absl::StrCat("DistanceResult(distance=", r.distance, ", sphere_a=", r.sphere_a,
                            ", sphere_b=", r.sphere_b, ")");
      });

  py::class_<DistanceBatch>(m, "DistanceBatch",
                            "Answers to N poses, as read-only numpy views (no copies).")
      .def_property_readonly(
          "distance",
          [](py::object s) {
            return BatchField<double>(
                s, [](const DistanceResult& r) { return &r.distance; }, 0);
          },
          "(N,) float64 signed distances, mesh units")
      .def_property_readonly(
          "sphere_a",
          [](py::object s) {
            return BatchField<std::int32_t>(
                s, [](const DistanceResult& r) { return &r.sphere_a; }, 0);
          },
          "(N,) int32 closest sphere of a (-1 when a closer_than query answered no)")
      .def_property_readonly(
          "sphere_b",
          [](py::object s) {
            return BatchField<std::int32_t>(
                s, [](const DistanceResult& r) { return &r.sphere_b; }, 0);
          },
          "(N,) int32 closest sphere of b")
      .def_property_readonly(
          "point_a",
          [](py::object s) {
            return BatchField<double>(
                s, [](const DistanceResult& r) { return r.point_a.data(); }, 3);
          },
          "(N, 3) float64 witness on a's spheres, world frame")
      .def_property_readonly(
          "point_b",
          [](py::object s) {
            return BatchField<double>(
                s, [](const DistanceResult& r) { return r.point_b.data(); }, 3);
          },
          "(N, 3) float64 witness on b's spheres, world frame")
      .def_property_readonly(
          "closer",
          [](py::object s) {
            return BatchField<bool>(
                s, [](const DistanceResult& r) { return &r.closer; }, 0);
          },
          "(N,) bool: closer than closer_than")
      .def("__len__", [](const DistanceBatch& b) { return b.results.size(); });

  m.def(
      "distance",
      [](py::handle a, py::handle b, py::handle poses, py::handle pose_a,
         std::optional<double> abs_err, std::optional<double> rel_err,
         std::optional<double> closer_than, const py::object& progress) -> py::object {
        const HierarchyPtr ha = HierarchyOf(a);
        const HierarchyPtr hb = HierarchyOf(b);
        DistanceRequest request;
        if (abs_err) request.abs_err = *abs_err;
        if (rel_err) request.rel_err = *rel_err;
        if (closer_than) request.closer_than = *closer_than;
        const bool one = IsOnePose(poses);
        const std::vector<RigidPose> poses_b = PosesOf(poses, "poses");
        const std::vector<RigidPose> poses_a =
            pose_a.is_none() ? std::vector<RigidPose>{RigidPose{}} : PosesOf(pose_a, "pose_a");
        const std::vector<PosedPair> pairs = PairsOf(*ha, *hb, poses_a, poses_b);
        absl::StatusOr<std::vector<DistanceResult>> results;
        if (one) {
          py::gil_scoped_release release;
          results = PairSeparationDistances(pairs, request);
        } else {
          OkOrRaise(RunInterruptible(progress, [&](const GenerationControl& control) {
            results = PairSeparationDistances(pairs, request, control.cancel);
            return results.status();
          }));
        }
        std::vector<DistanceResult> answers = ValueOrRaise(std::move(results));
        if (one) return py::cast(answers.front());
        return py::cast(DistanceBatch{std::move(answers)});
      },
      py::arg("a"), py::arg("b"), py::arg("poses"), py::kw_only(), py::arg("pose_a") = py::none(),
      py::arg("abs_err") = py::none(), py::arg("rel_err") = py::none(),
      py::arg("closer_than") = py::none(), py::arg("progress") = py::none(),
      R"doc(Separation distance between two unions of spheres (paper Section VI).

a, b: Hierarchy, SphereSet or (N, 4) float64 array (a Hierarchy is built each call otherwise:
    build one once for loops).
poses: world pose of b, a (7,) float64 array [qw, qx, qy, qz, tx, ty, tz] (unit quaternion,
    normalised here; translation in mesh units), or an (N, 7) C-contiguous float64 array for
    a batch. pose_a: a's world pose, one (7,) or one per row of poses; default identity.
abs_err (mesh units), rel_err: the answer may exceed the true minimum by
    max(abs_err, rel_err * |d|); both 0 by default (exact over sphere pairs).
closer_than (mesh units): ask "closer than this?" instead; stops early.

One pose: a DistanceResult. A batch: a DistanceBatch of (N,) / (N, 3) read-only arrays
(distance, sphere_a, sphere_b, point_a, point_b, closer), computed in parallel without the
GIL; Ctrl-C cancels it. Witness points are in the world frame.)doc");

  py::class_<CertifiedObjectHandle>(m, "CertifiedObject",
                                    "A solid for certified distance: its internal spheres and a "
                                    "certified cover with its delta (mesh units).")
      .def(py::init([](py::handle internal, py::handle cover, std::optional<double> delta,
                       std::optional<std::vector<double>> protrusions) {
             // A cover SphereSet with its certificate gives delta and protrusions by default,
             // when the certificate names its spheres and mesh.
             if (py::isinstance<PySphereSet>(cover)) {
               const PySphereSet& set = cover.cast<const PySphereSet&>();
               if (set.certificate && (!delta || !protrusions)) {
                 OkOrRaise(CheckCoverCertificateBinding(*set.certificate, set.set.spheres,
                                                        set.mesh_sha256));
                 if (!delta) delta = set.certificate->delta;
                 if (!protrusions) protrusions = set.certificate->protrusions;
               }
             }
             if (!delta) {
               throw py::value_error(
                   "delta: give the cover's certificate delta (or a cover SphereSet that "
                   "carries its certificate)");
             }
             CertifiedObjectHandle handle;
             handle.cover = HierarchyOf(cover);
             if (protrusions && !protrusions->empty() &&
                 !py::isinstance<SphereHierarchy>(internal) &&
                 !py::isinstance<SphereHierarchy>(cover)) {
               const std::vector<Sphere> upper = ValueOrRaise(
                   UpperBoundSpheres(SpheresOf(internal), SpheresOf(cover), *protrusions));
               handle.internal = std::make_shared<const SphereHierarchy>(
                   ValueOrRaise(SphereHierarchy::Build(upper, HierarchyVolume::kSphere)));
             } else if (protrusions && !protrusions->empty()) {
               throw py::value_error(
                   "protrusions: the covers' cores need the internal and cover spheres (a "
                   "SphereSet or an (N, 4) array), not built hierarchies");
             } else {
               handle.internal = HierarchyOf(internal);
             }
             handle.object = CertifiedObject{handle.internal.get(), handle.cover.get(), *delta};
             OkOrRaise(CheckCertifiedObject(handle.object));
             return handle;
           }),
           py::arg("internal"), py::arg("cover"), py::arg("delta") = py::none(),
           py::arg("protrusions") = py::none(),
           "internal: spheres inside the solid (Hierarchy, SphereSet or (N, 4) array); cover: a "
           "certified cover of it; delta: the cover's certificate.delta; protrusions: its "
           "certificate.protrusions, one per cover sphere (mesh units), whose cores (radius "
           "less protrusion, inside the solid) stand in for the internal spheres for a tighter "
           "upper bound, as the service does. A cover SphereSet carrying its certificate gives "
           "both (inscribe.Error FAILED_PRECONDITION when the certificate does not name its "
           "spheres and mesh_sha256). "
           "The caller vouches for the certificate (see inscribe.certify).");

  py::class_<CertifiedBatch>(m, "CertifiedDistances",
                             "Intervals that provably hold the exact distance between two "
                             "solids, one per pose (mesh units).")
      .def_property_readonly(
          "lower",
          [](const CertifiedBatch& b) {
            return py::array_t<double>(static_cast<py::ssize_t>(b.lower.size()), b.lower.data());
          },
          "(N,) float64: no closer than this (mesh units)")
      .def_property_readonly(
          "upper",
          [](const CertifiedBatch& b) {
            return py::array_t<double>(static_cast<py::ssize_t>(b.upper.size()), b.upper.data());
          },
          "(N,) float64: no farther than this (mesh units)")
      .def_readonly("closer", &CertifiedBatch::closer,
                    "'yes', 'no' or 'undecided' per pose ('undecided' without closer_than)")
      .def("__len__", [](const CertifiedBatch& b) { return b.lower.size(); });

  m.def(
      "certified_distance",
      [](const CertifiedObjectHandle& a, const CertifiedObjectHandle& b, py::handle poses,
         py::handle pose_a, std::optional<double> closer_than) {
        const std::vector<RigidPose> poses_b = PosesOf(poses, "poses");
        const std::vector<RigidPose> poses_a =
            pose_a.is_none() ? std::vector<RigidPose>{RigidPose{}} : PosesOf(pose_a, "pose_a");
        if (poses_a.size() != 1 && poses_a.size() != poses_b.size()) {
          throw py::value_error("pose_a must hold one pose or one per pose of b");
        }
        std::vector<CertifiedPair> pairs(poses_b.size());
        for (std::size_t i = 0; i < pairs.size(); ++i) {
          pairs[i] = CertifiedPair{&a.object, &b.object,
                                   poses_a.size() == 1 ? poses_a[0] : poses_a[i], poses_b[i]};
        }
        absl::StatusOr<std::vector<CertifiedDistanceResult>> results;
        OkOrRaise(RunInterruptible(py::none(), [&](const GenerationControl& control) {
          results = CertifiedDistances(
              pairs, closer_than.value_or(std::numeric_limits<double>::infinity()), control.cancel);
          return results.status();
        }));
        CertifiedBatch batch;
        for (const CertifiedDistanceResult& r : *results) {
          batch.lower.push_back(r.lower);
          batch.upper.push_back(r.upper);
          batch.closer.push_back(CloserAnswerName(r.closer));
        }
        return batch;
      },
      py::arg("a"), py::arg("b"), py::arg("poses"), py::kw_only(), py::arg("pose_a") = py::none(),
      py::arg("closer_than") = py::none(),
      "For each pose of b ((7,) or (N, 7) float64 [qw, qx, qy, qz, tx, ty, tz]): lower <= exact "
      "distance between the two solids <= upper (CertifiedDistances), and with closer_than a "
      "yes/no/undecided answer that is never wrong.");
}

}  // namespace inscribe::python
