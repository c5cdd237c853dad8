// The MJCF reader against MuJoCo's own (libmujoco 2.2.2, mj_loadXML + mj_kinematics): on models
// written by the tests, at random joint values, every body's and every geom's world pose from our
// model and kinematics equals MuJoCo's to 1e-9 (mesh geoms, which MuJoCo recentres on their
// centroid and principal axes, by their vertices in the world, to MuJoCo's float precision), and
// every model spherizes with no body skipped. Skipped when libmujoco is not installed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "inscribe/robot/kinematics.h"
#include "inscribe/robot/mjcf_robot.h"
#include "inscribe/robot/robot_file.h"
#include "inscribe/robot/self_collision.h"
#include "inscribe/robot/spherized_mjcf.h"
#include "inscribe/robot/urdf_spherize.h"
#include "mjcf_test_models.h"

#ifdef INSCRIBE_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

namespace inscribe::robot {
namespace {

using mjcf_models::FreshFolder;
using mjcf_models::WriteArm;
using mjcf_models::WriteHand;
using mjcf_models::WriteQuadruped;

#ifdef INSCRIBE_HAVE_MUJOCO

struct MujocoModel {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  std::string error;
  explicit MujocoModel(const std::string& path) {
    char message[1000] = "";
    model = mj_loadXML(path.c_str(), nullptr, message, sizeof(message));
    error = message;
    if (model != nullptr) data = mj_makeData(model);
  }
  ~MujocoModel() {
    if (data != nullptr) mj_deleteData(data);
    if (model != nullptr) mj_deleteModel(model);
  }
};

Eigen::Quaterniond Turn(double angle, const Vector3& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
}

// MuJoCo's qpos for our configuration q (hinge, slide: value + ref; ball: q_x q_y q_z; free: the
// body's pose moved by the slides, then turned as a ball).
std::vector<double> Qpos(const MjcfModel& model, const Kinematics& kinematics,
                         const std::vector<double>& q, const mjModel& m) {
  std::vector<double> qpos(static_cast<std::size_t>(m.nq));
  const auto value = [&](int coordinate) {
    return q[static_cast<std::size_t>(
        kinematics.variable(model.robot.joints[static_cast<std::size_t>(coordinate)].name))];
  };
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const MjcfJoint& joint = model.joints[j];
    double* at = qpos.data() + m.jnt_qposadr[j];
    const std::vector<int>& c = joint.coordinates;
    if (joint.type == MjcfJointType::kHinge || joint.type == MjcfJointType::kSlide) {
      at[0] = value(c[0]) + joint.ref;
      continue;
    }
    const int turns = joint.type == MjcfJointType::kBall ? 0 : 3;
    Eigen::Quaterniond turn = Turn(value(c[turns]), Vector3::UnitX()) *
                              Turn(value(c[turns + 1]), Vector3::UnitY()) *
                              Turn(value(c[turns + 2]), Vector3::UnitZ());
    if (joint.type == MjcfJointType::kFree) {
      const UrdfOrigin& pose = model.robot.joints[static_cast<std::size_t>(c[0])].origin;
      const Vector3 t(value(c[0]), value(c[1]), value(c[2]));
      const Vector3 position = pose.xyz + OriginRotation(pose) * t;
      for (int k = 0; k < 3; ++k) at[k] = position[k];
      turn = Eigen::Quaterniond(OriginRotation(pose)) * turn;
      at += 3;
    }
    at[0] = turn.w();
    at[1] = turn.x();
    at[2] = turn.y();
    at[3] = turn.z();
  }
  return qpos;
}

Eigen::Matrix3d Mat(const double* m) {
  Eigen::Matrix3d r;
  r << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];
  return r;
}

Vector3 Vec(const double* v) { return Vector3(v[0], v[1], v[2]); }

