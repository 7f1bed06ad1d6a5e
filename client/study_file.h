// Reading a study file for submission: the text-format study with its scene
// inlined, as the server expects it. Errors name file:line:column and field.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "mbopt/v1/study.pb.h"

namespace mbopt::client {

absl::StatusOr<v1::Study> ReadStudyForSubmission(const std::string& path);

}  // namespace mbopt::client
