"""Spoken commands: the grammar of this world's words, recognition of synthesised speech, bt-run --audio end to end."""

import json
import re
import subprocess
import sys
import wave
from types import SimpleNamespace

import numpy as np
import pytest

from bt_humanoid.cli import EXIT_INVALID, EXIT_OK, run_main
from bt_humanoid.commanding import plan_command
from bt_humanoid.language.asr import CommandRecognizer, command_grammar, frame_power, heard_words, with_noise_floor
from bt_humanoid.language.audio import (
    SpeechOut,
    espeak_available,
    read_wav,
    spoken,
    synthesize,
    with_noise,
    write_wav,
)
from bt_humanoid.language.listening import END_SILENCE, Listener, heard_in
from bt_humanoid.language.pronunciation import UNCLEAR_SPEECH
from bt_humanoid.language.whisper_asr import WhisperRecognizer, world_prompt
from bt_humanoid.language.words import UNCLEAR
from bt_humanoid.paths import project_root
from bt_humanoid.sim.world_config import load_world_config
from bt_humanoid.testing.told import told_planning_context


def test_espeak_ng_is_installed_by_the_set_up():
    assert espeak_available(), "espeak-ng is missing: scripts/setup.sh installs it with apt-get"


@pytest.fixture(scope="module")
def recognizer() -> CommandRecognizer:
    return CommandRecognizer(load_world_config("apartment"), dictation=True)


def test_the_grammar_speaks_the_worlds_words():
    grammar = command_grammar(load_world_config("apartment"))
    for words in ("red cube", "coffee mug", "living room", "counter", "hey robot"):
        assert words in grammar
    assert re.search(r"<colour> = [^;]*\byellow\b", grammar)


def test_a_spoken_command_after_the_wake_word_is_heard(recognizer):
    heard = recognizer.transcribe(spoken("hey robot, put the red cube on the counter"))
    assert heard.woken and heard.command == "put the red cube on the counter"
    assert heard.dictated == ""  # free dictation is only for unclear speech
    assert heard.text in ("hey robot put the red cube on the counter", "robot put the red cube on the counter")


def test_a_long_command_without_any_noise_is_heard_whole(recognizer):
    # espeak-ng leaves digital silence between words; decoded as it is, the second step was lost
    heard = recognizer.transcribe(spoken("pick up the red cube and put it on the counter"))
    assert re.fullmatch(r"pick up the red cube (and|then) put it on the counter", heard.text), heard.text


@pytest.mark.parametrize("voice", ["en-us", "en-gb"])
def test_words_the_robot_does_not_know_are_heard_as_unclear_and_refused(recognizer, voice):
    # Without the grammar's unclear speech this was heard as a command that fits ("lift the cup and wave")
    heard = recognizer.transcribe(spoken("hey robot, make me a cup of tea", voice))
    assert heard.woken and UNCLEAR in heard.command, heard.text
    assert heard.dictated and f"(free dictation: {heard.dictated})" in heard.shown  # its words shown, not planned
    outcome = plan_command(heard.command, told_planning_context("apartment"), lambda _: None)
    assert outcome.plan.kind == "refusal" and outcome.spec is None
    assert "could not make out" in outcome.plan.say


def test_a_stretch_of_unclear_speech_is_written_as_one_mark():
    class Hypothesis:
        hypstr = f"bring me the {UNCLEAR_SPEECH} {UNCLEAR_SPEECH}  and {UNCLEAR_SPEECH}"

    assert heard_words(Hypothesis()) == f"bring me the {UNCLEAR} and {UNCLEAR}"
    assert heard_words(None) == ""


def test_a_noise_floor_fills_digital_silence_and_leaves_noisy_speech_alone():
    clean = spoken("go to the kitchen")
    floored = frame_power(with_noise_floor(clean))
    speech = np.percentile(frame_power(clean), 90)
    assert np.percentile(frame_power(clean), 10) == 0.0
    assert 10 * np.log10(speech / np.percentile(floored, 10)) == pytest.approx(35.0, abs=3.0)
    noisy = with_noise(clean, 20.0, np.random.default_rng(0))
    assert np.array_equal(with_noise_floor(noisy), noisy)


def test_wav_files_of_any_rate_come_out_at_16_khz(tmp_path):
    path = synthesize("stop", tmp_path / "stop.wav")
    with wave.open(str(path)) as file:
        rate, frames = file.getframerate(), file.getnframes()
    assert rate == 22050  # espeak-ng's own rate
    samples = read_wav(path)
    assert abs(len(samples) - frames * 16000 / rate) <= 1  # the same duration at 16 kHz
    again = read_wav(write_wav(tmp_path / "16k.wav", samples))
    assert np.array_equal(again, samples)


