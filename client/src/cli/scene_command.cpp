#include "scene_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cli_help.h"
#include "command_outcome.h"
#include "cover_verdict.h"
#include "exit_codes.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/base/atomic_file.h"
#include "inscribe/generation/sphere_file_record.h"
#include "inscribe/scene/scene.h"
#include "nlohmann/json.hpp"
#include "output_files.h"
#include "remote_options.h"
#include "scene_files.h"
#include "service_session.h"
#include "solid_loading.h"

namespace inscribe::cli {
namespace {

struct SceneCliOptions {
  std::string scene_path, poses_path;
  std::optional<double> threshold;  // overrides the scene file's
  std::string output_path;
  bool json = false;
  RemoteOptions remote;
};

// The service's keys of every file a scene names, each file read and stored once.
class SceneUploads {
 public:
  explicit SceneUploads(const client::Client& client) : client_(client) {}

  // The mesh at `path` stored (PutMesh); its key.
  absl::StatusOr<std::string> Mesh(const std::string& path) {
    if (auto it = meshes_.find(path); it != meshes_.end()) return it->second;
    absl::StatusOr<StoredSolid> solid = StoreSolid(client_, path);
    if (!solid.ok()) return solid.status();
    meshes_[path] = solid->sha256;
    return solid->sha256;
  }

  // The object's spheres: its sphere file (with its mesh when it names one), or generated
  // from its mesh.
  absl::StatusOr<std::string> Spheres(const SceneFileObject& object) {
    std::string mesh;
    if (!object.mesh_path.empty()) {
      absl::StatusOr<std::string> stored = Mesh(object.mesh_path);
      if (!stored.ok()) return stored.status();
      mesh = *stored;
    }
    if (object.spheres_path.empty()) {
      client::GenerateSettings settings;
      settings.parameters = object.generate;
      absl::StatusOr<client::GenerateResult> generated = client_.Generate(mesh, settings);
      if (!generated.ok()) return WithContext(object.mesh_path, generated.status());
      return generated->sphere_set_key;
    }
    absl::StatusOr<SphereFile> file = ReadSphereFile(object.spheres_path);
    if (!file.ok()) return BadInputError(file.status().message());
    if (file->set.spheres.empty()) return BadInputError(object.spheres_path + ": no spheres");
    absl::StatusOr<client::PutSphereSetResult> stored = client_.PutSphereSet(file->set, mesh);
    if (!stored.ok()) return WithContext(object.spheres_path, stored.status());
    return stored->sphere_set_key;
  }

  // The object's cover: with the certificate its file records when it names the cover's
  // spheres (and the object's mesh, when given: UsableCoverCertificate), else with its mesh,
  // against which the service certifies it on first use.
  absl::StatusOr<std::string> Cover(const SceneFileObject& object, const std::string& where) {
    absl::StatusOr<SphereFile> file = ReadSphereFile(object.cover_path);
    if (!file.ok()) return BadInputError(file.status().message());
    if (file->set.spheres.empty()) return BadInputError(object.cover_path + ": no spheres");
    std::string mesh;
    if (!object.mesh_path.empty()) {
      absl::StatusOr<std::string> stored = Mesh(object.mesh_path);
      if (!stored.ok()) return stored.status();
      mesh = *stored;
    }
    absl::StatusOr<std::optional<CoverCertificate>> usable =
        UsableCoverCertificate(*file, object.cover_path, mesh.empty() ? file->mesh_sha256 : mesh);
    if (usable.status().code() == absl::StatusCode::kInvalidArgument) {
      return BadInputError(usable.status().message());
    }
    absl::StatusOr<client::PutSphereSetResult> stored;
    if (usable.ok() && usable->has_value()) {
      stored = client_.PutCertifiedCover(file->set, **usable);
    } else if (!mesh.empty()) {
      if (!usable.ok()) {
        std::cerr << "inscribe: " << where << ": " << usable.status().message()
                  << " (certifying it against " << object.mesh_path << " now)\n";
      }
      stored = client_.PutSphereSet(file->set, mesh);
    } else if (!usable.ok()) {
      return BadInputError(
          absl::StrCat("cover ", usable.status().message(), " (give the object's mesh)"));
    } else {
      return UsageError(absl::StrCat(
          "cover ", object.cover_path,
          " records no certificate (the files `inscribe generate --cover` writes do); give the "
          "object's mesh to certify it"));
    }
    if (!stored.ok()) return WithContext(object.cover_path, stored.status());
    return stored->sphere_set_key;
  }

