"""Command-line entry points: bt-run, bt-plan, bt-validate and bt-export.

Exit codes: 0 success, 1 mission failed, 2 invalid input. A user error is one
line on stderr naming the place and what would be valid; never a traceback.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import time
from pathlib import Path

from rich.console import Console
from rich.markup import escape

from bt_humanoid.errors import UserError
from bt_humanoid.paths import missions_dir

EXIT_OK, EXIT_FAILED, EXIT_INVALID = 0, 1, 2
SCHEMA_FILE = "mission.schema.json"
GROOT_PORT = 1667  # Groot2's default (BehaviorTree.CPP's Groot2Publisher)


def _fail_invalid(error: UserError) -> int:
    Console(stderr=True, highlight=False).print(f"[bold red]error:[/] {escape(str(error))}", soft_wrap=True)
    return EXIT_INVALID


class _Parser(argparse.ArgumentParser):
    """argparse, but bad usage exits 2 with a one-line message (argparse's own convention)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        self.exit(EXIT_INVALID, f"error: {message}\n")


# --- bt-run -------------------------------------------------------------------------


def _run_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="bt-run", description="Validate, compile and run a mission headless in MuJoCo.")
    parser.add_argument("mission", type=Path, nargs="?", help="mission YAML file (or give --command or --interactive)")
    _command_arguments(parser, "plan from an English command instead of a mission file")
    parser.add_argument(
        "--interactive", action="store_true", help="type commands (and answers, and 'stop') one after another"
    )
    parser.add_argument("--audio", type=Path, metavar="FILE.wav", help="a spoken command: 'hey robot, …'")
    parser.add_argument(
        "--listen",
        nargs="?",
        const="microphone",
        metavar="FILE.wav",
        help="listen for 'hey robot, …' and 'stop' from the microphone (or a WAV file played as one) while working",
    )
    parser.add_argument(
        "--whisper-model", type=Path, metavar="DIR", help="recognise with a local Whisper model (faster-whisper)"
    )
    parser.add_argument("--speak", action="store_true", help="say things aloud through the speaker (espeak-ng)")
    parser.add_argument("--speech-wav", type=Path, metavar="DIR", help="also write everything said as WAV files here")
    parser.add_argument("--seed", type=int, default=None, help="random seed (default: the mission's)")
    parser.add_argument("--no-live", action="store_true", help="plain status lines instead of the live tree")
    parser.add_argument("--summary-json", type=Path, help="write the run summary to this JSON file")
    parser.add_argument("--events", type=Path, help="write the JSONL event log to this file")
    parser.add_argument("--record", type=Path, help="write a video of the run (.mp4) from the scene camera")
    parser.add_argument("--realtime", action="store_true", help="pace the simulation to the wall clock")
    parser.add_argument("--tick-hz", type=float, default=20.0, help="tree tick rate in simulation time")
    parser.add_argument(
        "--ideal-sensors", action="store_true", help="exact sensors: no noise, nothing lost (robot.yaml's sensors: off)"
    )
    parser.add_argument(
        "--groot",
        nargs="?",
        type=int,
        const=GROOT_PORT,
        metavar="PORT",
        help=f"serve the tree and its statuses to Groot2 on PORT (default {GROOT_PORT}) and PORT + 1 while it runs "
        "(needs pyzmq: docs/groot2.md)",
    )
    parser.add_argument(
        "--rerun",
        type=Path,
        metavar="FILE.rrd",
        help="record the run in 3-D for Rerun's viewer (needs rerun-sdk: docs/rerun.md)",
    )
    return parser


def _command_arguments(parser: argparse.ArgumentParser, command_help: str) -> None:
    parser.add_argument("--command", metavar="TEXT", help=command_help)
    parser.add_argument("--world", default="apartment", help="world of a command (default: apartment)")
    parser.add_argument(
        "--robot",
        help="robot to run on: a command's (default: wheeled_humanoid), or one over a mission file's own "
        "(biped_humanoid walks a base-motion mission)",
    )
    parser.add_argument(
        "--scene",
        metavar="NAME|FILE",
        help="the scene the world starts from: a name in worlds/WORLD/scenes/ or a scene file "
        "(default: the mission's, else the world's own)",
    )
    parser.add_argument(
        "--answer", action="append", default=[], metavar="TEXT", help="answer to the planner's question (repeatable)"
    )
    parser.add_argument("--llm-url", help="OpenAI-compatible endpoint to plan with (or BT_LLM_BASE_URL)")
    parser.add_argument("--llm-model", help="model name at that endpoint (or BT_LLM_MODEL)")
    parser.add_argument("--llm-key", help="API key for that endpoint (or BT_LLM_API_KEY)")


