"""The recogniser's dictionary and grammar, checked as text: British forms, the grammar's words, what it accepts."""

from collections.abc import Callable

import pytest

from bt_humanoid.errors import UserError
from bt_humanoid.language.asr import command_grammar
from bt_humanoid.language.pronunciation import UNCLEAR_SPEECH, british, grammar_words, write_dictionary
from bt_humanoid.sim.world_config import load_world_config
from bt_humanoid.testing.grammar import finite_state_grammar


@pytest.fixture(scope="module")
def grammar() -> str:
    return command_grammar(load_world_config("apartment"))


def test_a_british_speaker_drops_an_r_that_no_vowel_follows():
    assert british("M IY T ER") == "M IY T AH"  # meter
    assert british("F AO R W ER D") == "F AO W AH D"  # forward
    assert british("W EH R") == "W EH AH"  # where: the r leaves a schwa


def test_an_r_before_a_vowel_is_kept():
    assert british("K AE R IY") == "K AE R IY"  # carry
    assert british("R OW B AA T") == "R OW B AA T"  # robot


def test_half_takes_the_vowel_of_father_but_cat_does_not():
    assert british("HH AE F") == "HH AA F"
    assert british("K AE T") == "K AE T"


def test_grammar_words_leave_out_rule_names_and_comments():
    text = "#JSGF V1.0;\ngrammar g;\npublic <u> = stop | say <what>;  // a stop or a greeting\n<what> = hello;\n"
    assert grammar_words(text) == ["hello", "say", "stop"]


def test_the_dictionary_holds_the_grammars_words_in_both_accents(grammar, tmp_path):
    entries = {}
    for line in write_dictionary(grammar, tmp_path / "words.dict").read_text().splitlines():
        word, phones = line.split(" ", 1)
        entries.setdefault(word.split("(")[0], []).append(phones)
    assert entries["half"] == ["HH AE F", "HH AA F"]
    assert "M IY T AH" in entries["meter"]
    assert {"red", "living", "counter", "robot"} <= set(entries)
    assert "zebra" not in entries  # only what the grammar can say
    assert entries[UNCLEAR_SPEECH] == ["+SPN+"]  # unclear speech is the acoustic model's spoken noise


def test_a_word_the_dictionary_lacks_is_named_with_its_world(tmp_path):
    with pytest.raises(UserError, match=r"^world attic: .*'zorblax'.*\(name objects"):
        write_dictionary("public <u> = pick up the zorblax;", tmp_path / "words.dict", where="world attic")


@pytest.fixture(scope="module")
def accepts(grammar: str, tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], bool]:
    """Whether the grammar's finite-state form (pocketsphinx's own compilation) has a path for some words."""
    folder = tmp_path_factory.mktemp("fsg")
    fsg = finite_state_grammar(grammar, folder)
    start, final, arcs = fsg.start, fsg.final, fsg.arcs

    def closure(states: set[int]) -> set[int]:
        todo, seen = list(states), set(states)
        while todo:
            for to, word in arcs.get(todo.pop(), []):
                if word is None and to not in seen:
                    seen.add(to)
                    todo.append(to)
        return seen

    def accepted(words: str) -> bool:
        states = closure({start})
        for word in words.split():
            states = closure({to for s in states for to, w in arcs.get(s, []) if w == word})
        return final in states

    return accepted


def test_steps_are_joined_by_a_word(accepts):
    assert accepts("go to the table then wave")
    assert accepts("hey robot go to the kitchen and pick up the mug and then bring it to me")
    assert not accepts("wave lift the coffee mug")  # "where is the coffee mug", misheard


def test_the_grammar_holds_what_the_planner_refuses(accepts):
    assert accepts("pick up the table")
    assert accepts("pick up the person")
    assert not accepts("go to the person now")  # the person is "me": "come to me"


def test_unclear_speech_stands_for_a_step_an_object_or_a_surface(accepts):
    unclear = f"{UNCLEAR_SPEECH} {UNCLEAR_SPEECH}"
    assert accepts(unclear)  # "make me a sandwich"
    assert accepts(f"wave and then {unclear}")
    assert accepts(f"bring me the {unclear}")  # "bring me the banana"
    assert accepts(f"put the red cube on the {unclear}")  # "on the ceiling"
    assert not accepts(f"pick up the red {unclear}")  # not after a known word of the same phrase
    assert not accepts(f"turn left {unclear} degrees")  # nor for a number
