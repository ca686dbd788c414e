"""Skills that talk to people."""

from __future__ import annotations

from pydantic import Field

from bt_humanoid.skills.base import Skill
from bt_humanoid.skills.registry import skill
from bt_humanoid.strict_model import StrictModel


class SayParams(StrictModel):
    text: str = Field(min_length=1, max_length=500, description="what to say")


@skill("say", "say something to the people nearby (printed for now)")
class Say(Skill):
    Params = SayParams

    def start(self) -> None:
        self.context.speak(self.params.text)
        self.feedback_message = f'said "{self.params.text}"'
