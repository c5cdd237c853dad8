#include "inscribe/distance/sphere_hierarchy.h"

#include <CGAL/Min_sphere_of_spheres_d.h>
#include <CGAL/Min_sphere_of_spheres_d_traits_3.h>
#include <CGAL/Simple_cartesian.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <utility>

#include "absl/strings/str_cat.h"

namespace inscribe {
namespace {

constexpr char kMagic[8] = {'I', 'N', 'S', 'C', 'H', 'I', 'E', 'R'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kMaxSpheres = std::size_t{1} << 30;

// Containment is checked with this much slack, relative to the volume's size: bounding volumes
// are padded by more than that when built.
constexpr double kContainSlack = 1e-10;

// The smallest sphere around spheres[indices[0..count)], padded outward so that rounding in
// CGAL's floating-point algorithm never leaves a sphere sticking out.
Sphere EnclosingSphere(const std::vector<Sphere>& spheres, const std::int32_t* indices,
                       std::size_t count) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using Traits = CGAL::Min_sphere_of_spheres_d_traits_3<Kernel, double>;
  using MinSphere = CGAL::Min_sphere_of_spheres_d<Traits>;
  std::vector<Traits::Sphere> input;
  input.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const Sphere& s = spheres[static_cast<std::size_t>(indices[i])];
    input.emplace_back(Kernel::Point_3(s.center.x(), s.center.y(), s.center.z()), s.radius);
  }
  MinSphere min_sphere(input.begin(), input.end());
  Sphere out;
  auto coordinate = min_sphere.center_cartesian_begin();
  for (int k = 0; k < 3; ++k, ++coordinate) out.center[k] = CGAL::to_double(*coordinate);
  // The radius that really covers every sphere from that centre (CGAL's is exact only up to
  // its number type), then a relative pad for the distance computations of later checks.
  double radius = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const Sphere& s = spheres[static_cast<std::size_t>(indices[i])];
    radius = std::max(radius, (s.center - out.center).norm() + s.radius);
  }
  out.radius = radius * (1.0 + 4.0 * std::numeric_limits<double>::epsilon()) +
               std::numeric_limits<double>::denorm_min();
  return out;
}