def _espeak_from_stdin(text: str, path, *options: str) -> np.ndarray:
    """What espeak-ng says for ``text`` read from stdin, where it can never be taken as an option."""
    command = ["espeak-ng", "-v", "en-us", *options, "-w", str(path), "--stdin"]
    subprocess.run(command, input=text.encode(), check=True)
    return read_wav(path)


def _option_like_texts(folder) -> list[str]:
    long_file = folder / "long.txt"
    long_file.write_text("This file is long and must never be read aloud. " * 6)
    return [f"-w{folder / 'stray.wav'}", "-f/etc/hostname", f"-f{long_file}", f"say -w{folder / 'stray.wav'} now"]


def test_text_that_looks_like_espeak_options_is_spoken_as_words(tmp_path):
    # Before the text went after "--", "-w…" wrote the WAV elsewhere and "-f…" read a file aloud
    for index, text in enumerate(_option_like_texts(tmp_path)):
        wav = synthesize(text, tmp_path / f"said{index}.wav")
        assert wav.exists(), text
        assert np.array_equal(read_wav(wav), _espeak_from_stdin(text, tmp_path / "reference.wav", "-s", "160")), text
    assert sorted(path.name for path in tmp_path.iterdir()) == ["long.txt", "reference.wav"] + [
        f"said{index}.wav" for index in range(4)
    ]


def test_the_speaker_gets_the_text_as_words_too(tmp_path, monkeypatch):
    commands = []
    recorder = SimpleNamespace(Popen=lambda command, **_: commands.append(command), DEVNULL=subprocess.DEVNULL)
    monkeypatch.setattr("bt_humanoid.language.audio.subprocess", recorder)
    texts = _option_like_texts(tmp_path)
    speech = SpeechOut(speaker=True)
    for text in texts:
        speech(text)
    for index, (text, command) in enumerate(zip(texts, commands, strict=True)):
        # the speaker's command line, writing to a file instead of the sound card
        wav = tmp_path / f"speaker{index}.wav"
        subprocess.run([command[0], "-w", str(wav), *command[1:]], check=True, capture_output=True)
        assert np.array_equal(read_wav(wav), _espeak_from_stdin(text, tmp_path / "reference.wav")), text
    assert not (tmp_path / "stray.wav").exists()


@pytest.mark.sim
def test_bt_run_audio_puts_the_red_cube_on_the_counter(tmp_path, capsys):
    wav = synthesize("hey robot, put the red cube on the counter", tmp_path / "command.wav")
    summary = tmp_path / "summary.json"
    assert run_main(["--audio", str(wav), "--no-live", "--summary-json", str(summary)]) == EXIT_OK
    assert "robot put the red cube on the counter" in capsys.readouterr().out  # "hey" may be lost; "robot" wakes
    assert json.loads(summary.read_text())["tree_status"] == "SUCCESS"


def test_bt_run_audio_without_the_wake_word_is_refused_with_exit_2(tmp_path, capsys):
    wav = synthesize("put the red cube on the counter", tmp_path / "command.wav")
    assert run_main(["--audio", str(wav), "--no-live"]) == EXIT_INVALID
    assert "no 'hey robot' at the start" in capsys.readouterr().err


@pytest.mark.sim
def test_what_the_robot_says_is_spoken_into_wav_files(tmp_path, capsys):
    speech = tmp_path / "speech"
    demo = project_root() / "missions" / "demo.yaml"
    assert run_main([str(demo), "--no-live", "--speech-wav", str(speech)]) == EXIT_OK
    files = sorted(speech.glob("*.wav"))
    said = [line for line in capsys.readouterr().out.splitlines() if "said" in line]
    assert len(files) == len(said) == 2  # "Heading to the table." and "Ready at the table."
    for file in files:
        samples = read_wav(file)
        assert len(samples) > 0.5 * 16000 and abs(samples).max() > 1000  # a second or so of speech, not silence


def _stream(*parts: tuple[str, float], rng: np.random.Generator, snr_db: float = 30.0) -> np.ndarray:
    """Speech and silences (text, or "" with a duration) as one noisy 16 kHz stream.

    30 dB by default: these tests are about segmenting and timing; the voice benchmark measures accuracy at 20 dB.
    """
    pieces = [spoken(text) if text else np.zeros(int(seconds * 16000), dtype=np.int16) for text, seconds in parts]
    return with_noise(np.concatenate(pieces), snr_db, rng)


def _listen(listener: Listener, audio: np.ndarray) -> list:
    return list(heard_in(listener, (audio[start : start + 1600] for start in range(0, len(audio), 1600))))  # 100 ms


