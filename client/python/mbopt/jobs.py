"""Jobs as plain Python values: a job's status (from the server's
JobSummary) and its results (from GetJobResponse), with the fields and names
of `mbopt results --json` (client/job_format.cc; a Pareto front's points
and a sweep's or sample's designs as client/pareto_format.cc and
client/design_set_format.cc list them), so that a script and the CLI read
the same thing. Values are in the study's units as the server
reports them; a value that is not finite (no objective yet) is None, as the
CLI's JSON writes null.
"""

import math
from dataclasses import dataclass, field

from mbopt.v1 import service_pb2, study_pb2

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


def _record_entry(r):
    """What a job's history and a front point's run history both say of one
    LP solve."""
    return {
        "cycle": r.cycle,
        "restoration": r.restoration,
        "objective": _number(r.objective_trial),
        "max_violation": _number(r.max_violation_trial),
        "max_approximation_error": _number(r.max_approximation_error),
        "optimality_residual": _number(r.optimality_residual),
        "lp_feasible": r.lp_feasible,
        "analyses": r.analyses_total,
        "design": [_number(v) for v in r.x_trial_physical],
    }


def _history_entry(r):
    entry = _record_entry(r)
    entry["attempts"] = r.attempt + 1
    entry["move_limits"] = [_number(v) for v in r.move_limits]
    entry["move_limits_next"] = [_number(v) for v in r.move_limits_next]
    entry["x_scaled"] = [_number(v) for v in r.x_trial_scaled]
    return entry


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


def _second_objective_label(o):
    """A front's second objective as the CLI names it (client/pareto_format.cc,
    SecondObjectiveLabel): "F2: s1", "F2: x (maximized)", "F2: max |s1|", ..."""
    form = o.WhichOneof("form")
    if form == "minimize":
        return f"F2: {o.minimize}"
    if form == "maximize":
        return f"F2: {o.maximize} (maximized)"
    if form == "minimize_max_of":
        bar = "|" if o.reduction == study_pb2.REDUCTION_MAX_ABS else ""
        return f"F2: max {bar}{o.minimize_max_of}{bar}"
    if form == "minimize_max_over":
        return f"F2: largest of {len(o.minimize_max_over.terms)} terms"
    if form == "minimize_sum":
        return f"F2: sum of {len(o.minimize_sum.terms)} terms"
    return "F2"


def _at(values, i):
    return _number(values[i]) if i < len(values) else None


def _point_history_entry(r):
    entry = _record_entry(r)
    entry["attempt"] = r.attempt
    entry["accepted"] = r.accepted
    return entry


def _run_status(r):
    """A front point's status as far as its own run tells it: "" for a
    feasible end (front or dominated is decided against the other points),
    "not run", "failed" or "infeasible"."""
    if r.pareto_state == "not_run":
        return "not run"
    if not r.accepted:
        return "failed" if r.pareto_state == "failed" or not math.isfinite(r.objective_trial) else "infeasible"
    return ""


def _front_point(r, names, constraints, history):
    """One point of a front from its record, as FrontResults.points lists it
    but without "status" (which needs the other points)."""
    point = {
        "point": r.cycle,
        "level": _number(r.pareto_level),
        "objective": _number(r.objective_trial),
        "value": _number(r.pareto_value),
    }
    if r.pareto_three:
        # A front of three objectives: the third's level and value.
        point["level3"] = _number(r.pareto_level3)
        point["value3"] = _number(r.pareto_value3)
    point.update({
        "max_violation": _number(r.max_violation_trial),
        "run_state": r.pareto_state,
        "cycles": r.pareto_cycles,
        "analyses": r.pareto_analyses,
        "design": {n: _at(r.x_trial_physical, i) for i, n in enumerate(names)},
        "x_scaled": [_number(v) for v in r.x_trial_scaled],
        "constraints": {n: _at(r.constraint_violations, c) for c, n in enumerate(constraints)},
        "reason": r.rejection_reason,
        "history": history,
    })
    return point


