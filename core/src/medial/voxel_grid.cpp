// The voxel grid, culling and corner screen of medial-sphere generation; see voxel_grid.h.
#include "medial/voxel_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "absl/strings/str_format.h"
#include "base/parallel.h"
#include "inscribe/medial/voxel_grid_cells.h"

namespace inscribe::internal {
namespace {

// Inward normal direction "seen" from x: the unit vector from x's nearest boundary point
// towards x for x inside, away from x for x outside, i.e. the inward normal at the foot for
// any x near a face. The side comes from the foot triangle's own normal, so no inside test is
// needed: at a face the sign of (x - foot) . inward normal tells it, and at a convex edge or
// vertex (x - foot) lies in the normal cone of the adjacent faces, so the sign agrees.
Vector3 InwardDirectionAtFoot(const Mesh& mesh, const Vector3& x, const BoundaryPoint& foot) {
  const Vector3 a = mesh.vertices.row(mesh.triangles(foot.triangle, 0));
  const Vector3 b = mesh.vertices.row(mesh.triangles(foot.triangle, 1));
  const Vector3 c = mesh.vertices.row(mesh.triangles(foot.triangle, 2));
  const Vector3 inward = (c - a).cross(b - a);  // triangles are counter-clockwise from outside
  const Vector3 away = x - foot.point;
  const double length = away.norm();
  if (!(length > 0.0)) {
    const double n = inward.norm();
    return n > 0.0 ? Vector3(inward / n) : Vector3::Zero();
  }
  return away.dot(inward) >= 0.0 ? Vector3(away / length) : Vector3(-away / length);
}

}  // namespace

absl::StatusOr<Grid> MakeGrid(const BoundingBox& box, double size, std::int64_t max_voxels) {
  const Vector3 extent = box.extent();
  const Vector3 cells = VoxelGridCells(extent, size);
  // Every axis has at least one cell, so the product only grows: checking it once is checking
  // every partial product, and it is finite or +infinity, never an overflowed integer.
  if (!(cells.prod() <= static_cast<double>(max_voxels))) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "voxel size %g gives a grid of more than %d voxels over the bounding box (%g x %g x "
        "%g); use a larger voxel size or raise the voxel limit",
        size, max_voxels, extent.x(), extent.y(), extent.z()));
  }
  Grid grid;
  grid.size = size;
  for (int axis = 0; axis < 3; ++axis) grid.dims[axis] = static_cast<std::int64_t>(cells[axis]);
  grid.origin = box.min - 0.5 * (cells * size - extent);
  return grid;
}

double FinestVoxelSize(const BoundingBox& box, std::int64_t max_voxels) {
  const Vector3 extent = box.extent().cwiseMax(Vector3::Constant(1e-12 * box.diagonal()));
  // From the volume's estimate up until the grid, whose sides round up to whole voxels, fits.
  double finest = std::cbrt(extent.prod() / static_cast<double>(max_voxels));
  while (!MakeGrid(box, finest, max_voxels).ok()) finest *= 1.001;
  return finest;
}

