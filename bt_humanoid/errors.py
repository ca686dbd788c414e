"""Errors a user can cause. The CLI prints them as one line and exits 2."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


class UserError(Exception):
    """Invalid input: a mission, a parameter, a name. Carries where and what would be valid."""

    def __init__(self, message: str, where: str | None = None, hint: str | None = None) -> None:
        self.message = message
        self.where = where
        self.hint = hint
        super().__init__(str(self))

    def __str__(self) -> str:
        text = f"{self.where}: {self.message}" if self.where else self.message
        if self.hint:
            text += f" ({self.hint})"
        return text


def did_you_mean(name: str, options: Iterable[str]) -> str:
    """'did you mean X?' plus the valid choices, for unknown-name messages."""
    options = sorted(set(options))
    close = difflib.get_close_matches(name, options, n=1, cutoff=0.6)
    valid = ", ".join(options)
    if close:
        return f"did you mean '{close[0]}'? valid: {valid}"
    return f"valid: {valid}"