// Splits indices[begin, end) (at least 2) in two non-empty halves; returns the split point.
std::size_t Split(const std::vector<Sphere>& spheres, std::vector<std::int32_t>& indices,
                  std::size_t begin, std::size_t end) {
  const auto count = static_cast<double>(end - begin);
  Vector3 mean = Vector3::Zero();
  for (std::size_t i = begin; i < end; ++i) {
    mean += spheres[static_cast<std::size_t>(indices[i])].center;
  }
  mean /= count;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t i = begin; i < end; ++i) {
    const Vector3 d = spheres[static_cast<std::size_t>(indices[i])].center - mean;
    covariance += d * d.transpose();
  }
  // The principal axis: the direction of the least-squares line through the centres.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Vector3 axis = solver.eigenvectors().col(2);
  const auto first = indices.begin() + static_cast<std::ptrdiff_t>(begin);
  const auto last = indices.begin() + static_cast<std::ptrdiff_t>(end);
  const std::size_t n = end - begin;
  const auto projection_on = [&](const Vector3& direction) {
    return [&spheres, direction](std::int32_t i) {
      return spheres[static_cast<std::size_t>(i)].center.dot(direction);
    };
  };
  const auto by = [](auto key) {
    return [key](std::int32_t a, std::int32_t b) {
      const double pa = key(a), pb = key(b);
      return pa < pb || (pa == pb && a < b);
    };
  };
  // Candidates: every split of the centres sorted along the principal axis or a coordinate
  // axis, keeping at least an eighth of them on each side (depth stays O(log n)). Cost: the
  // children's sizes times their squared radii, the radius taken as half the diagonal of the
  // box around their spheres: the chance that a distance query opens a node grows with its
  // size, and small, tight children prune early.
  const Vector3 axes[4] = {axis, Vector3::UnitX(), Vector3::UnitY(), Vector3::UnitZ()};
  const std::size_t least = std::max<std::size_t>(1, n / 8);
  std::vector<std::int32_t> order(first, last);
  std::vector<double> prefix(n + 1), suffix(n + 1);
  double best = std::numeric_limits<double>::infinity();
  int best_axis = -1;
  std::size_t best_k = 0;
  for (int a = 0; a < 4; ++a) {
    std::sort(order.begin(), order.end(), by(projection_on(axes[a])));
    Eigen::AlignedBox3d box;
    for (std::size_t k = 0; k < n; ++k) {
      const Sphere& s = spheres[static_cast<std::size_t>(order[k])];
      box.extend(s.center - Vector3::Constant(s.radius));
      box.extend(s.center + Vector3::Constant(s.radius));
      prefix[k + 1] = box.diagonal().squaredNorm();
    }
    box.setEmpty();
    for (std::size_t k = n; k-- > 0;) {
      const Sphere& s = spheres[static_cast<std::size_t>(order[k])];
      box.extend(s.center - Vector3::Constant(s.radius));
      box.extend(s.center + Vector3::Constant(s.radius));
      suffix[k] = box.diagonal().squaredNorm();
    }
    for (std::size_t k = least; k + least <= n; ++k) {
      const double cost =
          static_cast<double>(k) * prefix[k] + static_cast<double>(n - k) * suffix[k];
      const auto off_centre = [n](std::size_t i) {
        return std::max(2 * i, n) - std::min(2 * i, n);
      };
      if (cost < best || (cost == best && off_centre(k) < off_centre(best_k))) {
        best = cost;
        best_axis = a;
        best_k = k;
      }
    }
  }
  const bool coincident = (covariance.array() == 0.0).all();
  if (best_axis >= 0 && !coincident) {
    std::sort(first, last, by(projection_on(axes[best_axis])));
    return begin + best_k;
  }
  auto projection = [&](std::int32_t i) {
    return (spheres[static_cast<std::size_t>(i)].center - mean).dot(axis);
  };
  auto middle = std::partition(first, last, [&](std::int32_t i) { return projection(i) < 0.0; });
  if (middle == first || middle == last) {
    // Every centre on one side (coincident or symmetric centres): split at the median.
    middle = first + (last - first) / 2;
    std::nth_element(first, middle, last, [&](std::int32_t a, std::int32_t b) {
      const double pa = projection(a), pb = projection(b);
      return pa < pb || (pa == pb && a < b);
    });
  }
  return static_cast<std::size_t>(middle - indices.begin());
}

// ---- Little-endian encoding ---------------------------------------------------------------

void PutU32(std::string& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xFF));
}
void PutF64(std::string& out, double value) {
  std::uint64_t v;
  std::memcpy(&v, &value, sizeof v);
  for (int k = 0; k < 8; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xFF));
}

class Reader {
 public:
  explicit Reader(absl::string_view bytes) : bytes_(bytes) {}
  bool U32(std::uint32_t* v) {
    if (bytes_.size() - at_ < 4) return false;
    *v = 0;
    for (int k = 0; k < 4; ++k) {
      *v |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes_[at_++])) << (8 * k);
    }
    return true;
  }
  bool I32(std::int32_t* v) {
    std::uint32_t u;
    if (!U32(&u)) return false;
    std::memcpy(v, &u, sizeof *v);
    return true;
  }
  bool F64(double* value) {
    if (bytes_.size() - at_ < 8) return false;
    std::uint64_t v = 0;
    for (int k = 0; k < 8; ++k) {
      v |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes_[at_++])) << (8 * k);
    }
    std::memcpy(value, &v, sizeof *value);
    return true;
  }
  bool Bytes(char* out, std::size_t n) {
    if (bytes_.size() - at_ < n) return false;
    std::memcpy(out, bytes_.data() + at_, n);
    at_ += n;
    return true;
  }
  std::size_t remaining() const { return bytes_.size() - at_; }

 private:
  absl::string_view bytes_;
  std::size_t at_ = 0;
};

absl::Status Invalid(absl::string_view why) {
  return absl::InvalidArgumentError(absl::StrCat("hierarchy: ", why));
}