// Voxels inside the mesh or possibly crossed by its boundary, by octree-style culling over
// blocks of voxels: a block whose centre lies outside by more than the block's circumradius is
// dropped whole; one inside by more than that is kept whole without further queries.
std::vector<VisitedVoxel> CullVoxels(const BoundaryOracle& oracle, const Grid& grid,
                                     std::int64_t& queries, const std::atomic<bool>* cancel) {
  auto cancelled = [cancel] {
    return cancel != nullptr && cancel->load(std::memory_order_relaxed);
  };
  struct Block {
    std::array<std::int64_t, 3> start;
    std::int64_t size;  // power of two, in voxels
  };
  std::int64_t top = 1;
  while (top < std::max({grid.dims[0], grid.dims[1], grid.dims[2]})) top *= 2;
  std::vector<Block> blocks = {Block{{0, 0, 0}, top}};
  std::vector<VisitedVoxel> visited;
  auto block_end = [&](const Block& block, int axis) {
    return std::min(block.start[axis] + block.size, grid.dims[axis]);
  };
  auto add_voxels = [&](const Block& block, bool boundary) {
    for (std::int64_t k = block.start[2]; k < block_end(block, 2); ++k) {
      for (std::int64_t j = block.start[1]; j < block_end(block, 1); ++j) {
        for (std::int64_t i = block.start[0]; i < block_end(block, 0); ++i) {
          visited.push_back(
              VisitedVoxel{i + grid.dims[0] * (j + grid.dims[1] * k), {i, j, k}, boundary});
        }
      }
    }
  };
  while (!blocks.empty() && !cancelled()) {
    std::vector<double> distances(blocks.size());
    std::vector<double> radii(blocks.size());
    ParallelForRange(std::size_t{0}, blocks.size(), 64, [&](std::size_t begin, std::size_t end) {
      if (cancelled()) return;  // the result is discarded
      for (std::size_t b = begin; b != end; ++b) {
        const Block& block = blocks[b];
        Vector3 lo = grid.corner(block.start[0], block.start[1], block.start[2]);
        Vector3 hi = grid.corner(block_end(block, 0), block_end(block, 1), block_end(block, 2));
        radii[b] = 0.5 * (hi - lo).norm();
        distances[b] = oracle.SignedDistance(0.5 * (lo + hi));
      }
    });
    queries += static_cast<std::int64_t>(blocks.size());
    std::vector<Block> next;
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      const Block& block = blocks[b];
      if (distances[b] > radii[b]) continue;  // wholly outside
      if (block.size == 1) {
        add_voxels(block, distances[b] >= -radii[b]);
      } else if (distances[b] < -radii[b]) {
        add_voxels(block, false);  // wholly inside
      } else {
        const std::int64_t half = block.size / 2;
        for (int octant = 0; octant < 8; ++octant) {
          Block child{{block.start[0] + ((octant & 1) ? half : 0),
                       block.start[1] + ((octant & 2) ? half : 0),
                       block.start[2] + ((octant & 4) ? half : 0)},
                      half};
          if (child.start[0] < grid.dims[0] && child.start[1] < grid.dims[1] &&
              child.start[2] < grid.dims[2]) {
            next.push_back(child);
          }
        }
      }
    }
    blocks = std::move(next);
  }
  std::sort(visited.begin(), visited.end(),
            [](const VisitedVoxel& x, const VisitedVoxel& y) { return x.linear < y.linear; });
  return visited;
}

bool SheetEstimateNearVoxel(const Vector3& foot_i, const Vector3& inward_i, const Vector3& foot_j,
                            const Vector3& inward_j, const Vector3& lo, const Vector3& hi,
                            double reach) {
  if (!(reach < std::numeric_limits<double>::infinity())) return true;
  const double parallel = 1.0 - inward_i.dot(inward_j);
  auto near_from = [&](const Vector3& foot, const Vector3& inward, const Vector3& other_foot,
                       const Vector3& other_inward) {
    const double t = other_inward.dot(foot - other_foot) / parallel;
    if (!(t > 0.0) || !std::isfinite(t)) return true;
    const Vector3 m = foot + t * inward;
    const Vector3 gap = (lo - m).cwiseMax(m - hi).cwiseMax(Vector3::Zero());
    return !(gap.squaredNorm() > reach * reach);
  };
  return near_from(foot_i, inward_i, foot_j, inward_j) ||
         near_from(foot_j, inward_j, foot_i, inward_i);
}

CornerVertices ListCornerVertices(const Grid& grid, const std::vector<VisitedVoxel>& voxels) {
  auto corner_id = [&grid](const VisitedVoxel& voxel, int corner) {
    return grid.vertex_id(voxel.index[0] + (corner & 1), voxel.index[1] + ((corner >> 1) & 1),
                          voxel.index[2] + (corner >> 2));
  };
  CornerVertices out;
  out.of_voxel.resize(8 * voxels.size());
  const std::int64_t words = (grid.vertex_count() + 63) / 64;
  if (words <= static_cast<std::int64_t>(voxels.size())) {
    // Dense: one bit per grid vertex and the number of set bits before each word, so a
    // vertex's place in the list is that number plus a popcount.
    std::vector<std::uint64_t> bits(static_cast<std::size_t>(words), 0);
    for (const VisitedVoxel& voxel : voxels) {
      for (int corner = 0; corner < 8; ++corner) {
        const std::int64_t id = corner_id(voxel, corner);
        bits[static_cast<std::size_t>(id >> 6)] |= std::uint64_t{1} << (id & 63);
      }
    }
    std::vector<std::int64_t> before(bits.size());
    std::int64_t count = 0;
    for (std::size_t w = 0; w < bits.size(); ++w) {
      before[w] = count;
      count += __builtin_popcountll(bits[w]);
    }
    out.ids.reserve(static_cast<std::size_t>(count));
    for (std::size_t w = 0; w < bits.size(); ++w) {
      for (std::uint64_t b = bits[w]; b != 0; b &= b - 1) {
        out.ids.push_back(static_cast<std::int64_t>(64 * w) + __builtin_ctzll(b));
      }
    }
    ParallelForRange(std::size_t{0}, voxels.size(), 1024, [&](std::size_t begin, std::size_t end) {
      for (std::size_t v = begin; v != end; ++v) {
        for (int corner = 0; corner < 8; ++corner) {
          const std::int64_t id = corner_id(voxels[v], corner);
          const auto w = static_cast<std::size_t>(id >> 6);
          const std::uint64_t below = bits[w] & ((std::uint64_t{1} << (id & 63)) - 1);
          out.of_voxel[8 * v + static_cast<std::size_t>(corner)] =
              before[w] + __builtin_popcountll(below);
        }
      }
    });
    return out;
  }
  // Sparse (a few voxels in a large grid): the corners sorted, then found by binary search.
  out.ids.reserve(8 * voxels.size());
  for (const VisitedVoxel& voxel : voxels) {
    for (int corner = 0; corner < 8; ++corner) out.ids.push_back(corner_id(voxel, corner));
  }
  std::sort(out.ids.begin(), out.ids.end());
  out.ids.erase(std::unique(out.ids.begin(), out.ids.end()), out.ids.end());
  ParallelForRange(std::size_t{0}, voxels.size(), 1024, [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v != end; ++v) {
      for (int corner = 0; corner < 8; ++corner) {
        out.of_voxel[8 * v + static_cast<std::size_t>(corner)] =
            std::lower_bound(out.ids.begin(), out.ids.end(), corner_id(voxels[v], corner)) -
            out.ids.begin();
      }
    }
  });
  return out;
}

