"""Voice benchmark: the planner's command set spoken, noisy, recognised offline, then planned.

    python -m bt_humanoid.benchmarks.voice

Every command of tests/data/commands.yaml is synthesised with espeak-ng in
two voices (en-us, en-gb), each 20 % slower and 20 % faster than the usual
175 words a minute, with white noise added at 20 dB SNR. The recogniser
(pocketsphinx with the world's command grammar) hears it, and the embedded
planner plans what it heard, over the apartment with its five objects known.
A command counts when the plan matches the one expected for the typed text
(the same steps and targets, the same question, a refusal or a stop).

Each utterance is heard twice: whole (the recogniser decodes the clip, as
``bt-run --audio`` does) and streamed (a second of silence before and after,
noise throughout, fed in 100 ms blocks to the listener that ``bt-run
--listen`` uses: voice activity detection, decoding while the person speaks,
stops spotted before the utterance ends). Prints both accuracies, the share
heard word for word, the recogniser's latency (median overall and for
commands of 2.5 to 3.5 seconds; for the stream, the time from the end of the
utterance to its transcript, after the listener's silence wait), stops the
stream reported in commands that are not stops, how many were heard with
unclear speech (refused; free dictation is shown to the person) and the
recogniser's time on those, the accuracy on the same speech without noise
(as espeak-ng writes it, with digital silence between words), and the
embedded planner's latency from typed text to a validated mission. Pinned
to one CPU core;
``--json PATH`` also writes the figures.
"""

from __future__ import annotations

import statistics
import time
from typing import Any

import numpy as np
import yaml

from bt_humanoid.benchmarks.common import benchmark_parser, parse_benchmark_args, save_figures
from bt_humanoid.commanding import plan_command
from bt_humanoid.language.asr import CommandRecognizer, Transcript
from bt_humanoid.language.audio import RATE, spoken, with_noise
from bt_humanoid.language.embedded import EmbeddedPlanner
from bt_humanoid.language.listening import END_SILENCE, Listener
from bt_humanoid.language.plan import PlanningContext, plan_outcome
from bt_humanoid.language.words import normalise
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.paths import project_root
from bt_humanoid.testing.told import told_planning_context

VOICES = ("en-us", "en-gb")
SPEEDS = (140, 210)  # words a minute: 175 ± 20 %
SNR_DB = 20.0
BLOCK = RATE // 10  # samples a microphone block holds (100 ms)


def _as_read(text: str) -> str:
    """Words as the planner reads them, without commas: what "heard word for word" compares (a trailing "now"
    that the grammar heard and the planner leaves out is not a word lost)."""
    return " ".join(normalise(text).replace(",", " ").split())


def streamed(recognizer: CommandRecognizer, clean: np.ndarray, rng: np.random.Generator) -> tuple[Transcript, bool]:
    """What the listener makes of ``clean`` said between two seconds of silence, noise throughout.

    Returns the transcript the robot acts on last (a stop, or the command that followed a false one) and whether
    a stop was reported. The transcript's seconds are the decoding time of the block that reported it: the time
    from the end of the utterance to its transcript, after the listener's silence wait.
    """
    quiet = np.zeros(RATE, dtype=np.int16)
    audio = with_noise(np.concatenate([quiet, clean, quiet]), SNR_DB, rng)
    listener = Listener(recognizer)
    heard = []
    for start in range(0, len(audio), BLOCK):
        began = time.perf_counter()
        for item in listener.feed(audio[start : start + BLOCK]):
            heard.append((item, time.perf_counter() - began))
    heard.extend((item, 0.0) for item in listener.close())
    stopped = any(item.kind == "stop" for item, _ in heard)
    if not heard:
        return Transcript("", 0.0), False
    item, seconds = heard[-1]
    return Transcript(item.text, seconds), stopped


def planned(planner: EmbeddedPlanner, heard: Transcript, context: PlanningContext) -> dict[str, Any]:
    """What the robot makes of a transcript, as ``bt-run`` plans it (steps and targets, a question, a refusal or a
    stop); questions go unanswered."""
    return plan_outcome(plan_command(heard.command or "(nothing heard)", context, lambda _: None, planner).plan)


