"""One analysis (`eval`): runs `mbopt-worker eval STUDY --json` and returns
its JSON object parsed (docs/workers.md): status, objective, worst
constraint, per-output summaries, counters; with `series_out`, the worker
also writes every series to that file (read it with read_series).
"""

import json
import os
import shutil
import subprocess

from mbopt.errors import BadInput, MboptError


def find_worker_program(program=None):
    """`program`, else $MBOPT_WORKER_BIN (as `mbopt run` and `mbopt report`
    read it), else mbopt-worker on PATH, else the one of the build tree this
    package was built in (build/python beside build/worker/main)."""
    program = program or os.environ.get("MBOPT_WORKER_BIN") or shutil.which("mbopt-worker")
    if program:
        return program
    built = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                         "worker", "main", "mbopt-worker")
    if os.access(built, os.X_OK):
        return built
    raise MboptError("cannot find mbopt-worker: put it on PATH, set MBOPT_WORKER_BIN, or pass worker_program=")


def evaluate(study_path, overrides=None, series_out=None, drivers=None, worker_program=None):
    """Analyses the study at its initial design, with `overrides` ({name: value}:
    a design variable, scaled, or a scene parameter in its own unit) applied.
    An analysis that fails is an outcome, not an error: the result's
    "status" is "failed" and "failure_reason" says why. Bad input (an
    unreadable study, an unknown name in `overrides`) raises BadInput with the
    worker's message."""
    argv = [find_worker_program(worker_program), "eval", os.fspath(study_path), "--json"]
    for name, value in (overrides or {}).items():
        argv += ["--set", f"{name}={value!r}"]
    if series_out is not None:
        argv += ["--series-out", os.fspath(series_out)]
    if drivers is not None:
        argv += ["--drivers", os.fspath(drivers)]
    done = subprocess.run(argv, capture_output=True, text=True, check=False)
    if done.returncode == 2:
        raise BadInput(done.stderr.strip().splitlines()[0] if done.stderr.strip() else "mbopt-worker eval: bad input")
    if done.returncode not in (0, 1):
        raise MboptError(f"mbopt-worker eval exited with status {done.returncode}: {done.stderr.strip()}")
    try:
        return json.loads(done.stdout)
    except ValueError:
        raise MboptError(f"mbopt-worker eval printed no JSON object: {done.stdout[:200]!r}") from None
