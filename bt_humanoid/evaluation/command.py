"""bt-eval SUITE: run a benchmark suite's episodes in parallel, print the figures and save them as JSON."""

from __future__ import annotations

import cProfile
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
from bt_humanoid.evaluation.profiling import save, top_costs
from bt_humanoid.evaluation.report import markdown, summarize
from bt_humanoid.evaluation.suite import load_suite
from bt_humanoid.paths import missions_dir
from bt_humanoid.sim.sensor_models import ideal_sensors_requested, request_ideal_sensors
from bt_humanoid.yaml_source import display_path


def _parser() -> _Parser:
    parser = _Parser(prog="bt-eval", description="Run a benchmark suite over randomized scenes and report.")
    parser.add_argument("suite", help="a suite YAML file, or the name of one in missions/benchmarks/ (e.g. fetch)")
    parser.add_argument(
        "--markdown", action="store_true", help="SUITE is a saved JSON run: print its README section, run nothing"
    )
    parser.add_argument(
        "--merge",
        nargs="+",
        type=Path,
        metavar="JSON",
        help="SUITE is a saved JSON run: join these saved runs of other episodes to it (same suite, seed, robot "
        "and commit), print the figures and save them (--json); run nothing",
    )
    parser.add_argument("--episodes", type=int, help="how many episodes, from --first (default: the suite's)")
    parser.add_argument(
        "--first",
        type=int,
        default=0,
        help="the first episode's index (default 0): a long run split in parts, joined with --merge",
    )
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
    parser.add_argument("--ideal-sensors", action="store_true", help="exact sensors: no noise, nothing lost")
    parser.add_argument(
        "--profile",
        type=Path,
        metavar="PATH",
        help="run the episodes under cProfile (one worker): save the statistics to PATH, print the top costs per "
        "simulated second",
    )
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
    if args.merge:
        return _merge([Path(args.suite), *args.merge], args.json, console)
    try:
        if args.workers < 1:
            raise UserError(f"--workers {args.workers}: give 1 or more")
        if args.episodes is not None and args.episodes < 1:
            raise UserError(f"--episodes {args.episodes}: give 1 or more")
        if args.seed is not None and args.seed < 0:
            raise UserError(f"--seed {args.seed}: give 0 or more")
        if args.first < 0:
            raise UserError(f"--first {args.first}: give 0 or more")
        if args.profile is not None and (args.workers != 1 or args.backend != "local"):
            raise UserError("--profile profiles this process: give --workers 1 and the local backend")
        file = _suite_file(args.suite)
        suite, _ = load_suite(file, args.scene, args.robot)
        if args.scene is not None:
            args.scene = suite.scene  # a file's path made absolute: the workers may start elsewhere
        last = min(args.first + (args.episodes or suite.episodes), len(suite.instructions) or 10**9)
        indices = list(range(args.first, last))
        if not indices:
            raise UserError(f"--first {args.first}: the suite has {len(suite.instructions)} instructions")
        if args.family is not None:
            if not suite.instructions:
                raise UserError("--family is for suites of instructions (household)")
            indices = [i for i in indices if suite.instructions[i].family == args.family]
            if not indices:
                known = sorted({i.family for i in suite.instructions})
                raise UserError(f"--family {args.family}: no such instructions", hint=f"one of {', '.join(known)}")
        seed = suite.seed if args.seed is None else args.seed
        console.print(
            f"bt-eval [bold]{suite.suite}[/]: {len(indices)} episodes"
            f"{f' ({indices[0]}–{indices[-1]})' if args.first else ''}, seed {seed}, "
            f"{args.workers if args.backend == 'local' else 'ray'} worker(s) — {suite.description}"
        )
        commit = source_commit()  # before the run: the code the episodes ran, whatever is edited meanwhile
        if args.ideal_sensors:
            request_ideal_sensors()  # the workers inherit it
        # CPU time, not wall time: a shared core does not inflate the figures
        profile = cProfile.Profile(time.process_time) if args.profile is not None else None
        if profile is not None:
            profile.enable()
        records, wall = _run(str(file.resolve()), indices, seed, args, console)
        if profile is not None:
            profile.disable()
            _print_profile(profile, args.profile, records, console)
    except UserError as error:
        return _fail_invalid(error)
    command = " ".join(["bt-eval", *(argv if argv is not None else sys.argv[1:])])
    run = {"suite": suite.suite, "file": display_path(file), "seed": seed, "robot": suite.robot, "commit": commit}
    run["sensors"] = "ideal" if ideal_sensors_requested() else "modelled"  # the flag, or BT_IDEAL_SENSORS=1
    return _report({**run, "command": command}, records, wall, args.workers, args.json, console)


