"""Questions the robot asks a person while a mission runs, and their yes-or-no answers.

A node's ``ask`` recovery step puts a question out and polls for the answer on later ticks (leaves and
decorators never block). Whoever hears the person (the interactive session, typed or spoken) hands each
line to ``answer()`` while a question is out. Runs with no one to ask have no channel at all.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from enum import Enum

YES = re.compile(r"^\s*(yes|yeah|yep|sure|ok|okay|please|go ahead|try again|do it)\b", re.IGNORECASE)
NO = re.compile(r"^\s*(no|nope|don'?t|do not|stop|cancel|give up|never ?mind|leave it)\b", re.IGNORECASE)


class Answer(Enum):
    YES = "yes"
    NO = "no"


def read_answer(text: str) -> Answer | None:
    """Yes, no, or None when the reply is neither."""
    if NO.match(text):
        return Answer.NO
    if YES.match(text):
        return Answer.YES
    return None


class Questions:
    """One question at a time: ``ask()`` says it, ``answer()`` takes the person's reply, ``take()`` reads it."""

    def __init__(self, say: Callable[[str], None]) -> None:
        self.say = say
        self.pending: str | None = None  # the question that is out, if any
        self._answer: Answer | None = None

    @property
    def awaiting(self) -> bool:
        """A question is out and not yet answered."""
        return self.pending is not None and self._answer is None

    def ask(self, question: str) -> None:
        self.pending, self._answer = question, None
        self.say(question)

    def answer(self, text: str) -> None:
        """A reply from the person; anything but yes or no gets the question repeated."""
        if self.pending is None:
            return
        answer = read_answer(text)
        if answer is None:
            self.say("Please answer yes or no. " + self.pending)
            return
        self._answer = answer

    def take(self) -> Answer | None:
        """The answer, once given (the question is then closed); None while waiting."""
        answer = self._answer
        if answer is not None:
            self.pending, self._answer = None, None
        return answer

    def withdraw(self) -> None:
        self.pending, self._answer = None, None
