// `mbopt-server init-tls DIR` makes everything a secure installation needs
// (a CA, the server's certificate, a worker certificate, tokens and the
// server's token table) and `mbopt-server add-token` adds a token to a
// table (docs/server.md, "Security").
#pragma once

namespace mbopt::server_main {

// argv holds the arguments after the subcommand's name. Return the process's
// exit status: 0 done, 1 a file could not be made, 2 a bad command line.
int RunInitTlsCommand(int argc, char** argv);
int RunAddTokenCommand(int argc, char** argv);

}  // namespace mbopt::server_main