def _print_profile(profile: cProfile.Profile, path: Path, records: list[dict[str, Any]], console: Console) -> None:
    simulated = sum(r.get("sim_time", 0.0) for r in records) or 1.0
    save(profile, path)
    console.print(f"  profile: {path} ({simulated:.0f} s simulated); the top costs, CPU ms per simulated second:")
    for cost in top_costs(profile, simulated, 10):
        console.print(f"    {cost.own_ms:8.1f} own {cost.total_ms:8.1f} total {cost.calls:8.0f} calls  {cost.function}")


def _report(
    run: dict[str, Any],
    records: list[dict[str, Any]],
    wall: float,
    workers: int,
    out: Path | None,
    console: Console,
) -> int:
    """Print the figures of ``records`` (what ``run`` names: suite, file, seed, robot, commit, command) and save
    them with the episodes."""
    records.sort(key=lambda r: r["episode"])
    figures = {**run, **summarize(records, wall, workers)}
    _print(console, figures)
    out = out or Path(f"bt-eval-{run['suite']}.json")
    out.write_text(json.dumps({**figures, "episodes": records}, indent=1) + "\n")
    console.print(f"wrote {out}")
    return EXIT_OK


SAME_RUN = ("suite", "seed", "robot", "commit", "sensors")  # what saved parts must share to be one run


def _merge(parts: list[Path], out: Path | None, console: Console) -> int:
    """Join saved runs of one suite's episodes, run apart (``--first``), into one."""
    try:
        saved = [(part, _load_saved(part)) for part in parts]
        first = saved[0][1]
        for part, run in saved:
            if not run.get("commit") or "uncommitted" in run["commit"]:
                raise UserError(
                    f"commit {run.get('commit')!r}: the code it ran is not known",
                    where=display_path(part),
                    hint="join runs made from a clean checkout of one commit",
                )
            for key in SAME_RUN:
                if run.get(key) != first.get(key):
                    raise UserError(
                        f"{key} {run.get(key)!r}, where {display_path(parts[0])} has {first.get(key)!r}",
                        where=display_path(part),
                        hint=f"join parts of one run: the same {', '.join(SAME_RUN)}",
                    )
        seen: dict[int, Path] = {}
        for part, run in saved:
            for record in run["episodes"]:
                if record["episode"] in seen:
                    raise UserError(
                        f"episode {record['episode']} is in {display_path(seen[record['episode']])} too",
                        where=display_path(part),
                        hint="join parts of other episodes (--first)",
                    )
                seen[record["episode"]] = part
    except UserError as error:
        return _fail_invalid(error)
    run = {key: first.get(key) for key in ("suite", "file", "seed", "robot", "commit", "sensors")}
    run["command"] = "\n".join(r["command"] for _, r in saved)
    records = [record for _, r in saved for record in r["episodes"]]
    wall = sum(r["wall_s"] for _, r in saved)
    console.print(f"joined {len(records)} episodes of {len(saved)} runs of {run['suite']}")
    return _report(run, records, wall, max(r["workers"] for _, r in saved), out, console)


def _load_saved(path: Path) -> dict[str, Any]:
    """A run ``bt-eval`` saved as JSON."""
    try:
        run = json.loads(path.read_text())
    except (OSError, ValueError) as error:
        raise UserError(f"not a saved bt-eval run: {error}", where=display_path(path)) from None
    if not isinstance(run, dict) or not isinstance(run.get("episodes"), list) or "suite" not in run:
        raise UserError("not a saved bt-eval run: no suite and episodes in it", where=display_path(path))
    return run


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
        figures = _load_saved(saved)
    except UserError as error:
        return _fail_invalid(error)
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
            if record["success"] and not console.is_terminal:  # a log has no live bar: a line per episode
                progress.console.print(f"  episode {record['episode']}: succeeded ({len(records)}/{len(indices)} done)")
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
        f"with a fall: {figures['episodes_with_fall']}; "
        f"stopped by the bumper: {figures['episodes_with_collision_stop']}; "
        f"tree finished while moving: {figures['episodes_ended_moving']}; "
        f"moving after braking: {figures['episodes_moving_after_brake']}",
        f"stop latency (new command → rest): median {ms(latency['median'], 's', 2)}, "
        f"p95 {ms(latency['p95'], 's', 2)} over {latency['count']}",
        f"plan {ms(figures['plan_ms_median'])}, camera look {ms(figures['look_ms_median'])}, "
        f"whole-body QP {ms(figures['qp_ms_median'], 'ms', 3)} (medians)",
        f"localisation error: p95 {ms(figures.get('localisation_p95_cm_median'), 'cm')} (median over episodes), "
        f"worst {ms(figures.get('localisation_max_cm'), 'cm')}",
        f"real-time factor per core {figures['real_time_factor_per_core']:.1f}×; "
        f"wall {figures['wall_s']:.0f} s with {figures['workers']} worker(s)",
    ]
    for line in lines:
        console.print("  " + line)
