"""Whisper as the recogniser, from a model the user has on disk (faster-whisper, an optional extra).

Nothing is downloaded at run time: the model is a local CTranslate2 folder
(for example one converted with ``ct2-transformers-converter`` or copied from
a machine that has one; it holds ``model.bin``). Whisper writes free text
("Hey robot, put the red cube on the counter."); it is brought to the
recogniser's form (lower case, no punctuation) so the wake word and the
planner see the same words as from pocketsphinx. Use it with
``bt-run --audio``/``--listen`` and ``--whisper-model DIR``; the stop word is
still spotted by the grammar decoder while the person speaks.
"""

from __future__ import annotations

import re
import time
from pathlib import Path
from typing import Any

import numpy as np

from bt_humanoid.errors import UserError
from bt_humanoid.language.asr import Transcript
from bt_humanoid.language.vocabulary import WorldVocabulary
from bt_humanoid.sim.world_config import WorldConfig


def whisper_text(text: str) -> str:
    """Whisper's punctuated text in the recogniser's form: lower case words, no punctuation."""
    words = re.sub(r"[^a-z0-9' ]+", " ", text.lower().replace("-", " "))
    return " ".join(words.split())


def world_prompt(world: WorldConfig) -> str:
    """The words of this world (its names and aliases, as the grammar has them), given to Whisper as earlier text
    so it spells them the planner's way."""
    words = WorldVocabulary.of(world)
    names = [*sorted(words.objects), *sorted(words.surfaces), *sorted(set(words.places) - set(words.surfaces))]
    return "Hey robot, " + ", ".join(names) + "."


class WhisperRecognizer:
    """Transcribes whole utterances (16 kHz int16) with a Whisper model; ``transcribe`` as CommandRecognizer's."""

    def __init__(self, model: Any, prompt: str = "") -> None:
        self.model = model  # a faster_whisper.WhisperModel, or anything with its transcribe()
        self.prompt = prompt  # the world's words, so names like "coffee mug" are spelled as the planner knows them

    @classmethod
    def from_folder(cls, folder: Path, prompt: str = "", device: str = "cpu") -> WhisperRecognizer:
        if not (folder / "model.bin").is_file():
            raise UserError(
                f"--whisper-model {folder}: no Whisper model there (a CTranslate2 folder with model.bin)",
                hint="convert one with ct2-transformers-converter, or leave the option out to use pocketsphinx",
            )
        try:
            from faster_whisper import WhisperModel
        except ImportError:
            raise UserError("--whisper-model needs faster-whisper", hint="pip install 'bt-humanoid[whisper]'") from None
        return cls(WhisperModel(str(folder), device=device, compute_type="int8", local_files_only=True), prompt)

    def transcribe(self, samples: np.ndarray) -> Transcript:
        started = time.perf_counter()
        audio = np.asarray(samples, dtype=np.float32) / 32768.0  # at RATE, 16 kHz: Whisper's own rate
        segments, _info = self.model.transcribe(audio, language="en", beam_size=1, initial_prompt=self.prompt or None)
        text = whisper_text(" ".join(segment.text for segment in segments))
        return Transcript(text, time.perf_counter() - started)