// Distance from a point to the RSS's rectangle (the degenerate rectangle trick: a point is a
// rectangle of zero size).
double DistanceToRectangle(const Rss& rss, const Vector3& p) {
  Rss point;
  point.origin = p;
  Vector3 a, b;
  return RectangleDistance(rss, point, &a, &b);
}

// Nearest float, saturated: a double beyond float's range would be undefined behaviour. The
// query never uses the floats of such a set (its magnitudes disable the float filter).
float ToFloat(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  return static_cast<float>(std::clamp(v, -kMax, kMax));
}

}  // namespace

const char* HierarchyVolumeName(HierarchyVolume volume) {
  return volume == HierarchyVolume::kRss ? "rss" : "sphere";
}

absl::StatusOr<SphereHierarchy> SphereHierarchy::Build(std::vector<Sphere> spheres,
                                                       HierarchyVolume volume) {
  if (spheres.empty()) return absl::InvalidArgumentError("no spheres to build a hierarchy of");
  if (spheres.size() > kMaxSpheres) {
    return absl::InvalidArgumentError(
        absl::StrCat(spheres.size(), " spheres: more than 2^30 in one hierarchy"));
  }
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    if (absl::Status s = CheckSphere(spheres[i], i); !s.ok()) return s;
  }
  SphereHierarchy h;
  h.volume_ = volume;
  h.spheres_ = std::move(spheres);
  const std::size_t n = h.spheres_.size();
  std::vector<std::int32_t> indices(n);
  std::iota(indices.begin(), indices.end(), 0);
  h.left_.reserve(n - 1);
  h.right_.reserve(n - 1);

  // Depth-first, left child first, so a node's subtree is contiguous after it. An explicit
  // stack: unbalanced mean splits can make the tree deep.
  struct Task {
    std::size_t begin, end;
    HierarchyRef* slot;  // where the parent keeps the reference (root_ for the root)
    int depth;
  };
  std::vector<Task> tasks = {{0, n, &h.root_, 0}};
  while (!tasks.empty()) {
    const Task task = tasks.back();
    tasks.pop_back();
    h.depth_ = std::max(h.depth_, task.depth);
    HierarchyRef ref;
    if (task.end - task.begin == 1) {
      ref = -1 - indices[task.begin];
    } else {
      const auto node = static_cast<std::int32_t>(h.left_.size());
      ref = node;
      h.left_.push_back(0);
      h.right_.push_back(0);
      const std::int32_t* members = &indices[task.begin];
      const std::size_t count = task.end - task.begin;
      if (volume == HierarchyVolume::kRss) {
        h.rss_.push_back(FitRss(h.spheres_, members, count));
      } else {
        h.bounding_spheres_.push_back(EnclosingSphere(h.spheres_, members, count));
      }
      const std::size_t middle = Split(h.spheres_, indices, task.begin, task.end);
      // Right pushed first so the left subtree is built (and numbered) first. Slots point
      // into left_/right_, which never reallocate (reserved for n - 1 nodes).
      tasks.push_back(
          {middle, task.end, &h.right_[static_cast<std::size_t>(node)], task.depth + 1});
      tasks.push_back(
          {task.begin, middle, &h.left_[static_cast<std::size_t>(node)], task.depth + 1});
    }
    *task.slot = ref;
  }
  h.ComputeDerived();
  return h;
}