class FrontPointFollower:
    """Turns a front's records, in the order the server sends them (a
    point's run history, then the point's own record), into its points:
    feed() returns the point a record completes, or None."""

    def __init__(self, job):
        self._names = list(job.summary.design_names)
        self._constraints = [c.name for c in job.study.constraints]
        self._histories = {}

    def feed(self, r):
        if r.pareto_point > 0:
            self._histories.setdefault(r.pareto_point, []).append(_point_history_entry(r))
            return None
        if not r.pareto:
            return None
        point = _front_point(r, self._names, self._constraints, self._histories.pop(r.cycle, []))
        point["run_status"] = _run_status(r) or "feasible"
        return point


def _dominated(points):
    """Which of (first, second, usable, third) points another usable point
    beats: no worse in every objective (as minimized) and better in one
    (spec/pareto.h, DominatedPoints); third is 0 on a front of two."""
    dominated = [False] * len(points)
    for i, (first, second, usable, third) in enumerate(points):
        if not usable:
            continue
        for j, (other_first, other_second, other_usable, other_third) in enumerate(points):
            if j == i or not other_usable:
                continue
            no_worse = other_first <= first and other_second <= second and other_third <= third
            better = other_first < first or other_second < second or other_third < third
            if no_worse and better:
                dominated[i] = True
                break
    return dominated


@dataclass
class FrontResults:
    """What `mbopt results --json` prints for a Pareto front, field for field:
    `points` has one dict per point of the front (its level, both
    objectives, its run's end, its design, each constraint's largest
    normalized value, its status: "front", "dominated", "infeasible",
    "failed" or "not run", and its run's `history`, one dict per LP solve),
    in the points' order. The second objective and its levels are as the
    CLI shows them: a traded constraint's in its unit, a maximized
    objective as itself. A front of three objectives names its second
    traded constraint in `against3` (its unit in `against3_unit`), and each
    point has its `level3` and `value3`."""

    job_id: str
    study: str
    status: str
    against: str
    against_unit: str
    objective_unit: str
    points_total: int
    points_done: int
    analyses: int
    message: str
    points: list
    against3: str = ""       # a front of three objectives: the second traded constraint
    against3_unit: str = ""

    def point(self, number):
        """Point `number` (1-based) of the front; KeyError naming the points
        there are when it has no such point."""
        for p in self.points:
            if p["point"] == number:
                return p
        raise KeyError(f"point {number}: job {self.job_id} has "
                       + (f"points 1 to {len(self.points)}" if self.points else "no point yet")
                       + f" (of {self.points_total})")

    @classmethod
    def from_proto(cls, job):
        s = job.summary
        study = job.study
        pareto = study.pareto
        maximized = False
        if pareto.HasField("objective"):
            against = _second_objective_label(pareto.objective)
            against_unit = pareto.objective.unit
            maximized = pareto.objective.WhichOneof("form") == "maximize"
        else:
            against = pareto.against[0] if pareto.against else ""
            against_unit = next((c.unit for c in study.constraints if c.name == against), "")
        # A front of three objectives names a second constraint.
        three = len(pareto.against) == 2
        against3 = pareto.against[1] if three else ""
        against3_unit = next((c.unit for c in study.constraints if c.name == against3), "") if three else ""
        # Dominance on both objectives as the runs minimize them.
        first_sign = -1.0 if study.objective.WhichOneof("form") == "maximize" else 1.0
        second_sign = -1.0 if maximized else 1.0
        names = list(s.design_names)
        constraints = [c.name for c in study.constraints]
        histories = {}
        for r in job.cycles:
            if r.pareto_point > 0:
                histories.setdefault(r.pareto_point, []).append(_point_history_entry(r))
        points, ranked = [], []
        for r in job.cycles:
            if not r.pareto:
                continue
            point = _front_point(r, names, constraints, histories.get(r.cycle, []))
            point["status"] = _run_status(r)
            points.append(point)
            ranked.append((first_sign * r.objective_trial, second_sign * r.pareto_value, point["status"] == "",
                           r.pareto_value3 if three else 0.0))
        for p, dominated in zip(points, _dominated(ranked)):
            if p["status"] == "":
                p["status"] = "dominated" if dominated else "front"
        return cls(job_id=s.job_id, study=s.study_name, status=state_name(s.state), against=against,
                   against_unit=against_unit, objective_unit=s.objective_unit, points_total=s.max_cycles,
                   points_done=s.cycles, analyses=s.analyses, message=s.message, points=points,
                   against3=against3, against3_unit=against3_unit)

    def as_dict(self):
        """The same object as `mbopt results --json` parsed with json.loads."""
        out = {
            "job_id": self.job_id, "study": self.study, "status": self.status, "form": "pareto",
            "against": self.against, "against_unit": self.against_unit,
        }
        if self.against3:
            out.update({"against3": self.against3, "against3_unit": self.against3_unit})
        out.update({
            "objective_unit": self.objective_unit,
            "points_total": self.points_total, "points_done": self.points_done, "analyses": self.analyses,
            "message": self.message, "points": [dict(p) for p in self.points],
        })
        return out


