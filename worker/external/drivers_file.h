// The worker's drivers file (proto/mbopt/v1/drivers.proto, text format): the
// external simulation codes this worker offers, read and validated into
// DriverDeclarations. The only part of worker/external that sees Protobuf.
//
// Every problem of the file is reported at once, each naming the file, the
// line and column, the field (e.g. "driver[1].file[0]") and what was
// expected. Checked here: names (safe in file names, unique), the command
// (found and executable; a bare program name is looked up in PATH now and
// kept as an absolute path), every declared path (relative, no "..", inside
// the driver's directory with links resolved), the template's placeholders
// (each a declared parameter), the results file and format, the time limit
// and the exit codes.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "worker/external/driver.h"

namespace mbopt::external {

absl::StatusOr<std::vector<DriverDeclaration>> LoadDriversFile(const std::string& path);

// The same from text in memory; `source_name` names it in messages and its
// directory is where relative driver directories start.
absl::StatusOr<std::vector<DriverDeclaration>> ParseDriversText(const std::string& text,
                                                                const std::string& source_name);

}  // namespace mbopt::external
