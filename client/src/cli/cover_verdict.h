// A cover certificate's verdict in words, as evaluate --certify and distance print it. What a
// cover file records of its certificate is core's (inscribe/generation/sphere_file_record.h).
#pragma once

#include <string>

#include "inscribe/cover/cover_certificate.h"

namespace inscribe::cli {

// "certified: ...", or "NOT certified: " and the point of the solid in no sphere (its depth and
// gap), or the unsettled cells when no such point was found.
std::string CoverVerdict(const CoverCertificate& certificate);

}  // namespace inscribe::cli
