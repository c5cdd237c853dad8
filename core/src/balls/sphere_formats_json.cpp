// inscribe's own sphere file, through nlohmann::json (confined to this file). Doubles are
// written by nlohmann's Grisu2-based formatter, which emits a decimal that parses back to the
// same double, and read with strtod-exact parsing: the round trip is bit-exact.
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>

#include "absl/strings/str_cat.h"
#include "balls/sphere_formats.h"

namespace inscribe::internal {
namespace {

// Keeps the order of params and stats as written.
using Json = nlohmann::ordered_json;

constexpr absl::string_view kFormatName = "inscribe.spheres";
constexpr std::int64_t kVersion = 1;

absl::Status Invalid(std::string message) { return absl::InvalidArgumentError(std::move(message)); }

// `value` in JSON notation, cut short for an error message.
std::string Shown(const Json& value) {
  return QuoteToken(value.dump(-1, ' ', true, Json::error_handler_t::replace));
}

// nlohmann's messages start with "[json.exception.parse_error.101] "; the rest names the line
// and column. Bytes outside printable ASCII are escaped so the message stays clean text.
std::string CleanParseMessage(absl::string_view what) {
  if (!what.empty() && what[0] == '[') {
    const std::size_t close = what.find("] ");
    if (close != absl::string_view::npos) what.remove_prefix(close + 2);
  }
  std::string out;
  for (const char ch : what) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7f) {
      out.push_back(ch);
    } else {
      out += QuoteToken(absl::string_view(&ch, 1)).substr(1, 4);
    }
  }
  return out;
}

absl::Status ReadNamedValues(const Json& doc, const char* key, NamedValues* out) {
  const auto it = doc.find(key);
  if (it == doc.end()) return absl::OkStatus();
  if (!it->is_object()) {
    return Invalid(absl::StrCat("\"", key, "\" is ", it->type_name(), ", expected an object"));
  }
  for (const auto& [name, value] : it->items()) {
    switch (value.type()) {
      case Json::value_t::boolean:
        out->emplace_back(name, value.get<bool>());
        break;
      case Json::value_t::number_integer:
        out->emplace_back(name, value.get<std::int64_t>());
        break;
      case Json::value_t::number_unsigned: {
        const std::uint64_t u = value.get<std::uint64_t>();
        if (u > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
          return Invalid(absl::StrCat(key, " ", QuoteToken(name), ": ", u,
                                      " does not fit in a signed 64-bit integer"));
        }
        out->emplace_back(name, static_cast<std::int64_t>(u));
        break;
      }
      case Json::value_t::number_float:
        out->emplace_back(name, value.get<double>());
        break;
      case Json::value_t::string:
        out->emplace_back(name, value.get<std::string>());
        break;
      default:
        return Invalid(absl::StrCat(key, " ", QuoteToken(name), ": ", value.type_name(),
                                    " values are not supported (version 1 holds booleans, "
                                    "numbers and strings)"));
    }
  }
  return absl::OkStatus();
}

// `row` must be an array of exactly four numbers; what = "sphere 3" or "contact 3", and
// `shape` describes the expected array for the message.
absl::Status ReadFourNumbers(const Json& row, const std::string& what, const char* shape,
                             double out[4]) {
  if (!row.is_array() || row.size() != 4) {
    return Invalid(absl::StrCat(
        what, ": expected an array of 4 numbers ", shape, ", found ",
        row.is_array() ? absl::StrCat(row.size(), " elements") : std::string(row.type_name())));
  }
  for (std::size_t k = 0; k < 4; ++k) {
    if (!row[k].is_number()) {
      return Invalid(absl::StrCat(what, ": element ", k, " is ", row[k].type_name(), " ",
                                  Shown(row[k]), ", expected a number"));
    }
    out[k] = row[k].get<double>();
  }
  return absl::OkStatus();
}

absl::Status ReadSpheres(const Json& doc, SphereSet* set) {
  const auto it = doc.find("spheres");
  if (it == doc.end()) return Invalid("missing \"spheres\"");
  if (!it->is_array()) {
    return Invalid(absl::StrCat("\"spheres\" is ", it->type_name(), ", expected an array"));
  }
  for (std::size_t i = 0; i < it->size(); ++i) {
    double xyzr[4];
    if (absl::Status status =
            ReadFourNumbers((*it)[i], absl::StrCat("sphere ", i), "[x, y, z, r]", xyzr);
        !status.ok()) {
      return status;
    }
    Sphere sphere;
    sphere.center = Vector3(xyzr[0], xyzr[1], xyzr[2]);
    sphere.radius = xyzr[3];
    if (absl::Status status = CheckSphere(sphere, i); !status.ok()) return status;
    set->spheres.push_back(sphere);
  }
  return absl::OkStatus();
}