// Corner screening: one closest-point query per grid vertex, shared by the 8 voxels around it.
// A medial sheet of object angle phi that cuts a voxel separates its corners into two groups
// whose inward directions differ by about phi; a voxel whose 8 corner directions are all
// within (theta - margin) of each other is skipped. So is one whose wide pairs all straddle a
// sheet estimated well outside it: near a tube's axis the directions turn by more than theta
// across voxels a few sigma away, while the sheet they point to (the axis) lies elsewhere.
// Returns one flag per visited voxel.
std::vector<char> ScreenByCorners(const BoundaryOracle& oracle, const Grid& grid,
                                  const std::vector<VisitedVoxel>& voxels, double min_angle,
                                  double reach, std::int64_t& queries,
                                  const std::atomic<bool>* cancel) {
  const CornerVertices corners = ListCornerVertices(grid, voxels);
  const std::vector<std::int64_t>& vertices = corners.ids;
  std::vector<Vector3> feet(vertices.size());
  std::vector<Vector3> directions(vertices.size());
  const Mesh& mesh = oracle.mesh();
  ParallelForRange(std::size_t{0}, vertices.size(), 256, [&](std::size_t begin, std::size_t end) {
    // Cancelled: stop; the caller discards the (incomplete) result.
    if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) return;
    // Consecutive vertices are mostly neighbours along x: the previous foot bounds the query.
    std::optional<Vector3> previous_foot;
    for (std::size_t v = begin; v != end; ++v) {
      const std::int64_t id = vertices[v];
      const Vector3 x = grid.vertex(id);
      const BoundaryPoint foot =
          previous_foot ? oracle.ClosestPointNear(x, *previous_foot) : oracle.ClosestPoint(x);
      previous_foot = foot.point;
      feet[v] = foot.point;
      directions[v] = InwardDirectionAtFoot(mesh, x, foot);
    }
  });
  queries += static_cast<std::int64_t>(vertices.size());
  const double max_cosine = std::cos(std::max(0.0, min_angle));
  std::vector<char> pass(voxels.size(), 0);
  ParallelForRange(std::size_t{0}, voxels.size(), 256, [&](std::size_t begin, std::size_t end) {
    for (std::size_t n = begin; n != end; ++n) {
      const VisitedVoxel& voxel = voxels[n];
      const std::int64_t* corner_vertex = &corners.of_voxel[8 * n];
      const Vector3 lo = grid.corner(voxel.index[0], voxel.index[1], voxel.index[2]);
      const Vector3 hi = lo + Vector3::Constant(grid.size);
      for (int x = 0; x < 8 && !pass[n]; ++x) {
        const auto a = static_cast<std::size_t>(corner_vertex[x]);
        for (int y = x + 1; y < 8; ++y) {
          const auto b = static_cast<std::size_t>(corner_vertex[y]);
          if (directions[a].dot(directions[b]) <= max_cosine &&
              SheetEstimateNearVoxel(feet[a], directions[a], feet[b], directions[b], lo, hi,
                                     reach)) {
            pass[n] = 1;
            break;
          }
        }
      }
    }
  });
  return pass;
}

}  // namespace inscribe::internal

namespace inscribe {

Vector3 VoxelGridCells(const Vector3& extent, double voxel_size) {
  Vector3 cells;
  for (int axis = 0; axis < 3; ++axis) {
    cells[axis] = std::max(1.0, std::ceil(extent[axis] / voxel_size));
  }
  return cells;
}

}  // namespace inscribe