void SphereHierarchy::ComputeDerived() {
  // Leaf order and ranges: children are visited left first, so each node's leaves are
  // contiguous; a node's count is known once its subtree is done (post-order pass).
  const std::size_t nodes = left_.size();
  leaf_order_.clear();
  leaf_order_.reserve(spheres_.size());
  leaf_position_.assign(spheres_.size(), 0);
  first_.assign(nodes, 0);
  count_.assign(nodes, 0);
  std::vector<std::pair<HierarchyRef, bool>> stack = {{root_, false}};
  while (!stack.empty()) {
    auto [ref, done] = stack.back();
    stack.pop_back();
    if (IsLeaf(ref)) {
      leaf_position_[static_cast<std::size_t>(LeafSphere(ref))] =
          static_cast<std::int32_t>(leaf_order_.size());
      leaf_order_.push_back(LeafSphere(ref));
      continue;
    }
    const auto node = static_cast<std::size_t>(ref);
    if (done) {
      count_[node] = static_cast<std::int32_t>(leaf_order_.size()) - first_[node];
      continue;
    }
    first_[node] = static_cast<std::int32_t>(leaf_order_.size());
    stack.push_back({ref, true});
    stack.push_back({right_[node], false});
    stack.push_back({left_[node], false});
  }
  ordered_spheres_.resize(spheres_.size());
  for (std::size_t i = 0; i < spheres_.size(); ++i) {
    ordered_spheres_[i] = spheres_[static_cast<std::size_t>(leaf_order_[i])];
  }
  const std::size_t padded = spheres_.size() + kFloatPadding;
  float_x_.resize(padded);
  float_y_.resize(padded);
  float_z_.resize(padded);
  float_r_.resize(padded);
  for (std::size_t i = 0; i < padded; ++i) {
    const Sphere& s = ordered_spheres_[std::min(i, spheres_.size() - 1)];
    float_x_[i] = ToFloat(s.center.x());
    float_y_[i] = ToFloat(s.center.y());
    float_z_[i] = ToFloat(s.center.z());
    float_r_[i] = ToFloat(s.radius);
  }
  query_spheres_.resize(nodes + spheres_.size());
  for (std::size_t i = 0; i < nodes; ++i) {
    query_spheres_[i] =
        volume_ == HierarchyVolume::kSphere
            ? bounding_spheres_[i]
            : EnclosingSphere(spheres_, &leaf_order_[static_cast<std::size_t>(first_[i])],
                              static_cast<std::size_t>(count_[i]));
  }
  std::copy(spheres_.begin(), spheres_.end(),
            query_spheres_.begin() + static_cast<std::ptrdiff_t>(nodes));
  max_abs_coordinate_ = max_radius_ = max_center_norm_ = 0.0;
  for (const Sphere& s : query_spheres_) {
    max_abs_coordinate_ = std::max(max_abs_coordinate_, s.center.cwiseAbs().maxCoeff());
    max_radius_ = std::max(max_radius_, s.radius);
    max_center_norm_ = std::max(max_center_norm_, s.center.norm());
  }
  quads_.assign(nodes, Quad{});
  for (std::size_t i = 0; i < nodes; ++i) {
    Quad& q = quads_[i];
    for (const HierarchyRef child : {left_[i], right_[i]}) {
      const bool expand = !IsLeaf(child);
      const HierarchyRef grandchildren[2] = {
          expand ? left_[static_cast<std::size_t>(child)] : child,
          expand ? right_[static_cast<std::size_t>(child)] : 0};
      for (int k = 0; k < (expand ? 2 : 1); ++k) {
        const Sphere& s = query_sphere(grandchildren[k]);
        q.x[q.size] = ToFloat(s.center.x());
        q.y[q.size] = ToFloat(s.center.y());
        q.z[q.size] = ToFloat(s.center.z());
        q.radius[q.size] = ToFloat(s.radius);
        q.child[q.size] = grandchildren[k];
        ++q.size;
      }
    }
  }
  if (volume_ == HierarchyVolume::kSphere) {
    outer_spheres_ = bounding_spheres_;
  } else {
    outer_spheres_.resize(rss_.size());
    for (std::size_t i = 0; i < rss_.size(); ++i) {
      const Rss& r = rss_[i];
      const double half0 = 0.5 * r.length[0], half1 = 0.5 * r.length[1];
      Sphere& s = outer_spheres_[i];
      s.center = r.origin + half0 * r.axes.col(0) + half1 * r.axes.col(1);
      // Padded: the corners' distance from the centre, computed, may round below the true one.
      s.radius = (r.radius + std::sqrt(half0 * half0 + half1 * half1)) *
                 (1.0 + 8.0 * std::numeric_limits<double>::epsilon());
    }
  }
  slots_.resize(nodes + spheres_.size());
  for (std::size_t i = 0; i < nodes; ++i) {
    slots_[i] = Slot{outer_spheres_[i].center,
                     outer_spheres_[i].radius,
                     first_[i],
                     count_[i],
                     left_[i],
                     right_[i]};
  }
  for (std::size_t i = 0; i < spheres_.size(); ++i) {
    slots_[nodes + i] = Slot{spheres_[i].center, spheres_[i].radius, leaf_position_[i], 1, 0, 0};
  }
}

