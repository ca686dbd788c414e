"""Spoken commands: the grammar of this world's words, recognition of synthesised speech, bt-run --audio end to end."""

import json
import re
import wave

import numpy as np
import pytest

from bt_humanoid.cli import EXIT_INVALID, EXIT_OK, run_main
from bt_humanoid.language.asr import CommandRecognizer, command_grammar
from bt_humanoid.language.audio import espeak_available, read_wav, spoken, synthesize, write_wav
from bt_humanoid.paths import project_root
from bt_humanoid.sim.world_config import load_world_config


def test_espeak_ng_is_installed_by_the_set_up():
    assert espeak_available(), "espeak-ng is missing: scripts/setup.sh installs it with apt-get"


@pytest.fixture(scope="module")
def recognizer() -> CommandRecognizer:
    return CommandRecognizer(load_world_config("apartment"))


def test_the_grammar_speaks_the_worlds_words():
    grammar = command_grammar(load_world_config("apartment"))
    for words in ("red cube", "coffee mug", "living room", "counter", "hey robot"):
        assert words in grammar
    assert re.search(r"<colour> = [^;]*\byellow\b", grammar)


def test_a_spoken_command_after_the_wake_word_is_heard(recognizer):
    heard = recognizer.transcribe(spoken("hey robot, put the red cube on the counter"))
    assert heard.text == "hey robot put the red cube on the counter"
    assert heard.woken and heard.command == "put the red cube on the counter"


def test_wav_files_of_any_rate_come_out_at_16_khz(tmp_path):
    path = synthesize("stop", tmp_path / "stop.wav")
    with wave.open(str(path)) as file:
        rate, frames = file.getframerate(), file.getnframes()
    assert rate == 22050  # espeak-ng's own rate
    samples = read_wav(path)
    assert abs(len(samples) - frames * 16000 / rate) <= 1  # the same duration at 16 kHz
    again = read_wav(write_wav(tmp_path / "16k.wav", samples))
    assert np.array_equal(again, samples)


def test_bt_run_audio_puts_the_red_cube_on_the_counter(tmp_path, capsys):
    wav = synthesize("hey robot, put the red cube on the counter", tmp_path / "command.wav")
    summary = tmp_path / "summary.json"
    assert run_main(["--audio", str(wav), "--no-live", "--summary-json", str(summary)]) == EXIT_OK
    assert "heard: hey robot put the red cube on the counter" in capsys.readouterr().out
    assert json.loads(summary.read_text())["tree_status"] == "SUCCESS"


def test_bt_run_audio_without_the_wake_word_is_refused_with_exit_2(tmp_path, capsys):
    wav = synthesize("put the red cube on the counter", tmp_path / "command.wav")
    assert run_main(["--audio", str(wav), "--no-live"]) == EXIT_INVALID
    assert "no 'hey robot' at the start" in capsys.readouterr().err


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