def run_main(argv: list[str] | None = None) -> int:
    parser = _run_parser()
    args = parser.parse_args(argv)
    given = (args.mission is not None, args.command is not None, args.interactive, args.audio, args.listen)
    if sum(map(bool, given)) != 1:
        parser.error("give a mission file, --command TEXT, --audio FILE.wav, --interactive or --listen (one of them)")
    console = Console(soft_wrap=True)
    if args.ideal_sensors:
        from bt_humanoid.sim.sensor_models import request_ideal_sensors

        request_ideal_sensors()
    if args.interactive or args.listen:
        if args.groot is not None or args.rerun is not None:
            parser.error("--groot and --rerun watch one mission: give a mission file, --command or --audio")
        return _interactive(args, console)
    stack = None
    watchers: list = []  # the Groot2 server and the Rerun recorder, when asked for: closed at the end
    try:
        from bt_humanoid.engine.runner import MissionRun, stack_for
        from bt_humanoid.engine.stack import RobotStack
        from bt_humanoid.mission.loader import MissionLoader

        if not 1.0 <= args.tick_hz <= 1000.0:
            raise UserError(f"--tick-hz {args.tick_hz}: out of range", hint="valid: 1 to 1000")
        _check_watchers(args)
        speech = _speech_out(args)
        heard = None
        if args.audio is not None:
            args.command = heard = _heard_command(args, console)
        plan = None
        if args.command is not None:
            # one robot from its first look to its last step: the plan comes from what this stack believes
            stack = RobotStack.load(args.world, _robot(args), args.seed or 0, speak=speech, scene=args.scene)
            outcome = _plan_from_command(args, console, stack)
            if outcome.spec is None:
                stack.close()
                return EXIT_OK if outcome.plan.kind == "stop" else EXIT_INVALID
            spec, plan = outcome.spec, outcome.plan.mission
        else:
            from bt_humanoid.interop.btcpp import load_mission  # YAML, or BehaviorTree.CPP XML

            spec = load_mission(args.mission, MissionLoader(scene=args.scene, robot=args.robot))
            stack = stack_for(spec, args.seed, speak=speech)
        run = MissionRun(stack, spec, tick_hz=args.tick_hz)
        recorder = None
        if args.record:
            from bt_humanoid.viz.recorder import VideoRecorder

            recorder = VideoRecorder(run.sim, args.record)
            stack.observers.append(recorder.capture)
        _watch(args, run, plan, heard, watchers, console)
    except UserError as error:
        for watcher in watchers:
            watcher.close()
        if stack is not None:
            stack.close()
        return _fail_invalid(error)

    if args.realtime:
        _pace_to_wall_clock(stack)

    def on_interrupt(signum: int, frame: object) -> None:
        if run.stop_monitor.reason is not None:
            raise KeyboardInterrupt
        run.request_stop("stop requested (Ctrl-C)")

    previous = signal.signal(signal.SIGINT, on_interrupt)
    live = not args.no_live and console.is_terminal
    try:
        if live:
            from bt_humanoid.viz.live import LiveTreeView

            with LiveTreeView(run.executor, console):
                result = run.execute()
        else:
            from bt_humanoid.viz.live import print_event

            console.print(f"mission: {spec.header.mission}  ({args.mission or 'from the command'})", highlight=False)
            run.events.listeners.append(lambda event: print_event(console, event))
            result = run.execute()
    finally:
        signal.signal(signal.SIGINT, previous)
        for watcher in watchers:
            watcher.close()
        stack.close()
        if recorder is not None:
            recorder.close()

    _print_summary(console, result, args)
    if args.summary_json:
        args.summary_json.parent.mkdir(parents=True, exist_ok=True)
        args.summary_json.write_text(json.dumps(result.summary(), indent=2) + "\n")
    if args.events:
        result.events.write(args.events)
    return EXIT_OK if result.success else EXIT_FAILED


