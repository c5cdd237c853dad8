#include "inscribe/robot/spherized_mjcf.h"

#include <tinyxml2.h>

#include <filesystem>
#include <map>
#include <set>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "inscribe/robot/spherized_urdf.h"
#include "mjcf_document.h"

namespace inscribe::robot {
namespace {

namespace fs = std::filesystem;
using mjcf::Node;

// The attributes that decide contacts, copied from a solid geom to its spheres.
const std::set<std::string>& ContactAttributes() {
  static const std::set<std::string> names = {"contype", "conaffinity", "condim", "friction",
                                              "solref",  "solimp",      "solmix", "priority",
                                              "margin",  "gap"};
  return names;
}

std::string Triple(const Vector3& v) {
  return absl::StrCat(ShortestDecimal(v.x()), " ", ShortestDecimal(v.y()), " ",
                      ShortestDecimal(v.z()));
}

class Writer {
 public:
  Writer(const RobotFile& file, const std::vector<LinkSpherizeResult>& links,
         const std::string& output_directory)
      : model_(*file.mjcf), links_(links), output_(output_directory) {
    geoms_of_body_.resize(model_.bodies.size());
    for (std::size_t g = 0; g < model_.geoms.size(); ++g) {
      geoms_of_body_[static_cast<std::size_t>(model_.geoms[g].body)].push_back(static_cast<int>(g));
    }
  }

  std::string Write(const Node& root, const std::string& folder) {
    folder_ = folder;
    tinyxml2::XMLDocument document;
    tinyxml2::XMLElement* mujoco = document.NewElement("mujoco");
    document.InsertEndChild(mujoco);
    for (const auto& [name, value] : root.attributes)
      mujoco->SetAttribute(name.c_str(), value.c_str());
    bool has_compiler = false;
    for (const Node& child : root.children) has_compiler = has_compiler || child.name == "compiler";
    if (!has_compiler) {
      tinyxml2::XMLElement* compiler = mujoco->InsertNewChildElement("compiler");
      compiler->SetAttribute("meshdir", Relative("").c_str());
      compiler->SetAttribute("texturedir", Relative("").c_str());
    }
    for (const Node& child : root.children) Copy(child, mujoco, /*body=*/-1);
    tinyxml2::XMLPrinter printer;
    document.Print(&printer);
    return printer.CStr();
  }

 private:
  // The model folder's `path` as seen from the output's folder.
  std::string Relative(const std::string& path) const {
    const fs::path absolute = (fs::path(folder_) / path).lexically_normal();
    std::string relative = absolute.lexically_relative(output_).string();
    if (relative.empty()) relative = ".";
    return relative + "/";
  }

  // `node` copied under `parent`; `body` is the index of the body it is in (-1 outside
  // <worldbody>), bodies counted as the reader does (depth first).
  tinyxml2::XMLElement* Copy(const Node& node, tinyxml2::XMLElement* parent, int body) {
    tinyxml2::XMLElement* element = parent->InsertNewChildElement(node.name.c_str());
    for (const auto& [name, value] : node.attributes) {
      if (node.name == "compiler" &&
          (name == "meshdir" || name == "texturedir" || name == "assetdir")) {
        continue;
      }
      element->SetAttribute(name.c_str(), value.c_str());
    }
    if (node.name == "compiler") {
      // assetdir set both when meshdir and texturedir are not given.
      const std::string* asset = node.Attribute("assetdir");
      const std::string* mesh = node.Attribute("meshdir");
      const std::string* texture = node.Attribute("texturedir");
      element->SetAttribute("meshdir", Relative(mesh ? *mesh : asset ? *asset : "").c_str());
      element->SetAttribute("texturedir", Relative(texture ? *texture
                                                   : asset ? *asset
                                                           : "")
                                              .c_str());
    }
    int inner = body;
    if (node.name == "worldbody") inner = 0;
    if (node.name == "body") inner = ++bodies_seen_;
    int geom_in_body = 0;
    for (const Node& child : node.children) {
      tinyxml2::XMLElement* copied = Copy(child, element, inner);
      if (child.name != "geom" || inner < 0) continue;
      const int g =
          geoms_of_body_[static_cast<std::size_t>(inner)][static_cast<std::size_t>(geom_in_body++)];
      const MjcfGeom& geom = model_.geoms[static_cast<std::size_t>(g)];
      const MjcfBody& mjcf_body = model_.bodies[static_cast<std::size_t>(inner)];
      const LinkSpherizeResult& link = links_[static_cast<std::size_t>(mjcf_body.link)];
      if (!geom.solid || link.status != LinkStatus::kSpherized) continue;
      copied->SetAttribute("contype", 0);
      copied->SetAttribute("conaffinity", 0);
      if (!spheres_written_.insert(inner).second) continue;
      for (const Sphere& sphere : link.spheres) {
        tinyxml2::XMLElement* s = element->GetDocument()->NewElement("geom");
        element->InsertAfterChild(copied, s);
        copied = s;
        if (geom.class_name != "main") s->SetAttribute("class", geom.class_name.c_str());
        for (const auto& [name, value] : child.attributes) {
          if (ContactAttributes().count(name)) s->SetAttribute(name.c_str(), value.c_str());
        }
        if (geom.contype == 0 && geom.conaffinity == 0) {
          // Visual geoms standing in for a missing solid: their spheres collide all the same.
          s->SetAttribute("contype", 1);
          s->SetAttribute("conaffinity", 1);
        }
        s->SetAttribute("type", "sphere");
        s->SetAttribute("size", ShortestDecimal(sphere.radius).c_str());
        s->SetAttribute("pos", Triple(sphere.center).c_str());
        s->SetAttribute("group", 3);
        s->SetAttribute("mass", 0);
      }
    }
    return element;
  }

  const MjcfModel& model_;
  const std::vector<LinkSpherizeResult>& links_;
  fs::path output_;
  std::string folder_;
  std::vector<std::vector<int>> geoms_of_body_;
  std::set<int> spheres_written_;
  int bodies_seen_ = 0;
};

}  // namespace

absl::StatusOr<std::string> SpherizedMjcf(const RobotFile& file,
                                          const std::vector<LinkSpherizeResult>& links,
                                          const std::string& output_directory) {
  if (!file.mjcf) return absl::InvalidArgumentError(file.path + " is not an MJCF model");
  if (links.size() != file.robot().links.size()) {
    return absl::InvalidArgumentError(absl::StrCat(links.size(), " link results for a model of ",
                                                   file.robot().links.size(), " links"));
  }
  absl::StatusOr<mjcf::Document> document = mjcf::ReadDocument(file.bytes, file.path);
  if (!document.ok()) return document.status();
  Writer writer(file, links, fs::absolute(output_directory).lexically_normal().string());
  return writer.Write(document->root, document->folder);
}

}  // namespace inscribe::robot
