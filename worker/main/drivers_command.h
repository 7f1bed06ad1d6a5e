// `mbopt-worker drivers FILE`: reads a drivers file as `serve --drivers FILE`
// would and lists what it declares, or every problem it has. `mbopt run
// --drivers FILE` calls it before starting anything, so a wrong file is
// reported at once instead of in a worker's log.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace mbopt::worker {

// Exit 0 when the file is good (its drivers on `out`), 2 otherwise (the
// problems on `err`).
int RunDrivers(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
const char* DriversUsage();

}  // namespace mbopt::worker