def _check_watchers(args: argparse.Namespace) -> None:
    """--groot and --rerun need their packages: say so before anything is loaded."""
    if args.groot is not None:
        from bt_humanoid.interop.groot2_server import import_zmq

        import_zmq()
    if args.rerun is not None:
        from bt_humanoid.viz.rerun_recorder import import_rerun

        import_rerun()


def _watch(args: argparse.Namespace, run, plan: dict | None, heard: str | None, watchers: list, console: Console):
    """Start what watches the run (``run``: a MissionRun): Groot2's monitor (--groot), Rerun's recording (--rerun).
    Each goes into ``watchers`` as soon as it holds a resource, so that a failure after it still closes it."""
    if args.rerun is not None:
        import yaml

        from bt_humanoid.viz.rerun_recorder import RerunRecorder

        rerun = RerunRecorder(run.stack, args.rerun)
        watchers.append(rerun)
        if heard is not None:
            rerun.note("heard", heard)
        if plan is not None:
            rerun.note("planned", yaml.safe_dump(plan, sort_keys=False, allow_unicode=True).rstrip())
    if args.groot is not None:
        from bt_humanoid.interop.btcpp import mission_document
        from bt_humanoid.interop.groot2_server import Groot2Server
        from bt_humanoid.interop.groot2_tree import groot2_tree

        tree = groot2_tree(mission_document(plan if plan is not None else args.mission), run.compiled)
        server = Groot2Server(tree, args.groot)
        watchers.insert(0, server)  # closed first: the monitor goes before the recording is finished
        run.executor.tick_listeners.append(server.snapshot)
        console.print(f"Groot2: connect to port {args.groot} ({len(tree.nodes)} nodes)", highlight=False)


def _robot(args: argparse.Namespace) -> str:
    """The robot a command (typed, spoken or interactive) runs on: --robot, else the wheeled humanoid."""
    return args.robot or "wheeled_humanoid"


def _pace_to_wall_clock(stack) -> None:  # a RobotStack (imported late: it loads MuJoCo)
    """Hold each control step back until the wall clock catches up with simulation time."""
    started = time.perf_counter() - stack.sim.time

    def pace() -> None:
        ahead = stack.sim.time - (time.perf_counter() - started)
        if ahead > 0:
            time.sleep(ahead)

    stack.observers.append(pace)


def _print_summary(console: Console, result, args: argparse.Namespace) -> None:
    ok = result.success
    verdict = "[bold green]SUCCESS[/]" if ok else "[bold red]FAILURE[/]"
    console.print(f"\n{verdict}  {result.mission}")
    console.print(f"  tree: {result.tree_status}", highlight=False)
    if result.safety:
        console.print(f"  safety stop: {result.safety}", highlight=False, markup=False)
    if result.cause:
        console.print(f"  failed: {result.cause}", highlight=False, markup=False)
    for condition in result.conditions:
        mark = "[green]✔[/]" if condition.holds else "[red]✘[/]"
        console.print(f"  {mark} {condition.condition}: {condition.detail}", highlight=False)
    console.print(
        f"  sim time {result.sim_time:.2f} s, wall time {result.wall_time:.2f} s, "
        f"real-time factor {result.real_time_factor:.1f}×",
        highlight=False,
    )
    if args.record:
        console.print(f"  video: {args.record}", highlight=False)
    if args.rerun:
        console.print(f"  rerun recording: {args.rerun}  (view it: rerun {args.rerun})", highlight=False)


# --- commands: bt-plan, bt-run --command -----------------------------------------------


