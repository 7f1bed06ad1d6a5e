"""Jobs as plain Python values: a job's status (from the server's
JobSummary) and its results (from GetJobResponse), with the fields and names
of `mbopt results --json` (client/job_format.cc), so that a script and the
CLI read the same thing. Values are in the study's units as the server
reports them; a value that is not finite (no objective yet) is None, as the
CLI's JSON writes null.
"""

import math
from dataclasses import dataclass, field

from mbopt.v1 import service_pb2

_STATE_NAMES = {
    service_pb2.JOB_STATE_QUEUED: "queued",
    service_pb2.JOB_STATE_RUNNING: "running",
    service_pb2.JOB_STATE_CONVERGED: "converged",
    service_pb2.JOB_STATE_COMPLETED: "completed",
    service_pb2.JOB_STATE_MAX_CYCLES: "max_cycles",
    service_pb2.JOB_STATE_STALLED: "stalled",
    service_pb2.JOB_STATE_FAILED: "failed",
    service_pb2.JOB_STATE_CANCELLED: "cancelled",
    service_pb2.JOB_STATE_INTERRUPTED: "interrupted",
}

# The job will not change by itself (client/job_format.cc, IsTerminal).
TERMINAL_STATES = frozenset(("converged", "completed", "max_cycles", "stalled", "failed", "cancelled", "interrupted"))


def state_name(state):
    """"converged", "running", ... for a JobState value."""
    return _STATE_NAMES.get(state, "unknown")


def _number(value):
    return value if math.isfinite(value) else None


@dataclass
class JobStatus:
    """What `mbopt status` shows: the server's JobSummary."""

    job_id: str
    study: str
    status: str
    cycles: int
    max_cycles: int
    analyses: int
    objective: float
    objective_unit: str
    max_violation: float
    design: dict  # variable name -> value of the parameter it sets (its unit)
    design_units: dict
    wall_seconds: float
    message: str
    waiting_for: str
    owner: str
    failed_analyses: dict  # failure kind -> count

    @property
    def finished(self):
        return self.status in TERMINAL_STATES

    @classmethod
    def from_proto(cls, s):
        names = list(s.design_names)
        return cls(
            job_id=s.job_id, study=s.study_name, status=state_name(s.state), cycles=s.cycles,
            max_cycles=s.max_cycles, analyses=s.analyses, objective=_number(s.objective),
            objective_unit=s.objective_unit, max_violation=_number(s.max_violation),
            design={n: _number(v) for n, v in zip(names, s.design)},
            design_units={n: u for n, u in zip(names, s.design_units)},
            wall_seconds=s.wall_seconds, message=s.message, waiting_for=s.waiting_for, owner=s.owner,
            failed_analyses=dict(sorted(s.failed_analyses_by_kind.items())))


def _history_entry(r):
    return {
        "cycle": r.cycle,
        "attempts": r.attempt + 1,
        "restoration": r.restoration,
        "objective": _number(r.objective_trial),
        "max_violation": _number(r.max_violation_trial),
        "max_approximation_error": _number(r.max_approximation_error),
        "optimality_residual": _number(r.optimality_residual),
        "lp_feasible": r.lp_feasible,
        "analyses": r.analyses_total,
        "move_limits": [_number(v) for v in r.move_limits],
        "move_limits_next": [_number(v) for v in r.move_limits_next],
        "design": [_number(v) for v in r.x_trial_physical],
        "x_scaled": [_number(v) for v in r.x_trial_scaled],
    }


@dataclass
class JobResults:
    """What `mbopt results --json` prints, field for field; `history` has
    one entry per accepted cycle, `cycles_all` every LP solve (rejected
    attempts too) as mbopt.v1.CycleRecord messages."""

    job_id: str
    study: str
    status: str
    cycles: int
    analyses: int
    objective: float
    objective_unit: str
    max_violation: float
    design: dict
    design_scaled: dict
    design_parameters: dict
    design_units: dict
    wall_seconds: float
    message: str
    failed_analyses: dict
    history: list
    waiting_for: str = ""
    cycles_all: list = field(default_factory=list, repr=False)

    @classmethod
    def from_proto(cls, job):
        s = job.summary
        variables = {v.name: v for v in job.study.variables} if job.HasField("study") else {}
        names = list(s.design_names)
        design = {n: _number(v) for n, v in zip(names, s.design)}
        scaled, parameters = {}, {}
        for n, v in zip(names, s.design):
            if n in variables:
                scale = variables[n].scale or 1.0
                scaled[n] = _number(v / scale)
        for n in names:
            if n in variables:
                parameters[n] = variables[n].parameter
        return cls(
            job_id=s.job_id, study=s.study_name, status=state_name(s.state), cycles=s.cycles,
            analyses=s.analyses, objective=_number(s.objective), objective_unit=s.objective_unit,
            max_violation=_number(s.max_violation), design=design, design_scaled=scaled,
            design_parameters=parameters, design_units={n: u for n, u in zip(names, s.design_units)},
            wall_seconds=_number(s.wall_seconds), message=s.message,
            failed_analyses=dict(sorted(s.failed_analyses_by_kind.items())),
            history=[_history_entry(r) for r in job.cycles if r.accepted],
            waiting_for=s.waiting_for, cycles_all=list(job.cycles))

    def as_dict(self):
        """The same object as `mbopt results --json` parsed with json.loads."""
        out = {
            "job_id": self.job_id, "study": self.study, "status": self.status, "cycles": self.cycles,
            "analyses": self.analyses, "objective": self.objective, "objective_unit": self.objective_unit,
            "max_violation": self.max_violation, "design": dict(self.design),
            "design_scaled": dict(self.design_scaled), "design_parameters": dict(self.design_parameters),
            "design_units": dict(self.design_units), "wall_seconds": self.wall_seconds,
            "message": self.message,
        }
        if self.waiting_for:
            out["waiting_for"] = self.waiting_for
        out["failed_analyses"] = dict(self.failed_analyses)
        out["history"] = [dict(h) for h in self.history]
        return out