 private:
  const client::Client& client_;
  std::map<std::string, std::string> meshes_;  // path -> key
};

// One answered frame of the log.
struct AnsweredFrame {
  std::int64_t frame = 0;
  client::SceneFrameResult result;
  double seconds = 0.0;  // round trip, as the client saw it
};

constexpr char kCsvHeader[] =
    "frame,a,b,distance,lower,upper,certified,sphere_a,sphere_b,ax,ay,az,bx,by,bz\n";

void AppendCsv(const AnsweredFrame& f, std::string* out) {
  for (const ScenePair& p : f.result.pairs) {
    const DistanceResult& r = p.result;
    absl::StrAppend(
        out, absl::StrFormat("%d,%d,%d,%.17g,%.17g,%.17g,%d,%d,%d,%.17g,%.17g,%.17g,%.17g,%.17g,"
                             "%.17g\n",
                             f.frame, p.a, p.b, r.distance, p.lower, p.upper, p.certified ? 1 : 0,
                             r.sphere_a, r.sphere_b, r.point_a.x(), r.point_a.y(), r.point_a.z(),
                             r.point_b.x(), r.point_b.y(), r.point_b.z()));
  }
}

// JSON numbers cannot be infinite: an unbounded upper is null.
nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json FrameJson(const AnsweredFrame& f) {
  nlohmann::json pairs = nlohmann::json::array();
  for (const ScenePair& p : f.result.pairs) {
    const DistanceResult& r = p.result;
    pairs.push_back({{"a", p.a},
                     {"b", p.b},
                     {"distance", Number(r.distance)},
                     {"lower", Number(p.lower)},
                     {"upper", Number(p.upper)},
                     {"certified", p.certified},
                     {"sphere_a", r.sphere_a},
                     {"sphere_b", r.sphere_b},
                     {"point_a", {r.point_a.x(), r.point_a.y(), r.point_a.z()}},
                     {"point_b", {r.point_b.x(), r.point_b.y(), r.point_b.z()}}});
  }
  return {{"frame", f.frame},
          {"candidate_pairs", f.result.candidate_pairs},
          {"close_pairs", f.result.close_pairs},
          {"truncated", f.result.truncated},
          {"server_seconds", f.result.server_seconds},
          {"pairs", std::move(pairs)}};
}

// The q-quantile (0..1) of `values`, nearest rank; 0 when empty.
double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

// One JSON line on stderr: the scene, the frames and pairs, and frame times.
void PrintSummary(const SceneCliOptions& options, const SceneFile& scene,
                  const client::SceneFrameResult& created,
                  const std::vector<AnsweredFrame>& frames) {
  std::vector<double> round_trips, server;
  std::int64_t pairs = 0, truncated = 0;
  for (const AnsweredFrame& f : frames) {
    round_trips.push_back(f.seconds);
    server.push_back(f.result.server_seconds);
    pairs += static_cast<std::int64_t>(f.result.pairs.size());
    truncated += f.result.truncated;
  }
  nlohmann::json j;
  j["scene"] = options.scene_path;
  j["objects"] = scene.objects.size();
  j["initial_pairs"] = created.pairs.size();
  j["frames"] = frames.size();
  j["pairs"] = pairs;
  j["truncated_frames"] = truncated;
  j["p50_ms"] = 1e3 * Quantile(round_trips, 0.5);
  j["p99_ms"] = 1e3 * Quantile(round_trips, 0.99);
  j["server_p50_ms"] = 1e3 * Quantile(server, 0.5);
  j["server_p99_ms"] = 1e3 * Quantile(server, 0.99);
  if (options.remote.enabled()) j["server"] = options.remote.server;
  std::cerr << j.dump() << "\n";
}

absl::Status RunScene(const SceneCliOptions& options) {
  absl::StatusOr<SceneFile> scene = ReadSceneFile(options.scene_path);
  if (!scene.ok()) return BadInputError(scene.status().message());
  if (options.threshold) {
    scene->query.threshold = *options.threshold;
    if (absl::Status s = CheckSceneQuery(scene->query); !s.ok()) {
      return UsageError(absl::StrCat("--threshold: ", s.message()));
    }
  }
  absl::flat_hash_set<SceneObjectId> ids;
  for (const SceneFileObject& object : scene->objects) ids.insert(object.object.id);
  absl::StatusOr<std::vector<PoseLogFrame>> log = ReadPoseLog(options.poses_path, ids);
  if (!log.ok()) return BadInputError(log.status().message());

  absl::StatusOr<std::unique_ptr<ServiceSession>> service = ServiceSession::Open(options.remote);
  if (!service.ok()) return service.status();
  const client::Client& client = (*service)->client();
  SceneUploads uploads(client);
  std::vector<client::SceneSessionObject> objects;
  for (std::size_t i = 0; i < scene->objects.size(); ++i) {
    const SceneFileObject& object = scene->objects[i];
    const std::string where =
        absl::StrCat(options.scene_path, ": objects[", i, "] (id ", object.object.id, ")");
    client::SceneSessionObject session_object;
    session_object.object = object.object;
    absl::StatusOr<std::string> spheres = uploads.Spheres(object);
    if (!spheres.ok()) return WithContext(where, spheres.status());
    session_object.sphere_set_key = *spheres;
    if (!object.cover_path.empty()) {
      absl::StatusOr<std::string> cover = uploads.Cover(object, where);
      if (!cover.ok()) return WithContext(where, cover.status());
      session_object.cover_key = *cover;
    }
    objects.push_back(std::move(session_object));
  }

  client::SceneSessionOptions session_options;
  session_options.volume = scene->volume;
  session_options.query = scene->query;
  session_options.ignored = scene->ignored;
  session_options.frame_timeout = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::duration<double>(options.remote.timeout_seconds));
  absl::StatusOr<client::SceneSession> session = client.OpenSceneSession(objects, session_options);
  if (!session.ok()) return WithContext(options.scene_path, session.status());

