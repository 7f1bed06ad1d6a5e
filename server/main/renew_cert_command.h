// `mbopt-server renew-cert DIR`: a new server certificate from the CA of an
// init-tls directory, for the same host names unless told others, so that
// clients and workers keep their ca.pem and tokens (docs/server.md,
// "Security").
#pragma once

namespace mbopt::server_main {

// argv holds the arguments after "renew-cert". Returns the exit status: 0
// done, 1 a file could not be read or written, 2 a bad command line.
int RunRenewCertCommand(int argc, char** argv);

}  // namespace mbopt::server_main