absl::Status ReadContacts(const Json& doc, SphereSet* set) {
  const auto it = doc.find("contacts");
  if (it == doc.end()) return absl::OkStatus();
  if (!it->is_array()) {
    return Invalid(absl::StrCat("\"contacts\" is ", it->type_name(), ", expected an array"));
  }
  // An empty array means no contacts, like a missing key.
  if (it->empty()) return absl::OkStatus();
  if (it->size() != set->spheres.size()) {
    return Invalid(absl::StrCat(it->size(), " contacts for ", set->spheres.size(),
                                " spheres (need one per sphere, or none)"));
  }
  for (std::size_t i = 0; i < it->size(); ++i) {
    const Json& row = (*it)[i];
    const std::string what = absl::StrCat("contact ", i);
    double values[4];
    if (absl::Status status = ReadFourNumbers(row, what, "[triangle, b0, b1, b2]", values);
        !status.ok()) {
      return status;
    }
    if (!row[0].is_number_integer()) {
      return Invalid(absl::StrCat(what, ": triangle ", Shown(row[0]), " is not an integer"));
    }
    if (row[0].is_number_unsigned() ? row[0].get<std::uint64_t>() > 0x7fffffffu
                                    : row[0].get<std::int64_t>() > 0x7fffffff) {
      return Invalid(absl::StrCat(what, ": triangle ", Shown(row[0]),
                                  " is beyond the largest triangle index (2^31 - 1)"));
    }
    const std::int64_t triangle = row[0].get<std::int64_t>();
    if (triangle < 0) {
      return Invalid(absl::StrCat(what, ": triangle ", triangle, " is negative"));
    }
    SurfaceContact contact;
    contact.triangle = static_cast<std::int32_t>(triangle);
    contact.barycentric = Vector3(values[1], values[2], values[3]);
    if (!contact.barycentric.allFinite()) {
      return Invalid(absl::StrCat(what, ": barycentric weights are not finite"));
    }
    set->contacts.push_back(contact);
  }
  return absl::OkStatus();
}

absl::Status ReadProtrusions(const Json& doc, SphereFile* file) {
  const auto it = doc.find("protrusions");
  if (it == doc.end()) return absl::OkStatus();
  if (!it->is_array()) {
    return Invalid(absl::StrCat("\"protrusions\" is ", it->type_name(), ", expected an array"));
  }
  if (it->empty()) return absl::OkStatus();
  if (it->size() != file->set.spheres.size()) {
    return Invalid(absl::StrCat(it->size(), " protrusions for ", file->set.spheres.size(),
                                " spheres (need one per sphere, or none)"));
  }
  for (std::size_t i = 0; i < it->size(); ++i) {
    const Json& value = (*it)[i];
    if (!value.is_number()) {
      return Invalid(absl::StrCat("protrusion ", i, ": ", Shown(value), " is not a number"));
    }
    const double p = value.get<double>();
    if (!std::isfinite(p)) {
      return Invalid(absl::StrCat("protrusion ", i, ": ", Shown(value), " is not finite"));
    }
    file->protrusions.push_back(p);
  }
  return absl::OkStatus();
}

absl::StatusOr<Json> NamedValuesToJson(const NamedValues& values, const char* key) {
  Json object = Json::object();
  std::set<absl::string_view> seen;
  for (const auto& [name, value] : values) {
    if (!seen.insert(name).second) {
      return Invalid(absl::StrCat(key, " ", QuoteToken(name), ": the name appears twice"));
    }
    if (const double* d = std::get_if<double>(&value); d != nullptr && !std::isfinite(*d)) {
      return Invalid(absl::StrCat(key, " ", QuoteToken(name), ": ", FormatDouble(*d),
                                  " is not finite (JSON has no such numbers)"));
    }
    std::visit([&object, &name = name](const auto& v) { object[name] = v; }, value);
    try {
      // dump() refuses strings that are not UTF-8; find out here, where the value has a name.
      (void)object[name].dump();
      (void)Json(name).dump();
    } catch (const Json::exception&) {
      return Invalid(absl::StrCat(key, " ", QuoteToken(name), ": not valid UTF-8"));
    }
  }
  return object;
}

}  // namespace

