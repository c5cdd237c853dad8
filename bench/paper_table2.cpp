// The paper's Table II protocol (Section VI-D): approximate separation distance between
// two copies of a model, each a union of grown medial spheres S_D+, against the exact
// mesh-mesh distance of FCL, on random poses. For each model: S_D from GenerateWithSphereBudget
// with boundary voxels split in 8 (subdivide_boundary), S_D+ = DilateSpheres(S_D), an RSS
// hierarchy and a sphere hierarchy over S_D+, and FCL's OBBRSS tree over the triangles. For two
// sets of random pose pairs ('near', 'far'), the error |d_sph - d_exact| on the poses where the
// meshes do not touch, and the median time of one query (each timed alone, one thread).
// Every model is first scaled so that its bounding box's largest side is 10, as in the paper.
//
//   paper_table2 [--models eight,cow,...] [--max-spheres N] [--model-spheres fandisk=N,...]
//                [--poses N] [--seed S]
//                [--check-every K] [--data DIR]
//
// Exit status: 0 every check passed (targets may still be missed: they are reported, not
// enforced); 1 a check failed, printed after the tables: the sphere hierarchy's answer differs
// from the RSS hierarchy's (or, every K-th pose, the brute-force one's) by more than 1e-9, FCL
// gave a non-finite distance, FCL's distance disagrees with fcl::collide or exceeds the
// distance from some vertex to the other mesh (every K-th pose), its witness points are not on
// the meshes (every K-th pose), or it exceeds the distance between the internal spheres S_D
// (every pose); 2 a model could not be run.
#include <fcl/fcl.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/geometry/rigid_pose.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/medial/sphere_dilation.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/boundary_oracle.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/solid/solid.h"
#include "support/fcl_solid_distance.h"
#include "table2_poses.h"

