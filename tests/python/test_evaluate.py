"""The evaluation harness (examples/python/evaluate.py) on tiny runs: the expert succeeding and
replayed from its saved actions, Python policies that raise, exit, hang or answer malformed actions,
action chunks, a policy server on a loopback port speaking openpi's websocket protocol, worker
processes giving the serial result, an interrupted run resumed to the uninterrupted result, bad
flags, and the Wilson interval against textbook values."""
import asyncio
import csv
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import unittest

import msgpack
import numpy as np
import websockets

import eval_policies
import evaluate


def episodes(out):
    with open(os.path.join(out, "episodes.csv")) as f:
        return list(csv.DictReader(f))


class PolicyServer:
    """An openpi-style policy server: metadata on connect, then {"actions": H x 61} per request."""

    def __init__(self, chunk, delay=0.0):
        self.chunk, self.delay, self.requests = chunk, delay, []
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            self.port = s.getsockname()[1]
        self.loop = asyncio.new_event_loop()
        self.ready = threading.Event()
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()
        self.ready.wait(10)

    async def _handler(self, ws, path=None):
        await ws.send(msgpack.packb({"policy": "zeros", "action_dim": 61}, default=evaluate.pack_openpi))
        async for message in ws:
            request = msgpack.unpackb(message, object_hook=evaluate.unpack_openpi)
            self.requests.append((request["observation/image"].shape, request["observation/image"].dtype, request["prompt"]))
            await asyncio.sleep(self.delay)
            if ws.closed:
                return  # the client gave up waiting (the slow-server test)
            await ws.send(msgpack.packb({"actions": np.zeros((self.chunk, 61), np.float32)}, default=evaluate.pack_openpi))

    def _serve(self):
        asyncio.set_event_loop(self.loop)
        self.server = self.loop.run_until_complete(websockets.serve(self._handler, "127.0.0.1", self.port, compression=None, max_size=None))
        self.ready.set()
        self.loop.run_forever()

    def stop(self):
        async def shutdown():
            self.server.close()
            await self.server.wait_closed()
        asyncio.run_coroutine_threadsafe(shutdown(), self.loop).result(10)
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(5)
        self.loop.close()


class EvaluateTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="manisoft_eval_")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def out(self, name):
        return os.path.join(self.dir, name)

    def test_wilson_interval_textbook_values(self):
        low, high = evaluate.wilson_interval(8, 10)
        self.assertAlmostEqual(low, 0.4902, places=4)
        self.assertAlmostEqual(high, 0.9433, places=4)
        low, high = evaluate.wilson_interval(0, 20)
        self.assertEqual(low, 0.0)
        self.assertAlmostEqual(high, 0.1611, places=4)
        self.assertAlmostEqual(evaluate.wilson_interval(1, 1)[0], 1 / (1 + 1.959963984540054 ** 2), places=12)

    def test_expert_succeeds_and_its_actions_replay(self):
        out = self.out("expert")
        self.assertEqual(evaluate.main(["--task", "ALN", "--setting", "clean", "--policy", "expert", "--indices", "2",
                                        "--out", out, "--save-actions"]), 0)
        (row,) = episodes(out)
        self.assertEqual((row["task"], row["index"], row["success"], row["failure"]), ("ALN", "2", "True", ""))
        steps = int(row["steps"])
        self.assertLessEqual(steps, 1500)
        with open(os.path.join(out, "results.csv")) as f:
            table = {(r["task"], r["category"]): r for r in csv.DictReader(f)}
        self.assertEqual(float(table[("ALN", "all")]["acc"]), 100.0)
        self.assertEqual(float(table[("ALN", "all")]["mean_steps"]), steps)
        self.assertAlmostEqual(float(table[("ALN", "all")]["acc_low"]), 100 / (1 + 1.959963984540054 ** 2), places=2)
        with open(os.path.join(out, "summary.json")) as f:
            self.assertEqual(json.load(f)["success_rate"], 1.0)
        with open(os.path.join(out, "results.md")) as f:
            self.assertIn("| ALN | **all** | 1 | 100.0 |", f.read())
        self.assertEqual(np.load(os.path.join(out, "actions", "ALN_clean_2.npy")).shape, (steps, 61))
        replay = self.out("replay")
        evaluate.main(["--task", "ALN", "--setting", "clean", "--policy", "replay:" + out, "--indices", "2", "--out", replay])
        (again,) = episodes(replay)
        self.assertEqual((again["success"], again["steps"]), ("True", row["steps"]))

    def test_the_expert_on_the_end_effector_track(self):
        # its recorded targets sent every 36 control steps; the saved actions are 7-float ee actions
        out = self.out("ee")
        self.assertEqual(evaluate.main(["--task", "ALN", "--setting", "clean", "--policy", "expert", "--indices", "2",
                                        "--action-mode", "ee_pose", "--out", out, "--save-actions"]), 0)
        (row,) = episodes(out)
        self.assertEqual((row["success"], row["failure"]), ("True", ""))
        actions = np.load(os.path.join(out, "actions", "ALN_clean_2.npy"))
        self.assertEqual(actions.shape, (-(-int(row["steps"]) // 36), 7))
        with open(os.path.join(out, "results.md")) as f:
            self.assertIn("action mode ee_pose, 36 control steps an action", f.read())
        with open(os.path.join(out, "summary.json")) as f:
            self.assertEqual(json.load(f)["action_mode"], "ee_pose")

    def test_failing_python_policies_fail_their_episodes_only(self):
        for name, reason, detail in [("raising", "policy_error", "RuntimeError: model checkpoint missing"),
                                     ("wrong_shape", "bad_action", "shape (4, 7)"),
                                     ("exiting", "policy_error", "SystemExit: 3")]:
            out = self.out(name)
            code = evaluate.main(["--task", "COLL", "--setting", "clean", "--policy", "python:eval_policies:" + name,
                                  "--indices", "0", "1", "--image-size", "32", "32", "--out", out])
            self.assertEqual(code, 0)
            rows = episodes(out)
            self.assertEqual(len(rows), 2)
            for r in rows:
                self.assertEqual((r["success"], r["failure"], r["steps"]), ("False", reason, "0"))
                self.assertIn(detail, r["detail"])

    def test_action_chunks_run_chunk_steps_per_call(self):
        eval_policies.calls["zeros_chunk"] = 0
        out = self.out("chunks")
        evaluate.main(["--task", "ALN", "--setting", "clean", "--policy", "python:eval_policies:zeros_chunk", "--indices", "0",
                       "--chunk-steps", "8", "--image-size", "32", "24", "--out", out])
        (row,) = episodes(out)
        self.assertEqual((row["failure"], row["steps"]), ("timeout", "1500"))
        self.assertEqual(eval_policies.calls["zeros_chunk"], -(-1500 // 8))

    def run_with_server(self, server, *flags):
        """One ALN clean episode (eval index 0) against `server`, 32 x 24 images; its episodes.csv row."""
        out = self.out(f"ws{server.port}")
        try:
            evaluate.main(["--task", "ALN", "--setting", "clean", "--policy", f"ws://127.0.0.1:{server.port}", "--indices", "0",
                           "--image-size", "32", "24", "--out", out, *flags])
        finally:
            server.stop()
        (row,) = episodes(out)
        return row

    def test_policy_server_on_loopback(self):
        server = PolicyServer(chunk=5)
        row = self.run_with_server(server, "--chunk-steps", "5")
        self.assertEqual((row["failure"], row["steps"]), ("timeout", "1500"))
        self.assertEqual(len(server.requests), 300)
        shape, dtype, prompt = server.requests[0]
        self.assertEqual((shape, dtype), ((24, 32, 3), np.uint8))
        self.assertTrue(prompt.endswith("."))

    def test_slow_policy_server_times_out(self):
        row = self.run_with_server(PolicyServer(chunk=5, delay=2.0), "--policy-timeout", "0.5")
        self.assertEqual((row["success"], row["failure"], row["steps"]), ("False", "policy_timeout", "0"))

    def test_no_server_is_a_failed_episode(self):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        out = self.out("none")
        evaluate.main(["--task", "ALN", "--setting", "clean", "--policy", f"ws://127.0.0.1:{port}", "--indices", "0",
                       "--image-size", "32", "24", "--out", out])
        (row,) = episodes(out)
        self.assertEqual(row["failure"], "policy_error")
        self.assertIn("cannot connect", row["detail"])

    def test_worker_processes_give_the_serial_result(self):
        results = []
        for jobs in ("1", "2"):
            out = self.out("jobs" + jobs)
            evaluate.main(["--task", "ARR", "--setting", "randomized", "--policy", "random", "--indices", "0", "1", "2",
                           "--jobs", jobs, "--out", out])
            results.append([{k: v for k, v in r.items() if k != "wall_s"} for r in episodes(out)])
        self.assertEqual(results[0], results[1])

    def test_bad_flags_exit_2(self):
        a_file = self.out("a_file")
        open(a_file, "w").close()
        for argv in (["--policy", "python:nomodule"], ["--policy", "grpc://x"], ["--jobs", "0"], ["--chunk-steps", "0"],
                     ["--policy", "python:no_such_module:act"], ["--indices", "3", "-1"], ["--max-scan", "-1"],
                     ["--out", os.path.join(a_file, "out")]):
            with self.assertRaises(SystemExit) as e:
                evaluate.main(argv + ([] if "--out" in argv else ["--out", self.out("bad")]))
            self.assertEqual(e.exception.code, 2)

    def test_a_hanging_policy_stops_the_run_and_resume_goes_on(self):
        out = self.out("hang")
        argv = ["--task", "COLL", "--setting", "clean", "--policy", "python:eval_policies:hanging", "--indices", "0", "1",
                "--image-size", "32", "24", "--policy-timeout", "0.5", "--out", out]
        self.assertEqual(evaluate.main(argv), 1)  # stopped after the first episode: the call still runs
        self.assertFalse(os.path.exists(os.path.join(out, "results.md")))
        self.assertEqual(evaluate.main(argv + ["--resume"]), 1)  # the second, in the same way
        self.assertEqual(evaluate.main(argv + ["--resume"]), 0)  # nothing left: the tables
        rows = episodes(out)
        self.assertEqual([(r["index"], r["failure"], r["steps"]) for r in rows], [("0", "policy_timeout", "0"), ("1", "policy_timeout", "0")])

    def test_replay_without_a_recording_fails_that_episode_only(self):
        empty = self.out("no_recordings")
        os.makedirs(os.path.join(empty, "actions"))
        out = self.out("replay_missing")
        self.assertEqual(evaluate.main(["--task", "ALN", "--setting", "clean", "--policy", "replay:" + empty, "--indices", "0", "1",
                                        "--out", out]), 0)
        for r in episodes(out):
            self.assertEqual((r["failure"], r["steps"]), ("policy_error", "0"))
            self.assertIn("no recorded actions", r["detail"])

    def test_an_interrupted_run_resumes_to_the_uninterrupted_result(self):
        flags = ["--task", "ALN", "--setting", "clean", "--policy", "python:eval_policies:slow_zeros", "--chunk-steps", "8",
                 "--indices", "0", "1", "2", "3", "--image-size", "16", "16", "--python-path", os.path.dirname(eval_policies.__file__)]
        out = self.out("interrupted")
        script = os.path.join(os.path.dirname(evaluate.__file__), "evaluate.py")
        run = subprocess.Popen([sys.executable, script, *flags, "--out", out], stdout=subprocess.PIPE, text=True)
        for line in run.stdout:
            if line.startswith("[1/4]"):
                run.send_signal(signal.SIGINT)
                break
        self.assertEqual(run.wait(60), 130)
        run.stdout.close()
        with open(os.path.join(out, "episodes.jsonl")) as f:
            finished = len(f.readlines())
        self.assertGreaterEqual(finished, 1)
        self.assertLess(finished, 4)
        self.assertFalse(os.path.exists(os.path.join(out, "episodes.csv")))
        with self.assertRaises(SystemExit) as e:  # the folder holds a run: only --resume goes on with it
            evaluate.main(flags + ["--out", out])
        self.assertEqual(e.exception.code, 2)
        with self.assertRaises(SystemExit) as e:  # with the same arguments
            evaluate.main(flags + ["--out", out, "--resume", "--seed", "1"])
        self.assertEqual(e.exception.code, 2)
        self.assertEqual(evaluate.main(flags + ["--out", out, "--resume"]), 0)
        whole = self.out("whole")
        self.assertEqual(evaluate.main(flags + ["--out", whole]), 0)
        strip = lambda rows: [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]
        self.assertEqual(strip(episodes(out)), strip(episodes(whole)))


if __name__ == "__main__":
    unittest.main()
