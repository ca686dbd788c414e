"""Sound in and out: WAV files at the recogniser's rate, and speech synthesised with espeak-ng.

espeak-ng is a Debian package (``scripts/setup.sh`` installs it). Without it
the robot prints what it says and speech cannot be synthesised; everything
else works.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
import wave
from math import gcd
from pathlib import Path

import numpy as np
from scipy.signal import resample_poly

RATE = 16000  # Hz: what the recogniser's acoustic model was trained on


def espeak_available() -> bool:
    return shutil.which("espeak-ng") is not None


def synthesize(text: str, path: Path, voice: str = "en-us", words_per_minute: int = 160) -> Path:
    """Speak ``text`` into a WAV file with espeak-ng; a RuntimeError says how to install it if it is missing.

    The text is always words, never options: a ``say`` text (which may come from a language model) of
    ``-w/some/path`` or ``-f/some/file`` is spoken as written, not obeyed (see ``_espeak_command``).
    """
    if not espeak_available():
        raise RuntimeError("espeak-ng is not installed (apt-get install espeak-ng, or run scripts/setup.sh)")
    subprocess.run(
        _espeak_command(text, voice, "-s", str(words_per_minute), "-w", str(path)),
        check=True,
        capture_output=True,
    )
    return path


def _espeak_command(text: str, voice: str, *options: str) -> list[str]:
    """espeak-ng's command line with ``text`` after ``--``, where its option parser (getopt) reads no options."""
    return ["espeak-ng", "-v", voice, *options, "--", text]


def read_wav(path: Path) -> np.ndarray:
    """Mono 16-bit samples at ``RATE`` from a WAV file of any rate and channel count."""
    try:
        with wave.open(str(path)) as file:
            rate, channels, width = file.getframerate(), file.getnchannels(), file.getsampwidth()
            raw = file.readframes(file.getnframes())
    except (wave.Error, EOFError) as error:
        raise ValueError(f"{path}: not a PCM WAV file ({error})") from None
    if width != 2:
        raise ValueError(f"{path}: {8 * width}-bit samples; 16-bit PCM expected")
    samples = np.frombuffer(raw, dtype=np.int16).reshape(-1, channels).mean(axis=1)
    if rate != RATE:
        common = gcd(rate, RATE)
        samples = resample_poly(samples, RATE // common, rate // common)
    return np.clip(samples, -32768, 32767).astype(np.int16)


def write_wav(path: Path, samples: np.ndarray, rate: int = RATE) -> Path:
    with wave.open(str(path), "wb") as file:
        file.setnchannels(1)
        file.setsampwidth(2)
        file.setframerate(rate)
        file.writeframes(np.asarray(samples, dtype=np.int16).tobytes())
    return path


def spoken(text: str, voice: str = "en-us", words_per_minute: int = 160) -> np.ndarray:
    """``text`` as speech samples at ``RATE`` (espeak-ng), for tests and benchmarks."""
    with tempfile.TemporaryDirectory() as folder:
        return read_wav(synthesize(text, Path(folder) / "speech.wav", voice, words_per_minute))


def with_noise(samples: np.ndarray, snr_db: float, rng: np.random.Generator) -> np.ndarray:
    """White noise added at ``snr_db`` below the speech's power (measured where it is not silent)."""
    speech = samples.astype(float)
    active = speech[np.abs(speech) > 0.02 * np.abs(speech).max()] if np.any(speech) else speech
    power = float(np.mean(active**2)) if len(active) else 0.0
    noise = rng.normal(0.0, np.sqrt(power / 10 ** (snr_db / 10)), size=len(speech))
    return np.clip(speech + noise, -32768, 32767).astype(np.int16)


class SpeechOut:
    """What the robot says, spoken with espeak-ng: through the speaker, into numbered WAV files, or both.

    Speaking never holds up the robot: playback runs in the background. Without espeak-ng it does nothing
    (the run still prints what is said).
    """

    def __init__(self, speaker: bool = False, folder: Path | None = None, voice: str = "en-us") -> None:
        self.speaker = speaker and espeak_available()
        self.folder = folder
        self.voice = voice
        self.files: list[Path] = []
        if folder is not None:
            folder.mkdir(parents=True, exist_ok=True)

    def __call__(self, text: str) -> None:
        if not espeak_available():
            return
        if self.folder is not None:
            path = self.folder / f"{len(self.files) + 1:03d}.wav"
            self.files.append(synthesize(text, path, self.voice))
        if self.speaker:
            subprocess.Popen(_espeak_command(text, self.voice), stderr=subprocess.DEVNULL)
