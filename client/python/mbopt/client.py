"""A connection to an mbopt server and the job calls of the `mbopt` CLI:
submit, watch, status, list, results, cancel, resume, workers.

    import mbopt
    with mbopt.Client() as server:          # $MBOPT_SERVER or 127.0.0.1:50051
        job = server.submit("examples/vehicle/vehicle.study.textproto")
        final = server.wait(job)
        print(server.results(job).objective)

Every failure is an mbopt.errors exception carrying the server's message.
"""

import grpc

from mbopt.connection import UNARY_DEADLINE_S, Security, create_channel, resolve_address, rpc_error
from mbopt.jobs import FrontPointFollower, JobStatus, results_of
from mbopt.errors import BadInput
from mbopt.study_file import StudyFile
from mbopt.v1 import service_pb2, service_pb2_grpc


class Client:
    """One server. `address` and the security settings default to the
    environment as in the CLI (mbopt.connection); without a CA file the
    connection is plaintext, as to a server on loopback."""

    def __init__(self, address=None, *, tls_ca=None, tls_cert=None, tls_key=None, tls_server_name=None,
                 token_file=None):
        self.address = resolve_address(address)
        self._security = Security(tls_ca=tls_ca, tls_cert=tls_cert, tls_key=tls_key,
                                  tls_server_name=tls_server_name, token_file=token_file)
        self._channel = create_channel(self.address, self._security)
        self._jobs = service_pb2_grpc.JobServiceStub(self._channel)

    def close(self):
        self._channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _call(self, method, request):
        try:
            return method(request, timeout=UNARY_DEADLINE_S, metadata=self._security.metadata())
        except grpc.RpcError as e:
            raise rpc_error(e, self.address) from None

    def submit(self, study_path):
        """Submits the study file (its scene inlined) and returns the job id.
        A study the server refuses raises BadInput with its message, each
        field named with its file and line as `mbopt submit` names it."""
        study_file = StudyFile(study_path)
        request = service_pb2.SubmitJobRequest(study=study_file.study.SerializeToString(), source_name=study_file.path)
        try:
            return self._call(self._jobs.Submit, request).job_id
        except BadInput as e:
            raise BadInput(study_file.with_lines(str(e))) from None

    def status(self, job_id):
        """The job's JobStatus (`mbopt status`)."""
        return JobStatus.from_proto(self._call(self._jobs.Get, service_pb2.JobRef(job_id=job_id)).summary)

    def list(self):
        """Every job this token may see, as JobStatus (`mbopt list`)."""
        return [JobStatus.from_proto(s) for s in self._call(self._jobs.List, service_pb2.ListJobsRequest()).jobs]

    def results(self, job_id):
        """The job's results as `mbopt results --json` gives them: JobResults
        for an optimization, FrontResults (its points) for a Pareto front,
        DesignSetResults (its designs) for a sweep or sample."""
        return results_of(self._call(self._jobs.Get, service_pb2.JobRef(job_id=job_id)))

    def get(self, job_id):
        """The server's whole answer (mbopt.v1.GetJobResponse): summary, every
        CycleRecord and the study as submitted."""
        return self._call(self._jobs.Get, service_pb2.JobRef(job_id=job_id))

    def cancel(self, job_id):
        """Cancels the job; its JobStatus after."""
        return JobStatus.from_proto(self._call(self._jobs.Cancel, service_pb2.JobRef(job_id=job_id)))

    def resume(self, job_id):
        """Resumes an interrupted or cancelled job; its JobStatus after."""
        return JobStatus.from_proto(self._call(self._jobs.Resume, service_pb2.JobRef(job_id=job_id)))

    def workers(self):
        """The registered workers (mbopt.v1.WorkerSummary messages)."""
        return list(self._call(self._jobs.ListWorkers, service_pb2.ListWorkersRequest()).workers)

    def watch(self, job_id):
        """Yields the job's events until it ends: first its cycle records so
        far, then each new one (mbopt.v1.CycleRecord) and a JobStatus after
        every cycle and on every state change. No deadline: a job runs as
        long as it runs; leaving the loop (or closing the client) ends the
        call."""
        call = self._jobs.Watch(service_pb2.JobRef(job_id=job_id), metadata=self._security.metadata())
        try:
            for event in call:
                if event.HasField("cycle"):
                    yield event.cycle
                elif event.HasField("summary"):
                    yield JobStatus.from_proto(event.summary)
        except grpc.RpcError as e:
            raise rpc_error(e, self.address) from None
        finally:
            call.cancel()

    def watch_front(self, job_id):
        """For a Pareto front: yields each point as its run ends (a dict with
        the keys of FrontResults.points, its run's `history` included, and
        `run_status` "feasible", "infeasible", "failed" or "not run" in
        place of `status`: whether a feasible point is on the front or
        dominated needs the points still to come, results() tells it once
        the job has ended), and a JobStatus whenever the job's state or its
        count of points done changes. The runs' own cycle records are
        gathered into their points' histories, not yielded. ValueError when
        the job is not a front."""
        job = self.get(job_id)
        if not (job.summary.pareto or job.study.HasField("pareto")):
            raise ValueError(f"job {job_id} is not a Pareto front; watch() follows it")
        follower = FrontPointFollower(job)
        last = None
        for event in self.watch(job_id):
            if isinstance(event, JobStatus):
                if last is None or (event.status, event.cycles) != (last.status, last.cycles):
                    yield event
                last = event
                continue
            point = follower.feed(event)
            if point is not None:
                yield point

    def wait(self, job_id, on_event=None):
        """Follows the job to its end and returns its last JobStatus;
        `on_event` is called with every event of watch()."""
        last = None
        for event in self.watch(job_id):
            if on_event is not None:
                on_event(event)
            if isinstance(event, JobStatus):
                last = event
        return last if last is not None else self.status(job_id)
