// inscribe.SphereSet, sphere files (read_spheres, write_spheres), and the report types that
// come with sets: QualityReport and CoverCertificate.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstddef>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "absl/strings/str_cat.h"
#include "bindings.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/generation/sphere_file_record.h"
#include "inscribe/mesh/mesh_io.h"
#include "sphere_set.h"
#include "status_errors.h"

namespace inscribe::python {

// (N, 4) views of spheres need this layout: x, y, z, r with no padding.
static_assert(sizeof(Sphere) == 4 * sizeof(double) &&
                  offsetof(Sphere, radius) == 3 * sizeof(double),
              "Sphere must be four packed doubles");

std::vector<Sphere> SpheresOf(py::handle spheres) {
  if (py::isinstance<PySphereSet>(spheres)) return spheres.cast<const PySphereSet&>().set.spheres;
  py::array_t<double> array = RequireMatrix<double>(spheres, 4, "spheres");
  std::vector<Sphere> result(static_cast<std::size_t>(array.shape(0)));
  if (!result.empty())
    std::memcpy(static_cast<void*>(result.data()), array.data(), array.size() * sizeof(double));
  OkOrRaise(CheckSpheres(result));
  return result;
}

namespace {

py::dict DictOf(const NamedValues& values) {
  py::dict dict;
  for (const auto& [name, value] : values) {
    dict[py::str(name)] = std::visit([](const auto& v) { return py::cast(v); }, value);
  }
  return dict;
}

NamedValues NamedValuesOf(const py::dict& dict, const char* what) {
  NamedValues values;
  for (const auto& [key, value] : dict) {
    const std::string name = py::str(key);
    if (py::isinstance<py::bool_>(value)) {
      values.emplace_back(name, value.cast<bool>());
    } else if (py::isinstance<py::int_>(value)) {
      values.emplace_back(name, value.cast<std::int64_t>());
    } else if (py::isinstance<py::float_>(value)) {
      values.emplace_back(name, value.cast<double>());
    } else if (py::isinstance<py::str>(value)) {
      values.emplace_back(name, value.cast<std::string>());
    } else {
      throw py::type_error(absl::StrCat(what, "['", name,
                                        "'] must be a bool, int, float or str, got ",
                                        std::string(py::str(py::type::of(value)))));
    }
  }
  return values;
}

PySphereSet MakeSphereSet(py::handle spheres, py::handle contact_triangles,
                          py::handle contact_barycentrics, std::string kind,
                          std::string mesh_sha256) {
  PySphereSet result;
  result.set.spheres = SpheresOf(spheres);
  if (contact_triangles.is_none() != contact_barycentrics.is_none()) {
    throw py::value_error(
        "contact_triangles and contact_barycentrics go together: both or neither");
  }
  if (!contact_triangles.is_none()) {
    py::array_t<std::int32_t> triangles = RequireMatrix<std::int32_t>(
        py::module_::import("numpy").attr("reshape")(contact_triangles, py::make_tuple(-1, 1)), 1,
        "contact_triangles");
    py::array_t<double> weights =
        RequireMatrix<double>(contact_barycentrics, 3, "contact_barycentrics");
    if (triangles.shape(0) != static_cast<py::ssize_t>(result.set.size()) ||
        weights.shape(0) != static_cast<py::ssize_t>(result.set.size())) {
      throw py::value_error(absl::StrCat("contacts must have one row per sphere (",
                                         result.set.size(), "), got ", triangles.shape(0),
                                         " triangles and ", weights.shape(0), " barycentrics"));
    }
    result.set.contacts.resize(result.set.size());
    for (std::size_t i = 0; i < result.set.size(); ++i) {
      result.set.contacts[i].triangle = triangles.at(i, 0);
      result.set.contacts[i].barycentric =
          Vector3(weights.at(i, 0), weights.at(i, 1), weights.at(i, 2));
    }
  }
  if (!kind.empty() && kind != "internal" && kind != "dilated" && kind != "cover") {
    throw py::value_error("kind must be 'internal', 'dilated', 'cover' or '', got '" + kind + "'");
  }
  result.kind = std::move(kind);
  result.mesh_sha256 = std::move(mesh_sha256);
  return result;
}

SphereFile FileOf(const PySphereSet& spheres) {
  SphereFile file;
  file.set = spheres.set;
  file.mesh_sha256 = spheres.mesh_sha256;
  file.params = spheres.params;
  file.stats = spheres.stats;
  if (spheres.certificate) file.protrusions = spheres.certificate->protrusions;
  return file;
}

// The (N, 4) read-only view of an inscribe.SphereSet's spheres, keeping it alive.
py::array SpheresView(py::handle self) {
  const SphereSet& set = self.cast<const PySphereSet&>().set;
  const double* data = set.spheres.empty() ? nullptr : set.spheres.front().center.data();
  return ReadOnlyView(data, static_cast<py::ssize_t>(set.size()), 4, sizeof(Sphere), self);
}

std::optional<SphereFileFormat> FormatOf(const std::optional<std::string>& name) {
  if (!name) return std::nullopt;
  return ValueOrRaise(ParseSphereFileFormat(*name));
}

}  // namespace

void BindSpheres(py::module_& m) {
  py::class_<PySphereSet, std::shared_ptr<PySphereSet>>(
      m, "SphereSet",
      "Spheres approximating a solid, in the mesh's units and frame. `.spheres` is an (N, 4) "
      "float64 array of [x, y, z, r] rows (read-only view, no copy); the set itself is "
      "array-like: np.asarray(set) is that array, and len, shape, indexing and iteration "
      "are the array's.")
      .def(py::init(&MakeSphereSet), py::arg("spheres"), py::arg("contact_triangles") = py::none(),
           py::arg("contact_barycentrics") = py::none(), py::kw_only(), py::arg("kind") = "",
           py::arg("mesh_sha256") = "",
           "SphereSet(spheres, contact_triangles=None, contact_barycentrics=None, *, kind='', "
           "mesh_sha256=''): spheres a C-contiguous (N, 4) float64 array [x, y, z, r] (finite, "
           "r > 0, else ValueError naming the sphere); contacts, for deformation, an (N,) int32 "
           "array of triangle indices and an (N, 3) float64 array of barycentric weights.")
      .def_property_readonly(
          "spheres", &SpheresView,
          "(N, 4) float64 [x, y, z, r], mesh units and frame; a read-only view of the set")
      .def(
          "__array__",
          [](py::handle self, py::object dtype, py::object copy) {
            py::object array = SpheresView(self);
            if (!dtype.is_none())
              array = py::module_::import("numpy").attr("asarray")(array, dtype);
            if (!copy.is_none() && copy.cast<bool>()) array = array.attr("copy")();
            return array;
          },
          py::arg("dtype") = py::none(), py::arg("copy") = py::none(),
          "numpy's protocol: the (N, 4) view (.spheres), converted to `dtype` or copied when "
          "asked")
      .def_property_readonly(
          "shape", [](const PySphereSet& s) { return py::make_tuple(s.set.size(), 4); },
          "(N, 4), as .spheres")
      .def(
          "__getitem__",
          [](py::handle self, py::handle index) { return py::object(SpheresView(self)[index]); },
          "indexes .spheres: set[i] is row i [x, y, z, r], set[:, 3] the radii")
      .def(
          "__iter__", [](py::handle self) { return SpheresView(self).attr("__iter__")(); },
          "the rows of .spheres")
      .def(
          "to_mesh",
          [](const PySphereSet& s, int subdivision) {
            SphereFile file;
            file.set.spheres = s.set.spheres;
            SphereFileWriteOptions options;
            options.obj_subdivision = subdivision;
            absl::StatusOr<Mesh> mesh;
            {
              py::gil_scoped_release release;
              absl::StatusOr<std::string> obj =
                  FormatSphereFile(file, SphereFileFormat::kObj, options);
              mesh = obj.ok() ? ParseMesh(*obj, "obj") : absl::StatusOr<Mesh>(obj.status());
            }
            return std::make_shared<Mesh>(ValueOrRaise(std::move(mesh)));
          },
          py::arg("subdivision") = 1,
          "The spheres as one triangle mesh for viewing (an inscribe.Mesh: .vertices, .faces, "
          "so trimesh.Trimesh(m.vertices, m.faces)): each sphere an icosphere with its vertices "
          "on the sphere, subdivided `subdivision` times (0..5: 10 * 4^s + 2 vertices each), "
          "as write_spheres writes .obj. The spheres overlap: it is not a closed solid.")
      .def_property_readonly(
          "centers",
          [](py::object self) {
            const SphereSet& set = self.cast<const PySphereSet&>().set;
            const double* data = set.spheres.empty() ? nullptr : set.spheres.front().center.data();
            return ReadOnlyView(data, static_cast<py::ssize_t>(set.size()), 3, sizeof(Sphere),
                                self);
          },
          "(N, 3) float64 view of the centres")
      .def_property_readonly(
          "radii",
          [](py::object self) {
            const SphereSet& set = self.cast<const PySphereSet&>().set;
            const double* data = set.spheres.empty() ? nullptr : &set.spheres.front().radius;
            py::array view(py::dtype::of<double>(), {static_cast<py::ssize_t>(set.size())},
                           {static_cast<py::ssize_t>(sizeof(Sphere))}, data, self);
            view.attr("flags").attr("writeable") = false;
            return view;
          },
          "(N,) float64 view of the radii")
      .def_property_readonly(
          "contact_triangles",
          [](const PySphereSet& s) -> py::object {
            if (!s.set.has_contacts()) return py::none();
            py::array_t<std::int32_t> result(static_cast<py::ssize_t>(s.set.size()));
            for (std::size_t i = 0; i < s.set.size(); ++i) {
              result.mutable_at(i) = s.set.contacts[i].triangle;
            }
            return result;
          },
          "(N,) int32 triangle of each sphere's contact point, or None")
      .def_property_readonly(
          "contact_barycentrics",
          [](const PySphereSet& s) -> py::object {
            if (!s.set.has_contacts()) return py::none();
            py::array_t<double> result({static_cast<py::ssize_t>(s.set.size()), py::ssize_t{3}});
            for (std::size_t i = 0; i < s.set.size(); ++i) {
              for (int k = 0; k < 3; ++k)
                result.mutable_at(i, k) = s.set.contacts[i].barycentric[k];
            }
            return result;
          },
          "(N, 3) float64 barycentric weights of each contact point, or None")
      .def_readonly("kind", &PySphereSet::kind, "'internal', 'dilated', 'cover', or ''")
      .def_readwrite("mesh_sha256", &PySphereSet::mesh_sha256)
      .def_property(
          "params", [](const PySphereSet& s) { return DictOf(s.params); },
          [](PySphereSet& s, const py::dict& d) { s.params = NamedValuesOf(d, "params"); },
          "generation settings, as a sphere file's 'params' (a copy; assign to change)")
      .def_property(
          "stats", [](const PySphereSet& s) { return DictOf(s.stats); },
          [](PySphereSet& s, const py::dict& d) { s.stats = NamedValuesOf(d, "stats"); },
          "figures about the run, as a sphere file's 'stats' (a copy; assign to change)")
      .def_readonly("quality", &PySphereSet::quality, "QualityReport, when evaluated")
      .def_readonly("certificate", &PySphereSet::certificate, "CoverCertificate of a cover")
      .def_property_readonly(
          "reference_index",
          [](const PySphereSet& s) -> py::object {
            if (s.reference_index.empty()) return py::none();
            return py::array_t<std::int32_t>(static_cast<py::ssize_t>(s.reference_index.size()),
                                             s.reference_index.data());
          },
          "for Deformer.update's sets: (N,) int32 index of each sphere in the reference set")
      .def("__len__", [](const PySphereSet& s) { return s.set.size(); })
      .def("__repr__", [](const PySphereSet& s) {
        return absl::StrCat("SphereSet(", s.set.size(), " spheres",
                            s.kind.empty() ? "" : ", kind='" + s.kind + "'",
                            s.set.has_contacts() ? ", with contacts" : "", ")");
      });

  m.def(
      "read_spheres",
      [](py::handle path_like, std::optional<std::string> format, int sph_level,
         const std::string& yaml_link) {
        const std::string path = PathOf(path_like, "path");
        SphereFileReadOptions options;
        options.format = FormatOf(format);
        options.sph_level = sph_level;
        options.yaml_link = yaml_link;
        absl::StatusOr<SphereFile> file;
        {
          py::gil_scoped_release release;
          file = ReadSphereFile(path, options);
        }
        SphereFile read = ValueOrRaise(std::move(file));
        auto result = std::make_shared<PySphereSet>();
        // The kind and a cover's certificate as the file records them; the certificate only
        // when it names these spheres and certifies them (UsableCoverCertificate), as the CLI
        // takes a cover file.
        result->kind = RecordedKind(read);
        absl::StatusOr<std::optional<CoverCertificate>> certificate =
            UsableCoverCertificate(read, path, "");
        if (certificate.ok()) result->certificate = *std::move(certificate);
        result->set = std::move(read.set);
        result->mesh_sha256 = std::move(read.mesh_sha256);
        result->params = std::move(read.params);
        result->stats = std::move(read.stats);
        return result;
      },
      py::arg("path"), py::kw_only(), py::arg("format") = py::none(), py::arg("sph_level") = -1,
      py::arg("yaml_link") = "",
      "Reads a sphere file: inscribe JSON, spheretree .sph, CSV x,y,z,r or cuRobo YAML, by "
      "extension unless `format` ('json', 'sph', 'csv', 'yaml') is given. sph_level: the tree "
      "level of a .sph (-1 = leaves); yaml_link: the link of a YAML with several. JSON keeps "
      "mesh_sha256, params and stats. FileNotFoundError, or ValueError naming the line.");

  m.def(
      "write_spheres",
      [](const PySphereSet& spheres, py::handle path_like, std::optional<std::string> format,
         bool csv_header, int obj_subdivision, const std::string& yaml_link_name) {
        const std::string path = PathOf(path_like, "path");
        SphereFileWriteOptions options;
        options.format = FormatOf(format);
        options.csv_header = csv_header;
        options.obj_subdivision = obj_subdivision;
        options.yaml_link_name = yaml_link_name;
        const SphereFile file = FileOf(spheres);
        absl::Status status;
        {
          py::gil_scoped_release release;
          status = WriteSphereFile(path, file, options);
        }
        OkOrRaise(status);
      },
      py::arg("sphere_set"), py::arg("path"), py::kw_only(), py::arg("format") = py::none(),
      py::arg("csv_header") = true, py::arg("obj_subdivision") = 1,
      py::arg("yaml_link_name") = "mesh",
      "Writes `sphere_set` to `path` atomically, in the format of its extension (.json, .sph, "
      ".csv, .obj, .yaml/.yml) unless `format` is given. JSON keeps doubles bit-exact with "
      "contacts, mesh_sha256, params and stats; the others keep spheres only.");

  m.def(
      "format_curobo_yaml",
      [](const std::vector<std::pair<std::string, py::object>>& links, const std::string& comment) {
        std::vector<LinkSpheres> converted;
        for (const auto& [link, spheres] : links) converted.push_back({link, SpheresOf(spheres)});
        return ValueOrRaise(FormatCuroboYaml(converted, comment));
      },
      py::arg("links"), py::arg("comment") = "inscribe spheres",
      "cuRobo's collision_spheres YAML text for [(link_name, spheres), ...] in that order; "
      "spheres a SphereSet or an (N, 4) float64 array in the link's frame.");

  m.def(
      "parse_curobo_yaml",
      [](const std::string& text) {
        std::vector<LinkSpheres> links = ValueOrRaise(ParseCuroboYaml(text));
        py::dict result;
        for (LinkSpheres& link : links) {
          auto set = std::make_shared<PySphereSet>();
          set->set.spheres = std::move(link.spheres);
          result[py::str(link.link)] = set;
        }
        return result;
      },
      py::arg("text"),
      "Every link of a cuRobo YAML's collision_spheres, in file order: {link: SphereSet}; "
      "placeholder spheres (radius <= 0) dropped. ValueError with the YAML line.");
}

}  // namespace inscribe::python