namespace {

using namespace inscribe;
using Clock = std::chrono::steady_clock;
using bench::kPoseSets;
using bench::PosePair;
using bench::PoseSetSpec;
using bench::RandomPosePairs;
using testing::BuildFclMesh;
using testing::FclMesh;
using testing::ToFcl;

constexpr double kLargestSide = 10.0;      // every model is scaled to this (paper: "bbox 10")
constexpr double kTargetSpeedup = 30.0;    // RSS median at least this many times FCL's
constexpr double kTargetMeanError = 0.05;  // mean |d_sph - d_exact|, bbox 10
// Both hierarchies and the brute force are exact minima over the same sphere pairs; they may
// differ only by the rounding of how each transforms the centres.
constexpr double kAgreement = 1e-9;

// How far a query answering `answer` may lie above the exact minimum under `request`'s
// tolerances (the search stops refining once no pair can beat it by more than this).
double Allowance(const DistanceRequest& request, double answer) {
  return std::max(request.abs_err, request.rel_err * std::abs(answer)) + kAgreement;
}

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

struct Options {
  std::vector<std::string> models;
  std::int64_t max_spheres = 1000;
  // Budgets of named models that override max_spheres ("fandisk" -> 3000).
  std::map<std::string, std::int64_t> model_spheres;
  int poses = 1000;
  std::uint64_t seed = 1;
  int check_every = 25;
  std::string data_dir;
  double growth = 1.0;      // DilationOptions::growth
  DistanceRequest request;  // tolerances of the timed sphere queries
};

// Per model: how S_D and S_D+ were made and what the hierarchies cost.
struct ModelRow {
  std::string model;
  std::int64_t triangles = 0;
  std::int64_t holes_filled_edges = 0;  // border edges closed by hole filling (pig.off)
  double sigma = 0.0;                   // voxel size found by the budget search
  int runs = 0;
  double generation_seconds = 0.0;  // the whole budget search
  std::size_t spheres = 0;          // |S_D| = |S_D+|
  bool fat = false;                 // S_D is (sigma, theta)-fat: r_min / sqrt(3) >= sigma
  double fat_ratio = 0.0;           // r_min / (sqrt(3) sigma): fat when >= 1
  double fat_share = 0.0;           // fraction of S_D's spheres with r >= sqrt(3) sigma
  double dilation_seconds = 0.0;
  std::int64_t grown = 0;
  double max_growth = 0.0;
  double rss_build_ms = 0.0, sphere_build_ms = 0.0, fcl_build_ms = 0.0;
  int rss_depth = 0, sphere_depth = 0;
  double protrusion = 0.0;  // how far S_D reaches outside the mesh (EvaluateSpheres), mesh units
  // How far the spheres of S_D+ reach outside the mesh, mean and max over spheres, mesh units.
  double dilated_protrusion_mean = 0.0, dilated_protrusion_max = 0.0;
};

// Per model and pose set.
struct PoseSetRow {
  std::string model;
  std::string set;
  std::size_t spheres = 0;
  int poses = 0;
  int touching = 0;  // fcl::collide reports contact
  // Over the poses that do not touch, bbox-10 units.
  double mean_error = 0.0, max_error = 0.0, mean_signed_error = 0.0;
  int false_contacts = 0;             // spheres overlap (d_sph < 0) though the meshes do not touch
  double undilated_mean_error = 0.0;  // the same mean error for S_D (before dilation)
  double rss_us = 0.0, sphere_us = 0.0, fcl_us = 0.0;        // medians of one query each
  double rss_volume_tests = 0.0, sphere_volume_tests = 0.0;  // means
  double rss_sphere_tests = 0.0, sphere_sphere_tests = 0.0;  // sphere pairs compared, means
  double speedup() const { return fcl_us / rss_us; }
};

struct Results {
  std::vector<ModelRow> models;
  std::vector<PoseSetRow> sets;
  std::vector<std::string> failed_checks;  // exit status 1
  std::vector<std::string> errors;         // exit status 2
};

// What the timed loops need about one model.
struct Model {
  Mesh mesh;  // scaled and centred, holes filled
  BoundaryOracle oracle;
  std::vector<Sphere> dilated;  // S_D+
  SphereHierarchy rss, sphere;
  SphereHierarchy undilated;  // S_D, sphere volumes: untimed, for its error and a check on FCL
  double protrusion = 0.0;    // of S_D, mesh units
  std::shared_ptr<FclMesh> fcl;
  double diagonal = 0.0;
};

// The mesh moved so that its bounding box is centred on the origin and scaled so that its
// largest side is kLargestSide.
Mesh ScaledToBox(Mesh mesh) {
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const Vector3 centre = 0.5 * (box.min + box.max);
  const double scale = kLargestSide / box.extent().maxCoeff();
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    mesh.vertices.row(i) = ((mesh.vertices.row(i).transpose() - centre) * scale).transpose();
  }
  return mesh;
}

