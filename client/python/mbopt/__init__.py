"""The mbopt Python client (docs/python.md): submit and follow jobs on an
mbopt server, read their results, run one analysis, read series files.
The generated mbopt.v1 modules (the wire schema) sit beside this package in
the build tree (build/python)."""

from mbopt.analysis import evaluate
from mbopt.client import Client
from mbopt.errors import AccessDenied, BadInput, JobNotFound, MboptError, ServerUnreachable, StudyFileError
from mbopt.jobs import TERMINAL_STATES, DesignSetResults, FrontResults, JobResults, JobStatus
from mbopt.series import AnalysisSeries, Signal, read_series
from mbopt.study_file import read_study

__all__ = [
    "AccessDenied", "AnalysisSeries", "BadInput", "Client", "DesignSetResults", "FrontResults", "JobNotFound",
    "JobResults", "JobStatus",
    "MboptError", "ServerUnreachable", "Signal", "StudyFileError", "TERMINAL_STATES", "evaluate",
    "read_series", "read_study",
]