// Every body's and geom's pose at `configurations` random configurations, ours against MuJoCo's.
void ExpectSamePoses(const std::string& path, int configurations, bool with_meshes = false) {
  absl::StatusOr<MjcfModel> model = ReadMjcf(path);
  ASSERT_TRUE(model.ok()) << model.status();
  MujocoModel mujoco(path);
  ASSERT_NE(mujoco.model, nullptr) << mujoco.error;
  const mjModel& m = *mujoco.model;
  ASSERT_EQ(static_cast<int>(model->bodies.size()), m.nbody);
  ASSERT_EQ(static_cast<int>(model->joints.size()), m.njnt);
  ASSERT_EQ(static_cast<int>(model->geoms.size()), m.ngeom);
  for (int g = 0; g < m.ngeom; ++g) {
    const MjcfGeom& geom = model->geoms[static_cast<std::size_t>(g)];
    EXPECT_EQ(geom.body, m.geom_bodyid[g]) << "geom " << g;
    const char* name = mj_id2name(mujoco.model, mjOBJ_GEOM, g);
    EXPECT_EQ(geom.name, name == nullptr ? "" : name);
  }
  absl::StatusOr<Kinematics> kinematics = Kinematics::Create(model->robot);
  ASSERT_TRUE(kinematics.ok()) << kinematics.status();
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), shift(-0.3, 0.3);
  double worst_body = 0.0, worst_geom = 0.0, worst_vertex = 0.0;
  int primitives = 0, meshes = 0;
  for (int sample = 0; sample < configurations; ++sample) {
    std::vector<double> q;
    for (const JointVariable& variable : kinematics->variables()) {
      q.push_back(variable.type == UrdfJointType::kPrismatic ? shift(random) : angle(random));
    }
    const std::vector<double> qpos = Qpos(*model, *kinematics, q, m);
    std::copy(qpos.begin(), qpos.end(), mujoco.data->qpos);
    mj_kinematics(mujoco.model, mujoco.data);
    absl::StatusOr<std::vector<Eigen::Isometry3d>> poses = kinematics->LinkPoses(q);
    ASSERT_TRUE(poses.ok()) << poses.status();
    for (int b = 0; b < m.nbody; ++b) {
      const Eigen::Isometry3d& ours =
          (*poses)[static_cast<std::size_t>(model->bodies[static_cast<std::size_t>(b)].link)];
      worst_body =
          std::max({worst_body, (ours.translation() - Vec(mujoco.data->xpos + 3 * b)).norm(),
                    (ours.linear() - Mat(mujoco.data->xmat + 9 * b)).cwiseAbs().maxCoeff()});
    }
    for (int g = 0; g < m.ngeom; ++g) {
      const MjcfGeom& geom = model->geoms[static_cast<std::size_t>(g)];
      const Eigen::Isometry3d& link = (*poses)[static_cast<std::size_t>(
          model->bodies[static_cast<std::size_t>(geom.body)].link)];
      const Vector3 position = Vec(mujoco.data->geom_xpos + 3 * g);
      const Eigen::Matrix3d rotation = Mat(mujoco.data->geom_xmat + 9 * g);
      if (geom.type == MjcfGeomType::kMesh) {
        ++meshes;
        // Every MuJoCo vertex is one of ours, placed by our element transform and kinematics.
        UrdfSpherizeOptions options;
        absl::StatusOr<Mesh> mesh = ElementMeshInLinkFrame(geom.element, options);
        ASSERT_TRUE(mesh.ok()) << mesh.status();
        const int id = m.geom_dataid[g];
        for (int v = m.mesh_vertadr[id]; v < m.mesh_vertadr[id] + m.mesh_vertnum[id]; ++v) {
          const Vector3 world =
              position + rotation * Vector3(m.mesh_vert[3 * v], m.mesh_vert[3 * v + 1],
                                            m.mesh_vert[3 * v + 2]);
          double nearest = INFINITY;
          for (Eigen::Index i = 0; i < mesh->vertices.rows(); ++i) {
            nearest = std::min(nearest,
                               (link * Vector3(mesh->vertices.row(i).transpose()) - world).norm());
          }
          worst_vertex = std::max(worst_vertex, nearest);
        }
        continue;
      }
      if (geom.element.geometry.shape == UrdfShape::kUnsupported) continue;  // planes
      ++primitives;
      Eigen::Isometry3d element = Eigen::Isometry3d::Identity();
      element.translation() = geom.element.origin.xyz;
      element.linear() = OriginRotation(geom.element.origin);
      const Eigen::Isometry3d ours = link * element;
      worst_geom = std::max({worst_geom, (ours.translation() - position).norm(),
                             (ours.linear() - rotation).cwiseAbs().maxCoeff()});
      // Sizes: MuJoCo's half sizes against ours.
      const UrdfGeometry& shape = geom.element.geometry;
      const double* size = m.geom_size + 3 * g;
      switch (shape.shape) {
        case UrdfShape::kSphere:
          EXPECT_DOUBLE_EQ(size[0], shape.radius);
          break;
        case UrdfShape::kCapsule:
        case UrdfShape::kCylinder:
          EXPECT_DOUBLE_EQ(size[0], shape.radius);
          EXPECT_NEAR(size[1], 0.5 * shape.length, 1e-15);
          break;
        case UrdfShape::kBox:
          for (int k = 0; k < 3; ++k) EXPECT_NEAR(size[k], 0.5 * shape.size[k], 1e-15);
          break;
        case UrdfShape::kEllipsoid:
          for (int k = 0; k < 3; ++k) EXPECT_NEAR(size[k], shape.size[k], 1e-15);
          break;
        default:
          ADD_FAILURE() << "geom " << g;
      }
    }
  }
  EXPECT_LT(worst_body, 1e-9) << path;
  EXPECT_LT(worst_geom, 1e-9) << path;
  EXPECT_LT(worst_vertex, 1e-6) << path;  // MuJoCo keeps mesh vertices as floats
  EXPECT_GT(primitives, 0);
  EXPECT_EQ(meshes > 0, with_meshes);
  ::testing::Test::RecordProperty("worst_body", absl::StrCat(worst_body));
  ::testing::Test::RecordProperty("worst_geom", absl::StrCat(worst_geom));
  ::testing::Test::RecordProperty("worst_vertex", absl::StrCat(worst_vertex));
}