std::string SphereHierarchy::Serialize() const {
  std::string out(kMagic, sizeof kMagic);
  PutU32(out, kVersion);
  PutU32(out, volume_ == HierarchyVolume::kRss ? 0u : 1u);
  PutU32(out, static_cast<std::uint32_t>(spheres_.size()));
  PutU32(out, static_cast<std::uint32_t>(root_));
  for (const Sphere& s : spheres_) {
    for (int k = 0; k < 3; ++k) PutF64(out, s.center[k]);
    PutF64(out, s.radius);
  }
  for (std::size_t i = 0; i < left_.size(); ++i) {
    PutU32(out, static_cast<std::uint32_t>(left_[i]));
    PutU32(out, static_cast<std::uint32_t>(right_[i]));
    if (volume_ == HierarchyVolume::kRss) {
      const Rss& r = rss_[i];
      for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < 3; ++k) PutF64(out, r.axes(k, c));
      }
      for (int k = 0; k < 3; ++k) PutF64(out, r.origin[k]);
      PutF64(out, r.length[0]);
      PutF64(out, r.length[1]);
      PutF64(out, r.radius);
    } else {
      const Sphere& s = bounding_spheres_[i];
      for (int k = 0; k < 3; ++k) PutF64(out, s.center[k]);
      PutF64(out, s.radius);
    }
  }
  return out;
}

absl::StatusOr<SphereHierarchy> SphereHierarchy::Deserialize(absl::string_view bytes) {
  Reader in(bytes);
  char magic[sizeof kMagic];
  if (!in.Bytes(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0) {
    return Invalid("not a hierarchy (bad magic bytes)");
  }
  std::uint32_t version = 0, kind = 0, count = 0;
  std::int32_t root = 0;
  if (!in.U32(&version) || !in.U32(&kind) || !in.U32(&count) || !in.I32(&root)) {
    return Invalid("truncated header");
  }
  if (version != kVersion) return Invalid(absl::StrCat("unsupported version ", version));
  if (kind > 1) return Invalid(absl::StrCat("unknown bounding volume kind ", kind));
  if (count == 0 || count > kMaxSpheres) return Invalid(absl::StrCat(count, " spheres"));
  const std::size_t node_bytes = 8 + 8 * (kind == 0 ? 15 : 4);
  const std::size_t expected = 32 * std::size_t{count} + node_bytes * (std::size_t{count} - 1);
  if (in.remaining() != expected) {
    return Invalid(absl::StrCat(count, " spheres need ", expected,
                                " bytes after the header, "
                                "found ",
                                in.remaining()));
  }
  SphereHierarchy h;
  h.volume_ = kind == 0 ? HierarchyVolume::kRss : HierarchyVolume::kSphere;
  h.root_ = root;
  h.spheres_.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    Sphere& s = h.spheres_[i];
    for (int k = 0; k < 3; ++k) in.F64(&s.center[k]);
    in.F64(&s.radius);
    if (absl::Status status = CheckSphere(s, i); !status.ok()) return Invalid(status.message());
  }
  const std::size_t nodes = count - 1;
  h.left_.resize(nodes);
  h.right_.resize(nodes);
  for (std::size_t i = 0; i < nodes; ++i) {
    in.I32(&h.left_[i]);
    in.I32(&h.right_[i]);
    bool finite = true;
    if (h.volume_ == HierarchyVolume::kRss) {
      Rss r;
      for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < 3; ++k) in.F64(&r.axes(k, c));
      }
      for (int k = 0; k < 3; ++k) in.F64(&r.origin[k]);
      in.F64(&r.length[0]);
      in.F64(&r.length[1]);
      in.F64(&r.radius);
      finite =
          r.axes.allFinite() && r.origin.allFinite() && std::isfinite(r.length[0]) &&
          std::isfinite(r.length[1]) && std::isfinite(r.radius) && r.length[0] >= 0.0 &&
          r.length[1] >= 0.0 && r.radius >= 0.0 &&
          (r.axes.transpose() * r.axes - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-9;
      h.rss_.push_back(r);
    } else {
      Sphere s;
      for (int k = 0; k < 3; ++k) in.F64(&s.center[k]);
      in.F64(&s.radius);
      finite = s.center.allFinite() && std::isfinite(s.radius) && s.radius >= 0.0;
      h.bounding_spheres_.push_back(s);
    }
    if (!finite) {
      return Invalid(absl::StrCat("node ", i,
                                  ": bounding volume has a non-finite or negative "
                                  "number, or axes that are not orthonormal"));
    }
  }
  if (absl::Status s = h.CheckStructure(&h.depth_); !s.ok()) return s;
  h.ComputeDerived();
  return h;
}