// Loads and prepares one model, generates S_D and S_D+, builds the three trees.
absl::StatusOr<Model> PrepareModel(const std::string& name, const Options& options, ModelRow& row) {
  absl::StatusOr<Mesh> read = ReadMesh(options.data_dir + "/" + name + ".off");
  if (!read.ok()) return read.status();
  ValidateOptions validate;
  validate.repair.level = MeshRepair::kFill;  // pig.off is open; closed meshes come back unchanged
  absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(ScaledToBox(*std::move(read)), validate);
  if (!prepared.ok()) return prepared.status();
  BoundaryOracleOptions oracle_options;
  oracle_options.inside_test = InsideTestFor(prepared->report);
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(prepared->mesh, oracle_options);
  if (!oracle.ok()) return oracle.status();
  row.model = name;
  row.triangles = prepared->mesh.num_triangles();
  row.holes_filled_edges = prepared->report.holes_filled > 0 ? prepared->report.border_edges : 0;

  SphereBudgetOptions budget;
  const auto own_budget = options.model_spheres.find(name);
  budget.max_spheres =
      own_budget != options.model_spheres.end() ? own_budget->second : options.max_spheres;
  budget.base.subdivide_boundary = true;  // the paper's setting for Table II
  absl::StatusOr<SphereBudgetResult> generated = GenerateWithSphereBudget(*oracle, budget);
  if (!generated.ok()) return generated.status();
  row.sigma = generated->best.voxel_size;
  row.runs = generated->runs;
  row.generation_seconds = generated->seconds;
  row.spheres = generated->best.set.size();

  // Fatness of S_D (before dilation) at the sigma it was generated with; only the radii matter.
  QualityOptions quality_options;
  quality_options.surface_samples = 0;
  quality_options.voxel_size = row.sigma;
  absl::StatusOr<QualityReport> quality =
      EvaluateSpheres(*oracle, generated->best.set.spheres, quality_options);
  if (!quality.ok()) return quality.status();
  row.fat = quality->fat;
  row.fat_ratio = quality->fat_up_to_voxel_size / row.sigma;
  row.fat_share = quality->fraction_radius_over_sqrt3_sigma;
  row.protrusion = quality->protrusion_max;
  absl::StatusOr<SphereHierarchy> undilated =
      SphereHierarchy::Build(generated->best.set.spheres, HierarchyVolume::kSphere);
  if (!undilated.ok()) return undilated.status();

  DilationOptions dilation;
  dilation.growth = options.growth;
  absl::StatusOr<DilationResult> dilated = DilateSpheres(*oracle, generated->best.set, dilation);
  if (!dilated.ok()) return dilated.status();
  row.dilation_seconds = dilated->seconds;
  row.grown = dilated->grown;
  row.max_growth = dilated->max_growth;
  absl::StatusOr<QualityReport> dilated_quality =
      EvaluateSpheres(*oracle, dilated->set.spheres, quality_options);
  if (!dilated_quality.ok()) return dilated_quality.status();
  row.dilated_protrusion_mean = dilated_quality->protrusion_mean;
  row.dilated_protrusion_max = dilated_quality->protrusion_max;

  auto start = Clock::now();
  absl::StatusOr<SphereHierarchy> rss =
      SphereHierarchy::Build(dilated->set.spheres, HierarchyVolume::kRss);
  if (!rss.ok()) return rss.status();
  row.rss_build_ms = 1e3 * SecondsSince(start);
  start = Clock::now();
  absl::StatusOr<SphereHierarchy> sphere =
      SphereHierarchy::Build(dilated->set.spheres, HierarchyVolume::kSphere);
  if (!sphere.ok()) return sphere.status();
  row.sphere_build_ms = 1e3 * SecondsSince(start);
  row.rss_depth = rss->depth();
  row.sphere_depth = sphere->depth();
  start = Clock::now();
  std::shared_ptr<FclMesh> fcl_mesh = BuildFclMesh(prepared->mesh);
  row.fcl_build_ms = 1e3 * SecondsSince(start);

  const double diagonal = ComputeBoundingBox(prepared->mesh.vertices).diagonal();
  return Model{std::move(prepared->mesh),
               *std::move(oracle),
               std::move(dilated->set.spheres),
               *std::move(rss),
               *std::move(sphere),
               *std::move(undilated),
               row.protrusion,
               std::move(fcl_mesh),
               diagonal};
}

// FCL's answer checked without FCL, on one pose pair that does not touch: its witness points
// lie on the two meshes and are d apart, and d is at most the distance from any vertex of one
// copy to the other copy's surface (the oracle's exact point-mesh distance), since the mesh
// distance is a minimum over, among others, those vertex-surface pairs.
void CheckFclDistance(const Model& model, const PosePair& pose, double d, const std::string& where,
                      Results& results) {
  fcl::DistanceRequestd request(/*enable_nearest_points=*/true);
  fcl::DistanceResultd result;
  fcl::distance(model.fcl.get(), ToFcl(pose.a), model.fcl.get(), ToFcl(pose.b), request, result);
  const Vector3 pa = pose.a.Inverse() * Vector3(result.nearest_points[0]);
  const Vector3 pb = pose.b.Inverse() * Vector3(result.nearest_points[1]);
  const double on_a = model.oracle.ClosestPoint(pa).distance;
  const double on_b = model.oracle.ClosestPoint(pb).distance;
  const double apart = (result.nearest_points[0] - result.nearest_points[1]).norm();
  constexpr double kOnMesh = 1e-9 * kLargestSide;
  if (on_a > kOnMesh || on_b > kOnMesh || std::abs(apart - d) > kOnMesh ||
      result.min_distance != d) {
    results.failed_checks.push_back(absl::StrFormat(
        "%s: FCL witnesses off: %.3g and %.3g from the meshes, %.17g apart, distance %.17g "
        "(timed query %.17g)",
        where, on_a, on_b, apart, result.min_distance, d));
  }
  // Vertices of each copy in the other copy's frame.
  const std::pair<const RigidPose*, const RigidPose*> sides[] = {{&pose.a, &pose.b},
                                                                 {&pose.b, &pose.a}};
  double vertex_bound = std::numeric_limits<double>::infinity();
  for (const auto& [from, to] : sides) {
    const RigidPose into = to->Inverse() * *from;
    Vertices moved(model.mesh.vertices.rows(), 3);
    for (Eigen::Index i = 0; i < moved.rows(); ++i) {
      moved.row(i) = (into * Vector3(model.mesh.vertices.row(i).transpose())).transpose();
    }
    for (const BoundaryPoint& p : model.oracle.ClosestPoints(moved)) {
      vertex_bound = std::min(vertex_bound, p.distance);
    }
  }
  if (d > vertex_bound + kOnMesh) {
    results.failed_checks.push_back(absl::StrFormat(
        "%s: FCL distance %.17g exceeds a vertex-to-mesh distance %.17g", where, d, vertex_bound));
  }
}