def _plan_from_command(args: argparse.Namespace, console: Console, stack):  # stack: a RobotStack
    """Plan ``--command`` from what ``stack`` sees at its first look; print what the robot says and the mission;
    ask questions of ``--answer`` or the user."""
    import yaml

    from bt_humanoid.commanding import plan_from_here

    if not args.command.strip():
        raise UserError("--command is empty", hint='say what to do, e.g. --command "pick up the red cube"')
    answers = iter(args.answer)

    def answer(question: str) -> str | None:
        console.print(f"[bold]robot:[/] {question}", highlight=False)
        reply = next(answers, None)
        if reply is None and sys.stdin.isatty():
            reply = console.input("[bold]you:[/] ")
        elif reply is not None:
            console.print(f"[bold]you:[/] {reply}", highlight=False)
        return reply

    outcome = plan_from_here(stack, args.command, answer, _planner(args))
    plan = outcome.plan
    if plan.kind == "mission":
        console.print(f"[bold]robot:[/] {plan.say}", highlight=False)
        console.print(yaml.safe_dump(plan.mission, sort_keys=False, allow_unicode=True).rstrip(), highlight=False)
    elif plan.kind == "stop":
        console.print(f"[bold]robot:[/] {plan.say}", highlight=False)
    else:
        where = "not understood" if plan.kind == "refusal" else "needs an answer (give --answer TEXT)"
        Console(stderr=True, highlight=False).print(
            f"[bold red]error:[/] command {args.command!r} {where}: {plan.say}", soft_wrap=True
        )
    return outcome


def _planner(args: argparse.Namespace):
    """The embedded planner, or an LLM one when --llm-url and --llm-model (or their variables) are given."""
    from bt_humanoid.commanding import make_planner
    from bt_humanoid.language.llm import LlmSettings

    settings = LlmSettings.from_environment(args.llm_url, args.llm_model, args.llm_key)
    if (args.llm_url or args.llm_model) and settings is None:
        hint = "give both, or set BT_LLM_BASE_URL and BT_LLM_MODEL"
        raise UserError("--llm-url and --llm-model go together", hint=hint)
    return make_planner(settings)


def _interactive(args: argparse.Namespace, console: Console) -> int:
    """Commands typed (--interactive) or spoken (--listen) until they end; the robot works on one simulation."""
    import queue
    import threading

    from bt_humanoid.commanding import InteractiveSession

    lines: queue.Queue[str | None] = queue.Queue()
    try:
        speech = _speech_out(args)

        def say(text: str) -> None:
            console.print(f"[bold]robot:[/] {text}", highlight=False)
            if speech is not None:
                speech(text)

        from bt_humanoid.engine.stack import RobotStack

        planner = _planner(args)
        stack = RobotStack.load(args.world, _robot(args), args.seed or 0, speak=say, scene=args.scene)
        session = InteractiveSession(stack, lines, say, planner)
        if args.listen:
            relay = _listener_thread(args, lines, session, console)
            _pace_to_wall_clock(session.stack)  # spoken words come in real time; so must the robot move
    except UserError as error:
        return _fail_invalid(error)
    if args.listen:
        from bt_humanoid.language.words import WAKE_WORDS

        say(f"Ready. Say '{WAKE_WORDS[0]}, …' and a command; 'stop' stops me.")
        relay.start()
    else:
        say("Ready. Tell me what to do; 'stop' stops me; end with Ctrl-D.")
        threading.Thread(target=lambda: _read_lines(lines), daemon=True).start()
    try:
        session.serve()
    except KeyboardInterrupt:
        session.request_stop("stop requested (Ctrl-C)")
    return EXIT_OK


def _read_lines(lines) -> None:  # a queue.Queue of typed lines
    for line in sys.stdin:
        lines.put(line.rstrip("\n"))
    lines.put(None)


def _listener_thread(args: argparse.Namespace, lines, session, console: Console):
    """A thread that listens (microphone or file) and passes what it hears to the session as lines."""
    import threading

    from bt_humanoid.commanding import relay_heard
    from bt_humanoid.language.asr import CommandRecognizer
    from bt_humanoid.language.listening import Listener
    from bt_humanoid.language.sound_sources import file_blocks, microphone_blocks

    blocks = microphone_blocks() if args.listen == "microphone" else file_blocks(Path(args.listen))
    world = session.stack.world
    listener = Listener(CommandRecognizer(world, dictation=True), transcriber=_transcriber(args, world))

    def show(label: str, words: str) -> None:
        console.print(f"[bold]{escape(label)}:[/] {escape(words)}", highlight=False)

    def awaiting() -> bool:
        return session.awaiting_answer

    return threading.Thread(target=relay_heard, args=(blocks, listener, lines, awaiting, show), daemon=True)