def test_the_listener_splits_a_stream_into_utterances(recognizer):
    audio = _stream(
        ("", 1.0),
        ("hey robot, go to the kitchen", 0),
        ("", 1.5),
        ("hey robot, pick up the red cube", 0),
        ("", 1.0),
        rng=np.random.default_rng(3),
    )
    heard = _listen(Listener(recognizer), audio)
    assert [(item.kind, item.text) for item in heard] == [
        ("utterance", "hey robot go to the kitchen"),
        ("utterance", "hey robot pick up the red cube"),
    ]
    assert heard[0].at < heard[1].at <= len(audio) / 16000


def test_a_spoken_stop_is_reported_before_the_speaker_falls_silent(recognizer):
    speech = spoken("stop")
    audio = _stream(("", 1.0), ("stop", 0), ("", 1.0), rng=np.random.default_rng(4))
    heard = _listen(Listener(recognizer), audio)
    assert [item.kind for item in heard] == ["stop"]
    end_of_word = 1.0 + np.nonzero(speech)[0][-1] / 16000
    assert heard[0].at < end_of_word + END_SILENCE  # spotted while decoding, not after the endpoint


def test_noise_alone_is_not_heard_as_anything(recognizer):
    audio = with_noise(
        np.concatenate([np.zeros(8000, np.int16), spoken("hmm"), np.zeros(8000, np.int16)]),
        20.0,
        np.random.default_rng(5),
    )
    quiet = np.random.default_rng(6).normal(0.0, 30.0, 3 * 16000).astype(np.int16)
    assert _listen(Listener(recognizer), quiet) == []
    assert all(item.kind != "stop" for item in _listen(Listener(recognizer), audio))


@pytest.mark.sim
def test_bt_run_listen_hears_a_command_a_spoken_stop_and_the_next_command(tmp_path, capsys):
    """A WAV file played as a microphone, in real time: the robot sets off, 'stop' stops it, it waves after."""
    quiet = lambda seconds: np.zeros(int(seconds * 16000), dtype=np.int16)  # noqa: E731
    sound = [quiet(0.5), spoken("hey robot, go to the kitchen"), quiet(2.5), spoken("stop"), quiet(1.0)]
    sound += [spoken("hey robot, wave"), quiet(1.0)]
    wav = write_wav(tmp_path / "stream.wav", with_noise(np.concatenate(sound), 30.0, np.random.default_rng(0)))
    assert run_main(["--listen", str(wav)]) == EXIT_OK
    said = [line for line in capsys.readouterr().out.splitlines() if line.startswith(("heard", "robot"))]
    assert said[1:] == [
        "heard: hey robot go to the kitchen",
        "robot: I will go to the kitchen.",
        "heard: stop",
        "robot: I have stopped.",  # mid-way: the kitchen is more than 2.5 s away
        "heard: hey robot wave",
        "robot: I will wave.",
        "robot: Done.",
    ]


def test_bt_run_listen_without_a_microphone_says_what_to_install(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "sounddevice", None)  # as if it were not installed
    assert run_main(["--listen"]) == EXIT_INVALID
    assert "pip install 'bt-humanoid[microphone]'" in capsys.readouterr().err


class _ScriptedWhisper:
    """Stands in for faster_whisper.WhisperModel: returns fixed segments and records what it was given."""

    def __init__(self, *texts: str) -> None:
        self.texts = texts
        self.calls: list[dict] = []

    def transcribe(self, audio, **options):
        self.calls.append({"audio": audio, **options})
        return [type("Segment", (), {"text": text})() for text in self.texts], None


def test_whisper_text_is_brought_to_the_recognisers_form():
    model = _ScriptedWhisper(" Hey robot,", " put the red cube on the counter.")
    whisper = WhisperRecognizer(model, prompt=world_prompt(load_world_config("apartment")))
    heard = whisper.transcribe(np.full(16000, 16384, dtype=np.int16))
    assert heard.woken and heard.command == "put the red cube on the counter"
    assert heard.dictated == ""  # free dictation is only for unclear speech
    call = model.calls[0]
    assert call["audio"].dtype == np.float32 and abs(call["audio"].max() - 0.5) < 1e-6  # int16 → [-1, 1)
    assert call["language"] == "en" and "red cube" in call["initial_prompt"]


def test_bt_run_whisper_model_that_is_not_there_is_exit_2(tmp_path, capsys):
    wav = synthesize("hey robot, wave", tmp_path / "command.wav")
    assert run_main(["--audio", str(wav), "--whisper-model", str(tmp_path / "nowhere")]) == EXIT_INVALID
    assert "no Whisper model there" in capsys.readouterr().err