TEST(MjcfAgainstMujoco, ArmWithClassesIncludesAndEveryOrientationForm) {
  ExpectSamePoses(WriteArm(FreshFolder("mjcf_arm")), 50, true);
}

TEST(MjcfAgainstMujoco, EveryEulerSequenceIntrinsicAndExtrinsic) {
  for (const char* sequence : {"xyz", "XYZ", "zyx", "ZYX", "xYz", "ZxY", "yzy", "XzX"}) {
    SCOPED_TRACE(sequence);
    ExpectSamePoses(WriteArm(FreshFolder(absl::StrCat("mjcf_euler_", sequence)), sequence), 3,
                    true);
  }
}

TEST(MjcfAgainstMujoco, HandWithManySmallBodies) {
  ExpectSamePoses(WriteHand(FreshFolder("mjcf_hand"), 5, 4, 11), 30);
}

TEST(MjcfAgainstMujoco, QuadrupedWithFreeAndBallJoints) {
  ExpectSamePoses(WriteQuadruped(FreshFolder("mjcf_quadruped")), 50);
}

// The spherized model MuJoCo loads: the same bodies with the same masses and inertias (the
// solid geoms keep them, the spheres weigh nothing), one sphere geom per sphere with the
// solid's contact settings, the solid geoms no longer colliding, and every sphere where our
// kinematics puts it at random configurations.
void ExpectSpherizedModelLoads(const std::string& path) {
  absl::StatusOr<RobotFile> file = ReadRobotFile(path);
  ASSERT_TRUE(file.ok()) << file.status();
  UrdfSpherizeOptions options;
  options.max_spheres_per_link = 5;
  absl::StatusOr<RobotSpherizeResult> spherized = SpherizeRobot(file->robot(), options);
  ASSERT_TRUE(spherized.ok()) << spherized.status();
  const std::string out_folder = FreshFolder("mjcf_spherized_out");
  absl::StatusOr<std::string> text = SpherizedMjcf(*file, spherized->links, out_folder);
  ASSERT_TRUE(text.ok()) << text.status();
  const std::string out = out_folder + "/spherized.xml";
  std::ofstream(out) << *text;
  MujocoModel original(path), spheres(out);
  ASSERT_NE(spheres.model, nullptr) << spheres.error << "\n" << *text;
  const mjModel& a = *original.model;
  const mjModel& b = *spheres.model;
  ASSERT_EQ(a.nbody, b.nbody);
  for (int i = 0; i < a.nbody; ++i) {
    EXPECT_NEAR(a.body_mass[i], b.body_mass[i], 1e-12 * (1 + a.body_mass[i])) << i;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(a.body_inertia[3 * i + k], b.body_inertia[3 * i + k],
                  1e-12 * (1 + a.body_inertia[3 * i + k]));
    }
  }
  std::size_t total = 0;
  for (const LinkSpherizeResult& link : spherized->links) total += link.spheres.size();
  int sphere_geoms = 0;
  for (int g = 0; g < b.ngeom; ++g) {
    if (b.geom_group[g] == 3 && b.geom_type[g] == mjGEOM_SPHERE && b.geom_contype[g] == 1) {
      ++sphere_geoms;
    }
  }
  EXPECT_EQ(sphere_geoms, static_cast<int>(total));
  // Every other geom that collided before was a solid one and collides no more.
  EXPECT_EQ(b.ngeom, a.ngeom + static_cast<int>(total));
  absl::StatusOr<Kinematics> kinematics = Kinematics::Create(file->robot());
  ASSERT_TRUE(kinematics.ok());
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  double worst = 0.0;
  for (int sample = 0; sample < 10; ++sample) {
    std::vector<double> q;
    for (std::size_t v = 0; v < kinematics->variables().size(); ++v) q.push_back(angle(random));
    const std::vector<double> qpos = Qpos(*file->mjcf, *kinematics, q, b);
    std::copy(qpos.begin(), qpos.end(), spheres.data->qpos);
    mj_kinematics(spheres.model, spheres.data);
    const std::vector<Eigen::Isometry3d> poses = *kinematics->LinkPoses(q);
    std::vector<std::size_t> next(static_cast<std::size_t>(b.nbody), 0);
    for (int g = 0; g < b.ngeom; ++g) {
      if (b.geom_group[g] != 3 || b.geom_type[g] != mjGEOM_SPHERE || b.geom_contype[g] != 1) {
        continue;
      }
      const int body = b.geom_bodyid[g];
      const MjcfBody& mjcf_body = file->mjcf->bodies[static_cast<std::size_t>(body)];
      const LinkSpherizeResult& link = spherized->links[static_cast<std::size_t>(mjcf_body.link)];
      ASSERT_LT(next[static_cast<std::size_t>(body)], link.spheres.size());
      const Sphere& sphere = link.spheres[next[static_cast<std::size_t>(body)]++];
      const Vector3 ours = poses[static_cast<std::size_t>(mjcf_body.link)] * sphere.center;
      worst = std::max(worst, (ours - Vec(spheres.data->geom_xpos + 3 * g)).norm());
      EXPECT_EQ(b.geom_size[3 * g], sphere.radius);
    }
  }
  EXPECT_LT(worst, 1e-9);
}

