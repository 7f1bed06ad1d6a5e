"""The exceptions of the mbopt Python client.

Each carries one message a user can act on, worded as the `mbopt` CLI words
the same failure (docs/cli.md, "Exit codes"), and the CLI's exit code for it
in `exit_code`.
"""


class MboptError(Exception):
    """Any failure of the client; `str(error)` is the message."""

    exit_code = 1


class BadInput(MboptError):
    """Invalid input: a study file that does not parse (file:line:column and
    field), a request the server refused as invalid (its message), a token
    file others can read, an unknown option of `eval`."""

    exit_code = 2


class StudyFileError(BadInput):
    """A study or scene file that cannot be read or parsed."""


class JobNotFound(BadInput):
    """No such job on the server (another user's job is answered so too)."""


class ServerUnreachable(MboptError):
    """The server cannot be reached, did not answer in time, or failed
    during the call."""

    exit_code = 3


class AccessDenied(MboptError):
    """The server refused the call: no token, or one it does not accept."""

    exit_code = 5
