"""Offline speech recognition: pocketsphinx with a grammar of the robot's commands in this world.

Free dictation with pocketsphinx's general language model is poor on short
commands (see docs/dependencies.md), so it is only a fallback shown to the person where
the grammar heard unclear speech (``FreeDictation``). A JSGF grammar of what
the planner understands, filled with the world's own words (its objects,
colours, places and surfaces), decodes them reliably and fast. An utterance
may start with the wake word ("hey robot"); the transcript keeps it so
callers can tell. The grammar also holds what the planner understands only
to refuse ("pick up the table", "pick up the person"), so that the robot
refuses what was asked instead of picking up the nearest thing that fits.
Words the robot does not know are heard as unclear speech, a garbage model
in the places where they are said (a whole step, an object, a surface):
"make me a sandwich" is heard as "…" and "bring me the banana" as "bring me
the …", which the robot refuses, instead of the nearest command that fits
("lift the dice and wave"). Speech that no path through the grammar fits
within the decoder's beams comes back as nothing heard. The dictionary holds
the grammar's words in American and British forms (``pronunciation.py``).
"""

from __future__ import annotations

import re
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from bt_humanoid.errors import UserError
from bt_humanoid.language.audio import RATE, with_noise
from bt_humanoid.language.pronunciation import UNCLEAR_SPEECH, known_words, write_dictionary
from bt_humanoid.language.vocabulary import INTENTS, SAY_PHRASES, WorldVocabulary
from bt_humanoid.language.words import AFTER, POLITE_SPOKEN, UNCLEAR, WAKE_WORDS, is_unclear
from bt_humanoid.sim.world_config import WorldConfig

if TYPE_CHECKING:
    from pocketsphinx import Decoder, Hypothesis

WAKE_WORD = WAKE_WORDS[0]  # "hey robot": the one people are told to say
SPOKEN_WAKE_WORDS = (WAKE_WORD, "robot")  # what the grammar hears; "hey" is short and often lost in noise
PADDING = 0.2  # s of silence around an utterance
NOISE_FLOOR_DB = 35.0  # a quiet room: where the input is quieter than this under the speech, noise is added
DECODER_SETTINGS = {  # tuned on the voice benchmark's first noise draw (seed 0), checked on others
    "dither": True,  # synthetic silence is exact zeros; without dither the decoder drops the last words
    "seed": 1,  # the dither's random numbers; pocketsphinx seeds them from the clock otherwise (results vary)
    "bestpath": False,  # the lattice rescoring picks paths that leave the grammar ("Final result does not match")
    "pip": 0.2,  # a lower phone insertion penalty: espeak-ng's fast speech has short phones
    # Wider beams than the defaults (1e-48, 1e-48, 7e-29): fast or British speech scores poorly early in a word
    # and was pruned, leaving nothing heard. The looped grammar below keeps this within the latency target.
    "beam": 1e-60,
    "pbeam": 1e-60,
    "wbeam": 1e-40,
}
NUMBERS = (  # what distances, angles and counts are spoken as
    "one | two | three | four | five | six | seven | eight | nine | ten | fifteen | twenty | thirty | forty"
    " | forty five | fifty | sixty | seventy | eighty | ninety | one hundred | one hundred and eighty | half a"
    " | one point five | two point five"
)


@dataclass
class Transcript:
    text: str  # what was heard, lower case; empty if nothing fitted the grammar
    seconds: float  # wall time the decoding took
    dictated: str = ""  # free dictation's words, where the grammar heard unclear speech (shown, never planned)

    @property
    def shown(self) -> str:
        """What was heard, as the robot tells the person: with free dictation's words where the grammar had none."""
        return f"{self.text} (free dictation: {self.dictated})" if self.dictated else self.text

    @property
    def unclear(self) -> bool:
        """Whether some of the speech fitted none of the grammar's words (UNCLEAR in the text)."""
        return is_unclear(self.text)

    @property
    def wake_word(self) -> str | None:
        """The wake word the utterance starts with ("hey robot", or just "robot"), if any."""
        return next((w for w in SPOKEN_WAKE_WORDS if self.text == w or self.text.startswith(w + " ")), None)

    @property
    def woken(self) -> bool:
        return self.wake_word is not None

    @property
    def command(self) -> str:
        """The words after the wake word."""
        wake = self.wake_word
        return self.text[len(wake) :].strip() if wake else self.text