TEST(MjcfAgainstMujoco, SpherizedModelsLoadWithTheSameMassesAndSpheresInPlace) {
  const std::string folder = FreshFolder("mjcf_spherized");
  ExpectSpherizedModelLoads(WriteArm(folder + "/arm"));
  ExpectSpherizedModelLoads(WriteQuadruped(folder + "/quadruped"));
}

// MuJoCo's own collision (mj_collision's contacts) on the spherized model, at every
// configuration the self-collision matrix sampled: each contact between two of our sphere
// geoms is a pair our interval at that configuration calls colliding, and so never a pair the
// matrix calls "Never". Returns the contacts seen.
int ExpectMujocoContactsAreOurs(const std::string& path, int samples) {
  absl::StatusOr<RobotFile> file = ReadRobotFile(path);
  EXPECT_TRUE(file.ok()) << file.status();
  if (!file.ok()) return 0;
  UrdfSpherizeOptions options;
  options.max_spheres_per_link = 6;
  absl::StatusOr<RobotSpherizeResult> spherized = SpherizeRobot(file->robot(), options);
  EXPECT_TRUE(spherized.ok()) << spherized.status();
  absl::StatusOr<Kinematics> kinematics = Kinematics::Create(file->robot());
  EXPECT_TRUE(kinematics.ok()) << kinematics.status();
  if (!spherized.ok() || !kinematics.ok()) return 0;
  const std::vector<LinkCollisionGeometry> geometry = LinkCollisionGeometries(spherized->links);
  SelfCollisionOptions collision;
  collision.samples = samples;
  collision.seed = 5;
  absl::StatusOr<SelfCollisionMatrix> matrix =
      ComputeSelfCollisionMatrix(*kinematics, geometry, collision);
  EXPECT_TRUE(matrix.ok()) << matrix.status();
  if (!matrix.ok()) return 0;
  EXPECT_TRUE(matrix->certified);
  std::map<std::pair<int, int>, CollisionPairClass> type;
  for (const LinkPairCollision& pair : matrix->pairs) type[{pair.link_a, pair.link_b}] = pair.type;

  const std::string out_folder = FreshFolder("mjcf_contacts_out");
  absl::StatusOr<std::string> text = SpherizedMjcf(*file, spherized->links, out_folder);
  EXPECT_TRUE(text.ok()) << text.status();
  const std::string out = out_folder + "/spherized.xml";
  std::ofstream(out) << *text;
  MujocoModel mujoco(out);
  EXPECT_NE(mujoco.model, nullptr) << mujoco.error;
  if (mujoco.model == nullptr) return 0;
  // Room for every contact (the default buffer of 100 drops the rest, with a warning).
  mujoco.model->nconmax = 20000;
  mj_deleteData(mujoco.data);
  mujoco.data = mj_makeData(mujoco.model);
  const mjModel& m = *mujoco.model;
  const auto ours = [&](int g) {
    return m.geom_group[g] == 3 && m.geom_type[g] == mjGEOM_SPHERE && m.geom_contype[g] != 0;
  };
  const auto link_of = [&](int g) {
    return file->mjcf->bodies[static_cast<std::size_t>(m.geom_bodyid[g])].link;
  };
  int contacts = 0;
  for (const std::vector<double>& q : SampleConfigurations(*kinematics, samples, collision.seed)) {
    const std::vector<double> qpos = Qpos(*file->mjcf, *kinematics, q, m);
    std::copy(qpos.begin(), qpos.end(), mujoco.data->qpos);
    mj_kinematics(mujoco.model, mujoco.data);
    mj_collision(mujoco.model, mujoco.data);
    absl::StatusOr<std::vector<LinkPairInterval>> intervals =
        LinkPairIntervals(*kinematics, geometry, q);
    EXPECT_TRUE(intervals.ok()) << intervals.status();
    if (!intervals.ok()) return contacts;
    std::map<std::pair<int, int>, bool> colliding;
    for (const LinkPairInterval& i : *intervals) colliding[{i.link_a, i.link_b}] = i.colliding();
    for (int c = 0; c < mujoco.data->ncon; ++c) {
      const mjContact& contact = mujoco.data->contact[c];
      if (!ours(contact.geom1) || !ours(contact.geom2)) continue;
      const int a = std::min(link_of(contact.geom1), link_of(contact.geom2));
      const int b = std::max(link_of(contact.geom1), link_of(contact.geom2));
      if (a == b) continue;
      ++contacts;
      const std::pair<int, int> key(a, b);
      EXPECT_TRUE(colliding[key]) << matrix->links[a] << " / " << matrix->links[b]
                                  << ": MuJoCo reports a contact at depth " << -contact.dist
                                  << " that our interval rules out";
      EXPECT_NE(type[key], CollisionPairClass::kNever)
          << matrix->links[a] << " / " << matrix->links[b] << " is Never, MuJoCo has a contact";
    }
  }
  return contacts;
}