absl::StatusOr<SphereFile> ParseJsonSphereFile(absl::string_view bytes) {
  Json doc;
  try {
    doc = Json::parse(bytes.begin(), bytes.end());
  } catch (const Json::exception& e) {
    return Invalid(absl::StrCat("not valid JSON: ", CleanParseMessage(e.what())));
  }
  if (!doc.is_object()) {
    return Invalid(absl::StrCat("the top level is ", doc.type_name(), ", expected an object"));
  }
  const auto format = doc.find("format");
  if (format == doc.end()) {
    return Invalid(absl::StrCat("missing \"format\" (expected \"", kFormatName, "\")"));
  }
  if (!format->is_string() || format->get<std::string>() != kFormatName) {
    return Invalid(
        absl::StrCat("\"format\" is ", Shown(*format), ", expected \"", kFormatName, "\""));
  }
  const auto version = doc.find("version");
  if (version == doc.end()) return Invalid("missing \"version\"");
  if (!version->is_number_integer()) {
    return Invalid(absl::StrCat("\"version\" is ", Shown(*version), ", expected an integer"));
  }
  if (version->is_number_unsigned() ? version->get<std::uint64_t>() != kVersion
                                    : version->get<std::int64_t>() != kVersion) {
    return Invalid(absl::StrCat("unsupported version ", version->dump(),
                                " (this reader knows version ", kVersion, ")"));
  }
  SphereFile file;
  if (const auto hash = doc.find("mesh_sha256"); hash != doc.end()) {
    if (!hash->is_string()) {
      return Invalid(absl::StrCat("\"mesh_sha256\" is ", hash->type_name(), ", expected a string"));
    }
    file.mesh_sha256 = hash->get<std::string>();
    if (absl::Status status = CheckMeshSha256(file.mesh_sha256); !status.ok()) return status;
  }
  if (absl::Status status = ReadNamedValues(doc, "params", &file.params); !status.ok()) {
    return status;
  }
  if (absl::Status status = ReadSpheres(doc, &file.set); !status.ok()) return status;
  if (absl::Status status = ReadContacts(doc, &file.set); !status.ok()) return status;
  if (absl::Status status = ReadProtrusions(doc, &file); !status.ok()) return status;
  if (absl::Status status = ReadNamedValues(doc, "stats", &file.stats); !status.ok()) {
    return status;
  }
  return file;
}

absl::StatusOr<std::string> FormatJsonSphereFile(const SphereFile& file) {
  absl::StatusOr<Json> params = NamedValuesToJson(file.params, "params");
  if (!params.ok()) return params.status();
  absl::StatusOr<Json> stats = NamedValuesToJson(file.stats, "stats");
  if (!stats.ok()) return stats.status();
  // One sphere (and one contact) per line: readable, diffable, and still a single document.
  const auto dump = [](const Json& value) { return value.dump(); };
  std::string out;
  try {
    absl::StrAppend(&out, "{\n  \"format\": \"", kFormatName, "\",\n  \"version\": ", kVersion,
                    ",\n");
    if (!file.mesh_sha256.empty()) {
      absl::StrAppend(&out, "  \"mesh_sha256\": ", dump(file.mesh_sha256), ",\n");
    }
    absl::StrAppend(&out, "  \"params\": ", dump(*params), ",\n  \"spheres\": [");
    const SphereSet& set = file.set;
    for (std::size_t i = 0; i < set.spheres.size(); ++i) {
      const Sphere& s = set.spheres[i];
      absl::StrAppend(&out, i == 0 ? "\n    " : ",\n    ",
                      dump(Json::array({s.center.x(), s.center.y(), s.center.z(), s.radius})));
    }
    absl::StrAppend(&out, set.spheres.empty() ? "],\n" : "\n  ],\n");
    if (set.has_contacts()) {
      absl::StrAppend(&out, "  \"contacts\": [");
      for (std::size_t i = 0; i < set.contacts.size(); ++i) {
        const SurfaceContact& c = set.contacts[i];
        absl::StrAppend(&out, i == 0 ? "\n    " : ",\n    ",
                        dump(Json::array({c.triangle, c.barycentric.x(), c.barycentric.y(),
                                          c.barycentric.z()})));
      }
      absl::StrAppend(&out, "\n  ],\n");
    }
    if (!file.protrusions.empty()) {
      absl::StrAppend(&out, "  \"protrusions\": ", dump(Json(file.protrusions)), ",\n");
    }
    absl::StrAppend(&out, "  \"stats\": ", dump(*stats), "\n}\n");
  } catch (const Json::exception& e) {
    // dump() refuses strings that are not UTF-8 (type_error 316).
    return Invalid(absl::StrCat("cannot write JSON: ", CleanParseMessage(e.what())));
  }
  return out;
}

}  // namespace inscribe::internal