def command_grammar(world: WorldConfig) -> str:
    """A JSGF grammar of the commands the embedded planner understands, in this world's words.

    Its verbs are the spoken verbs of ``vocabulary.INTENTS`` (the planner's phrasings are built from the same
    table), its names every name and alias world.yaml gives an object, place or surface that the recogniser
    can hear: plain English words of its dictionary ("coca-cola", "7up" and "rxbar" are typed; "coca cola" and
    "seven up" are said). A thing with no name it can hear is an error naming it.
    """
    words = WorldVocabulary.of(world)
    names = _audible(words.objects, "object", world)
    home = {w for w, place in words.places.items() if place == "start"}  # "go home" says it
    places = sorted(set(_audible(words.places, "place", world)) - home)
    surfaces = _audible(words.surfaces, "surface", world)
    containers = _audible(words.containers, "bin", world)
    unmovable = sorted({"person", *places, *surfaces})
    rule = " | ".join
    verbs = {name: intent.rule() for name, intent in INTENTS.items() if intent.spoken}
    after = " ".join(f"[{word}]" for word in AFTER)
    return "\n".join(
        [
            "#JSGF V1.0;",
            "grammar robot;",
            f"public <utterance> = [{' | '.join(SPOKEN_WAKE_WORDS)}] [<polite>] <command> {after};",
            f"<polite> = {rule(POLITE_SPOKEN)};",
            # Steps are joined by a word, as in "A and B" or "A then B". A command of steps side by side ("where is
            # the mug" as "wave lift the mug") was the commonest misreading; a spoken comma is heard as "and".
            # The rule loops (right recursion), so the grammar holds one copy of a step, not one per position.
            "<command> = <clause> [<next>];",
            "<next> = (and | then | and then) <clause> [<next>];",
            "<clause> = <take> | <put> | <bring> | <go> | <step> | <turn> | <find> | <wave> | <stop> | <say>"
            f"{' | <throw>' if containers else ''} | <unclear>;",
            f"<take> = {verbs['take']} (<object> | the <unmovable>) | pick <object> up;",
            f"<put> = {verbs['put']} <thing> [down] (on | onto) <surface>"
            f" | {verbs['carry_to_surface']} <thing> [over] to <surface>;",
            f"<bring> = {verbs['bring_me']} me <object> | {verbs['carry_to_person']} <thing> to me;",
            f"<go> = {verbs['go']} [over] to (<place> | <object>) | {verbs['go_home']} | {verbs['come']};",
            f"<step> = {verbs['step']} (forward | back | backward) [<number> (meters | meter)];",
            f"<turn> = {verbs['turn']} (left | right) [<number> degrees] | turn around | {verbs['face']} <place>;",
            f"<find> = {verbs['find']} <object>;",
            *(
                [
                    f"<throw> = {verbs['throw_away']} <thing> | throw <thing> (away | out)"
                    f" | {verbs['put']} <thing> (in | into) <container>;",
                    f"<container> = the ({rule(containers)});",
                ]
                if containers
                else []
            ),
            f"<wave> = {verbs['wave']} [<number> times];",
            f"<stop> = {verbs['stop']};",
            f"<say> = {verbs['say']} ({rule(SAY_PHRASES)});",
            "<thing> = <object> | it | them | all the [<colour>] <plural> | both [<colour>] <plural>;",
            "<object> = the <description> | something to (drink | play with) | the <unclear>;",
            "<description> = [<colour>] <kind> [(on | from) <surface>] [in <place>] | <name>"
            " | (biggest | smallest) thing;",
            f"<name> = {rule(names)};",
            f"<unmovable> = {rule(unmovable)};  // the planner refuses these with a reason",
            f"<kind> = {rule([*words.kinds, 'thing'])};",
            f"<plural> = {rule(words.plurals)};",
            f"<colour> = {rule(words.colours)};",
            f"<surface> = the ({rule(surfaces)}) | the <unclear>;",
            f"<place> = the ({rule(places)}) | <surface>;",
            f"<number> = {NUMBERS};",
            # Words the robot does not know, where people say them: a step ("make me a sandwich"), an object
            # ("bring me the banana") or a surface ("put it on the ceiling"). Heard as UNCLEAR, and refused.
            f"<unclear> = {UNCLEAR_SPEECH}+;",
            "",
        ]
    )


def _audible(names: dict[str, str], what: str, world: WorldConfig) -> list[str]:
    """The names (words → thing) made of words the recogniser knows; every thing must keep one."""
    known = known_words()
    audible = sorted(n for n in names if all(re.fullmatch(r"[a-z']+", w) and w in known for w in n.split()))
    unheard = sorted(set(names.values()) - {names[n] for n in audible})
    if unheard:
        raise UserError(
            f"the recogniser cannot hear any name of the {what} {', '.join(repr(u) for u in unheard)}",
            where=f"worlds/{world.name}/world.yaml",
            hint="give it an alias of English words (aliases: [...]), as 'seven up' for 7up",
        )
    return audible


def frame_power(samples: np.ndarray, frame: float = 0.01) -> np.ndarray:
    """The mean power of each ``frame`` seconds of ``samples``."""
    size = int(frame * RATE)
    count = len(samples) // size
    return (samples[: count * size].astype(float).reshape(count, size) ** 2).mean(axis=1)


def speech_span(samples: np.ndarray, frame: float = 0.01, margin: float = 0.15) -> np.ndarray:
    """The samples from the first to the last loud frame (4× the quietest frames' power), with a margin.

    Noise before and after a command is where a grammar decoder invents words; cutting it also saves time.
    """
    power = frame_power(samples, frame)
    if len(power) < 10:
        return samples
    loud = np.nonzero(power > 4.0 * max(np.percentile(power, 10), 1.0))[0]
    if len(loud) == 0:
        return samples
    keep, size = int(margin / frame), int(frame * RATE)
    first, last = max(loud[0] - keep, 0), min(loud[-1] + keep + 1, len(power))
    return samples[first * size : last * size]