def _speech_out(args: argparse.Namespace):
    """espeak-ng for what the robot says, when asked for (--speak, --speech-wav); None: printed only."""
    if not (args.speak or args.speech_wav):
        return None
    from bt_humanoid.language.audio import SpeechOut, espeak_available

    if not espeak_available():
        raise UserError(
            "--speak and --speech-wav need espeak-ng", hint="apt-get install espeak-ng, or run scripts/setup.sh"
        )
    return SpeechOut(speaker=args.speak, folder=args.speech_wav)


def _transcriber(args: argparse.Namespace, world):  # world: a WorldConfig
    """What hears whole utterances: Whisper from --whisper-model, else None (the command grammar decoder)."""
    if args.whisper_model is None:
        return None
    from bt_humanoid.language.whisper_asr import WhisperRecognizer, world_prompt

    return WhisperRecognizer.from_folder(args.whisper_model, world_prompt(world))


def _heard_command(args: argparse.Namespace, console: Console) -> str:
    """The command spoken in a WAV file after the wake word; a UserError if there is none."""
    from bt_humanoid.language.asr import WAKE_WORD, CommandRecognizer
    from bt_humanoid.language.sound_sources import wav_samples
    from bt_humanoid.sim.world_config import load_world_config

    audio = args.audio
    world = load_world_config(args.world)
    samples = wav_samples(audio, "give a WAV file of a spoken command")
    heard = (_transcriber(args, world) or CommandRecognizer(world, dictation=True)).transcribe(samples)
    console.print(f"[bold]heard:[/] {heard.shown or '(nothing I understand)'}", highlight=False)
    if not heard.woken:
        raise UserError(f"{audio}: no '{WAKE_WORD}' at the start", hint=f"say '{WAKE_WORD}, …' and then the command")
    if not heard.command:
        raise UserError(f"{audio}: '{WAKE_WORD}' but no command after it")
    return heard.command


def _plan_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="bt-plan", description="Print the mission the planner makes of an English command.")
    parser.add_argument("text", help='the command, e.g. "pick up the red cube and put it on the counter"')
    _command_arguments(parser, argparse.SUPPRESS)
    return parser


def plan_main(argv: list[str] | None = None) -> int:
    args = _plan_parser().parse_args(argv)
    args.command = args.text
    console = Console(soft_wrap=True)
    stack = None
    try:
        from bt_humanoid.engine.stack import RobotStack

        stack = RobotStack.load(args.world, _robot(args), scene=args.scene)
        outcome = _plan_from_command(args, console, stack)
    except UserError as error:
        return _fail_invalid(error)
    finally:
        if stack is not None:
            stack.close()
    return EXIT_OK if outcome.plan.kind in ("mission", "stop") else EXIT_INVALID


# --- bt-validate ----------------------------------------------------------------------


def _validate_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="bt-validate", description="Check missions and behaviours without running them.")
    parser.add_argument("files", nargs="*", type=Path, help="mission or behaviour YAML files")
    parser.add_argument(
        "--schema", nargs="?", const="-", metavar="PATH", help="write the mission JSON Schema (to stdout with no PATH)"
    )
    parser.add_argument(
        "--expand",
        action="store_true",
        help="print each mission's tree as it will run: every safety guard and recovery step, with the values "
        "it resolved and where each came from",
    )
    return parser


def mission_schema() -> dict:
    from bt_humanoid.mission.behaviors import BehaviorLibrary
    from bt_humanoid.mission.schema import json_schema

    return json_schema(BehaviorLibrary().args_models())


