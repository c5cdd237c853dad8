// Writes deformation sequences of CGAL's demo meshes (scripts/make-deformations runs it):
// OUT/<model>-<kind>/frame_00.off (the reference, as read) to frame_<N>.off, each with the
// reference's triangles, coordinates written to 17 digits.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "deformation_sequences.h"
#include "inscribe/mesh/mesh_io.h"

namespace {

namespace fs = std::filesystem;
using inscribe::sequences::DeformationKind;

struct Sequence {
  std::string model;  // file stem in the data directory
  DeformationKind kind;
};

int Run(const std::string& data_dir, const std::string& out_dir, int frames,
        const std::vector<std::string>& specs) {
  std::vector<Sequence> sequences;
  for (const std::string& spec : specs) {
    const std::vector<std::string> parts = absl::StrSplit(spec, ':');
    if (parts.size() != 2) {
      std::cerr << "make_deformations: '" << spec << "' is not MODEL:KIND\n";
      return 64;
    }
    absl::StatusOr<DeformationKind> kind = inscribe::sequences::ParseDeformationKind(parts[1]);
    if (!kind.ok()) {
      std::cerr << "make_deformations: " << kind.status().message() << "\n";
      return 64;
    }
    sequences.push_back({parts[0], *kind});
  }
  for (const Sequence& sequence : sequences) {
    const std::string source = (fs::path(data_dir) / (sequence.model + ".off")).string();
    absl::StatusOr<inscribe::Mesh> mesh = inscribe::ReadMesh(source);
    if (!mesh.ok()) {
      std::cerr << "make_deformations: " << mesh.status().message() << "\n";
      return 2;
    }
    const std::string name =
        sequence.model + "-" + inscribe::sequences::DeformationKindName(sequence.kind);
    const fs::path dir = fs::path(out_dir) / name;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) {
      std::cerr << "make_deformations: cannot create " << dir << ": " << ec.message() << "\n";
      return 2;
    }
    std::vector<inscribe::Vertices> frames_out =
        inscribe::sequences::DeformationSequence(mesh->vertices, sequence.kind, frames);
    frames_out.insert(frames_out.begin(), mesh->vertices);
    for (std::size_t k = 0; k < frames_out.size(); ++k) {
      const inscribe::Mesh frame{frames_out[k], mesh->triangles};
      const std::string path = (dir / absl::StrFormat("frame_%02d.off", k)).string();
      if (absl::Status status = inscribe::WriteMesh(path, frame); !status.ok()) {
        std::cerr << "make_deformations: " << status.message() << "\n";
        return 2;
      }
    }
    std::cout << absl::StrFormat("%-18s %d frames (%d triangles) in %s\n", name, frames_out.size(),
                                 mesh->num_triangles(), dir.string());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Deformation sequences of the demo meshes for sphere-update tests"};
  std::string data_dir = "data";
  std::string out_dir = "data/deformations";
  int frames = 5;
  std::vector<std::string> specs = {"knot1:bend",    "elephant:bend",  "eight:twist",
                                    "fandisk:twist", "elephant:rigid", "eight:pinch",
                                    "knot1:pinch"};
  app.add_option("--data", data_dir, "Directory of the demo meshes (.off)")->capture_default_str();
  app.add_option("--out", out_dir, "Where the sequences go")->capture_default_str();
  app.add_option("--frames", frames, "Deformed frames per sequence (besides frame 0)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--sequences", specs, "MODEL:KIND, KIND one of bend, twist, rigid, pinch")
      ->delimiter(',')
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  return Run(data_dir, out_dir, frames, specs);
}
