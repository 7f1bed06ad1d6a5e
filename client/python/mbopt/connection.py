"""Where the client finds its server and how it connects, as the `mbopt` CLI
does (docs/cli.md, "Choosing the server" and "Connecting securely").

Each setting comes from its argument, else from the environment:

  address          MBOPT_SERVER           default 127.0.0.1:50051
  tls_ca           MBOPT_TLS_CA           CA certificate (PEM); TLS when set
  tls_cert/_key    MBOPT_TLS_CERT / _KEY  a client certificate and its key
  tls_server_name  MBOPT_TLS_SERVER_NAME  the name the server's certificate
                                          must carry (through a tunnel)
  token_file       MBOPT_TOKEN_FILE       the token, in a file
                   MBOPT_TOKEN            the token itself

A token is taken from a file or the environment only, never as an argument
of its own: a notebook's cells and a script's text are read by others.
"""

import os
import stat

import grpc

from mbopt.errors import AccessDenied, BadInput, JobNotFound, MboptError, ServerUnreachable

DEFAULT_SERVER_ADDRESS = "127.0.0.1:50051"

# Results of big studies (many cycles) exceed gRPC's 4 MB default.
MAX_RECEIVE_BYTES = 256 * 1024 * 1024

# A guard against a hung server on the short calls, not a pacing mechanism.
UNARY_DEADLINE_S = 30.0


def resolve_address(address=None):
    if address:
        return address
    return os.environ.get("MBOPT_SERVER") or DEFAULT_SERVER_ADDRESS


def _setting(value, option, variable):
    """The argument's value, else the variable's, and which of them it was."""
    if value:
        return value, option
    env = os.environ.get(variable)
    if env:
        return env, variable
    return None, None


def _read(path, source):
    try:
        with open(path, "rb") as f:
            return f.read()
    except OSError as e:
        raise BadInput(f"{source}: cannot open file {path}: {e.strerror}") from None


def check_secret_file_mode(path, what):
    """Refuses a file holding a secret that other users may read or write,
    as the CLI does (common/private_file.h): any access by others, writing
    by the group, or reading by a group that is not this process's own."""
    try:
        info = os.stat(path)
    except OSError as e:
        raise BadInput(f"cannot read {what} {path}: {e.strerror}") from None
    mode = stat.S_IMODE(info.st_mode)
    unsafe = mode & (stat.S_IRWXO | stat.S_IWGRP | stat.S_IXGRP)
    if mode & stat.S_IRGRP and info.st_gid != os.getegid():
        unsafe |= stat.S_IRGRP
    if not unsafe:
        return
    others = bool(unsafe & stat.S_IRWXO)
    readable = bool(unsafe & (stat.S_IROTH | stat.S_IRGRP))
    writable = bool(unsafe & (stat.S_IWOTH | stat.S_IWGRP))
    how = " and ".join(w for w, on in (("readable", readable), ("writable", writable)) if on)
    how = f"{how} by " if how else "usable by "
    who = "every user of this machine" if others else "its group"
    raise BadInput(
        f"{what} {path} has mode {mode:04o}: {how}{who}; it holds a secret and is refused. "
        f"Run `chmod 600 {path}` (or `chmod 640` with the file's group the one this program runs as)")


class Security:
    """The TLS and token settings as read, files loaded."""

    def __init__(self, tls_ca=None, tls_cert=None, tls_key=None, tls_server_name=None, token_file=None):
        ca_file, ca_source = _setting(tls_ca, "tls_ca", "MBOPT_TLS_CA")
        cert_file, cert_source = _setting(tls_cert, "tls_cert", "MBOPT_TLS_CERT")
        key_file, key_source = _setting(tls_key, "tls_key", "MBOPT_TLS_KEY")
        self.server_name, name_source = _setting(tls_server_name, "tls_server_name", "MBOPT_TLS_SERVER_NAME")
        self.tls = ca_file is not None
        self.ca_pem = _read(ca_file, ca_source) if self.tls else None
        self.cert_pem = self.key_pem = None
        if (cert_file is None) != (key_file is None):
            if cert_file is None:
                raise BadInput(f"{key_source} is set but no certificate: a client certificate needs "
                               "tls_cert (or MBOPT_TLS_CERT) too")
            raise BadInput(f"{cert_source} is set but no key: a client certificate needs "
                           "tls_key (or MBOPT_TLS_KEY) too")
        if cert_file is not None:
            if not self.tls:
                raise BadInput(f"{cert_source} is set but not tls_ca (or MBOPT_TLS_CA): "
                               "a client certificate is only used over TLS")
            self.cert_pem = _read(cert_file, cert_source)
            self.key_pem = _read(key_file, key_source)
            check_secret_file_mode(key_file, f"{key_source}: the client key")
        if self.server_name and not self.tls:
            raise BadInput(f"{name_source} is set but not tls_ca (or MBOPT_TLS_CA)")
        self.token = None
        token_path, token_source = _setting(token_file, "token_file", "MBOPT_TOKEN_FILE")
        if token_path is not None:
            text = _read(token_path, token_source)
            check_secret_file_mode(token_path, f"{token_source}: the token file")
            self.token = text.decode("utf-8", "replace").strip()
            source = f"{token_source} {token_path}"
            if not self.token:
                raise BadInput(f"{source}: the file is empty")
        elif os.environ.get("MBOPT_TOKEN"):
            self.token = os.environ["MBOPT_TOKEN"].strip()
            source = "MBOPT_TOKEN"
        if self.token and any(ord(c) < 0x21 or ord(c) == 0x7F for c in self.token):
            # A header value cannot hold control characters; a token never does.
            raise BadInput(f"{source}: the token holds a space or control character; "
                           "it is one word such as mbopt_3f2a...")

    def metadata(self):
        """What every call sends: the token as a bearer header, if any."""
        return (("authorization", "Bearer " + self.token),) if self.token else ()


def create_channel(address, security):
    options = [("grpc.max_receive_message_length", MAX_RECEIVE_BYTES)]
    if not security.tls:
        return grpc.insecure_channel(address, options=options)
    if security.server_name:
        options.append(("grpc.ssl_target_name_override", security.server_name))
    credentials = grpc.ssl_channel_credentials(root_certificates=security.ca_pem,
                                               private_key=security.key_pem,
                                               certificate_chain=security.cert_pem)
    return grpc.secure_channel(address, credentials, options=options)


def rpc_error(error, address):
    """A failed call as the exception a user should read, worded as the
    CLI's messages (client/connection.cc)."""
    code = error.code()
    detail = error.details() or ""
    if code == grpc.StatusCode.UNAVAILABLE:
        return ServerUnreachable(f"cannot reach server at {address}: {detail}")
    if code in (grpc.StatusCode.UNAUTHENTICATED, grpc.StatusCode.PERMISSION_DENIED):
        return AccessDenied(f"server at {address} refused: {detail}")
    if code == grpc.StatusCode.DEADLINE_EXCEEDED:
        return ServerUnreachable(f"server at {address} did not answer in time: {detail}")
    if code == grpc.StatusCode.NOT_FOUND:
        return JobNotFound(detail or f"not found on server {address}")
    if code in (grpc.StatusCode.INVALID_ARGUMENT, grpc.StatusCode.FAILED_PRECONDITION,
                grpc.StatusCode.OUT_OF_RANGE, grpc.StatusCode.ALREADY_EXISTS):
        return BadInput(detail)
    if code == grpc.StatusCode.CANCELLED:
        return MboptError(f"call cancelled: {detail}")
    return ServerUnreachable(f"server at {address} returned an error ({code.value[0]}): {detail}")
