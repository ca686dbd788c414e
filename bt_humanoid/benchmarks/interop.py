"""What watching a run costs: the real-time factor of a mission plain, with Groot2's monitor (``--groot``, a
client polling statuses as Groot2 does) and with a Rerun recording (``--rerun``).

    python -m bt_humanoid.benchmarks.interop [--runs 3] [--mission missions/demo.yaml]

The modes take turns run after run (plain, groot, rerun, plain, …) so that a machine busier at one moment
weighs on all of them; each run is a fresh stack, pinned to one core with the watchers' threads. The
real-time factor is bt-run's: simulated time over the wall time of ``MissionRun.execute()``; the set-up
(logging the geometry, building the tree XML) and the end (the recording's last flush) are timed apart.
"""

from __future__ import annotations

import statistics
import struct
import tempfile
import threading
import time
from pathlib import Path

from bt_humanoid.benchmarks.common import benchmark_parser, parse_benchmark_args, save_figures
from bt_humanoid.engine.runner import MissionRun, stack_for
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.paths import missions_dir

MODES = ("plain", "groot", "rerun")
POLL_HZ = 10.0  # how often the client asks for statuses (Groot2 polls its monitored tree a few times a second)
PORT = 17667


class _Poller:
    """A Groot2 stand-in: asks for the tree once, then for the statuses at ``rate`` until stopped."""

    def __init__(self, port: int, rate: float) -> None:
        import zmq

        self.socket = zmq.Context.instance().socket(zmq.REQ)
        self.socket.setsockopt(zmq.LINGER, 0)
        self.socket.setsockopt(zmq.RCVTIMEO, 5000)
        self.socket.connect(f"tcp://127.0.0.1:{port}")
        self.period = 1.0 / rate
        self.replies = 0
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._poll, daemon=True)
        self.thread.start()

    def _ask(self, kind: str) -> None:
        self.socket.send_multipart([struct.pack("<BBI", 2, ord(kind), self.replies)])
        self.socket.recv_multipart()
        self.replies += 1

    def _poll(self) -> None:
        self._ask("T")
        while not self.stop.wait(self.period):
            self._ask("S")

    def close(self) -> None:
        self.stop.set()
        self.thread.join()
        self.socket.close(linger=0)


def one_run(mission: Path, mode: str, seed: int, folder: Path) -> dict:
    """One run of ``mission`` in ``mode``: its real-time factor, and the watcher's set-up and closing times."""
    spec = MissionLoader().load_file(mission)
    stack = stack_for(spec, seed)
    run = MissionRun(stack, spec)
    started = time.perf_counter()
    watcher = poller = None
    if mode == "groot":
        from bt_humanoid.interop.btcpp import mission_document
        from bt_humanoid.interop.groot2_server import Groot2Server
        from bt_humanoid.interop.groot2_tree import groot2_tree

        watcher = Groot2Server(groot2_tree(mission_document(mission), run.compiled), PORT)
        run.executor.tick_listeners.append(watcher.snapshot)
        poller = _Poller(PORT, POLL_HZ)
    elif mode == "rerun":
        from bt_humanoid.viz.rerun_recorder import RerunRecorder

        watcher = RerunRecorder(stack, folder / "run.rrd")
    set_up = time.perf_counter() - started
    try:
        result = run.execute()
    finally:
        closing = time.perf_counter()
        if poller is not None:
            poller.close()
        if watcher is not None:
            watcher.close()
        closed = time.perf_counter() - closing
        stack.close()
    figures = {"rtf": result.real_time_factor, "sim_time": result.sim_time, "wall_time": result.wall_time}
    figures.update(set_up_s=set_up, close_s=closed, success=result.success)
    if poller is not None:
        figures["status_replies"] = poller.replies - 1
    if mode == "rerun":
        figures["rrd_mb"] = (folder / "run.rrd").stat().st_size / 1e6
    return figures


def main(argv: list[str] | None = None) -> None:
    parser = benchmark_parser(__doc__, "runs", 3, "runs of each mode")
    parser.add_argument("--mission", type=Path, default=missions_dir() / "demo.yaml", help="mission to run")
    args = parse_benchmark_args(parser, argv, "runs")
    results: dict[str, list[dict]] = {mode: [] for mode in MODES}
    with tempfile.TemporaryDirectory() as folder:
        for index in range(args.runs):
            for mode in MODES:
                figures = one_run(args.mission, mode, args.seed, Path(folder))
                results[mode].append(figures)
                outcome = "" if figures["success"] else ", the mission FAILED"
                print(f"run {index + 1} {mode:<6} real-time factor {figures['rtf']:5.2f}×{outcome}", flush=True)
    plain = statistics.median(r["rtf"] for r in results["plain"])
    summary = {"mission": str(args.mission), "runs": args.runs, "poll_hz": POLL_HZ, "modes": {}}
    print(f"\n{args.mission}: median of {args.runs} runs each")
    print(f"{'mode':<7} {'real-time factor':>17} {'cost':>7} {'set-up':>8} {'close':>7}")
    for mode in MODES:
        runs = results[mode]
        rtf = statistics.median(r["rtf"] for r in runs)
        cost = 1 - rtf / plain
        set_up = statistics.median(r["set_up_s"] for r in runs)
        close = statistics.median(r["close_s"] for r in runs)
        print(f"{mode:<7} {rtf:16.2f}× {cost:7.1%} {set_up * 1e3:6.0f}ms {close * 1e3:5.0f}ms")
        summary["modes"][mode] = {"median_rtf": rtf, "cost": cost, "runs": runs}
    save_figures(args.json, summary)


if __name__ == "__main__":
    main()
