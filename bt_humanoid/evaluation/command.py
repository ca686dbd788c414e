"""bt-eval SUITE: run a benchmark suite's episodes in parallel, print the figures and save them as JSON."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn
from rich.table import Table

from bt_humanoid.cli import EXIT_OK, _fail_invalid, _Parser
from bt_humanoid.errors import UserError
from bt_humanoid.evaluation.report import markdown, summarize
from bt_humanoid.evaluation.suite import load_suite
from bt_humanoid.paths import missions_dir
from bt_humanoid.yaml_source import display_path


def _parser() -> _Parser:
    parser = _Parser(prog="bt-eval", description="Run a benchmark suite over randomized scenes and report.")
    parser.add_argument("suite", help="a suite YAML file, or the name of one in missions/benchmarks/ (e.g. fetch)")
    parser.add_argument(
        "--markdown", action="store_true", help="SUITE is a saved JSON run: print its README section, run nothing"
    )
    parser.add_argument("--episodes", type=int, help="how many episodes (default: the suite's)")
    parser.add_argument("--seed", type=int, help="draws every scene (default: the suite's)")
    parser.add_argument(
        "--scene",
        metavar="NAME|FILE",
        help="the scene episodes start from: a name in the world's scenes/ or a scene file (default: the suite's)",
    )
    parser.add_argument(
        "--plan-only",
        action="store_true",
        help="household suites: plan each instruction and judge the plan, run nothing in physics (seconds, not hours)",
    )
    parser.add_argument("--robot", help="the robot episodes run on, a folder of robots/ (default: the suite's)")
    parser.add_argument("--family", help="household suites: only the instructions of this family")
    parser.add_argument("--workers", type=int, default=1, help="worker processes, one core each (default 1)")
    parser.add_argument("--backend", choices=["local", "ray"], default="local", help="where episodes run")
    parser.add_argument("--address", help="Ray cluster address for --backend ray (default: start a local Ray)")
    parser.add_argument("--json", type=Path, help="write figures and episodes here (default: bt-eval-SUITE.json)")
    return parser


def _suite_file(name: str) -> Path:
    path = Path(name)
    if path.suffix in (".yaml", ".yml") or path.exists():
        return path
    return missions_dir() / "benchmarks" / f"{name}.yaml"


def eval_main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    console = Console(highlight=False, soft_wrap=True)
    if args.markdown:
        return _print_markdown(Path(args.suite))
    try:
        if args.workers < 1:
            raise UserError(f"--workers {args.workers}: give 1 or more")
        if args.episodes is not None and args.episodes < 1:
            raise UserError(f"--episodes {args.episodes}: give 1 or more")
        if args.seed is not None and args.seed < 0:
            raise UserError(f"--seed {args.seed}: give 0 or more")
        file = _suite_file(args.suite)
        suite, _ = load_suite(file, args.scene, args.robot)
        if args.scene is not None:
            args.scene = suite.scene  # a file's path made absolute: the workers may start elsewhere
        episodes = min(args.episodes or suite.episodes, len(suite.instructions) or 10**9)
        indices = list(range(episodes))
        if args.family is not None:
            if not suite.instructions:
                raise UserError("--family is for suites of instructions (household)")
            indices = [i for i in indices if suite.instructions[i].family == args.family]
            if not indices:
                known = sorted({i.family for i in suite.instructions})
                raise UserError(f"--family {args.family}: no such instructions", hint=f"one of {', '.join(known)}")
        seed = suite.seed if args.seed is None else args.seed
        console.print(
            f"bt-eval [bold]{suite.suite}[/]: {len(indices)} episodes, seed {seed}, "
            f"{args.workers if args.backend == 'local' else 'ray'} worker(s) — {suite.description}"
        )
        commit = source_commit()  # before the run: the code the episodes ran, whatever is edited meanwhile
        records, wall = _run(str(file.resolve()), indices, seed, args, console)
    except UserError as error:
        return _fail_invalid(error)
    records.sort(key=lambda r: r["episode"])
    figures = summarize(records, wall, args.workers)
    command = " ".join(["bt-eval", *(argv if argv is not None else sys.argv[1:])])
    figures = {
        "suite": suite.suite,
        "file": display_path(file),
        "seed": seed,
        "command": command,
        "commit": commit,
        **figures,
    }
    _print(console, figures)
    out = args.json or Path(f"bt-eval-{suite.suite}.json")
    out.write_text(json.dumps({**figures, "episodes": records}, indent=1) + "\n")
    console.print(f"wrote {out}")
    return EXIT_OK


RUN_INPUTS = ["bt_humanoid", "behaviors", "missions", "robots", "worlds", "pyproject.toml"]  # what a run is made of


def source_commit() -> str | None:
    """The commit the code was run from ("+ uncommitted changes" when the code, missions, robots or worlds
    differ from it; results and docs do not count); None outside git."""
    root = Path(__file__).resolve().parents[2]
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True, text=True)
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--", *RUN_INPUTS], cwd=root, capture_output=True, text=True
        )
    except OSError:
        return None
    if head.returncode != 0:
        return None
    return head.stdout.strip() + (" + uncommitted changes" if dirty.stdout.strip() else "")


def _print_markdown(saved: Path) -> int:
    try:
        figures = json.loads(saved.read_text())
    except (OSError, ValueError) as error:
        return _fail_invalid(UserError(f"not a saved bt-eval run: {error}", where=str(saved)))
    print(markdown(figures, figures.get("command", f"bt-eval {figures['file']}")), end="")
    return EXIT_OK


def _run(file: str, indices: list[int], seed: int, args, console: Console) -> tuple[list[dict[str, Any]], float]:
    from bt_humanoid.evaluation.backends import run_local, run_ray

    stream = (
        run_ray(file, indices, seed, args.address, args.scene, args.plan_only, args.robot)
        if args.backend == "ray"
        else run_local(file, indices, seed, args.workers, args.scene, args.plan_only, args.robot)
    )
    records: list[dict[str, Any]] = []
    started = time.perf_counter()
    columns = (
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[rate]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
    )
    with Progress(*columns, console=console, transient=False) as progress:
        bar = progress.add_task("episodes", total=len(indices), rate="")
        for record in stream:
            records.append(record)
            wins = sum(r["success"] for r in records)
            rate = f"{wins}/{len(records)} succeeded"
            if "planned" in record:
                rate = f"{sum(r['planned'] for r in records)}/{len(records)} planned right, " + rate
            progress.update(bar, advance=1, rate=rate)
            if record.get("plan_failure"):
                said = f"  episode {record['episode']} ({record['command']})"
                progress.console.print(f"{said}: plan {record['plan_failure']}")
            elif not record["success"] and not args.plan_only:
                progress.console.print(
                    f"  episode {record['episode']} ({record['command'] or record['task']}"
                    f"{', fault ' + record['fault'] if record['fault'] else ''}): {record['failure']}"
                )
    return records, time.perf_counter() - started


def _percent(rate: dict[str, Any]) -> str:
    low, high = rate["ci95"]
    return f"{rate['rate']:.1%}  [{low:.1%}, {high:.1%}]  ({rate['successes']}/{rate['episodes']})"


def _print(console: Console, figures: dict[str, Any]) -> None:
    table = Table(title=f"{figures['suite']}: success with 95 % confidence interval", title_justify="left")
    table.add_column("group")
    if "planning" in figures:  # household instructions: the plan and the run, per family
        table.add_column("planned right")
        table.add_column("done")
        table.add_row("all", _percent(figures["planning"]), _percent(figures["success"]))
        for family, rates in figures["by_family"].items():
            table.add_row(family, _percent(rates["planned"]), _percent(rates["success"]))
    else:
        table.add_column("success")
        table.add_row("all", _percent(figures["success"]))
        for key in ("by_task", "by_object", "by_fault"):
            for name, rate in figures[key].items():
                table.add_row(f"{key[3:]}: {name}", _percent(rate))
    console.print(table)

    def ms(value: float | None, unit: str = "ms", digits: int = 1) -> str:
        return f"{value:.{digits}f} {unit}" if value is not None else "-"

    done, latency = figures["time_to_complete_s"], figures["stop_latency_s"]
    lines = [
        f"time to complete (successes): median {ms(done['median'], 's')}, p95 {ms(done['p95'], 's')}",
        f"episodes with a person touched: {figures['episodes_with_person_contact']}; "
        f"stopped by the bumper: {figures['episodes_with_collision_stop']}; "
        f"tree finished while moving: {figures['episodes_ended_moving']}; "
        f"moving after braking: {figures['episodes_moving_after_brake']}",
        f"stop latency (new command → rest): median {ms(latency['median'], 's', 2)}, "
        f"p95 {ms(latency['p95'], 's', 2)} over {latency['count']}",
        f"plan {ms(figures['plan_ms_median'])}, camera look {ms(figures['look_ms_median'])}, "
        f"whole-body QP {ms(figures['qp_ms_median'], 'ms', 3)} (medians)",
        f"real-time factor per core {figures['real_time_factor_per_core']:.1f}×; "
        f"wall {figures['wall_s']:.0f} s with {figures['workers']} worker(s)",
    ]
    for line in lines:
        console.print("  " + line)