// One pose set on one model: the three timed loops, then statistics and checks.
void RunPoseSet(const Model& model, const ModelRow& model_row, const PoseSetSpec& spec,
                std::uint64_t seed, const Options& options, Results& results) {
  const std::vector<PosePair> poses = RandomPosePairs(options.poses, spec, model.diagonal, seed);
  const std::size_t n = poses.size();
  const std::string where = model_row.model + " " + spec.name;

  // Each query is timed alone, so the median describes one query, not a batch.
  std::vector<double> rss_us(n), sphere_us(n), fcl_us(n), d_rss(n), d_sphere(n), d_fcl(n);
  double rss_tests = 0.0, sphere_tests = 0.0, rss_leaf_tests = 0.0, sphere_leaf_tests = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto start = Clock::now();
    absl::StatusOr<DistanceResult> r =
        SeparationDistance(model.rss, poses[i].a, model.rss, poses[i].b, options.request);
    rss_us[i] = 1e6 * SecondsSince(start);
    if (!r.ok()) {
      results.errors.push_back(where + ": " + r.status().ToString());
      return;
    }
    d_rss[i] = r->distance;
    rss_tests += static_cast<double>(r->volume_tests);
    rss_leaf_tests += static_cast<double>(r->sphere_tests);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto start = Clock::now();
    absl::StatusOr<DistanceResult> r =
        SeparationDistance(model.sphere, poses[i].a, model.sphere, poses[i].b, options.request);
    sphere_us[i] = 1e6 * SecondsSince(start);
    if (!r.ok()) {
      results.errors.push_back(where + ": " + r.status().ToString());
      return;
    }
    d_sphere[i] = r->distance;
    sphere_tests += static_cast<double>(r->volume_tests);
    sphere_leaf_tests += static_cast<double>(r->sphere_tests);
  }
  // Exact distance between the triangle sets. FCL 0.7 reports 0 for meshes that touch or
  // interpenetrate (the triangle-triangle distance of crossing triangles is 0; its "signed
  // distance" option changes nothing for meshes), so contact is decided by fcl::collide.
  const fcl::DistanceRequestd request;  // exact: rel_err = abs_err = 0, no witnesses
  for (std::size_t i = 0; i < n; ++i) {
    const fcl::Transform3d ta = ToFcl(poses[i].a), tb = ToFcl(poses[i].b);
    fcl::DistanceResultd result;  // fresh: a reused result keeps its earlier minimum
    const auto start = Clock::now();
    fcl::distance(model.fcl.get(), ta, model.fcl.get(), tb, request, result);
    fcl_us[i] = 1e6 * SecondsSince(start);
    d_fcl[i] = result.min_distance;
  }

  PoseSetRow row;
  row.model = model_row.model;
  row.set = spec.name;
  row.spheres = model.dilated.size();
  row.poses = static_cast<int>(n);
  int separated = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::string at = absl::StrFormat("%s pose %d", where, i);
    if (std::abs(d_sphere[i] - d_rss[i]) >
        std::max(Allowance(options.request, d_sphere[i]), Allowance(options.request, d_rss[i]))) {
      results.failed_checks.push_back(absl::StrFormat(
          "%s: sphere hierarchy %.17g, RSS hierarchy %.17g", at, d_sphere[i], d_rss[i]));
    }
    if (!std::isfinite(d_fcl[i])) {
      results.failed_checks.push_back(absl::StrFormat("%s: FCL distance %g", at, d_fcl[i]));
      continue;
    }
    fcl::CollisionRequestd collision_request;
    fcl::CollisionResultd collision_result;
    fcl::collide(model.fcl.get(), ToFcl(poses[i].a), model.fcl.get(), ToFcl(poses[i].b),
                 collision_request, collision_result);
    const bool touching = collision_result.isCollision();
    if (touching != (d_fcl[i] <= 0.0)) {
      results.failed_checks.push_back(
          absl::StrFormat("%s: fcl::collide says %s but fcl::distance gives %.17g", at,
                          touching ? "contact" : "no contact", d_fcl[i]));
    }
    const bool spot_check = options.check_every > 0 && i % options.check_every == 0;
    if (spot_check) {
      absl::StatusOr<DistanceResult> brute =
          BruteForceSeparationDistance(model.dilated, poses[i].a, model.dilated, poses[i].b);
      const auto off = [&](double d) {
        return d < brute->distance - kAgreement ||
               d - brute->distance > Allowance(options.request, d);
      };
      if (!brute.ok() || off(d_rss[i]) || off(d_sphere[i])) {
        results.failed_checks.push_back(
            absl::StrFormat(
                "%s: brute force %s, RSS hierarchy %.17g", at,
                brute.ok() ? absl::StrFormat("%.17g", brute->distance) : brute.status().ToString(),
                d_rss[i]) +
            absl::StrFormat(", sphere hierarchy %.17g", d_sphere[i]));
      }
    }
    if (touching) {
      ++row.touching;
      continue;
    }
    if (spot_check) CheckFclDistance(model, poses[i], d_fcl[i], at, results);
    ++separated;
    const double error = d_rss[i] - d_fcl[i];
    row.mean_error += std::abs(error);
    row.mean_signed_error += error;
    row.max_error = std::max(row.max_error, std::abs(error));
    if (d_rss[i] < 0.0) ++row.false_contacts;

    // S_D lies inside the solid (up to its protrusion p), so its two copies can be no closer
    // than the two meshes less 2p: a check on FCL that needs no FCL.
    absl::StatusOr<DistanceResult> undilated =
        SeparationDistance(model.undilated, poses[i].a, model.undilated, poses[i].b);
    if (!undilated.ok()) {
      results.errors.push_back(where + ": " + undilated.status().ToString());
      return;
    }
    row.undilated_mean_error += std::abs(undilated->distance - d_fcl[i]);
    if (undilated->distance < d_fcl[i] - 2.0 * model.protrusion - 1e-9 * kLargestSide) {
      results.failed_checks.push_back(absl::StrFormat(
          "%s: S_D (protrusion %.3g) is %.17g apart, less than FCL's mesh distance %.17g", at,
          model.protrusion, undilated->distance, d_fcl[i]));
    }
  }
  if (separated > 0) {
    row.mean_error /= separated;
    row.mean_signed_error /= separated;
    row.undilated_mean_error /= separated;
  }
  row.rss_us = Median(rss_us);
  row.sphere_us = Median(sphere_us);
  row.fcl_us = Median(fcl_us);
  row.rss_volume_tests = rss_tests / static_cast<double>(n);
  row.sphere_volume_tests = sphere_tests / static_cast<double>(n);
  row.rss_sphere_tests = rss_leaf_tests / static_cast<double>(n);
  row.sphere_sphere_tests = sphere_leaf_tests / static_cast<double>(n);
  results.sets.push_back(row);
}

