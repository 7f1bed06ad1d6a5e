#include "client/study_file.h"

#include "spec/io/study_io.h"

namespace mbopt::client {

absl::StatusOr<v1::Study> ReadStudyForSubmission(const std::string& path) {
  return spec::io::ReadStudyProto(path);
}

}  // namespace mbopt::client
