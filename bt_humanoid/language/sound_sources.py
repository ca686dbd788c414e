"""Where heard sound comes from: the microphone (sounddevice, optional) or a WAV file played as if it were one.

Both give 16 kHz mono int16 blocks of ``BLOCK`` seconds, as they would
arrive: a file is paced to the wall clock, so a "stop" in it comes while the
robot is moving, just as it would from a person.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from bt_humanoid.errors import UserError
from bt_humanoid.language.audio import RATE, read_wav

BLOCK = 0.1  # s of sound per block


def wav_samples(path: Path, hint: str) -> np.ndarray:
    """A WAV file's samples at ``RATE``; a UserError (with ``hint``) when it is missing or not a PCM WAV."""
    if not path.is_file():
        raise UserError(f"{path}: no such file", hint=hint)
    try:
        return read_wav(path)
    except ValueError as error:
        raise UserError(str(error)) from None


def file_blocks(path: Path, realtime: bool = True) -> Iterator[np.ndarray]:
    """The sound of a WAV file in blocks, each given when it would have been heard (or at once)."""
    return _paced(wav_samples(path, "give a WAV file to listen to, or no file for the microphone"), realtime)


def _paced(samples: np.ndarray, realtime: bool) -> Iterator[np.ndarray]:
    size = int(BLOCK * RATE)
    started = time.perf_counter()
    for index, start in enumerate(range(0, len(samples), size)):
        if realtime:
            time.sleep(max(0.0, started + index * BLOCK - time.perf_counter()))
        yield samples[start : start + size]


def microphone_blocks() -> Iterator[np.ndarray]:
    """Blocks from the default input device, for as long as they are read."""
    try:
        import sounddevice
    except (ImportError, OSError) as error:  # OSError: the package is there but PortAudio is not
        raise UserError(
            f"listening to a microphone needs sounddevice and PortAudio ({error})",
            hint="pip install 'bt-humanoid[microphone]' and apt-get install libportaudio2; or give a WAV file",
        ) from None
    try:
        stream = sounddevice.InputStream(samplerate=RATE, channels=1, dtype="int16", blocksize=int(BLOCK * RATE))
    except Exception as error:  # PortAudio reports a missing or busy device in its own error types
        raise UserError(f"no microphone to listen to: {error}", hint="plug one in, or give a WAV file") from None
    return _recorded(stream)


def _recorded(stream: object) -> Iterator[np.ndarray]:  # a sounddevice.InputStream
    with stream:
        while True:
            block, _overflowed = stream.read(int(BLOCK * RATE))
            yield np.asarray(block, dtype=np.int16).reshape(-1)
