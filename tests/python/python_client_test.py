"""The Python client (client/python, docs/python.md) against a real
mbopt-server and mbopt-worker on loopback: what it reads must be what the
`mbopt` CLI reads of the same job, its errors the CLI's messages.

Run by ctest (tests/python/CMakeLists.txt), which sets PYTHONPATH to the
built client and names the programs in MBOPT_TEST_SERVER, MBOPT_TEST_WORKER,
MBOPT_TEST_MBOPT and the source tree in MBOPT_TEST_SOURCE_DIR.
"""

import json
import os
import shutil
import subprocess
import tempfile
import unittest
from unittest import mock

import mbopt

SERVER = os.environ["MBOPT_TEST_SERVER"]
WORKER = os.environ["MBOPT_TEST_WORKER"]
MBOPT = os.environ["MBOPT_TEST_MBOPT"]
SOURCE_DIR = os.environ["MBOPT_TEST_SOURCE_DIR"]
VEHICLE_STUDY = os.path.join(SOURCE_DIR, "examples", "vehicle", "vehicle.study.textproto")
VEHICLE_SCENE = os.path.join(SOURCE_DIR, "examples", "vehicle", "vehicle.scene.textproto")
VEHICLE_PARETO = os.path.join(SOURCE_DIR, "examples", "vehicle", "vehicle_pareto.study.textproto")
VEHICLE_PARETO3 = os.path.join(SOURCE_DIR, "examples", "vehicle", "vehicle_pareto3.study.textproto")
VEHICLE_SWEEP = os.path.join(SOURCE_DIR, "examples", "vehicle", "vehicle_sweep.study.textproto")

# The tests' servers are their own: settings for another in the caller's
# environment must not reach the clients here.
for variable in ("MBOPT_SERVER", "MBOPT_TLS_CA", "MBOPT_TLS_CERT", "MBOPT_TLS_KEY", "MBOPT_TLS_SERVER_NAME",
                 "MBOPT_TOKEN_FILE", "MBOPT_TOKEN"):
    os.environ.pop(variable, None)


class Server:
    """An mbopt-server on a loopback port the system chooses, with `workers`
    workers; its address from its readiness line (docs/server.md)."""

    def __init__(self, folder, workers, server_args=(), worker_args=()):
        self._log = open(os.path.join(folder, "server.log"), "wb")
        self.process = subprocess.Popen(
            [SERVER, "--listen", "127.0.0.1:0", "--db", os.path.join(folder, "jobs.db"), *server_args],
            stdout=subprocess.PIPE, stderr=self._log)
        self._worker_args = list(worker_args)
        line = self.process.stdout.readline().decode()
        if "listening on " not in line:
            self.stop()
            raise RuntimeError(f"mbopt-server did not start: {line!r}; see {self._log.name}")
        self.address = line.split("listening on ", 1)[1].strip()
        self._folder = folder
        self.workers = []
        for _ in range(workers):
            self.add_worker()

    def add_worker(self):
        log = open(os.path.join(self._folder, f"worker{len(self.workers)}.log"), "wb")
        self.workers.append((subprocess.Popen([WORKER, "serve", "--server", self.address, *self._worker_args],
                                              stdout=subprocess.DEVNULL, stderr=log), log))

    def stop(self):
        for process, log in self.workers:
            process.terminate()
            process.wait()
            log.close()
        self.process.terminate()
        self.process.wait()
        self.process.stdout.close()
        self._log.close()


def mbopt_cli(*args):
    return subprocess.run([MBOPT, *args], capture_output=True, text=True, check=False)


class PythonClientTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.mkdtemp(prefix="mbopt-python-test-")
        cls.server = Server(os.path.join(cls.folder, ""), workers=1)
        cls.client = mbopt.Client(cls.server.address)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.stop()
        shutil.rmtree(cls.folder, ignore_errors=True)

    def write(self, name, text):
        path = os.path.join(self.folder, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def vehicle_with(self, name, old, new):
        """The vehicle study with one edit, beside a copy of its scene."""
        shutil.copy(VEHICLE_SCENE, self.folder)
        with open(VEHICLE_STUDY) as f:
            text = f.read()
        self.assertIn(old, text)
        return self.write(name, text.replace(old, new, 1))

    def test_vehicle_watched_to_the_end_reads_as_the_cli_reads_it(self):
        job = self.client.submit(VEHICLE_STUDY)
        events = list(self.client.watch(job))
        cycles = [e for e in events if not isinstance(e, mbopt.JobStatus)]
        statuses = [e for e in events if isinstance(e, mbopt.JobStatus)]
        self.assertTrue(cycles, "no cycle records")
        self.assertEqual(statuses[-1].status, "converged")
        self.assertEqual([c.cycle for c in cycles if c.accepted], list(range(1, statuses[-1].cycles + 1)))

        results = self.client.results(job)
        cli = mbopt_cli("results", job, "--json", "--server", self.server.address)
        self.assertEqual(cli.returncode, 0, cli.stderr)
        expected = json.loads(cli.stdout)
        # The same doubles, bit for bit (the CLI prints 17 digits).
        self.assertEqual(results.objective.hex(), float(expected["objective"]).hex())
        self.assertEqual({k: v.hex() for k, v in results.design.items()},
                         {k: float(v).hex() for k, v in expected["design"].items()})
        self.assertEqual(results.as_dict(), expected)
        self.assertEqual(len(results.history), statuses[-1].cycles)

        status = self.client.status(job)
        self.assertEqual((status.status, status.objective), ("converged", results.objective))
        self.assertIn(job, [s.job_id for s in self.client.list()])

    def assert_reads_as_the_cli(self, job, results):
        cli = mbopt_cli("results", job, "--json", "--server", self.server.address)
        self.assertEqual(cli.returncode, 0, cli.stderr)
        # The same doubles, bit for bit (the CLI prints 17 digits, which
        # json.loads reads back exactly).
        self.assertEqual(results.as_dict(), json.loads(cli.stdout))

    def test_front_lists_its_points_not_cycle_records(self):
        shutil.copy(VEHICLE_SCENE, self.folder)
        with open(VEHICLE_PARETO) as f:
            text = f.read()
        self.assertIn("points: 5", text)
        study = self.write("vehicle_pareto3.study.textproto", text.replace("points: 5", "points: 3", 1))
        job = self.client.submit(study)
        # Followed point by point: each point once, as its run ends, with
        # its run's history; the runs' cycle records are not yielded.
        watched, statuses = [], []
        for event in self.client.watch_front(job):
            (statuses if isinstance(event, mbopt.JobStatus) else watched).append(event)
        self.assertEqual(statuses[-1].status, "completed")
        done = [s.cycles for s in statuses]
        self.assertEqual(done, sorted(done))
        self.assertEqual(len(set((s.status, s.cycles) for s in statuses)), len(statuses))
        front = self.client.results(job)
        self.assertIsInstance(front, mbopt.FrontResults)
        self.assertEqual([p["point"] for p in watched], [1, 2, 3])
        for p, q in zip(watched, front.points):
            self.assertEqual(p.pop("run_status"), "feasible")
            self.assertEqual(p, {k: v for k, v in q.items() if k != "status"})
        sweep = self.client.submit(VEHICLE_SWEEP)
        with self.assertRaises(ValueError):
            next(self.client.watch_front(sweep))
        self.client.cancel(sweep)  # the other tests share the worker
        self.assertEqual((front.against, front.against_unit, front.points_done), ("s1", "in", 3))
        self.assertEqual([p["point"] for p in front.points], [1, 2, 3])
        records = {r.cycle: r for r in self.client.get(job).cycles if r.pareto}
        for p in front.points:
            self.assertEqual(p["status"], "front", p["reason"])
            # The traded constraint in its unit (inches), not SI.
            self.assertAlmostEqual(p["value"] * 0.0254, records[p["point"]].pareto_value_si, delta=1e-12)
            # Its run's cycles: the last one the run's last, or the cycle
            # its run stopped in.
            self.assertTrue(p["history"], f"point {p['point']} has no history")
            self.assertIn(p["history"][-1]["cycle"], (p["cycles"], p["cycles"] + 1))
        self.assertIsNone(front.point(1)["level"])
        self.assertLess(front.point(2)["level"], front.point(1)["value"])
        # The far end's run minimizes |s1|: its F in inches, the point's
        # value among its accepted designs'.
        far = [c["objective"] for c in front.point(3)["history"] if c["accepted"]]
        self.assertTrue(any(abs(f - front.point(3)["value"]) <= 1e-9 * front.point(3)["value"] for f in far),
                        (front.point(3)["value"], far))
        with self.assertRaises(KeyError) as raised:
            front.point(4)
        self.assertIn(f"job {job} has points 1 to 3 (of 3)", str(raised.exception))
        self.assert_reads_as_the_cli(job, front)

    def test_front_of_three_objectives_lists_both_traded_values_as_the_cli(self):
        shutil.copy(VEHICLE_SCENE, self.folder)
        with open(VEHICLE_PARETO3) as f:
            text = f.read()
        self.assertIn("points: 3", text)
        study = self.write("vehicle_pareto3_small.study.textproto", text.replace("points: 3", "points: 2", 1))
        job = self.client.submit(study)
        self.assertEqual(self.client.wait(job).status, "completed")
        front = self.client.results(job)
        self.assertIsInstance(front, mbopt.FrontResults)
        self.assertEqual((front.against, front.against3, front.against3_unit), ("s1", "s2", "in"))
        self.assertEqual([p["point"] for p in front.points], list(range(1, 3 + 2 * 2 + 1)))
        records = {r.cycle: r for r in self.client.get(job).cycles if r.pareto}
        for p in front.points:
            # The second traded constraint in its unit (inches), not SI.
            self.assertAlmostEqual(p["value3"] * 0.0254, records[p["point"]].pareto_value3_si, delta=1e-12)
            if p["point"] > 3:
                self.assertLessEqual(p["value3"], p["level3"] * (1 + 1e-3))
        self.assertIsNone(front.point(1)["level3"])
        # Anchors 2 and 3 optimize |s1| and |s2|: their runs' F is that
        # objective in inches, and the point's value is one of them.
        for number, key in ((2, "value"), (3, "value3")):
            anchor = front.point(number)
            objectives = [c["objective"] for c in anchor["history"] if c["accepted"]]
            self.assertTrue(any(abs(f - anchor[key]) <= 1e-9 * anchor[key] for f in objectives),
                            (number, anchor[key], objectives))
        self.assert_reads_as_the_cli(job, front)

    def test_sweep_lists_its_designs_not_cycle_records(self):
        job = self.client.submit(VEHICLE_SWEEP)
        self.assertEqual(self.client.wait(job).status, "completed")
        sweep = self.client.results(job)
        self.assertIsInstance(sweep, mbopt.DesignSetResults)
        self.assertEqual(sweep.form, "sweep")
        self.assertEqual(len(sweep.designs), sweep.designs_total)
        self.assertEqual([d["design"] for d in sweep.designs], list(range(1, sweep.designs_total + 1)))
        self.assertTrue(all(d["status"] == "ok" for d in sweep.designs))
        self.assert_reads_as_the_cli(job, sweep)

    def test_cancelled_job_resumes_to_the_same_optimum(self):
        # A server without workers: the job waits for its first analyses
        # until it is cancelled, whatever the machine's speed.
        folder = tempfile.mkdtemp(dir=self.folder)
        idle = Server(folder, workers=0)
        try:
            with mbopt.Client(idle.address) as client:
                job = client.submit(VEHICLE_STUDY)
                self.assertIn(client.status(job).status, ("queued", "running"))
                self.assertEqual(client.cancel(job).status, "cancelled")
                self.assertEqual(client.wait(job).status, "cancelled")
                self.assertEqual(client.resume(job).status, "running")
                idle.add_worker()
                self.assertEqual(client.wait(job).status, "converged")
                resumed = client.results(job)
        finally:
            idle.stop()
        uninterrupted = self.client.submit(VEHICLE_STUDY)
        self.client.wait(uninterrupted)
        reference = self.client.results(uninterrupted)
        self.assertEqual(resumed.objective.hex(), reference.objective.hex())
        self.assertEqual(resumed.design, reference.design)

    def test_unknown_job_raises_the_servers_message(self):
        with self.assertRaises(mbopt.JobNotFound) as raised:
            self.client.status("job-999")
        cli = mbopt_cli("status", "job-999", "--server", self.server.address)
        self.assertEqual(cli.returncode, raised.exception.exit_code)
        self.assertEqual("mbopt: " + str(raised.exception), cli.stderr.strip())

    def test_unreachable_server_is_named(self):
        # Port 1 on loopback: nothing listens there for an unprivileged test.
        with mbopt.Client("127.0.0.1:1") as client, self.assertRaises(mbopt.ServerUnreachable) as raised:
            client.list()
        self.assertIn("cannot reach server at 127.0.0.1:1", str(raised.exception))

    def assert_submit_fails_as_the_cli(self, study, *expected_parts):
        with self.assertRaises(mbopt.BadInput) as raised:
            self.client.submit(study)
        cli = mbopt_cli("submit", study, "--server", self.server.address)
        self.assertEqual(cli.returncode, 2, cli.stdout)
        self.assertEqual("mbopt: " + str(raised.exception), cli.stderr.strip())
        for part in expected_parts:
            self.assertIn(part, str(raised.exception))

    def test_study_with_an_unknown_field_names_file_line_and_field(self):
        study = self.vehicle_with("unknown_field.study.textproto", "  reduction: REDUCTION_MAX_ABS\n",
                                  "  reductio: REDUCTION_MAX_ABS\n")
        self.assert_submit_fails_as_the_cli(study, f"{study}:23:11:", 'no field named "reductio"')

    def test_study_the_server_refuses_names_file_line_and_field(self):
        study = self.vehicle_with("reversed_bounds.study.textproto", "lower: 5 upper: 50 }", "lower: 5 upper: 1 }")
        self.assert_submit_fails_as_the_cli(study, f"{study}:14:71: variables[0].upper: bounds reversed")

    def test_scene_error_names_the_scene_file(self):
        scene = os.path.join(self.folder, "bad_unit", "vehicle.scene.textproto")
        os.makedirs(os.path.dirname(scene))
        with open(VEHICLE_SCENE) as f:
            text = f.read()
        with open(scene, "w") as f:
            f.write(text.replace('unit: "lbf/in" description: "seat spring', 'unit: "furlong" description: "seat spring'))
        study = os.path.join(os.path.dirname(scene), "vehicle.study.textproto")
        shutil.copy(VEHICLE_STUDY, study)
        self.assert_submit_fails_as_the_cli(study, f"{scene}:27:", 'parameters[8].unit: unknown unit "furlong"')

    def test_series_file_holds_the_values_eval_summarizes(self):
        series_path = os.path.join(self.folder, "vehicle.series")
        evaluated = mbopt.evaluate(VEHICLE_STUDY, overrides={"x1": 20}, series_out=series_path,
                                   worker_program=WORKER)
        self.assertEqual(evaluated["status"], "ok")
        self.assertEqual(evaluated["design"]["x1"], 20)
        series = mbopt.read_series(series_path, use_numpy=False)
        self.assertEqual(series.failure, "")
        self.assertIsInstance(series.times_s, list)
        # By default arrays when numpy is installed, the same values either way.
        default = mbopt.read_series(series_path)
        try:
            import numpy
        except ImportError:
            numpy = None
        self.assertIsInstance(default.times_s, numpy.ndarray if numpy is not None else list)
        self.assertEqual(list(default.times_s), series.times_s)
        self.assertEqual(series.names(), [o["name"] for o in evaluated["outputs"]])
        for output in evaluated["outputs"]:
            for summary in output["series"]:
                values = series[output["name"]].values(summary["label"])
                self.assertEqual(len(values), len(series.times_s))
                # Exact: the file's doubles are those the worker summarized.
                self.assertEqual(min(values), summary["min_si"])
                self.assertEqual(max(values), summary["max_si"])
                self.assertEqual(series.times_s[values.index(max(values))], summary["t_max_s"])
        # The objective is the peak seat acceleration (max_abs).
        acceleration = series["seat_acceleration"].values()
        self.assertEqual(max(abs(v) for v in acceleration), evaluated["objective"])

    def test_eval_with_an_unknown_name_raises_the_workers_message(self):
        # The worker program as `mbopt report` finds it, from $MBOPT_WORKER_BIN.
        with mock.patch.dict(os.environ, {"MBOPT_WORKER_BIN": WORKER}), self.assertRaises(mbopt.BadInput) as raised:
            mbopt.evaluate(VEHICLE_STUDY, overrides={"no_such": 1})
        self.assertIn('"no_such" is neither a design variable', str(raised.exception))

    def test_token_file_others_can_read_is_refused(self):
        token = self.write("token", "mbopt_0123\n")
        os.chmod(token, 0o644)
        with self.assertRaises(mbopt.BadInput) as raised:
            mbopt.Client(self.server.address, token_file=token)
        self.assertIn("has mode 0644: readable by every user of this machine", str(raised.exception))
        self.assertIn(f"chmod 600 {token}", str(raised.exception))


class SecureServerTest(unittest.TestCase):
    """A server with TLS and tokens (`mbopt-server init-tls`, docs/server.md
    "Security"): the client takes the address, the CA and the token file
    from the environment, as the CLI does."""

    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="mbopt-python-secure-test-")
        self.pki = os.path.join(self.folder, "pki")
        made = subprocess.run([SERVER, "init-tls", self.pki, "--host", "127.0.0.1", "--user", "alice"],
                              capture_output=True, text=True, check=False)
        self.assertEqual(made.returncode, 0, made.stderr)
        self.server = Server(self.folder, workers=1, server_args=["--tls-dir", self.pki],
                             worker_args=["--tls-ca", f"{self.pki}/ca.pem",
                                          "--token-file", f"{self.pki}/worker.token"])

    def tearDown(self):
        self.server.stop()
        shutil.rmtree(self.folder, ignore_errors=True)

    def test_user_with_ca_and_token_from_the_environment_runs_a_study(self):
        env = {"MBOPT_SERVER": self.server.address, "MBOPT_TLS_CA": f"{self.pki}/ca.pem",
               "MBOPT_TOKEN_FILE": f"{self.pki}/alice.token"}
        with mock.patch.dict(os.environ, env), mbopt.Client() as client:
            self.assertEqual(client.address, self.server.address)
            job = client.submit(VEHICLE_STUDY)
            final = client.wait(job)
            self.assertEqual((final.status, final.owner), ("converged", "alice"))
            self.assertEqual([s.job_id for s in client.list()], [job])

    def test_call_without_a_token_is_refused(self):
        with mbopt.Client(self.server.address, tls_ca=f"{self.pki}/ca.pem") as client, \
                self.assertRaises(mbopt.AccessDenied) as raised:
            client.list()
        self.assertIn(f"server at {self.server.address} refused", str(raised.exception))
        self.assertIn("needs a token", str(raised.exception))

    def test_plaintext_call_to_a_tls_server_fails_as_unreachable(self):
        with mbopt.Client(self.server.address) as client, self.assertRaises(mbopt.ServerUnreachable) as raised:
            client.list()
        self.assertIn(f"cannot reach server at {self.server.address}", str(raised.exception))


if __name__ == "__main__":
    unittest.main()