TEST(MjcfAgainstMujoco, MujocoFindsNoContactForAPairOurMatrixCallsNever) {
  const std::string folder = FreshFolder("mjcf_contacts");
  int contacts = 0;
  for (const std::string& path : {WriteArm(folder + "/arm"), WriteHand(folder + "/hand", 3, 3, 9),
                                  WriteQuadruped(folder + "/quadruped")}) {
    SCOPED_TRACE(path);
    contacts += ExpectMujocoContactsAreOurs(path, 200);
  }
  std::printf("[ contacts ] %d MuJoCo contacts between sphere geoms, all ours\n", contacts);
  // The check met contacts (between pairs that are not Never), so it can fail.
  EXPECT_GT(contacts, 0);
  ::testing::Test::RecordProperty("mujoco_contacts", contacts);
}

#else

TEST(MjcfAgainstMujoco, NeedsLibmujoco) {
  GTEST_SKIP() << "libmujoco-dev is not installed: scripts/install-deps installs it";
}

#endif

// Every body with geometry is spherized; none is skipped; the bodies without solid geoms fall
// back to their visual ones with a warning.
TEST(MjcfSpherize, EveryBodyOfEveryTestModelIsSpherized) {
  const std::string folder = FreshFolder("mjcf_spherize");
  for (const std::string& path : {WriteArm(folder + "/arm"), WriteHand(folder + "/hand", 2, 3, 5),
                                  WriteQuadruped(folder + "/quadruped")}) {
    SCOPED_TRACE(path);
    absl::StatusOr<MjcfModel> model = ReadMjcf(path);
    ASSERT_TRUE(model.ok()) << model.status();
    UrdfSpherizeOptions options;
    options.max_spheres_per_link = 6;
    absl::StatusOr<RobotSpherizeResult> result = SpherizeRobot(model->robot, options);
    ASSERT_TRUE(result.ok()) << result.status();
    for (const MjcfBody& body : model->bodies) {
      const LinkSpherizeResult& link = result->links[static_cast<std::size_t>(body.link)];
      SCOPED_TRACE(body.name);
      EXPECT_NE(link.status, LinkStatus::kSkipped) << link.error;
      if (body.name != "world") {
        EXPECT_EQ(link.status, LinkStatus::kSpherized);
        EXPECT_TRUE(link.delta.has_value());
        EXPECT_LE(link.spheres.size(), 6u);
      }
    }
  }
}

}  // namespace
}  // namespace inscribe::robot