@dataclass
class DesignSetResults:
    """What `mbopt results --json` prints for a sweep or a sample, field for
    field: `designs` has one dict per design analysed, in the designs'
    order (its values, its objective and largest normalized constraint
    value, each constraint's, its status: "ok" or the failure's kind)."""

    job_id: str
    study: str
    status: str
    form: str  # "sweep" or "sample"
    designs_total: int
    designs_done: int
    analyses: int
    objective_unit: str
    best_objective: float
    best_max_violation: float
    variables: list
    constraints: list
    message: str
    failed_analyses: dict
    designs: list

    @classmethod
    def from_proto(cls, job):
        s = job.summary
        study = job.study
        names = list(s.design_names)
        units = list(s.design_units)
        variables = []
        for i, n in enumerate(names):
            variable = {"name": n}
            for v in study.variables:
                if v.name == n:
                    variable["parameter"] = v.parameter
                    variable["scale"] = v.scale or 1.0
            variable["unit"] = units[i] if i < len(units) else ""
            variables.append(variable)
        constraints = [c.name for c in study.constraints]
        designs = [{
            "design": r.cycle,
            "values": {n: _at(r.x_trial_physical, i) for i, n in enumerate(names)},
            "x_scaled": [_number(v) for v in r.x_trial_scaled],
            "objective": _number(r.objective_trial),
            "max_violation": _number(r.max_violation_trial),
            "constraints": {n: _at(r.constraint_violations, c) for c, n in enumerate(constraints)},
            "status": r.failure_kind or "ok",
            "failure_reason": r.rejection_reason,
        } for r in job.cycles]
        return cls(job_id=s.job_id, study=s.study_name, status=state_name(s.state),
                   form="sample" if study.HasField("sample") else "sweep", designs_total=s.max_cycles,
                   designs_done=s.cycles, analyses=s.analyses, objective_unit=s.objective_unit,
                   best_objective=_number(s.objective), best_max_violation=_number(s.max_violation),
                   variables=variables, constraints=constraints, message=s.message,
                   failed_analyses=dict(sorted(s.failed_analyses_by_kind.items())), designs=designs)

    def as_dict(self):
        """The same object as `mbopt results --json` parsed with json.loads."""
        return {
            "job_id": self.job_id, "study": self.study, "status": self.status, "form": self.form,
            "designs_total": self.designs_total, "designs_done": self.designs_done, "analyses": self.analyses,
            "objective_unit": self.objective_unit, "best_objective": self.best_objective,
            "best_max_violation": self.best_max_violation, "variables": [dict(v) for v in self.variables],
            "constraints": list(self.constraints), "message": self.message,
            "failed_analyses": dict(self.failed_analyses), "designs": [dict(d) for d in self.designs],
        }


def results_of(job):
    """A GetJobResponse as what `mbopt results --json` prints of it: a
    Pareto front's FrontResults, a sweep's or sample's DesignSetResults, an
    optimization's JobResults."""
    if job.summary.pareto or (job.HasField("study") and job.study.HasField("pareto")):
        return FrontResults.from_proto(job)
    if job.summary.design_set or (job.HasField("study") and
                                  (job.study.HasField("sweep") or job.study.HasField("sample"))):
        return DesignSetResults.from_proto(job)
    return JobResults.from_proto(job)