void PrintModels(const Options& options, const Results& results) {
  std::string overrides;
  for (const auto& [model, budget] : options.model_spheres) {
    absl::StrAppend(&overrides, "; ", model, " <= ", budget);
  }
  absl::PrintF(
      "Sphere sets: S_D = GenerateWithSphereBudget (<= %d spheres%s, boundary voxels split in "
      "8, theta 0.6), bounding box's largest side 10; S_D+ = DilateSpheres(S_D, growth %g) (same "
      "count). fat: S_D is (sigma, theta)-fat, i.e. r_min / (sqrt(3) sigma) >= 1 (that ratio; "
      "then the share of spheres with r >= sqrt(3) sigma). Build "
      "times of one hierarchy each, one thread for FCL (OBBRSS over the triangles).\n\n",
      options.max_spheres, overrides, options.growth);
  absl::PrintF(
      "| model | triangles | sigma | search runs | generation s | spheres | fat (ratio, share) | "
      "dilation s | grown | max growth | S_D+ protrusion mean / max | RSSH build ms | SH build ms "
      "| depth RSSH / SH | FCL "
      "build ms |\n");
  absl::PrintF("|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const ModelRow& m : results.models) {
    const std::string label =
        m.holes_filled_edges > 0
            ? absl::StrFormat("%s (%d border edges filled)", m.model, m.holes_filled_edges)
            : m.model;
    absl::PrintF(
        "| %s | %d | %.4f | %d | %.1f | %d | %s (%.3g, %.0f%%) | %.2f | %d | %.3f | %.3f / %.3f | "
        "%.1f | "
        "%.1f "
        "| %d / %d | %.1f |\n",
        label, m.triangles, m.sigma, m.runs, m.generation_seconds, m.spheres, m.fat ? "yes" : "no",
        m.fat_ratio, 100.0 * m.fat_share, m.dilation_seconds, m.grown, m.max_growth,
        m.dilated_protrusion_mean, m.dilated_protrusion_max, m.rss_build_ms, m.sphere_build_ms,
        m.rss_depth, m.sphere_depth, m.fcl_build_ms);
  }
}

