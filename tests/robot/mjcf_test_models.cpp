#include "mjcf_test_models.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/robot/primitive_meshes.h"

namespace inscribe::robot::mjcf_models {
namespace {

namespace fs = std::filesystem;

// A closed, outward octahedron off the origin: its centroid and principal axes are not the
// file's, so MuJoCo's recentring of meshes is exercised.
Mesh Octahedron() {
  Mesh mesh;
  mesh.vertices.resize(6, 3);
  mesh.vertices << 0.06, 0, 0, -0.04, 0, 0, 0.01, 0.05, 0, 0.01, -0.03, 0, 0.01, 0, 0.07, 0.01, 0,
      -0.02;
  for (Eigen::Index i = 0; i < 6; ++i)
    mesh.vertices.row(i) += Eigen::RowVector3d(0.02, -0.01, 0.03);
  mesh.triangles.resize(8, 3);
  // Vertices: 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z; counter-clockwise seen from outside.
  mesh.triangles << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return mesh;
}

// Binary STL, the form MuJoCo 2.2 reads.
void WriteBinaryStl(const std::string& path, const Mesh& mesh) {
  std::ofstream out(path, std::ios::binary);
  char header[80] = {};
  out.write(header, 80);
  const auto count = static_cast<std::uint32_t>(mesh.triangles.rows());
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    float values[12] = {};
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 3; ++k) {
        values[3 + 3 * c + k] = static_cast<float>(mesh.vertices(mesh.triangles(t, c), k));
      }
    }
    out.write(reinterpret_cast<const char*>(values), sizeof(values));
    const std::uint16_t attributes = 0;
    out.write(reinterpret_cast<const char*>(&attributes), 2);
  }
}

// A box off the origin and turned, written with float-exact coordinates.
Mesh TurnedBox() {
  Mesh mesh = BoxMesh(Vector3(0.08, 0.05, 0.03));
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.4, Vector3(1, 2, 3).normalized()).toRotationMatrix();
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    const Vector3 v = turn * Vector3(mesh.vertices.row(i).transpose()) + Vector3(0.01, 0.02, -0.01);
    for (int k = 0; k < 3; ++k) mesh.vertices(i, k) = static_cast<float>(v[k]);
  }
  return mesh;
}

std::string G(double value) { return absl::StrFormat("%.17g", value); }

}  // namespace

std::string FreshFolder(const std::string& name) {
  const fs::path folder =
      fs::temp_directory_path() / absl::StrCat("inscribe_", name, "_", ::getpid());
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder.string();
}

