"""A continuous stream of sound in; utterances and stop requests out, as they happen.

Frames of 20 ms are marked speech or not by pocketsphinx's voice activity
detector (WebRTC's). An utterance starts after ``START_FRAMES`` speech frames
(with ``PRE_ROLL`` of the sound before them, so its first word is whole) and
ends after ``END_SILENCE`` without speech. The command recogniser decodes it
while it arrives, so two things are known early:

- a stop: when the words so far are a stop command ("stop", "robot, halt")
  for ``STOP_FRAMES`` frames in a row, the stop is reported at once, before
  the utterance ends; the robot must not wait for the speaker to fall silent;
- the rest of the utterance, reported when it ends, with the wake word kept so
  the caller can tell whether it was spoken to the robot (also when a stop was
  spotted early in it and the whole turns out to be something else: the
  robot has stopped, which is safe, and the command is not lost). It is decoded again
  whole, as ``CommandRecognizer.transcribe`` does for a file: normalising the
  features over the whole utterance is more accurate than the running
  estimate the live decode has to use.

``Listener.feed`` takes any amount of sound (a microphone block, a file) and
returns what was heard in it; ``Listener.close`` ends the stream.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np

from bt_humanoid.language.asr import CommandRecognizer, Transcript
from bt_humanoid.language.audio import RATE
from bt_humanoid.language.embedded import is_stop

FRAME = 0.02  # s: the detector's frame
START_FRAMES = 3  # speech frames in a row that start an utterance
PRE_ROLL = 0.2  # s of sound before the start that the recogniser also hears
END_SILENCE = 0.4  # s without speech that end an utterance
TAIL = 0.15  # s of that silence kept with the utterance
STOP_FRAMES = 6  # frames in a row the words so far must be a stop before it counts (120 ms)
SETTLING = 0.2  # s at the start of a stream while the detector adapts to the room (it marks all of it speech)
SHORTEST = 0.15  # s of speech an utterance needs (shorter: a click or a breath)
LONGEST = 12.0  # s: an utterance is cut here (a radio left on must not hold the recogniser forever)


class Transcriber(Protocol):
    """Anything that turns a whole utterance into a Transcript (CommandRecognizer, WhisperRecognizer)."""

    def transcribe(self, samples: np.ndarray) -> Transcript: ...


@dataclass(frozen=True)
class Heard:
    """Something the listener heard: a stop (reported mid-utterance) or a finished utterance."""

    kind: Literal["stop", "utterance"]
    transcript: Transcript
    at: float  # s into the stream when it was reported

    @property
    def text(self) -> str:
        return self.transcript.text


class Listener:
    """Segments a 16 kHz stream into utterances, decodes them as they come and spots stops early."""

    def __init__(self, recognizer: CommandRecognizer, transcriber: Transcriber | None = None) -> None:
        from pocketsphinx import Vad

        self.recognizer = recognizer  # decodes as the person speaks, for stops
        self.transcriber = transcriber or recognizer  # the whole utterance when it ends (Whisper, when given)
        self.vad = Vad(Vad.LOOSE, RATE, FRAME)
        self.frame_samples = self.vad.frame_bytes // 2
        self._pending = np.zeros(0, dtype=np.int16)
        self._before: deque[np.ndarray] = deque(maxlen=round(PRE_ROLL / FRAME))
        self._frames = 0  # frames of the stream so far
        self._speech_run = 0
        self._in_utterance = False
        self._utterance_frames = 0
        self._speech_frames = 0
        self._held: list[np.ndarray] = []  # pause frames not yet decoded
        self._sound: list[np.ndarray] = []  # the utterance so far
        self._words = ""  # what the recogniser has heard so far in this utterance
        self._stop_run = 0
        self._stopped = False  # a stop was reported in this utterance

    @property
    def seconds(self) -> float:
        """How much of the stream has been listened to."""
        return self._frames * self.frame_samples / RATE

    def feed(self, samples: np.ndarray) -> list[Heard]:
        """Listen to the next samples of the stream; what was heard in them, in order."""
        audio = np.concatenate([self._pending, np.asarray(samples, dtype=np.int16)])
        heard: list[Heard] = []
        size = self.frame_samples
        whole = len(audio) - len(audio) % size
        for start in range(0, whole, size):
            heard.extend(self._frame(audio[start : start + size]))
        self._pending = audio[whole:]
        return heard

    def close(self) -> list[Heard]:
        """End of the stream: an utterance still open ends here."""
        return self._finish() if self._in_utterance else []

    def _frame(self, frame: np.ndarray) -> list[Heard]:
        self._frames += 1
        speech = self.vad.is_speech(frame.tobytes()) and self._frames * FRAME > SETTLING
        if not self._in_utterance:
            self._speech_run = self._speech_run + 1 if speech else 0
            self._before.append(frame)
            if self._speech_run < START_FRAMES:
                return []
            self._begin()
            return self._listen(self._sound[0])
        self._utterance_frames += 1
        if not speech:  # held back: a pause may be the end, and decoding a long tail of noise loses the command
            self._held.append(frame)
            heard = self._listen(None)
            if len(self._held) * FRAME >= END_SILENCE or self._utterance_frames * FRAME >= LONGEST:
                heard.extend(self._finish())
            return heard
        self._speech_frames += 1
        sound = np.concatenate([*self._held, frame])
        self._held.clear()
        self._sound.append(sound)
        return self._listen(sound)

    def _begin(self) -> None:
        self.recognizer.begin()
        self._sound = [np.concatenate(list(self._before))]
        self._in_utterance = True
        self._utterance_frames = len(self._before)
        self._speech_frames = START_FRAMES
        self._stop_run = 0
        self._words = ""
        self._held.clear()
        self._stopped = False

    def _listen(self, sound: np.ndarray | None) -> list[Heard]:
        """Decode ``sound`` (None: nothing new) and report a stop once the words have been one long enough."""
        if sound is not None:
            self._words = self.recognizer.hear(sound)
        if self._stopped:
            return []
        self._stop_run = self._stop_run + 1 if self._words and is_stop(self._words) else 0
        if self._stop_run < STOP_FRAMES:
            return []
        self._stopped = True
        return [Heard("stop", Transcript(self._words, 0.0), self.seconds)]

    def _finish(self) -> list[Heard]:
        self.recognizer.end()  # the running decode was for spotting stops; the whole utterance is decoded again
        sound = np.concatenate(self._sound + self._held[: round(TAIL / FRAME)])
        self._in_utterance = False
        self._speech_run = 0
        self._before.clear()
        self._held.clear()
        if self._speech_frames * FRAME < SHORTEST:
            return []  # a click or a breath: not worth decoding
        transcript = self.transcriber.transcribe(sound)
        if not transcript.text:
            return []  # nothing the grammar fits (a cough, a door)
        if is_stop(transcript.text):
            return [] if self._stopped else [Heard("stop", transcript, self.seconds)]
        return [Heard("utterance", transcript, self.seconds)]  # after an early stop too: it was not one after all


def heard_in(listener: Listener, blocks: Iterable[np.ndarray]) -> Iterator[Heard]:
    """Everything ``listener`` hears in a stream of blocks, as it is heard; an utterance open at the end ends there."""
    for block in blocks:
        yield from listener.feed(block)
    yield from listener.close()