def prepared(samples: np.ndarray) -> np.ndarray:
    """An utterance as the decoders hear it: the speech, a noise floor under it, and silence either side."""
    quiet = np.zeros(int(PADDING * RATE), dtype=np.int16)  # room before and after: the last word is not cut
    return np.concatenate([quiet, with_noise_floor(speech_span(np.asarray(samples, dtype=np.int16))), quiet])


def with_noise_floor(samples: np.ndarray, below_db: float = NOISE_FLOOR_DB) -> np.ndarray:
    """``samples`` with white noise ``below_db`` under the speech added, if they are quieter than that anywhere.

    Synthetic speech has digital silence between words, far quieter than any microphone. pocketsphinx's
    cepstral mean normalisation then skews, and long commands lost their second half ("pick up the red cube
    and put it on the counter" was heard as "pick up the red cube"). Input with that much noise already is left
    as it is.
    """
    power = frame_power(samples)
    if len(power) < 10 or np.percentile(power, 10) >= np.percentile(power, 90) / 10 ** (below_db / 10):
        return samples
    return with_noise(samples, below_db, np.random.default_rng(0))  # seeded: the same input is heard the same


class CommandRecognizer:
    """Decodes utterances (16 kHz mono samples) against the command grammar of a world.

    Whole utterances go to ``transcribe``; a stream goes to ``begin``, ``hear`` (each chunk, returning what is
    heard so far) and ``end``, so that most of the decoding is done while the person is still speaking.
    """

    def __init__(self, world: WorldConfig, dictation: bool = False) -> None:
        from pocketsphinx import Decoder, set_loglevel

        set_loglevel("FATAL")
        self._folder = tempfile.TemporaryDirectory()
        folder = Path(self._folder.name)
        grammar = command_grammar(world)
        (folder / "commands.gram").write_text(grammar)
        dictionary = write_dictionary(grammar, folder / "commands.dict", where=f"world {world.name}")
        self.decoder = Decoder(
            jsgf=str(folder / "commands.gram"), dict=str(dictionary), samprate=RATE, **DECODER_SETTINGS
        )
        self.dictation = FreeDictation() if dictation else None  # what unclear speech was, in any words

    def transcribe(self, samples: np.ndarray) -> Transcript:
        started = time.perf_counter()
        utterance = prepared(samples)
        self.begin()
        self.decoder.process_raw(utterance.tobytes(), full_utt=True)
        transcript = self.end(started)
        if self.dictation is not None and transcript.unclear:
            transcript.dictated = self.dictation.words(utterance)
            transcript.seconds = time.perf_counter() - started
        return transcript

    def begin(self) -> None:
        """Start an utterance of a stream."""
        self.decoder.start_utt()

    def hear(self, chunk: np.ndarray) -> str:
        """Decode the next chunk of the utterance; the best words so far ("" before any)."""
        self.decoder.process_raw(np.asarray(chunk, dtype=np.int16).tobytes(), False, False)
        return heard_words(self.decoder.hyp())

    def end(self, started: float | None = None) -> Transcript:
        """Finish the utterance: what was said, and the time taken since ``started`` (default: now)."""
        started = time.perf_counter() if started is None else started
        self.decoder.end_utt()
        return Transcript(heard_words(self.decoder.hyp()), time.perf_counter() - started)


def heard_words(hypothesis: Hypothesis | None) -> str:
    """A decoder's words as a transcript: single spaces, and UNCLEAR for each stretch of unclear speech."""
    if hypothesis is None:
        return ""
    return " ".join(re.sub(rf"(?:\b{UNCLEAR_SPEECH}\b\s*)+", f"{UNCLEAR} ", hypothesis.hypstr).split())


class FreeDictation:
    """Free dictation: pocketsphinx's general English language model, for what the command grammar cannot tell.

    It hears any words, but poorly and slowly on short commands: "pick up the red cube" as "the government you",
    "make me a cup of tea" as "leave me a cup of tea", in about 0.6 s (the voice benchmark). So it is a fallback
    the person is shown, to see what went wrong, and never a command the robot acts on. It loads on first use.
    """

    def __init__(self) -> None:
        self._decoder: Decoder | None = None

    def words(self, utterance: np.ndarray) -> str:
        """The words of ``utterance`` (as ``prepared`` gives it) in the general model's best guess."""
        if self._decoder is None:
            from pocketsphinx import Decoder

            # The default model (en-us LM, CMUdict); no second (flat) pass: a third faster, no worse on commands
            self._decoder = Decoder(samprate=RATE, dither=True, seed=DECODER_SETTINGS["seed"], fwdflat=False)
        self._decoder.start_utt()
        self._decoder.process_raw(np.asarray(utterance, dtype=np.int16).tobytes(), full_utt=True)
        self._decoder.end_utt()
        return heard_words(self._decoder.hyp())
