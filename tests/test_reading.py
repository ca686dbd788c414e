"""Reading requests as people write them (language/reading.py, phrases.py): what the planner is handed."""

import pytest

from bt_humanoid.language.embedded import known_words
from bt_humanoid.language.phrases import read_wanted
from bt_humanoid.language.reading import correct, read
from bt_humanoid.testing.told import told_planning_context


@pytest.fixture(scope="module")
def known() -> frozenset[str]:
    return known_words(told_planning_context("kitchen"))


@pytest.mark.parametrize(
    ("text", "clauses"),
    [
        ("Could you bring me the wter botle?", ["bring me the water bottle"]),
        ("put the aple on the tabel", ["put the apple on the table"]),
        ("Would you mind grabbing the pepsi for me?", ["grab the pepsi"]),
        ("I'm parched", ["bring me something to drink"]),
        ("I'd like the apple", ["bring me the apple"]),
        (
            "I knocked my drink over. Could you get me something to mop it up?",
            [
                "i knocked my drink over",
                "bring me something to mop it up",
            ],
        ),
        ("I'm thirsty, bring me something", ["bring me something to drink"]),
        ("I'm starving, bring me two snacks", ["bring me two snacks"]),
        ("before you come back, grab the red bull", ["grab the red bull", "come back"]),
        ("1. go to the table 2. pick up the coke", ["go to the table", "pick up the coke"]),
        ("how would you recycle the 7 up can?", ["recycle the 7up can"]),
        ("my desk is sticky, help", ["my desk is sticky", "bring me something to clean with"]),
        ("the coke, bring it here", ["bring the coke here"]),
        ("the apple on the table – compost it", ["compost the apple on the table"]),
        ("the sponge belongs on the far counter", ["put the sponge on the far counter"]),
        ("I want the tea taken to the table", ["put the tea to the table"]),
        ("bring me a snack, anything is fine", ["bring me a snack"]),
        ("come find me", ["come here"]),
        ("go and stand by the trash can", ["go by the trash can"]),
        ("is there anything I can eat?", ["bring me something to eat"]),
        ("I'm off sugar, anything to drink?", ["i am off sugar", "anything to drink without sugar"]),  # kept: context
        ("Bring me the pepsi - actually no, make it a coke.", ["bring me a coke"]),
        ("so thirsty after my run, could you bring me some water pls", ["bring me some water"]),
        (
            "got a splitting headache so no caffeine for me today, but I really want something fizzy",
            ["got a splitting headache", "no caffeine for me today", "bring me something fizzy without caffeine"],
        ),
        (
            "Recycle all the cans on the far counter, but leave the red bull.",
            ["recycle all the cans on the far counter except the red bull"],
        ),
        (
            "a) go to the far counter b) come back with the lime soda",
            ["go to the far counter", "bring me the lime soda"],
        ),
        ("I need to take a tablet. Could I have some water?", ["i need to take a tablet", "bring me some water"]),
        ("My doctor says I need to eat more fruit. Help me out?", ["bring me fruit"]),
        ("Bring me the cola. Not the Pepsi, the other one.", ["bring me the cola but not the pepsi"]),
        ("a) pepsi to the far counter b) energy bar to me", ["pepsi to the far counter", "energy bar to me"]),
        ("(1) visit the compost bin (2) go home", ["visit the compost bin", "go home"]),
        ("When you're done recycling the pepsi, bring me the chips.", ["recycle the pepsi", "bring me the chips"]),
        ("Would you mind terribly putting the apple in the compost?", ["put the apple in the compost"]),
        ("Fancy fetching me a packet of crisps? The yellow ones.", ["fetch me the yellow crisps"]),
        (
            "I think the rice crisps would be better on the table than on the counter",
            ["put the rice crisps on the table"],
        ),
        (
            "Make sure the coke, the pepsi and the tea are all on the table.",
            ["put the coke , the pepsi and the tea on the table"],
        ),
        ("Hmm, maybe the lime one? Yeah, bring me the lime seltzer.", ["bring me the lime seltzer"]),
        ("What's the easiest way for you to get me a protein bar? Go ahead and do it.", ["bring me a protein bar"]),
        ("could I trouble you for the water bottle", ["bring me the water bottle"]),
        ("do we have any sparkling water? I'd like one", ["with sparkling water", "bring me one"]),
        ("hungry!! food pls", ["food"]),
    ],
)
def test_requests_are_read_into_plain_clauses(known, text, clauses):
    assert read(text, known) == clauses


def test_english_words_are_not_corrected_into_names(known):
    assert correct("knocked", known) == "knocked"  # a word of English, not a misspelt "kettle"
    assert correct("botle", known) == "bottle"


def test_object_phrases_say_how_many_which_not_and_from_where():
    surfaces = {"table": "table", "far counter": "far_counter"}
    wanted = read_wanted("two different snacks and a drink", surfaces)
    assert [(i.words, i.count, i.different) for i in wanted.items] == [("snacks", 2, True), ("drink", None, False)]
    every = read_wanted("all the cans on the far counter", surfaces)
    assert every.items[0].every and every.items[0].words == "cans" and every.source == "far_counter"
    but = read_wanted("a drink that is not fizzy", surfaces)
    assert but.items[0].words == "drink" and but.exclude == "fizzy"
    both = read_wanted("both chip bags", surfaces)
    assert both.items[0].count == 2