void PrintPoseSets(const Options& options, const Results& results) {
  absl::PrintF(
      "\nSeparation distance, %d random pose pairs per set (seed %d; both copies randomly "
      "rotated; centre distance near: 0.4-0.9, far: 0.6-1.5 bbox diagonals). Errors |d_sph - "
      "d_exact| in bbox-10 units over the poses where the meshes do not touch (fcl::collide); "
      "d_sph is the signed sphere-pair distance (negative = overlap), d_exact FCL's exact "
      "mesh distance. signed = mean of d_sph - d_exact; overlaps = poses where the spheres "
      "overlap but the meshes do not touch; S_D err = the mean error of the spheres before "
      "dilation. Times: median microseconds of one query, each "
      "timed alone on one thread; BV tests = mean bounding-volume pairs tested per query; sphere "
      "pairs = mean sphere pairs "
      "compared per query. Tolerances of the sphere queries: abs_err %g, rel_err %g.\n\n",
      options.poses, options.seed, options.request.abs_err, options.request.rel_err);
  absl::PrintF(
      "| model | poses | spheres | touching | mean err | max err | signed | overlaps | S_D err | "
      "RSSH us | SH us | FCL us | FCL/RSSH | BV tests RSSH / SH | sphere pairs RSSH / SH | mean <= "
      "%.2f | FCL/RSSH >= %.0f "
      "|\n",
      kTargetMeanError, kTargetSpeedup);
  absl::PrintF(
      "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|\n");
  for (const PoseSetRow& r : results.sets) {
    absl::PrintF(
        "| %s | %s | %d | %.1f%% | %.4f | %.4f | %+.4f | %d | %.4f | %.1f | %.1f | %.1f | %.1f | "
        "%.0f / %.0f | %.0f / %.0f | %s | %s |\n",
        r.model, r.set, r.spheres, 100.0 * r.touching / r.poses, r.mean_error, r.max_error,
        r.mean_signed_error, r.false_contacts, r.undilated_mean_error, r.rss_us, r.sphere_us,
        r.fcl_us, r.speedup(), r.rss_volume_tests, r.sphere_volume_tests, r.rss_sphere_tests,
        r.sphere_sphere_tests, r.mean_error <= kTargetMeanError ? "pass" : "FAIL",
        r.speedup() >= kTargetSpeedup ? "pass" : "FAIL");
  }
  absl::PrintF(
      "\nPaper's Table II (S_D+, bbox 10, 8 models; 3.6 GHz Pentium 4, per-frame times of a "
      "physics simulation, not random poses): 296-1389 spheres, mean error 0.009-0.116, max "
      "error 0.024-0.325, SH 360-1458 us, RSSH 66-143 us per query.\n");
  int mean_pass = 0, speed_pass = 0;
  for (const PoseSetRow& r : results.sets) {
    mean_pass += r.mean_error <= kTargetMeanError;
    speed_pass += r.speedup() >= kTargetSpeedup;
  }
  const int rows = static_cast<int>(results.sets.size());
  absl::PrintF("\nTarget \"RSSH median >= %.0fx faster than FCL\": %s (%d of %d rows).\n",
               kTargetSpeedup, speed_pass == rows && rows > 0 ? "pass" : "FAIL", speed_pass, rows);
  absl::PrintF("Target \"mean error <= %.2f\": %s (%d of %d rows).\n", kTargetMeanError,
               mean_pass == rows && rows > 0 ? "pass" : "FAIL", mean_pass, rows);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "The paper's Table II (Section VI-D): separation distance of grown medial spheres S_D+ "
      "(RSS and sphere hierarchies) against FCL's exact mesh distance on random poses"};
  Options options;
  options.data_dir = INSCRIBE_SOURCE_DIR "/data";
  if (const char* env = std::getenv("INSCRIBE_DATA_DIR")) options.data_dir = env;
  options.models = {"eight", "cow", "elephant", "knot1", "fandisk", "pig"};
  app.add_option("--models", options.models, "Mesh file stems in the data directory (.off)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--max-spheres", options.max_spheres, "Sphere budget of S_D")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  std::vector<std::string> model_spheres;
  app.add_option("--model-spheres", model_spheres,
                 "Budgets of single models overriding --max-spheres, e.g. fandisk=3000")
      ->delimiter(',')
      ->check([&options](const std::string& item) -> std::string {
        const std::size_t equals = item.find('=');
        std::int64_t budget = 0;
        if (equals == std::string::npos || equals == 0 ||
            !absl::SimpleAtoi(item.substr(equals + 1), &budget) || budget <= 0) {
          return "expected MODEL=N with N > 0, got '" + item + "'";
        }
        options.model_spheres[item.substr(0, equals)] = budget;
        return "";
      });
  app.add_option("--poses", options.poses, "Random pose pairs per set (near, far)")
      ->check(CLI::Range(1, 1'000'000))
      ->capture_default_str();
  app.add_option("--growth", options.growth,
                 "DilationOptions::growth: fraction of the paper's growth (1 = the paper's rule)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--abs-err", options.request.abs_err,
                 "DistanceRequest::abs_err of the timed sphere queries (bbox-10 units)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--rel-err", options.request.rel_err,
                 "DistanceRequest::rel_err of the timed sphere queries")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--seed", options.seed, "Seed of the pose sets ('far' uses seed + 1)")
      ->capture_default_str();
  app.add_option("--check-every", options.check_every,
                 "Every K-th pose is also checked by brute force (spheres) and by vertex "
                 "distances and witness points (FCL); 0 turns these checks off")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--data", options.data_dir,
                 "Directory of the demo meshes (.off); INSCRIBE_DATA_DIR sets the default")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  Results results;
  for (const std::string& name : options.models) {
    std::fprintf(stderr, "paper_table2: %s: generating S_D+ and hierarchies\n", name.c_str());
    ModelRow row;
    absl::StatusOr<Model> model = PrepareModel(name, options, row);
    if (!model.ok()) {
      results.errors.push_back(absl::StrFormat("%s: %s", name, model.status().ToString()));
      continue;
    }
    results.models.push_back(row);
    for (std::size_t s = 0; s < std::size(kPoseSets); ++s) {
      std::fprintf(stderr, "paper_table2: %s: %s poses\n", name.c_str(), kPoseSets[s].name);
      RunPoseSet(*model, row, kPoseSets[s], options.seed + s, options, results);
    }
  }
  PrintModels(options, results);
  PrintPoseSets(options, results);
  for (const std::string& error : results.errors) absl::PrintF("\nNOT RUN: %s\n", error);
  for (const std::string& failure : results.failed_checks) {
    absl::PrintF("\nCHECK FAILED: %s\n", failure);
  }
  if (!results.failed_checks.empty()) return 1;
  return results.errors.empty() ? 0 : 2;
}