  std::vector<AnsweredFrame> frames;
  frames.reserve(log->size());
  for (const PoseLogFrame& frame : *log) {
    const auto start = std::chrono::steady_clock::now();
    absl::StatusOr<client::SceneFrameResult> result = session->Frame(frame.poses);
    if (!result.ok()) {
      return WithContext(absl::StrCat(options.poses_path, ": frame ", frame.frame),
                         result.status());
    }
    frames.push_back(AnsweredFrame{
        frame.frame, *std::move(result),
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()});
  }
  if (absl::Status closed = session->Close(); !closed.ok()) return closed;

  std::string text;
  if (options.json) {
    nlohmann::json j = nlohmann::json::array();
    for (const AnsweredFrame& f : frames) j.push_back(FrameJson(f));
    text = j.dump() + "\n";
  } else {
    text = kCsvHeader;
    for (const AnsweredFrame& f : frames) AppendCsv(f, &text);
  }
  if (!options.output_path.empty()) {
    if (absl::Status written = WriteFileAtomically(options.output_path, text); !written.ok()) {
      return BadInputError(written.message());
    }
    ReportWritten(options.output_path,
                  absl::StrCat(frames.size(), options.json ? " frames, JSON" : " frames, CSV"));
  } else {
    std::cout << text;
  }
  PrintSummary(options, *scene, session->created(), frames);
  return absl::OkStatus();
}

}  // namespace

void AddSceneCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<SceneCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "scene",
      "Replays a pose log over a scene of posed objects and prints, per frame, every pair of "
      "objects closer than the scene's threshold (CSV, or --json); a summary with frame times "
      "goes to stderr");
  cmd->add_option("SCENE", options->scene_path,
                  "Scene file (JSON: objects with sphere files or meshes, ignored pairs, "
                  "threshold; docs/formats.md)")
      ->required();
  cmd->add_option("POSES", options->poses_path,
                  "Pose log: CSV lines frame,id,qw,qx,qy,qz,tx,ty,tz, one per moved object per "
                  "frame, frames in order")
      ->required();
  cmd->add_option("--threshold", options->threshold,
                  "Report pairs closer than this (mesh units), instead of the scene file's");
  cmd->add_option("-o,--output", options->output_path, "Write the CSV (or JSON) here")
      ->check(WritableFile());
  cmd->add_flag("--json", options->json,
                "Print the frames as JSON (frame, counts, pairs with witnesses) instead of CSV");
  AddRemoteOptions(cmd, &options->remote, 60.0);
  SetExitStatusHelp(cmd, "a mesh cannot be used");
  cmd->callback([options, outcome] {
    *outcome = CommandOutcome{RunScene(*options), options->remote.server};
  });
}

}  // namespace inscribe::cli
