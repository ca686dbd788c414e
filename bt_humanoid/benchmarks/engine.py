"""Engine benchmark: compile time, executor overhead per tick, real-time factor of the demo.

    python -m bt_humanoid.benchmarks.engine

Runs pinned to one CPU core. Prints a table; ``--json PATH`` also writes it.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from bt_humanoid.benchmarks.common import pin_to_one_core, save_figures
from bt_humanoid.paths import missions_dir
from bt_humanoid.testing.scenario import build_run


def generated_mission(leaves: int, running: bool) -> dict:
    """A mission of about ``leaves`` leaves in groups of 10.

    ``running``: a parallel of long waits, so every node is ticked every tick
    (the worst case); otherwise a sequence of quick checks and sets.
    """
    groups = []
    for g in range(leaves // 10):
        if running:
            children = [{"wait": {"seconds": 1000}} for _ in range(10)]
            groups.append({"parallel": {"policy": "all", "children": children}})
        else:
            children = [{"set": {"key": f"k{g}_{i}", "value": i}} for i in range(5)]
            children += [{"check": {"key": f"k{g}_{i}", "op": "equals", "value": i}} for i in range(5)]
            groups.append({"sequence": children})
    tree = {"parallel": {"policy": "all", "children": groups}} if running else {"sequence": groups}
    return {"mission": f"generated {leaves} leaves", "tree": tree}


def node_count(run) -> int:
    return sum(1 for _ in run.compiled.root.iterate())


def bench_compile(leaves: int = 500, repeats: int = 5) -> dict:
    from bt_humanoid.engine.compiler import Compiler
    from bt_humanoid.mission.loader import MissionLoader

    mission = generated_mission(leaves, running=False)
    run = build_run(mission)
    mission_nodes = sum(1 for _ in run.spec.tree.walk())
    load_times, compile_times = [], []
    for _ in range(repeats):
        started = time.perf_counter()
        spec = MissionLoader().load_data(mission)
        loaded = time.perf_counter()
        Compiler(run.context, run.supervisor).compile(spec)
        done = time.perf_counter()
        load_times.append(loaded - started)
        compile_times.append(done - loaded)
    return {
        "mission_nodes": mission_nodes,
        "tree_nodes_with_wrappers": node_count(run),
        "validate_ms": statistics.median(load_times) * 1e3,
        "compile_ms": statistics.median(compile_times) * 1e3,
    }


def bench_tick_overhead(leaves: int = 500, ticks: int = 200) -> dict:
    """Executor.tick() against root.tick_once() on the same compiled tree, physics excluded."""
    results = {}
    for running in (True, False):
        bare_run, exec_run = (
            build_run(generated_mission(leaves, running)),
            build_run(generated_mission(leaves, running)),
        )
        bare_root, executor = bare_run.compiled.root, exec_run.executor
        bare_root.tick_once()
        executor.tick()
        started = time.perf_counter()
        for _ in range(ticks):
            bare_root.tick_once()
        bare = (time.perf_counter() - started) / ticks
        started = time.perf_counter()
        for _ in range(ticks):
            executor.tick()
        ours = (time.perf_counter() - started) / ticks
        label = "all_running" if running else "sequence"
        results[label] = {
            "tree_nodes": node_count(exec_run),
            "bare_tick_us": bare * 1e6,
            "executor_tick_us": ours * 1e6,
            "ratio": ours / bare,
        }
    return results


def bench_demo_rtf(repeats: int = 3) -> dict:
    factors, sim_times = [], []
    for _ in range(repeats):
        run = build_run(missions_dir() / "demo.yaml")
        result = run.execute()
        run.stack.close()  # its cameras' off-screen contexts: one per run adds up over a benchmark
        assert result.success, result.summary()
        factors.append(result.real_time_factor)
        sim_times.append(result.sim_time)
    return {"sim_time_s": statistics.median(sim_times), "real_time_factor": statistics.median(factors)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, help="also write the figures here")
    args = parser.parse_args(argv)
    pin_to_one_core()
    print("bt-humanoid engine benchmark (one core)")
    figures = {"compile": bench_compile(), "tick": bench_tick_overhead(), "demo": bench_demo_rtf()}
    c = figures["compile"]
    print(
        f"  compile: {c['mission_nodes']}-node mission ({c['tree_nodes_with_wrappers']} nodes with wrappers): "
        f"validate {c['validate_ms']:.1f} ms, compile {c['compile_ms']:.1f} ms"
    )
    for label, t in figures["tick"].items():
        print(
            f"  tick ({label}, {t['tree_nodes']} nodes): bare py_trees {t['bare_tick_us']:.0f} µs, "
            f"executor {t['executor_tick_us']:.0f} µs, ratio {t['ratio']:.2f}× (target ≤ 1.5×)"
        )
    d = figures["demo"]
    print(
        f"  demo mission: {d['sim_time_s']:.1f} s simulated, real-time factor {d['real_time_factor']:.1f}× "
        "(target ≥ 10×)"
    )
    save_figures(args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