void WriteText(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

std::string WriteArm(const std::string& folder, const std::string& eulerseq) {
  fs::create_directories(fs::path(folder) / "assets");
  if (!WriteMesh((fs::path(folder) / "assets" / "link.obj").string(), Octahedron()).ok()) {
    std::abort();
  }
  WriteBinaryStl((fs::path(folder) / "assets" / "shell.stl").string(), TurnedBox());
  WriteText(folder + "/arm_defaults.xml", R"(<mujoco>
  <default>
    <mesh scale="1 1 1"/>
    <default class="big"><mesh scale="1.5 0.75 2"/></default>
    <default class="arm">
      <joint axis="0 1 0" range="-90 90" damping="1"/>
      <geom type="capsule" size="0.03 0.1"/>
      <default class="visual">
        <geom contype="0" conaffinity="0" group="2" type="mesh"/>
      </default>
      <default class="collision">
        <geom group="3"/>
        <default class="pad"><geom type="box" size="0.01 0.02 0.03"/></default>
      </default>
    </default>
  </default>
</mujoco>
)");
  WriteText(folder + "/parts/arm_links.xml", R"(<mujoco>
  <body name="shoulder" pos="0 0 0.2" axisangle="0 0 1 30">
    <joint name="shoulder_pan" axis="0 0 1" pos="0.01 0 0" ref="10"/>
    <geom name="shoulder_capsule" class="collision" fromto="0 0 0 0 0 0.3" size="0.04"/>
    <geom name="shoulder_shell" class="visual" mesh="shell" euler="10 20 30"/>
    <body name="upper" pos="0 0.05 0.3" euler="20 -30 45">
      <joint name="shoulder_lift" pos="0 0 0.02" range="-45 120"/>
      <joint name="upper_slide" type="slide" axis="1 1 0" range="-0.1 0.1" ref="0.02"/>
      <geom name="upper_cylinder" class="collision" type="cylinder" fromto="0 0 0 0.2 0 -0.1" size="0.03"/>
      <geom name="upper_ellipsoid" class="collision" type="ellipsoid" size="0.03 0.04 0.05" xyaxes="1 1 0 -1 1 0.5"/>
      <geom name="upper_link" class="collision" type="mesh" mesh="link" quat="0.5 0.5 -0.5 0.5" pos="0.05 0 0"/>
      <body name="fore" pos="0.2 0 -0.1" zaxis="0 -1 0.2">
        <joint name="elbow" type="ball" pos="0 0 -0.01" range="0 60"/>
        <geom name="fore_box" class="collision" type="box" fromto="0 0 0 0 0.1 0.25" size="0.02"/>
        <geom name="fore_capsule" class="collision" size="0.02 0.1" zaxis="0 0 -1"/>
        <geom name="fore_ellipsoid" class="collision" type="ellipsoid" fromto="0 0 0 -0.1 0 0" size="0.015"/>
        <body name="hand" pos="0 0.1 0.25" quat="0 1 0 0">
          <joint name="wrist" limited="false"/>
          <geom name="pad" class="pad" pos="0.01 0 0" euler="0 90 0"/>
          <geom name="hand_visual" class="visual" type="sphere" size="0.02"/>
          <body name="camera_mount" pos="0 0 0.05" xyaxes="0 1 0 -1 0 0">
            <geom name="camera" class="visual" type="box" size="0.01 0.01 0.01"/>
          </body>
        </body>
      </body>
    </body>
  </body>
</mujoco>
)");
  const std::string path = folder + "/arm.xml";
  WriteText(path, absl::StrCat(R"(<mujoco model="arm">
  <compiler angle="degree" meshdir="assets" autolimits="true" eulerseq=")",
                               eulerseq, R"("/>
  <include file="arm_defaults.xml"/>
  <asset>
    <mesh file="link.obj" scale="1.5 1 0.8"/>
    <mesh name="shell" file="shell.stl" class="big"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="base" pos="0 0 0.1" quat="0.9 0.1 0.2 0.3" childclass="arm">
      <geom name="base_visual" class="visual" mesh="link"/>
      <geom name="base_collision" class="collision" type="cylinder" size="0.1 0.05"/>
      <include file="parts/arm_links.xml"/>
    </body>
  </worldbody>
</mujoco>
)"));
  return path;
}

std::string WriteHand(const std::string& folder, int fingers, int phalanges, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto numbers = [&](int n, double scale) {
    std::string text;
    for (int k = 0; k < n; ++k) absl::StrAppend(&text, k ? " " : "", G(scale * unit(random)));
    return text;
  };
  // One orientation form per body, in turn.
  const auto orientation = [&](int k) {
    switch (k % 5) {
      case 0:
        return absl::StrCat("quat=\"", numbers(4, 1.0), "\"");
      case 1:
        return absl::StrCat("axisangle=\"", numbers(3, 1.0), " ", G(3.0 * unit(random)), "\"");
      case 2:
        return absl::StrCat("euler=\"", numbers(3, 3.0), "\"");
      case 3:
        return absl::StrCat("xyaxes=\"", numbers(6, 1.0), "\"");
      default:
        return absl::StrCat("zaxis=\"", numbers(3, 1.0), "\"");
    }
  };
  std::string bodies;
  int count = 0;
  for (int f = 0; f < fingers; ++f) {
    std::string finger;
    for (int p = phalanges - 1; p >= 0; --p) {
      const std::string name = absl::StrCat("f", f, "_p", p);
      const std::string body_orientation = orientation(count++);
      const std::string skin_orientation = orientation(count++);
      const std::string pos = numbers(3, 0.03), anchor = numbers(3, 0.005), axis = numbers(3, 1.0),
                        tip = numbers(3, 0.02);
      finger = absl::StrCat(
          "<body name=\"", name, "\" pos=\"", pos, "\" ", body_orientation, ">\n",
          "  <joint name=\"", name, "_flex\" pos=\"", anchor, "\" axis=\"", axis,
          "\" range=\"-1.2 1.4\"/>\n", "  <geom name=\"", name,
          "_bone\" type=\"capsule\" fromto=\"0 0 0 ", tip, "\" size=\"0.006\"/>\n",
          "  <geom name=\"", name, "_skin\" type=\"ellipsoid\" size=\"0.01 0.006 0.004\" ",
          skin_orientation, " contype=\"0\" conaffinity=\"0\"/>\n", finger, "</body>\n");
    }
    bodies += finger;
  }
  const std::string path = folder + "/hand.xml";
  WriteText(path, absl::StrCat(R"(<mujoco model="hand">
  <compiler angle="radian" autolimits="true"/>
  <worldbody>
    <body name="palm" pos="0.1 0.2 0.3" euler="0.1 0.2 0.3">
      <geom name="palm_box" type="box" size="0.04 0.05 0.01"/>
)",
                               bodies, R"(    </body>
  </worldbody>
</mujoco>
)"));
  return path;
}

std::string WriteQuadruped(const std::string& folder) {
  std::string legs;
  const double sides[4][2] = {{1, 1}, {1, -1}, {-1, 1}, {-1, -1}};
  for (int l = 0; l < 4; ++l) {
    const std::string name = absl::StrCat("leg", l);
    const double x = 0.2 * sides[l][0], y = 0.1 * sides[l][1];
    legs += absl::StrCat(R"(      <body name=")", name, R"(_hip" pos=")", G(x), " ", G(y), R"( 0">
        <joint name=")",
                         name, R"(_abduct" axis="1 0 0" range="-30 30"/>
        <joint name=")",
                         name, R"(_swing" axis="0 1 0" pos="0 0 -0.01" range="-60 60"/>
        <geom name=")",
                         name, R"(_thigh" type="capsule" fromto="0 0 0 0 0 -0.15" size="0.02"/>
        <body name=")",
                         name, R"(_shin" pos="0 0 -0.15">
          <joint name=")",
                         name, R"(_knee" axis="0 1 0" range="-150 0" pos="0.005 0 0"/>
          <geom name=")",
                         name, R"(_calf" type="cylinder" fromto="0 0 0 0.02 0 -0.15" size="0.015"/>
          <body name=")",
                         name, R"(_foot" pos="0.02 0 -0.15">
            <joint name=")",
                         name, R"(_ankle" type="ball" pos="0 0 0.01"/>
            <geom name=")",
                         name, R"(_toe" type="sphere" size="0.02" pos="0.01 0 0"/>
          </body>
        </body>
      </body>
)");
  }
  const std::string path = folder + "/quadruped.xml";
  WriteText(path, absl::StrCat(R"(<mujoco model="quadruped">
  <compiler autolimits="true"/>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="torso" pos="0 0 0.4" euler="0 0 15">
      <freejoint name="root"/>
      <geom name="torso_shell" type="ellipsoid" size="0.25 0.12 0.06"/>
      <geom name="torso_box" type="box" size="0.2 0.1 0.05" pos="0 0 0.02" axisangle="1 0 0 5"/>
)",
                               legs, R"(    </body>
  </worldbody>
</mujoco>
)"));
  return path;
}

}  // namespace inscribe::robot::mjcf_models