def validate_file(file: Path) -> str:
    """Validate a mission or behaviour file (YAML, or BehaviorTree.CPP XML); returns a one-line description,
    raises UserError."""
    from bt_humanoid.mission.behaviors import load_behavior
    from bt_humanoid.mission.loader import MissionLoader
    from bt_humanoid.yaml_source import read_yaml

    if file.suffix.lower() == ".xml":
        return _validate_xml(file)
    source = read_yaml(file)
    if isinstance(source.data, dict) and "behavior" in source.data:
        behavior = load_behavior(file)
        loader = MissionLoader(check_world=False)
        # a behaviour's tree is checked by expanding it in a throw-away mission with its defaults
        loader.load_data(
            {"mission": f"check {behavior.name}", "tree": {behavior.name: _default_args(behavior)}}, str(file)
        )
        return f"behaviour '{behavior.name}'"
    spec = MissionLoader().load_source(source)
    count = sum(1 for _ in spec.tree.walk())
    return f"mission '{spec.header.mission}' ({count} nodes)"


def _validate_xml(file: Path) -> str:
    """A BehaviorTree.CPP XML mission or behaviour (bt_humanoid/interop/)."""
    from bt_humanoid.interop.btcpp import check_xml

    return check_xml(file)


def _print_expanded(file: Path, console: Console) -> None:
    """The mission in ``file`` as it will run (a behaviour has no robot or world to resolve against)."""
    from bt_humanoid.engine.expand import expand
    from bt_humanoid.mission.loader import MissionLoader
    from bt_humanoid.yaml_source import read_yaml

    if file.suffix.lower() == ".xml":
        from bt_humanoid.interop.btcpp import load_mission

        console.print(expand(load_mission(file)), markup=False)
        return
    source = read_yaml(file)
    if isinstance(source.data, dict) and "behavior" in source.data:
        console.print("  (a behaviour: --expand shows missions; call it from one to see it expanded)")
        return
    console.print(expand(MissionLoader().load_source(source)), markup=False)


def _default_args(behavior) -> dict:
    """Arguments for checking a behaviour's tree on its own (mission/behaviors.py)."""
    from bt_humanoid.mission.behaviors import default_args

    return default_args(behavior)


def validate_main(argv: list[str] | None = None) -> int:
    args = _validate_parser().parse_args(argv)
    console = Console(highlight=False, soft_wrap=True)
    try:
        if args.schema is not None:
            text = json.dumps(mission_schema(), indent=2) + "\n"
            if args.schema == "-":
                sys.stdout.write(text)
            else:
                Path(args.schema).write_text(text)
                console.print(f"wrote {args.schema}")
            if not args.files:
                return EXIT_OK
        if not args.files:
            raise UserError("no files given", hint=f"e.g. bt-validate {missions_dir().name}/*.yaml")
        for file in args.files:
            console.print(f"[green]ok[/] {file}: {validate_file(file)}")
            if args.expand:
                _print_expanded(file, console)
    except UserError as error:
        return _fail_invalid(error)
    return EXIT_OK


# --- bt-export ----------------------------------------------------------------------------


def _export_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="bt-export",
        description="Write a mission or behaviour as BehaviorTree.CPP v4 XML (for Groot2, Nav2 and BehaviorTree.CPP).",
    )
    parser.add_argument("file", type=Path, help="mission or behaviour YAML file (or BehaviorTree.CPP XML, rewritten)")
    parser.add_argument("-o", "--output", type=Path, metavar="FILE.xml", help="write here (default: stdout)")
    parser.add_argument(
        "--no-wrappers",
        action="store_true",
        help="the mission's own tree, without the safety and recovery wrappers the compiler adds: the form "
        "bt-run and bt-validate read back",
    )
    return parser


def export_main(argv: list[str] | None = None) -> int:
    args = _export_parser().parse_args(argv)
    console = Console(highlight=False, soft_wrap=True, stderr=True)
    try:
        from bt_humanoid.interop.btcpp import export_file

        text, note = export_file(args.file, wrappers=not args.no_wrappers)
    except UserError as error:
        return _fail_invalid(error)
    if note:
        console.print(note)
    if args.output is None:
        sys.stdout.write(text)
    else:
        args.output.parent.mkdir(parents=True, exist_ok=True)
        args.output.write_text(text)
        console.print(f"wrote {args.output}")
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(run_main())