absl::Status SphereHierarchy::CheckStructure(int* depth) const {
  const auto n = static_cast<std::int64_t>(spheres_.size());
  const auto nodes = static_cast<std::int64_t>(left_.size());
  auto in_range = [&](HierarchyRef ref) { return IsLeaf(ref) ? LeafSphere(ref) < n : ref < nodes; };
  if (!in_range(root_)) return Invalid(absl::StrCat("root ", root_, " is out of range"));
  std::vector<char> node_seen(static_cast<std::size_t>(nodes), 0);
  std::vector<char> sphere_seen(static_cast<std::size_t>(n), 0);
  // Depth-first from the root with the chain of ancestors, checking each sphere against each
  // bounding volume above it.
  struct Visit {
    HierarchyRef ref;
    int depth;
  };
  std::vector<Visit> stack = {{root_, 0}};
  std::vector<std::int32_t> ancestors;
  int max_depth = 0;
  while (!stack.empty()) {
    const Visit visit = stack.back();
    stack.pop_back();
    ancestors.resize(static_cast<std::size_t>(visit.depth));
    max_depth = std::max(max_depth, visit.depth);
    if (IsLeaf(visit.ref)) {
      const auto i = static_cast<std::size_t>(LeafSphere(visit.ref));
      if (sphere_seen[i]++) return Invalid(absl::StrCat("sphere ", i, " is in two leaves"));
      const Sphere& s = spheres_[i];
      for (const std::int32_t a : ancestors) {
        double excess;
        double size;
        if (volume_ == HierarchyVolume::kRss) {
          const Rss& r = rss_[static_cast<std::size_t>(a)];
          excess = DistanceToRectangle(r, s.center) + s.radius - r.radius;
          size = r.radius + r.length[0] + r.length[1] + r.origin.cwiseAbs().maxCoeff();
        } else {
          const Sphere& b = bounding_spheres_[static_cast<std::size_t>(a)];
          excess = (s.center - b.center).norm() + s.radius - b.radius;
          size = b.radius + b.center.cwiseAbs().maxCoeff();
        }
        if (excess > kContainSlack * size) {
          return Invalid(absl::StrCat("sphere ", i, " sticks out of node ", a,
                                      "'s bounding volume by ", excess));
        }
      }
      continue;
    }
    const auto node = static_cast<std::size_t>(visit.ref);
    if (node_seen[node]++) return Invalid(absl::StrCat("node ", node, " is reached twice"));
    for (const HierarchyRef child : {left_[node], right_[node]}) {
      if (!in_range(child)) {
        return Invalid(absl::StrCat("node ", node, ": child ", child, " is out of range"));
      }
      stack.push_back({child, visit.depth + 1});
    }
    ancestors.push_back(visit.ref);
  }
  for (std::int64_t i = 0; i < nodes; ++i) {
    if (!node_seen[static_cast<std::size_t>(i)]) {
      return Invalid(absl::StrCat("node ", i, " is not in the tree"));
    }
  }
  for (std::int64_t i = 0; i < n; ++i) {
    if (!sphere_seen[static_cast<std::size_t>(i)]) {
      return Invalid(absl::StrCat("sphere ", i, " is in no leaf"));
    }
  }
  *depth = max_depth;
  return absl::OkStatus();
}

}  // namespace inscribe