def main(argv: list[str] | None = None) -> int:
    parser = benchmark_parser(__doc__, "repeats", 1, "noise draws per command, voice and speed")
    args = parse_benchmark_args(parser, argv, "repeats")
    commands = yaml.safe_load((project_root() / "tests" / "data" / "commands.yaml").read_text())
    context = told_planning_context("apartment")  # language, not detection: the objects are told
    recognizer = CommandRecognizer(context.world, dictation=True)  # as bt-run hears
    # Noise-free speech gets its own decoder: a decoder's cepstral mean carries from one utterance to the next
    quiet_recognizer = CommandRecognizer(context.world, dictation=True)
    planner = EmbeddedPlanner()
    planner.plan("bring me something to drink", context)  # the sentence embeddings load once
    rng = np.random.default_rng(args.seed)
    total = len(commands) * len(VOICES) * len(SPEEDS) * args.repeats
    print(f"bt-humanoid voice benchmark: {total} utterances, noise {SNR_DB:.0f} dB SNR, seed {args.seed} (one core)")
    started = time.perf_counter()
    correct = verbatim = stream_correct = false_stops = not_stops = noise_free_correct = 0
    stream_latencies: list[float] = []
    latencies: list[float] = []
    three_seconds: list[float] = []
    unclear_seconds: list[float] = []  # recogniser time on whole utterances heard with unclear speech
    misses: list[str] = []
    typed: list[float] = []
    for command in commands:
        expected = {k: v for k, v in command.items() if k != "text"}
        planned_at = time.perf_counter()
        plan = planner.plan(command["text"], context)
        if plan.mission is not None:
            MissionLoader.for_plans().load_data(plan.mission)
        typed.append(time.perf_counter() - planned_at)
        for voice in VOICES:
            for speed in SPEEDS:
                clean = spoken(command["text"], voice, speed)
                three_second = 2.5 <= len(clean) / RATE <= 3.5
                without_noise = quiet_recognizer.transcribe(clean)
                noise_free_correct += planned(planner, without_noise, context) == expected
                for _ in range(args.repeats):
                    heard = recognizer.transcribe(with_noise(clean, SNR_DB, rng))
                    latencies.append(heard.seconds)
                    if heard.unclear:
                        unclear_seconds.append(heard.seconds)
                    if three_second:
                        three_seconds.append(heard.seconds)
                    got = planned(planner, heard, context)
                    correct += got == expected
                    verbatim += _as_read(heard.command) == _as_read(command["text"])
                    if got != expected:
                        misses.append(f"{command['text']!r} ({voice}, {speed} wpm) heard as {heard.text!r}")
                    live, stopped = streamed(recognizer, clean, rng)
                    live_correct = planned(planner, live, context) == expected
                    stream_correct += live_correct
                    false_stops += stopped and not expected.get("stop")
                    not_stops += not expected.get("stop")
                    if three_second and live.text:
                        stream_latencies.append(live.seconds)
                    if not live_correct:
                        misses.append(f"{command['text']!r} ({voice}, {speed} wpm) streamed, heard as {live.text!r}")
        print(f"  {command['text']}", flush=True)
    figures = {
        "utterances": total,
        "command_accuracy": correct / total,
        "heard_verbatim": verbatim / total,
        "asr_latency_median_ms": statistics.median(latencies) * 1000,
        "asr_latency_3s_median_ms": statistics.median(three_seconds) * 1000 if three_seconds else None,
        "three_second_commands": len(three_seconds),
        "unclear_utterances": len(unclear_seconds),
        "unclear_latency_median_ms": statistics.median(unclear_seconds) * 1000 if unclear_seconds else None,
        "stream_command_accuracy": stream_correct / total,
        "stream_latency_3s_median_ms": statistics.median(stream_latencies) * 1000 if stream_latencies else None,
        "stream_silence_wait_ms": END_SILENCE * 1000,
        "stream_false_stops": false_stops,
        "noise_free_command_accuracy": noise_free_correct / (total // args.repeats),
        "not_stop_utterances": not_stops,
        "typed_plan_latency_median_ms": statistics.median(typed) * 1000,
        "misses": misses,
        "wall_s": round(time.perf_counter() - started, 1),
    }
    print()
    print(f"  commands planned as typed: {figures['command_accuracy']:.1%} (≥ 95 %) of {total}")
    print(f"  heard word for word: {figures['heard_verbatim']:.1%}")
    print(
        f"  recogniser latency: median {figures['asr_latency_median_ms']:.0f} ms; for 3-second commands "
        f"({len(three_seconds)}) median {figures['asr_latency_3s_median_ms'] or float('nan'):.0f} ms (≤ 300 ms)"
    )
    print(
        f"  heard with unclear speech (refused; free dictation shown): {figures['unclear_utterances']}, recogniser "
        f"latency median {figures['unclear_latency_median_ms'] or float('nan'):.0f} ms with the dictation"
    )
    print(f"  streamed (listener): planned as typed {figures['stream_command_accuracy']:.1%}; ", end="")
    print(
        f"transcript {figures['stream_latency_3s_median_ms'] or float('nan'):.0f} ms (median, 3-second commands) "
        f"after the {END_SILENCE * 1000:.0f} ms silence that ends an utterance; "
        f"false stops {false_stops} of {not_stops}"
    )
    print(f"  without noise: planned as typed {figures['noise_free_command_accuracy']:.1%}")
    print(f"  typed text → validated mission: median {figures['typed_plan_latency_median_ms']:.1f} ms (≤ 50 ms)")
    for miss in misses[:40]:
        print(f"    {miss}")
    save_figures(args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
