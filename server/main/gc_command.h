// `mbopt-server gc`: prunes finished jobs from a job database, optionally
// exporting them first to another database (docs/server.md, "Pruning").
#pragma once

namespace mbopt::server_main {

// argv holds the arguments after "gc". Returns the process's exit status
// (0 done, 1 the database could not be used, 2 a bad command line).
int RunGcCommand(int argc, char** argv);

}  // namespace mbopt::server_main
